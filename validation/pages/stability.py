"""Page: the stability matrix (stiff and extreme scenes by every scheme) and a
random-scene campaign."""

from __future__ import annotations

import time
from collections import Counter

from beltsim import solvers
from beltsim.studies.stability import (
    ACCEPTED,
    BOUNDS,
    DISCRETE_BOUNDS,
    DRIVE_BOUNDS,
    DRIVE_CASES,
    DRIVE_DISCRETE_BOUNDS,
    STABILITY_CASES,
    CellStatus,
    stability_markdown,
    stability_matrix,
)
from validation.random_scenes import SKIPPED, failed, random_markdown, random_study

from .kit import Page, num

TITLE = "Stability matrix and random scenes"
#: the coarse matrix of --quick: every case but those about the grid, on this grid
QUICK_ELEMENTS = 60
#: (scenes, seed, elements or None for each scene's default, max wall s) of the campaign,
#: of straight belts and of closed drives, by --quick
RANDOM = {False: (40, 1, None, 900.0), True: (3, 1, None, 120.0)}
RANDOM_DRIVES = {False: (20, 1, None, 900.0), True: (1, 1, 100, 60.0)}


def _status(row) -> str:
    return getattr(row["status"], "value", row["status"])


def matrix_section(page: Page, quick: bool) -> None:
    cases = STABILITY_CASES
    extra = []
    if quick:
        cases = tuple(c for c in cases if not c.sets_grid)
        extra = [("numerics.elements", QUICK_ELEMENTS)]
    command = "beltsim stability" + (f" --elements {QUICK_ELEMENTS}" if quick else "")
    page.heading("The stability matrix")
    page.para(
        f"`{command}`: {len(cases)} stiff and extreme scenes, each derived from a paper "
        f"scene or, the last {len(DRIVE_CASES)}, from the closed drive drive_flat, by "
        f"every registered scheme ({', '.join(solvers.names())}). A cell ends in "
        f"one status: *converged* (steady, within the transient simulator's acceptance "
        f"bounds, " + ", ".join(f"{k} {b:g}" for k, b in BOUNDS.items())
        + "; a drive's, " + ", ".join(f"{k} {b:g}" for k, b in DRIVE_BOUNDS.items())
        + "), *bounded* "
        "(a case run over a fixed span, or a stable but slowly settling one: finite and "
        "bounded throughout), *refused* (a rule of the scene or its numerics, before "
        "anything runs), *not applicable*, *unstable steady state* (the time-accurate run "
        "did not settle and the model linearised about its steady state has a growing "
        "mode), *physical outcome* (a drive's gross slip or lift-off, where it has no "
        "steady state), or a failure: *out of bounds*, *not converged* (a gross slip or "
        "lift-off where the steady state exists counts here), *diverged*.")
    if quick:
        page.para(
            f"This is the coarse matrix of `--quick`: every case on {QUICK_ELEMENTS} "
            f"elements (the case about a very fine grid left out). The acceptance bounds "
            f"are set for each scene's default grid, so a coarse cell is judged against "
            f"the steady scheme's state on the same grid instead, within "
            + ", ".join(f"{k} {b:g}" for k, b in DISCRETE_BOUNDS.items())
            + " (a drive's, " + ", ".join(f"{k} {b:g}" for k, b in
                                          DRIVE_DISCRETE_BOUNDS.items())
            + "): each scheme must reach its grid's steady state.")
    start = time.perf_counter()
    rows = stability_matrix(cases, extra=extra, discrete=quick)
    wall = time.perf_counter() - start
    accepted = ACCEPTED
    for r in rows:
        if r["status"] not in accepted:
            page.fail(f"stability matrix, {r['case']}, {r['scheme']}: {_status(r)} "
                      f"({r['reason']})")
    schemes = list(dict.fromkeys(r["scheme"] for r in rows))
    statuses = [s.value for s in CellStatus if any(r["status"] is s for r in rows)]
    tally = Counter((r["scheme"], _status(r)) for r in rows)
    page.para(f"{len(rows)} cells in {wall:.0f} s of wall time; cells by scheme and status:")
    page.table(["scheme", *statuses, "failed"],
               [[s, *(str(tally[s, st]) for st in statuses),
                 str(sum(1 for r in rows if r["scheme"] == s and r["status"] not in accepted))]
                for s in schemes])
    page.para("Status of every cell:")
    by_case = {}
    for r in rows:
        cell = _status(r)
        if r["status"] not in accepted:
            cell = f"**{cell}**"
        by_case.setdefault(r["case"], {})[r["scheme"]] = cell
    page.table(["case", *schemes], [[case, *(cells.get(s, "") for s in schemes)]
                                    for case, cells in by_case.items()])
    page.para("Every cell in detail (errors against "
              + ("the steady scheme's state on the same grid" if quick else
                 "the exact steady solution of the case") + "; the slip start in metres):")
    page.raw(stability_markdown(rows))


def random_section(page: Page, quick: bool, drives: bool = False) -> None:
    n, seed, elements, max_wall = (RANDOM_DRIVES if drives else RANDOM)[quick]
    extra = [("numerics.elements", elements)] if elements else []
    command = (f"python -m validation.random_scenes {n} --seed {seed}"
               + (" --drives" if drives else "")
               + (f" --elements {elements}" if elements else "")
               + f" --max-wall {num(max_wall)}")
    if drives:
        page.heading("Random closed drives")
        page.para(
            f"`{command}`: {n} valid two-pulley drives drawn across their parameter space "
            f"(radii, centre distance, belt, installation tension, speeds up to rho c^2 = "
            f"0.5 N0, friction coefficient, a load of 0.1 to 0.9 of the capacity, the driven "
            f"pulley's inertia, the beam and the string, inertial and quasistatic; "
            f"validation/random_drives.py), each from rest by every applicable scheme, "
            f"judged by the stability matrix's rules.")
    else:
        page.heading("Random scenes")
        page.para(
            f"`{command}`: {n} valid scenes drawn across the whole parameter space "
            f"(geometry, materials, speeds up to 0.95 of the lower critical speed, "
            f"mismatch, friction, inertia and damping; scene i of seed S is always the same "
            f"scene), each by every applicable scheme on its default grid, judged by the "
            f"stability matrix's rules (the slip start's bound scaled to the grid). Cells "
            f"not started within the wall budget are reported as skipped, not as passed.")
    start = time.perf_counter()
    rows = random_study(n, seed, extra=extra, max_wall=max_wall, drives=drives)
    wall = time.perf_counter() - start
    for r in rows:
        if failed(r):
            page.fail(f"random {'drive' if drives else 'scene'} {r['index']} (seed {seed}), "
                      f"{r['scheme']}: {r['status']} ({r['reason']})")
    skipped = sum(r["status"] == SKIPPED for r in rows)
    text = random_markdown(rows, seed, n, wall, extra, drives)
    # its title becomes a subsection of this page
    lines = text.splitlines()
    if lines and lines[0].startswith("# "):
        lines[0] = "###" + lines[0][1:]
    page.raw("\n".join(lines))
    if skipped:
        page.para(f"{skipped} cells were skipped when the wall budget ran out.")


def build(page: Page, quick: bool) -> None:
    page.para(
        "Robustness, not accuracy: each scheme on scenes chosen to break it (stiff "
        "friction, near-critical speeds, short contacts, undamped belts, extreme Poisson "
        "ratios) and on random scenes. A scheme passes a cell when it delivers the "
        "steady state within the bounds or says why it cannot; it fails when it runs and "
        "does not deliver.")
    matrix_section(page, quick)
    random_section(page, quick)
    random_section(page, quick, drives=True)
