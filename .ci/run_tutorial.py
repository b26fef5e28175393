"""Run the Python API tutorial as a notebook and check what it shows.

Usage: ``python .ci/run_tutorial.py [PAGE] [--save NOTEBOOK]``. The page
(docs/user-guide/python-api.md by default: "a tutorial in the order of a notebook
session") becomes a notebook (jupytext: every ``python`` block a cell), runs top to
bottom in a Jupyter kernel from an empty folder (nbclient), and fails when a cell raises,
when a figure shows twice in one cell (the inline backend's copy and the cell's value:
the same picture twice), when none shows, or when tqdm warns about missing widgets.

It also fails when a line shows a value the code no longer gives: a line that is one
expression with a comment that starts like a Python value (``scene_names()  # ('drive_flat',
...)``) is run as ``_shown(EXPRESSION, COMMENT, LINE)``, which compares the value's repr (or
str) with the comment up to its prose (``: ``, ``; `` or ``, `` outside brackets and quotes),
``...`` standing for any text, as in a doctest.
"""

import argparse
import ast
import io
import re
import sys
import tempfile
import time
import tokenize
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]

#: A comment that shows a value starts like one: a number, a string, a bracket, an object's
#: repr (<...>) or None, True, False
VALUE = re.compile(r"""^(?:[-+(\[{'"<\d]|(?:None|True|False)\b)""")


def shown_value(comment: str) -> str | None:
    """The value a comment shows, cut where its prose starts; None when it shows none."""
    text = comment.strip()
    if not VALUE.match(text):
        return None
    depth, quote = 0, None
    for i, ch in enumerate(text):
        if quote:
            quote = None if ch == quote else quote
        elif ch in "'\"":
            quote = ch
        elif ch in "([{<":
            depth += 1
        elif ch in ")]}>":
            depth -= 1
        elif depth == 0 and text[i:i + 2] in (": ", "; ", ", "):
            return text[:i]
    return text


def ellipsis_match(want: str, got: str) -> bool:
    """Whether ``got`` is ``want`` with each ``...`` standing for any text (doctest's rule)."""
    pieces = want.split("...")
    if len(pieces) == 1:
        return want == got
    first, *middle, last = pieces
    if not (got.startswith(first) and got.endswith(last)
            and len(first) + len(last) <= len(got)):
        return False
    at, end = len(first), len(got) - len(last)
    for piece in middle:
        at = got.find(piece, at, end)
        if at < 0:
            return False
        at += len(piece)
    return True


def _shown(value, want: str, line: int):
    """The kernel's check of a line's value against what its comment shows; the value."""
    if not any(ellipsis_match(want, text) for text in (repr(value), str(value))):
        raise AssertionError(f"tutorial line {line} shows {want}, the code gives {value!r}")
    return value


def checked(source: str, first_line: int) -> str:
    """A cell's source with each line that shows a value wrapped in ``_shown``."""
    out = []
    for number, line in enumerate(source.splitlines(), start=first_line):
        try:
            tokens = list(tokenize.generate_tokens(io.StringIO(line).readline))
        except (tokenize.TokenError, SyntaxError, IndentationError):
            out.append(line)
            continue
        comment = next((t for t in tokens if t.type == tokenize.COMMENT), None)
        want = shown_value(comment.string[1:]) if comment else None
        code = line[:comment.start[1]].rstrip() if comment else ""
        try:
            tree = ast.parse(code) if want and code and not code[0].isspace() else None
        except SyntaxError:
            tree = None
        expression = (tree is not None and len(tree.body) == 1
                      and isinstance(tree.body[0], ast.Expr)
                      and not (isinstance(tree.body[0].value, ast.Call)
                               and getattr(tree.body[0].value.func, "id", "") == "print"))
        out.append(f"_shown(({code}), {want!r}, {number})  {comment.string}" if expression
                   else line)
    return "\n".join(out)


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
    import inspect

    import jupytext
    import nbformat
    from nbclient import NotebookClient
    from nbclient.exceptions import CellExecutionError

    text = Path(args.page).read_text(encoding="utf-8")
    nb = jupytext.reads(text, fmt="md")
    # each code cell's lines that show a value are checked against it; the checker first
    lines, at = text.splitlines(), 0
    for cell in nb.cells:
        if cell.cell_type == "code" and cell.source.strip():
            first = cell.source.splitlines()[0]
            at = next((i for i in range(at, len(lines)) if lines[i].rstrip() == first.rstrip()),
                      None)
            if at is None:  # jupytext changed the cell: its lines cannot be numbered
                print(f"tutorial notebook: FAILED: a cell starting {first!r} is not a block "
                      f"of the page", file=sys.stderr)
                return 1
            cell.source = checked(cell.source, at + 1)
            at += len(cell.source.splitlines())
    helpers = "\n\n".join(inspect.getsource(f) for f in (ellipsis_match, _shown))
    nb.cells.insert(0, nbformat.v4.new_code_cell(helpers))
    nb.metadata["kernelspec"] = {"name": "python3", "display_name": "Python 3",
                                 "language": "python"}
    start = time.perf_counter()
    with tempfile.TemporaryDirectory() as folder:
        try:
            NotebookClient(nb, timeout=600, kernel_name="python3",
                           resources={"metadata": {"path": folder}}).execute()
        except CellExecutionError as error:  # one line: what raised, and where it says so
            print(f"tutorial notebook: FAILED: {error.ename}: {error.evalue}", file=sys.stderr)
            return 1
    code = sum(c.cell_type == "code" for c in nb.cells)
    if args.save:
        nbformat.write(nb, args.save)
    problems = check(nb)
    for problem in problems:
        print(f"tutorial notebook: FAILED: {problem}", file=sys.stderr)
    if not problems:
        shown = sum(len(images(c)) for c in nb.cells)
        values = sum(c.source.count("_shown((") for c in nb.cells[1:])
        print(f"tutorial notebook: {code} cells ran in {time.perf_counter() - start:.0f} s, "
              f"{shown} figures, each shown once; {values} values as their comments show")
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
