"""A new user's first minute: a light `import beltsim`, a notice while the kernels compile,
and the compile or load time beside the solve's wall time."""

import json
import subprocess
import sys
import time

import pytest

import beltsim
from beltsim.cli import format_run
from beltsim.simulation import controller

pytestmark = pytest.mark.unit


def test_import_beltsim_leaves_numba_scipy_and_matplotlib_for_later():
    code = ("import sys, json, beltsim; beltsim.Scene; beltsim.load_scene('paper_slip'); "
            "print(json.dumps(sorted(m for m in ('numba', 'scipy', 'matplotlib', 'numpy') "
            "if m in sys.modules)))")
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                          timeout=120, check=True)
    assert json.loads(proc.stdout) == []


def test_the_exact_solutions_leave_scipy_optimize_out():
    """`beltsim analytic` and beltsim.solve of a scene, a slip front's included, do not
    wait for scipy.optimize (0.3-0.5 s to import): the roots are beltsim's own
    (problem.roots, Brent's method step for step as scipy's)."""
    code = ("import sys, beltsim; beltsim.solve(beltsim.shipped_scene('{}')); "
            "print('scipy.optimize' in sys.modules)")
    for scene in ("paper_quasistatic", "paper_slip", "drive_flat", "serpentine_tensioner"):
        proc = subprocess.run([sys.executable, "-c", code.format(scene)], capture_output=True,
                              text=True, timeout=120, check=True)
        assert proc.stdout.strip() == "False", scene


def test_a_runs_modules_leave_scipy_optimize_and_sparse_out():
    """What `beltsim run` imports before its kernels: no scipy.optimize (0.3-0.5 s) and no
    scipy.sparse (0.1 s), which only the linearisation, the modes and the peers need."""
    code = ("import sys, beltsim.cli, beltsim.simulation.controller, beltsim.io.results, "
            "beltsim.simulation.progress; "
            "print(sorted(m for m in ('scipy.optimize', 'scipy.sparse') if m in sys.modules))")
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                          timeout=120, check=True)
    assert proc.stdout.strip() == "[]"


def test_the_lazy_names_and_subpackages_resolve():
    assert set(beltsim.__all__) <= set(dir(beltsim))
    for name in beltsim.__all__:
        assert getattr(beltsim, name) is not None
    assert beltsim.solvers.settings.resolve is not None  # after a bare `import beltsim`
    with pytest.raises(AttributeError, match="no attribute 'nope'"):
        beltsim.nope  # noqa: B018


class _SlowScheme:
    """Stands for a scheme whose kernels compile: its warm-up takes a while."""

    def __init__(self, seconds):
        self.seconds = seconds

    def warm_up(self, state):
        time.sleep(self.seconds)
        return self.seconds


@pytest.mark.parametrize("notice, seconds, shown", [
    (True, 0.3, True), (True, 0.0, False), (False, 0.3, False)])
def test_a_long_warm_up_says_it_compiles(monkeypatch, capsys, notice, seconds, shown):
    monkeypatch.setattr(controller, "COMPILING_AFTER", 0.05)
    sim = controller.Simulation.__new__(controller.Simulation)
    sim.scheme, sim.state = _SlowScheme(seconds), None
    sim.warm_up(notice=notice)
    time.sleep(0.1)  # a timer that was not cancelled would print by now
    err = capsys.readouterr().err
    assert (controller.COMPILE_NOTICE in err) is shown
    assert err.count("\n") == (1 if shown else 0)


@pytest.mark.parametrize("compile_time, word", [(30.0, "compiling"), (0.3, "loading")])
def test_the_summary_line_states_the_kernels_time_beside_the_wall_time(compile_time, word):
    line = format_run({"converged": True, "steps": 436, "simulated_time": 0.4292,
                       "wall_time": 0.224, "compile_time": compile_time}).splitlines()[0]
    assert line.endswith(f"wall 0.224 s (+ {compile_time:.2g} s {word} the kernels)")
