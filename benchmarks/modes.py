"""A closed drive's modes: the call and the command, with numba's cache warm.

``python -m benchmarks.modes [SCENE] [--repeat R]`` from the repository root (SCENE
defaults to the shipped ``serpentine_accessory``) prints, each the shortest of R:

* the call ``beltsim.modes(scene)`` in a process whose kernels are loaded (the steady
  solve, the linearisation, the shift-invert sweep of the band and the listing);
* ``beltsim modes SCENE --out DIR`` end to end in a fresh process, numba's cache and
  Python's bytecode cache warm (a first process, not counted, fills both): the call plus
  the interpreter, the imports and the kernels' load from the cache;
* ``import beltsim.cli`` with numpy, scipy.sparse and numba in a fresh process, the part
  of the command's wall that is imports before any kernel is loaded.

Last, one line of JSON (:func:`bench`'s dict).
"""

from __future__ import annotations

import os
import subprocess
import sys
import tempfile
import time

REPEAT = 5
_IMPORTS = ("import time; t = time.perf_counter(); import beltsim.cli, numpy, "
            "scipy.sparse.linalg, numba; print(time.perf_counter() - t)")


def log(text):
    print(text, flush=True)


def call_time(scene, repeat: int = REPEAT) -> tuple[float, object]:
    """The shortest wall time (s) of ``beltsim.modes(scene)`` over ``repeat`` calls after
    one that loads the kernels, and the last call's modes."""
    import beltsim

    found = beltsim.modes(scene)
    best = float("inf")
    for _ in range(repeat):
        start = time.perf_counter()
        found = beltsim.modes(scene)
        best = min(best, time.perf_counter() - start)
    return best, found


def command_time(name: str, repeat: int = REPEAT) -> float:
    """The shortest wall time (s) of ``beltsim modes NAME --out DIR`` in a fresh process,
    after one uncounted process that fills the caches."""
    from beltsim.studies.bench import user_env

    env = user_env()
    times = []
    with tempfile.TemporaryDirectory() as out:
        cmd = [sys.executable, "-m", "beltsim.cli", "modes", name, "--out",
               os.path.join(out, "modes")]
        for _ in range(repeat + 1):
            start = time.perf_counter()
            proc = subprocess.run(cmd, env=env, capture_output=True, text=True)
            times.append(time.perf_counter() - start)
            if proc.returncode != 0:
                raise RuntimeError(f"beltsim modes {name} failed: {proc.stderr.strip()}")
    return min(times[1:])


def import_time(repeat: int = REPEAT) -> float:
    """The shortest wall time (s) of the command's imports in a fresh interpreter."""
    from beltsim.studies.bench import user_env

    times = []
    for _ in range(repeat):
        proc = subprocess.run([sys.executable, "-c", _IMPORTS], capture_output=True,
                              text=True, env=user_env())
        if proc.returncode != 0:
            raise RuntimeError(f"the imports failed: {proc.stderr.strip()}")
        times.append(float(proc.stdout))
    return min(times)


def bench(name: str, repeat: int = REPEAT) -> dict:
    """The call's, the command's and the imports' wall times (s) for the shipped scene
    ``name``, with the grid and the number of modes listed."""
    from beltsim.api import shipped_scene

    call, found = call_time(shipped_scene(name), repeat)
    out = {"scene": name, "elements": found.elements, "modes": len(found.modes),
           "eigenvalues": found.eigenvalues, "method": found.method, "call": call,
           "command": command_time(name, repeat), "imports": import_time(repeat)}
    log(f"{name} ({out['elements']} elements, {out['method']}, {out['eigenvalues']} "
        f"eigenvalues, {out['modes']} modes listed): call {call:.3f} s, command "
        f"{out['command']:.3f} s, imports {out['imports']:.3f} s (shortest of {repeat})")
    return out


def main(argv=None) -> int:
    import argparse

    from .drive import emit

    p = argparse.ArgumentParser(prog="python -m benchmarks.modes")
    p.add_argument("scene", nargs="?", default="serpentine_accessory")
    p.add_argument("--repeat", type=int, default=REPEAT)
    p.add_argument("--json", default=None, help="also write the dict to this file")
    args = p.parse_args(argv)
    emit(bench(args.scene, args.repeat), args.json)
    return 0


if __name__ == "__main__":
    sys.exit(main())
