"""Run the Python API tutorial as a notebook and check what it shows.

Usage: ``python .ci/run_tutorial.py [PAGE] [--save NOTEBOOK]``. The page
(docs/user-guide/python-api.md by default: "a tutorial in the order of a notebook
session") becomes a notebook (jupytext: every ``python`` block a cell), runs top to
bottom in a Jupyter kernel from an empty folder (nbclient), and fails when a cell raises,
when a figure shows twice in one cell (the inline backend's copy and the cell's value:
the same picture twice), when none shows, or when tqdm warns about missing widgets.
"""

import argparse
import sys
import tempfile
import time
from pathlib import Path

import jupytext
import nbformat
from nbclient import NotebookClient

ROOT = Path(__file__).resolve().parents[1]


def images(cell) -> list[str]:
    """The PNG pictures a cell's outputs show, in order."""
    return [out["data"]["image/png"] for out in cell.get("outputs", ())
            if out.get("output_type") in ("display_data", "execute_result")
            and "image/png" in out.get("data", {})]


def check(nb) -> list[str]:
    """What is wrong with an executed notebook, one line a problem."""
    problems, total = [], 0
    for number, cell in enumerate(nb.cells):
        if cell.cell_type != "code":
            continue
        shown = images(cell)
        total += len(shown)
        if len(set(shown)) < len(shown):
            first = cell.source.strip().splitlines()[-1]
            problems.append(f"cell {number} shows a figure {len(shown) - len(set(shown)) + 1} "
                            f"times ({len(shown)} pictures, {len(set(shown))} different; "
                            f"last line {first!r})")
        for out in cell.get("outputs", ()):
            if out.get("output_type") == "stream" and "IProgress" in out.get("text", ""):
                problems.append(f"cell {number}: tqdm warns: {out['text'].strip()[:120]}")
    if not total:
        problems.append("no cell shows a figure")
    return problems


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("page", nargs="?", default=ROOT / "docs/user-guide/python-api.md")
    parser.add_argument("--save", default=None, help="write the executed notebook here")
    args = parser.parse_args(argv)
    nb = jupytext.read(args.page, fmt="md")
    nb.metadata["kernelspec"] = {"name": "python3", "display_name": "Python 3",
                                 "language": "python"}
    start = time.perf_counter()
    with tempfile.TemporaryDirectory() as folder:
        NotebookClient(nb, timeout=600, kernel_name="python3",
                       resources={"metadata": {"path": folder}}).execute()
    code = sum(c.cell_type == "code" for c in nb.cells)
    if args.save:
        nbformat.write(nb, args.save)
    problems = check(nb)
    for problem in problems:
        print(f"tutorial notebook: FAILED: {problem}", file=sys.stderr)
    if not problems:
        shown = sum(len(images(c)) for c in nb.cells)
        print(f"tutorial notebook: {code} cells ran in {time.perf_counter() - start:.0f} s, "
              f"{shown} figures, each shown once")
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
