"""The verification pages of the documentation, from fresh runs.

``python -m validation.pages [--quick] [--out DIR] [--pages NAME,...]`` runs the
verification studies through beltsim's own API and writes one Markdown page each, with
its figures, into DIR (default ``docs/verification``), and ``index.md`` with their
toctree. ``--quick`` runs every study on small grids and short ladders (minutes, for
CI); without it the studies run as the committed pages show them.

Exit status: 0 when every study ran and every cell passed; 1 when a cell failed or a
study could not run (its page says which and why); 2 when an input is missing (a
shipped scene not installed) or an option is bad.
"""

from __future__ import annotations

import sys
import time
from pathlib import Path

from .kit import (
    ROOT,
    Page,
    command_line,
    commit,
    describe_machine,
    log,
    machine_facts,
    write_index,
)

DEFAULT_OUT = ROOT / "docs" / "verification"

INDEX_TITLE = "Verification"
INDEX_INTRO = (
    "How beltsim is checked against exact solutions, with the numbers of the last run. "
    "Each page below is written whole by `python -m validation.pages` from fresh runs "
    "through beltsim's own API, and names the command, the commit and the hash of the "
    "sources that produced it (`python -m validation.pages.stamps` checks that no page is "
    "older than its code); "
    "`python -m validation.pages --quick` runs the same studies on small grids (CI runs "
    "it). A failed run is shown as failed on its page, and the command exits non-zero. "
    "The last page, the cross-check against Exudyn, is written by hand from the output "
    "of `validation/exudyn_drive.py` (Exudyn is not a dependency of beltsim).")

#: Pages written by hand, not by this command, listed in the index after the generated ones
HAND_WRITTEN = ("exudyn",)


def _pages():
    """(name, title, build) of every page, in reading order."""
    from . import (
        balance,
        convergence,
        drive,
        end_states,
        flutter,
        paper,
        paths,
        serpentine,
        spectrum,
        stability,
        stability_map,
    )

    return (("paper", paper.TITLE, paper.build),
            ("end_states", end_states.TITLE, end_states.build),
            ("convergence", convergence.TITLE, convergence.build),
            ("paths", paths.TITLE, paths.build),
            ("spectrum", spectrum.TITLE, spectrum.build),
            ("stability_map", stability_map.TITLE, stability_map.build),
            ("flutter", flutter.TITLE, flutter.build),
            ("stability", stability.TITLE, stability.build),
            ("balance", balance.TITLE, balance.build),
            ("drive", drive.TITLE, drive.build),
            ("serpentine", serpentine.TITLE, serpentine.build))


def run_page(name: str, title: str, build, quick: bool, out: Path, command: str, sha: str,
             machine: str) -> Page:
    """Build one page; a study that raises leaves a page that says why (never a traceback
    in place of a page, never a page that looks complete)."""
    from beltsim.errors import MissingInputError

    from . import stamps

    page = Page(name, title, command, sha, out, machine,
                source_hash=stamps.page_hash(f"verification/{name}.md"))
    try:
        build(page, quick)
    except MissingInputError as exc:
        page.abort(f"missing input: {exc}", missing_input=True)
    except Exception as exc:  # noqa: BLE001  any failure of a study is reported, not hidden
        page.abort(f"{type(exc).__name__}: {exc}")
    return page


def main(argv=None) -> int:
    from beltsim.cli import OneLineParser

    argv = list(sys.argv[1:] if argv is None else argv)
    pages = _pages()
    names = [p[0] for p in pages]
    parser = OneLineParser(prog="python -m validation.pages",
                           description="Write the verification pages from fresh runs.")
    parser.add_argument("--quick", action="store_true",
                        help="small grids and short ladders (for CI)")
    parser.add_argument("--out", type=Path, default=DEFAULT_OUT,
                        help="output directory (default docs/verification)")
    parser.add_argument("--pages", default=None, metavar="NAME,...",
                        help=f"only these pages ({', '.join(names)}); the index lists all")
    args = parser.parse_args(argv)
    chosen = names
    if args.pages is not None:
        chosen = [n.strip() for n in args.pages.split(",") if n.strip()]
        unknown = [n for n in chosen if n not in names]
        if unknown or not chosen:
            parser.error(f"--pages: unknown page {', '.join(unknown) or '(none)'} "
                         f"(pages: {', '.join(names)})")

    import matplotlib
    matplotlib.use("Agg")  # a script's figures go to files: no display

    command = command_line("validation.pages", argv)
    sha = commit()
    machine = describe_machine(machine_facts())
    status = 0
    start = time.perf_counter()
    for name, title, build in pages:
        if name not in chosen:
            continue
        t0 = time.perf_counter()
        log(f"{name}: running")
        page = run_page(name, title, build, args.quick, args.out, command, sha, machine)
        path = page.write()
        took = time.perf_counter() - t0
        if page.aborted is not None:
            log(f"{name}: FAILED ({page.aborted}); wrote {path} in {took:.0f} s")
            status = max(status, 2 if page.missing_input else 1)
        elif page.failures:
            log(f"{name}: {len(page.failures)} failed cells; wrote {path} in {took:.0f} s")
            for f in page.failures:
                log(f"  {f}")
            status = max(status, 1)
        else:
            log(f"{name}: wrote {path} in {took:.0f} s")
    index = write_index(args.out, INDEX_TITLE, INDEX_INTRO, names + list(HAND_WRITTEN),
                        command, sha)
    log(f"wrote {index}; {time.perf_counter() - start:.0f} s in all, exit status {status}")
    return status
