"""Source stamps of the generated pages: which code each page's numbers come from, and
whether a committed page is older than that code.

Each generated page declares the source files its numbers depend on (:data:`SOURCES`:
the engine, its study modules, its own script) and carries their hash, written by
:meth:`validation.pages.kit.Page.markdown` as the MyST comment ``% source hash: HASH``.
The hash is over the code alone: comments and docstrings (any statement that is only a
string) are left out, so an edit of prose leaves every page current. A page is stale
when the hash of its sources now differs from the one it carries; only the pages whose
sources changed go stale, not every page on every commit.

A page written before the stamps (no ``% source hash``) is checked against the commit its
header names: the hash of its sources in that commit (``git show``), compared in the
same way. ``--restamp`` writes the stamp into such a page when that hash is the current
one: the page was made from the code there is now.

``python -m validation.pages.stamps [--restamp] [--report]`` checks every page of
``docs/verification`` and ``docs/performance`` (a few seconds). Exit status 0 when every
page is current; 1 when one is stale or cannot be checked, each named with the command
that rewrites it; with ``--report`` (CI's) 0 after naming them.
"""

from __future__ import annotations

import functools
import hashlib
import io
import re
import subprocess
import sys
import tokenize
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]

#: What every page's numbers come from: the model, the schemes, the scenes and the run
ENGINE = ("src/beltsim/physics", "src/beltsim/solvers", "src/beltsim/problem",
          "src/beltsim/simulation", "src/beltsim/api.py", "validation/pages/kit.py")
#: the closed drive's own modules
DRIVE = ("src/beltsim/beltdrive",)

#: Each generated page (its path under docs/) and the sources its numbers depend on, with
#: the command that writes it
SOURCES = {
    "verification/paper.md": (*ENGINE, "src/beltsim/studies/paper.py",
                              "src/beltsim/studies/sweep.py", "validation/pages/paper.py"),
    "verification/end_states.md": (*ENGINE, "src/beltsim/studies/convergence.py",
                                   "src/beltsim/studies/stability.py",
                                   "validation/pages/end_states.py"),
    "verification/convergence.md": (*ENGINE, "src/beltsim/studies/convergence.py",
                                     "validation/pages/convergence.py"),
    "verification/paths.md": (*ENGINE, "validation/pages/paths.py"),
    "verification/spectrum.md": (*ENGINE, "validation/pages/spectrum.py"),
    "verification/stability_map.md": (*ENGINE, "src/beltsim/studies/stability_map.py",
                                       "validation/pages/stability_map.py"),
    "verification/flutter.md": (*ENGINE, "src/beltsim/studies/flutter.py",
                                "validation/pages/spectrum.py", "validation/pages/flutter.py"),
    "verification/stability.md": (*ENGINE, "src/beltsim/studies/stability.py",
                                   "validation/pages/stability.py"),
    "verification/balance.md": (*ENGINE, "validation/pages/balance.py"),
    "verification/drive.md": (*ENGINE, *DRIVE, "validation/slip_fronts.py",
                             "validation/pages/drive.py"),
    "verification/serpentine.md": (*ENGINE, *DRIVE, "runs", "validation/slip_fronts.py",
                                  "validation/pages/serpentine.py"),
    "performance/timings.md": (*ENGINE, *DRIVE, "src/beltsim/studies/bench.py",
                               "benchmarks"),
}
COMMANDS = {"verification": "python -m validation.pages --pages {name}",
            "performance": "python -m benchmarks.pages"}

STAMP = re.compile(r"^% source hash: ([0-9a-f]{16})$", re.MULTILINE)
COMMIT = re.compile(r"at\s+commit\s+`([^`]+)`")


def code_of(text: str) -> str:
    """Python source without its comments, docstrings and blank lines (a file that does
    not tokenize is taken as it is)."""
    try:
        tokens = list(tokenize.generate_tokens(io.StringIO(text).readline))
    except (tokenize.TokenError, SyntaxError):
        return text
    starts = [0]
    for line in text.splitlines(keepends=True):
        starts.append(starts[-1] + len(line))

    def offset(pos):
        return starts[pos[0] - 1] + pos[1]

    drop, line = [], []
    skip = (tokenize.NL, tokenize.INDENT, tokenize.DEDENT, tokenize.ENCODING,
            tokenize.ENDMARKER)
    for tok in tokens:
        if tok.type == tokenize.COMMENT:
            drop.append((offset(tok.start), offset(tok.end)))
        elif tok.type == tokenize.NEWLINE:
            if line and all(t.type == tokenize.STRING for t in line):  # a docstring
                drop.extend((offset(t.start), offset(t.end)) for t in line)
            line = []
        elif tok.type not in skip:
            line.append(tok)
    kept, at = [], 0
    for a, b in sorted(drop):
        kept.append(text[at:a])
        at = max(at, b)
    kept.append(text[at:])
    lines = (ln.rstrip() for ln in "".join(kept).splitlines())
    return "\n".join(ln for ln in lines if ln)


@functools.cache
def _file_digest(path: str, data: bytes) -> bytes:
    """One file's part of a hash: its code alone for Python (pages share most files)."""
    text = data.decode("utf-8")
    body = code_of(text) if path.endswith(".py") else text
    return hashlib.sha256(f"{path}\0{body}".encode()).digest()


def _digest(files) -> str:
    """The hash of (path, content) pairs, Python files by their code alone."""
    h = hashlib.sha256()
    for path, data in sorted(files):
        h.update(_file_digest(path, data))
    return h.hexdigest()[:16]


def _wanted(path: str) -> bool:
    return path.endswith((".py", ".toml")) and "__pycache__" not in path


def source_hash(sources, root: Path = ROOT) -> str:
    """The hash of the files under ``sources`` (paths relative to ``root``) now."""
    files = []
    for src in sources:
        p = root / src
        for f in ([p] if p.is_file() else sorted(p.rglob("*"))):
            rel = f.relative_to(root).as_posix()
            if f.is_file() and _wanted(rel):
                files.append((rel, f.read_bytes()))
    return _digest(files)


def _git(*args, stdin: bytes | None = None) -> bytes:
    return subprocess.run(["git", "-C", str(ROOT), *args], capture_output=True, input=stdin,
                          timeout=60, check=True).stdout


def source_hash_at(commit: str, sources) -> str:
    """The hash of the files under ``sources`` in ``commit`` (git, read in one batch)."""
    rows = [line.split("\t", 1) for line in
            _git("ls-tree", "-r", commit, "--", *sources).decode().splitlines()]
    rows = [(meta.split()[2], name) for meta, name in rows if _wanted(name)]
    out = _git("cat-file", "--batch", stdin="".join(f"{sha}\n" for sha, _ in rows).encode())
    files, at = [], 0
    for _, name in rows:  # each object: "<sha> blob <size>\n<content>\n"
        eol = out.index(b"\n", at)
        size = int(out[at:eol].split()[2])
        files.append((name, out[eol + 1:eol + 1 + size]))
        at = eol + 1 + size + 1
    return _digest(files)


def page_hash(key: str) -> str:
    """The current hash of a page's sources (``key`` as in :data:`SOURCES`); empty for a
    page that declares none (a test's page: every page of the docs declares its own)."""
    return source_hash(SOURCES[key]) if key in SOURCES else ""


def stamp_line(digest: str) -> str:
    """The page's stamp: a MyST comment, not shown."""
    return f"% source hash: {digest}"


def check(key: str, restamp: bool = False) -> str | None:
    """None when the page is current, else why it is not; with ``restamp``, a current
    page without a stamp gets one."""
    path = ROOT / "docs" / key
    text = path.read_text(encoding="utf-8")
    now = page_hash(key)
    found = STAMP.search(text)
    if found:
        return None if found.group(1) == now else "its sources changed since it was written"
    made = COMMIT.search(text)
    if made is None or " " in made.group(1) or made.group(1) == "unknown":
        return (f"no source hash, and made at {made.group(1) if made else 'no commit'}: "
                f"cannot tell")
    try:
        then = source_hash_at(made.group(1), SOURCES[key])
    except (OSError, subprocess.SubprocessError) as exc:
        return f"no source hash, and git cannot read commit {made.group(1)}: {exc}"
    if then != now:
        return f"its sources changed since commit {made.group(1)}, where it was written"
    if restamp:
        title, rest = text.split("\n", 1)
        path.write_text(f"{title}\n{stamp_line(now)}\n{rest}", encoding="utf-8")
    return None


def main(argv=None) -> int:
    argv = list(sys.argv[1:] if argv is None else argv)
    restamp = "--restamp" in argv
    report = "--report" in argv  # name the stale pages, exit 0 (what CI runs)
    stale = 0
    for key in SOURCES:
        why = check(key, restamp)
        if why is not None:
            section, name = key.split("/")
            command = COMMANDS[section].format(name=name.removesuffix(".md"))
            print(f"docs/{key} is stale: {why}; rewrite it with `{command}`")
            stale += 1
    print(f"page stamps: {len(SOURCES) - stale} of {len(SOURCES)} pages current")
    return 1 if stale and not report else 0


if __name__ == "__main__":
    sys.exit(main())
