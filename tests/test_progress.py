"""The progress bar's total: the estimated time of steady state, not t_end."""

import io
import math

import pytest

from beltsim.simulation import progress
from beltsim.simulation.progress import SteadyEstimate, set_total
from beltsim.simulation.trackers import progress_bar

pytestmark = pytest.mark.unit


def test_an_exponential_decay_is_extrapolated_to_the_tolerance():
    # measure 1 at t = 0, decaying as exp(-t / 0.1): below 1e-6 at t = 0.1 ln(1e6)
    est = SteadyEstimate(tol=1e-6, t_min=0.01, hold=3, check=0.002, window=0.01,
                         t_end=5.0)
    reach = None
    for k in range(40):
        t = 0.002 * k
        reach = est.update(t, math.exp(-t / 0.1))
    assert reach == pytest.approx(0.1 * math.log(1e6) + 3 * 0.002, rel=1e-9)


def test_no_estimate_while_the_measure_grows_or_is_undefined():
    est = SteadyEstimate(tol=1e-6, t_min=0.0, hold=3, check=0.01, window=0.05, t_end=5.0)
    assert est.update(0.0, math.inf) is None
    assert all(est.update(0.01 * k, 1.0 + k) is None for k in range(1, 10))


def test_an_estimate_stays_between_the_earliest_steady_check_and_t_end():
    est = SteadyEstimate(tol=1e-3, t_min=0.5, hold=3, check=0.01, window=0.05, t_end=1.0)
    assert est.update(0.1, 1e-4) == pytest.approx(0.53)  # steady already: t_min + hold
    slow = SteadyEstimate(tol=1e-12, t_min=0.0, hold=3, check=0.01, window=0.05, t_end=1.0)
    for k in range(10):
        reach = slow.update(0.01 * k, math.exp(-0.01 * k))
    assert reach == 1.0


def test_a_text_bar_takes_a_new_total():
    bar = progress_bar(total=3.0, file=io.StringIO(), leave=False)
    set_total(bar, 0.5)
    bar.update(0.5)
    assert bar.total == 0.5 and bar.n == 0.5
    bar.close()


def test_a_widget_bar_takes_a_new_total_in_its_own_max():
    class Widget:
        max = 3.0

    class Bar:
        total = 3.0
        container = type("C", (), {"children": [None, Widget(), None]})()

    bar = Bar()
    progress.set_total(bar, 0.5)
    assert bar.total == 0.5 and bar.container.children[1].max == 0.5
