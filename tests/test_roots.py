"""beltsim's Brent root finder against scipy.optimize.brentq, whose algorithm it ports.

Every root the exact solutions solve for is found again by both, from the same bracket and
tolerances: the same root to the last bit (far inside the 1e-15 relative the exact
solutions ask of it) and the same calls of the function. The exact states of the shipped
scenes are the same with either finder.
"""

import math

import numpy as np
import pytest
from scipy import optimize

import beltsim
from beltsim.beltdrive import analytic as drive_analytic
from beltsim.beltdrive import arm, creep, tensioner
from beltsim.problem import analytic, roots

pytestmark = pytest.mark.unit

#: every module that solves a root, and so every place a recording finder goes
USERS = (analytic, drive_analytic, creep, arm, tensioner)

#: scenes whose exact state solves roots: the straight belt's slip front, the string's
#: and the beam's tight-span tension, the creep law's, and a tensioner's rest angle
SCENES = ("paper_slip", "drive_flat", "drive_load_step", "serpentine_accessory",
          "serpentine_tensioner", "serpentine_machine")


def _scipy(f, a, b, **kw):
    x, r = optimize.brentq(f, a, b, full_output=True, **kw)
    # scipy leaves the iterations unset when f(a) or f(b) is 0: no iteration then
    return x, r.iterations if r.function_calls > 2 else 0, r.function_calls


def _ours(f, a, b, **kw):
    return roots.brentq(f, a, b, full_output=True, **kw)


def _recorded(monkeypatch, name):
    """The brackets of the roots the exact state of scene ``name`` solves for."""
    calls = []

    def recording(f, a, b, *args, **kw):
        calls.append((f, a, b, args, kw))
        return roots.brentq(f, a, b, *args, **kw)

    for module in USERS:
        monkeypatch.setattr(module, "brentq", recording)
    analytic.clear_cache()  # an earlier test's solve of the scene would be reused
    beltsim.solve(name)
    return calls


@pytest.mark.parametrize("name", SCENES)
def test_same_root_as_scipy_on_the_exact_states_residuals(monkeypatch, name):
    calls = _recorded(monkeypatch, name)
    assert calls, f"{name}: no root solved"
    for f, a, b, args, kw in calls:
        assert not args  # the callers pass tolerances by name
        ours, theirs = _ours(f, a, b, **kw), _scipy(f, a, b, **kw)
        # the root to the bit (so within 1e-15 relative), its iterations and its calls
        assert ours == theirs


@pytest.mark.parametrize("name", SCENES)
def test_exact_states_unchanged(monkeypatch, name):
    ours = beltsim.solve(name).summary()
    for module in USERS:
        monkeypatch.setattr(module, "brentq", optimize.brentq)
    theirs = beltsim.solve(name).summary()
    assert ours.keys() == theirs.keys()
    for key, value in theirs.items():
        if isinstance(value, float):
            assert ours[key] == pytest.approx(value, rel=1e-15, abs=0.0), key
        else:
            assert np.all(np.asarray(ours[key]) == np.asarray(value)), key


FUNCTIONS = [
    (lambda x: x * x - 2.0, 0.0, 2.0),
    (lambda x: math.cos(x) - x, 0.0, 1.0),
    (lambda x: math.exp(x) - 1e3, -5.0, 20.0),
    (lambda x: (x - 1.0) ** 3, -3.0, 4.0),  # a triple root: slow, many bisections
    (lambda x: math.atan(1e6 * (x - 0.3)), -1.0, 1.0),  # a step
    (lambda x: x ** 9 - 1e-20, 0.0, 1.0),
    (lambda x: math.tanh(x) + 1e-300, -800.0, 10.0),  # f(a) rounds to about 1e-300
    (lambda x: x, -1.0, 1.0),  # the root at the bracket's middle
    (lambda x: x - 1.0, 1.0, 3.0),  # f(a) = 0
    (lambda x: x - 3.0, 1.0, 3.0),  # f(b) = 0
]


@pytest.mark.parametrize("f, a, b", FUNCTIONS)
@pytest.mark.parametrize("xtol, rtol", [(2e-12, roots.RTOL), (1e-15, 1e-15), (1e-3, 1e-6)])
def test_same_root_as_scipy_on_awkward_functions(f, a, b, xtol, rtol):
    kw = {"xtol": xtol, "rtol": rtol, "maxiter": 500}
    assert _ours(f, a, b, **kw) == _scipy(f, a, b, **kw)
    assert _ours(f, b, a, **kw) == _scipy(f, b, a, **kw)  # a reversed bracket


def test_args_passed_to_the_function():
    def f(x, c, d):
        return x * x - c - d

    assert roots.brentq(f, 0.0, 3.0, args=(1.0, 1.0)) == optimize.brentq(f, 0.0, 3.0,
                                                                        args=(1.0, 1.0))


def test_failures_as_scipy():
    with pytest.raises(ValueError, match="different signs"):
        roots.brentq(lambda x: x * x + 1.0, -1.0, 1.0)
    with pytest.raises(ValueError, match="NaN"):
        roots.brentq(lambda x: math.nan, -1.0, 1.0)
    with pytest.raises(ValueError, match="xtol"):
        roots.brentq(lambda x: x, -1.0, 1.0, xtol=0.0)
    with pytest.raises(ValueError, match="rtol"):
        roots.brentq(lambda x: x, -1.0, 1.0, rtol=1e-16)
    with pytest.raises(RuntimeError, match="converge"):
        roots.brentq(lambda x: (x - 1.0) ** 3, -3.0, 4.0, xtol=1e-300, rtol=roots.RTOL,
                     maxiter=3)
