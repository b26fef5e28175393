"""Documentation pages written by scripts: Markdown (MyST) with the command, the commit
and the hash of the sources that produced it at the top (:mod:`validation.pages.stamps`),
tables and figures (PNG beside the page), and every failure in view.

A page is rebuilt whole by its command: prose, tables and figures alike. A cell that
failed is written as failed and recorded (:meth:`Page.fail`), and a study that could not
run at all leaves a page that says so (:meth:`Page.abort`); the scripts then exit
non-zero, so a page never passes off a failure as a result.
"""

from __future__ import annotations

import math
import os
import platform
import shlex
import subprocess
import sys
import textwrap
from dataclasses import dataclass, field
from pathlib import Path

from beltsim.io.files import atomic_path, prepare_outdir, write_atomic

ROOT = Path(__file__).resolve().parents[2]
FAILED = "**failed**"  # a table cell whose run failed
WIDTH = 92  # prose is wrapped here, so that a regenerated page diffs line by line


def commit() -> str:
    """The short hash of the checkout's HEAD ("unknown" outside a git checkout), marked
    "+ uncommitted changes" when the code that makes the numbers (src/, validation/,
    benchmarks/) differs from it."""
    def git(*args):
        return subprocess.run(["git", "-C", str(ROOT), *args], capture_output=True,
                              text=True, timeout=30, check=False)
    try:
        head = git("rev-parse", "--short", "HEAD")
        if head.returncode != 0:
            return "unknown"
        dirty = git("status", "--porcelain", "--", "src", "validation", "benchmarks")
    except (OSError, subprocess.SubprocessError):
        return "unknown"
    return head.stdout.strip() + (" + uncommitted changes" if dirty.stdout.strip() else "")


def command_line(module: str, argv) -> str:
    """The command as typed: ``python -m MODULE ARGS``."""
    return shlex.join(["python", "-m", module, *argv])


def cpu_model() -> str:
    """The CPU's model name from /proc/cpuinfo (the platform's processor string elsewhere)."""
    try:
        with open("/proc/cpuinfo", encoding="utf-8") as fh:
            for line in fh:
                if line.startswith("model name"):
                    return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor() or "unknown"


def machine_facts() -> dict:
    """CPU, cores, load at the start, Python and the numerical libraries' versions."""
    import numba
    import numpy
    import scipy

    try:
        usable = len(os.sched_getaffinity(0))
    except AttributeError:
        usable = os.cpu_count()
    try:
        load = os.getloadavg()[0]
    except OSError:
        load = float("nan")
    return {"cpu": cpu_model(), "cores": os.cpu_count(), "usable_cores": usable,
            "load": load, "python": platform.python_version(), "numpy": numpy.__version__,
            "scipy": scipy.__version__, "numba": numba.__version__,
            "system": f"{platform.system()} {platform.machine()}"}


def describe_machine(facts: dict) -> str:
    return (f"{facts['cpu']}, {facts['cores']} cores ({facts['usable_cores']} usable), "
            f"{facts['system']}, load average {facts['load']:.2f} at the start; Python "
            f"{facts['python']}, numpy {facts['numpy']}, scipy {facts['scipy']}, numba "
            f"{facts['numba']}")


def fmt(value, spec: str = ".3g") -> str:
    """A number for a table: empty for None or NaN, else formatted with ``spec``."""
    if value is None:
        return ""
    if isinstance(value, float) and not math.isfinite(value):
        return "" if math.isnan(value) else str(value)
    return format(value, spec)


def num(value: float) -> str:
    """A parameter as one would type it: 250, 0.5, 6e-6, 1e7, 2^-13 as 0.00012207..."""
    if value == 0 or 1e-3 <= abs(value) < 1e5:
        return f"{value:.6g}"
    mantissa, exponent = f"{value:.5e}".split("e")
    return f"{mantissa.rstrip('0').rstrip('.')}e{int(exponent)}"


def wrap(text: str) -> str:
    """A paragraph of prose wrapped at WIDTH (inline code is never split inside a word)."""
    return textwrap.fill(" ".join(text.split()), WIDTH, break_long_words=False,
                         break_on_hyphens=False)


def decorate(ax, xlabel: str, ylabel: str, title: str) -> None:
    """Labels, a small title and legend, and a light grid (both ticks on log axes)."""
    ax.set_xlabel(xlabel)
    ax.set_ylabel(ylabel)
    ax.set_title(title, fontsize=10)
    ax.legend(fontsize=7)
    ax.grid(True, which="both", alpha=0.3)


def md_table(header, rows) -> str:
    """A Markdown table; ``|`` inside a cell is escaped."""
    def cell(v):
        return str(v).replace("|", "\\|").replace("\n", " ")
    lines = ["| " + " | ".join(cell(h) for h in header) + " |",
             "|" + "---|" * len(header)]
    lines += ["| " + " | ".join(cell(v) for v in row) + " |" for row in rows]
    return "\n".join(lines)


@dataclass
class Page:
    """One Markdown page and its figures, in ``out`` as ``<name>.md`` and ``<name>_*.png``."""

    name: str
    title: str
    command: str
    commit: str
    out: Path
    machine: str = ""
    #: the hash of the sources its numbers come from (:mod:`validation.pages.stamps`)
    source_hash: str = ""
    blocks: list = field(default_factory=list)
    failures: list = field(default_factory=list)
    aborted: str | None = None
    missing_input: bool = False

    # content ------------------------------------------------------------
    def heading(self, text: str, level: int = 2) -> None:
        self.blocks.append("#" * level + " " + text)

    def para(self, text: str) -> None:
        self.blocks.append(wrap(text))

    def bullets(self, items) -> None:
        self.blocks.append("\n".join(textwrap.fill(
            " ".join(str(i).split()), WIDTH, initial_indent="- ", subsequent_indent="  ",
            break_long_words=False, break_on_hyphens=False) for i in items))

    def table(self, header, rows) -> None:
        self.blocks.append(md_table(header, rows))

    def code(self, text: str, language: str = "text") -> None:
        self.blocks.append(f"```{language}\n{text.rstrip()}\n```")

    def raw(self, markdown: str) -> None:
        self.blocks.append(markdown.rstrip())

    def figure(self, fig, stem: str, caption: str, dpi: int = 110) -> Path:
        """Save a matplotlib figure as ``<name>_<stem>.png`` beside the page and show it."""
        import matplotlib.pyplot as plt

        path = self.figure_path(stem)
        try:
            with atomic_path(path, suffix=".png") as tmp:
                fig.savefig(tmp, dpi=dpi)
        finally:
            plt.close(fig)
        self.image(path, caption)
        return path

    def figure_path(self, stem: str) -> Path:
        """Where a figure drawn by another writer goes (then shown with :meth:`image`)."""
        prepare_outdir(self.out)
        return self.out / f"{self.name}_{stem}.png"

    def image(self, path: Path, caption: str) -> None:
        """Show a PNG of the page's directory, captioned."""
        self.blocks.append(f"```{{figure}} {Path(path).name}\n:alt: {' '.join(caption.split())}"
                           f"\n\n{wrap(caption)}\n```")

    # failures -----------------------------------------------------------
    def fail(self, what: str) -> str:
        """Record a failed cell; returns the table cell that shows it."""
        self.failures.append(" ".join(str(what).split()))
        return FAILED

    def abort(self, reason: str, missing_input: bool = False) -> None:
        """The study could not run: the page says so at the top."""
        self.aborted = " ".join(str(reason).split())
        self.missing_input = self.missing_input or missing_input

    @property
    def ok(self) -> bool:
        return not self.failures and self.aborted is None

    # output -------------------------------------------------------------
    def markdown(self) -> str:
        source = f" (source hash `{self.source_hash}`)" if self.source_hash else ""
        head = [f"# {self.title}", wrap(
            f"Generated by `{self.command}` at commit `{self.commit}`{source}. Every number "
            f"and figure on this page comes from that run; the page is rewritten whole by "
            f"the command and is not edited by hand.")]
        if self.source_hash:  # what validation.pages.stamps checks (a comment, not shown)
            head[0] += f"\n% source hash: {self.source_hash}"
        if self.machine:
            head.append(wrap(f"Machine: {self.machine}."))
        if self.aborted is not None:
            head.append("```{error}\n" + wrap(f"This study did not run to the end: "
                                               f"{self.aborted}") + "\n```")
        if self.failures:
            items = "\n".join(f"- {f}" for f in self.failures)
            head.append("```{error}\n" + f"{len(self.failures)} failed "
                        f"{'cell' if len(self.failures) == 1 else 'cells'} in this run:\n\n"
                        + items + "\n```")
        return "\n\n".join(head + self.blocks) + "\n"

    def write(self) -> Path:
        prepare_outdir(self.out)
        path = self.out / f"{self.name}.md"
        write_atomic(path, self.markdown())
        return path


def write_index(out: Path, title: str, intro: str, pages, command: str, sha: str) -> Path:
    """``index.md``: the section's title, a paragraph and a toctree of ``pages`` (names)."""
    text = "\n\n".join([
        f"# {title}", wrap(intro),
        wrap(f"Written by `{command}` at commit `{sha}`."),
        "```{toctree}\n:maxdepth: 1\n\n" + "\n".join(pages) + "\n```"]) + "\n"
    prepare_outdir(out)
    path = Path(out) / "index.md"
    write_atomic(path, text)
    return path


def log(message: str) -> None:
    print(message, file=sys.stderr, flush=True)


def observed_orders(h, e):
    """The observed orders of errors ``e`` over element sizes ``h``: log(e1 / e2) /
    log(h1 / h2) for each successive pair, and the least-squares slope of log abs(e)
    against log h over the nonzero errors (None with fewer than two)."""
    import numpy as np

    h, e = np.asarray(h, dtype=float), np.abs(np.asarray(e, dtype=float))
    ok = e > 0
    if ok.sum() < 2:
        return None, None
    with np.errstate(divide="ignore", invalid="ignore"):
        pairs = np.log(e[:-1] / e[1:]) / np.log(h[:-1] / h[1:])
    return pairs, float(np.polyfit(np.log(h[ok]), np.log(e[ok]), 1)[0])
