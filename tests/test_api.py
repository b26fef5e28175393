"""The Python API a notebook uses: typed scenes, results as arrays, plots on given axes,
progress and the user's own trackers."""

import dataclasses
import math

import matplotlib
import numpy as np
import pytest
from hypothesis import given, reject, settings
from hypothesis import strategies as st

import beltsim
from beltsim import (
    Beam,
    Contact,
    Motion,
    NumericsSection,
    Physics,
    RunStatus,
    Scene,
    SceneError,
    Sine,
    Stiffness,
    Stop,
    Tracker,
)
from beltsim.io.files import read_csv
from beltsim.problem.builder import SECTIONS
from beltsim.problem.scene import SCHEMA

# the paper's slip scene, typed out from the paper's data (Sect. 5), not read from its file
PAPER_BEAM = Beam(length=1.0, height=0.1, width=0.1, youngs_modulus=5e7, poisson_ratio=0.45,
                  density=1500.0, shear_factor=1.1)
PAPER_SLIP = {"beam": PAPER_BEAM, "motion": Motion(belt_speed=120.0, surface_speed=121.2),
              "contact": Contact(start=1 / 3, end=2 / 3, friction="coulomb", max_friction=1e5),
              "physics": Physics(inertia=True, damping=39.0)}
COARSE = NumericsSection(elements=60)  # a run in well under a second

pytestmark = pytest.mark.unit


# ---------------------------------------------------------------------------
# the builder


def test_the_builder_gives_the_shipped_scene():
    shipped = beltsim.paper_scene("slip")
    built = Scene.build(**PAPER_SLIP, title=shipped.title)
    assert built == shipped and hash(built) == hash(shipped)
    assert built.to_dict() == shipped.to_dict()
    assert built != shipped.replace(title="another") and built != shipped.to_dict()
    assert built.beam == PAPER_BEAM and built.contact.max_friction == 1e5
    assert built.params == shipped.params


def test_sections_name_the_schema_keys():
    """The typed sections and the file format have the same sections and keys."""
    assert tuple(SECTIONS) == tuple(SCHEMA)
    for name, cls in SECTIONS.items():
        assert {f.name for f in dataclasses.fields(cls)} == set(SCHEMA[name]), name


def test_numerics_section_is_not_the_resolved_settings():
    from beltsim.solvers.settings import Numerics, resolve

    scene = Scene.build(**PAPER_SLIP, numerics=COARSE)
    assert isinstance(scene.numerics, NumericsSection) and NumericsSection is not Numerics
    assert scene.numerics.elements == 60 and scene.numerics.dt is None
    # dictionary-style reads of the keys the scene sets, the defaults left to resolve()
    assert scene.numerics.get("elements") == 60 and "elements" in scene.numerics
    assert scene.numerics.get("dt", 1.5) == 1.5 and "dt" not in scene.numerics
    assert resolve(scene).elements == 60 and resolve(scene).dt > 0
    assert Scene.build(**PAPER_SLIP).numerics == NumericsSection()


def test_profiles_round_trip_through_toml():
    rows = [[0.0, 121.2], [0.05, 121.8], [0.1, 121.5]]
    scene = Scene.build(
        **PAPER_SLIP | {
            "motion": Motion(belt_speed=120.0, surface_speed=rows),
            "contact": Contact(start=1 / 3, end=2 / 3, friction="coulomb",
                               max_friction=Sine(mean=1e5, amplitude=2e4, period=0.02))},
        stiffness=Stiffness(shear=2e5), numerics=NumericsSection(elements=80, grading=2.5),
        title='a "quoted" title\\with a backslash,\na new line and a tab\t')
    text = scene.to_toml()
    again = Scene.loads(text)
    assert again == scene and again.to_toml() == text
    assert again.motion.surface_speed == ((0.0, 121.2), (0.05, 121.8), (0.1, 121.5))
    assert again.contact.max_friction == Sine(1e5, 2e4, 0.02)
    assert again.title == scene.title and "\n" in again.title
    assert again.stiffness == Stiffness(shear=2e5)


def _profile(low, high):
    number = st.floats(low, high)
    times = st.lists(st.floats(0.0, 1.0), min_size=1, max_size=4, unique=True).map(sorted)
    rows = times.flatmap(lambda ts: st.tuples(*[st.tuples(st.just(t), number) for t in ts]))
    sine = st.builds(Sine, mean=st.floats(low, high), amplitude=st.floats(-0.1 * low, 0.1 * low),
                     period=st.floats(1e-3, 1.0))
    return st.one_of(number, rows, sine)


@st.composite
def scenes(draw):
    """Scenes drawn from wide ranges; the few the validator refuses are rejected."""
    inertia = draw(st.booleans())
    length = draw(st.floats(0.1, 10.0))
    beam = Beam(length=length, height=draw(st.floats(1e-3, 0.5)),
                width=draw(st.floats(1e-3, 1.0)), youngs_modulus=draw(st.floats(1e5, 1e11)),
                poisson_ratio=draw(st.floats(-0.99, 0.49)),
                shear_factor=draw(st.floats(0.1, 2.0)),
                density=draw(st.floats(10.0, 1e4) if inertia else st.none()))
    c = draw(st.floats(0.1, 50.0))
    ends = sorted(draw(st.lists(st.floats(0.01, 0.99), min_size=2, max_size=2, unique=True)))
    friction = draw(st.sampled_from(("stick", "coulomb")))
    contact = Contact(start=ends[0] * length, end=ends[1] * length, friction=friction,
                      max_friction=draw(_profile(1e2, 1e6)) if friction == "coulomb" else None)
    stiffness = draw(st.none() | st.builds(Stiffness, shear=st.none() | st.floats(1e3, 1e9),
                                           bending=st.none() | st.floats(1e-2, 1e5)))
    numerics = draw(st.none() | st.builds(
        NumericsSection, elements=st.none() | st.integers(6, 5000),
        grading=st.none() | st.floats(1.0, 20.0), t_end=st.none() | st.floats(1e-3, 10.0),
        integrator=st.none() | st.sampled_from(("implicit", "explicit", "pseudo")),
        steady_tol=st.none() | st.floats(1e-12, 1e-2)))
    try:
        return Scene.build(beam=beam, motion=Motion(c, draw(_profile(0.5 * c, 1.5 * c))),
                           contact=contact,
                           physics=Physics(inertia=inertia,
                                           damping=draw(st.none() | st.floats(0.0, 1e3))),
                           stiffness=stiffness, numerics=numerics,
                           title=draw(st.none() | st.text(max_size=30)))
    except SceneError:
        reject()


@settings(max_examples=150, deadline=None)
@given(scenes())
def test_any_valid_scene_round_trips(scene):
    text = scene.to_toml()
    again = Scene.loads(text)
    assert again == scene and again.to_toml() == text and hash(again) == hash(scene)
    # the sections read back rebuild the same scene
    sections = {name: getattr(again, name) for name in SECTIONS}
    assert Scene.build(**sections, title=scene.to_dict().get("title")) == scene


@pytest.mark.parametrize("change, message", [
    ({"beam": dataclasses.replace(PAPER_BEAM, length=-1.0)}, "beam.length: must be > 0, got -1.0"),
    ({"contact": Contact(start=1 / 3, end=2 / 3, friction="coulomb")},
     'contact.max_friction: missing key (required when contact.friction = "coulomb")'),
    ({"motion": Motion(belt_speed=120.0, surface_speed=[[0.0, 121.0], [0.0, 122.0]])},
     "motion.surface_speed row 2: times must increase strictly"),
    ({"motion": Motion(belt_speed=120.0, surface_speed=Sine(1.0, 2.0, 0.1))},
     "motion.surface_speed: must stay > 0"),
    ({"numerics": NumericsSection(elements=3)}, "numerics.elements: must be >= 6, got 3"),
    ({"physics": Physics(inertia="yes")}, 'physics.inertia: must be true or false'),
    ({"beam": Motion(belt_speed=1.0, surface_speed=1.0)}, "[beam]: must be a Beam, got a Motion"),
])
def test_invalid_sections_are_one_line_errors_naming_the_key(change, message):
    with pytest.raises(SceneError) as err:
        Scene.build(**PAPER_SLIP | change)
    assert str(err.value).startswith(message) and "\n" not in str(err.value)


def test_the_builder_and_the_file_share_one_validator():
    """The same broken value gives the same message from sections and from --set."""
    file_route = "beam.poisson_ratio: must lie in the open interval (-1.0, 0.5), got 0.7"
    with pytest.raises(SceneError) as a:
        beltsim.paper_scene("slip", ["beam.poisson_ratio=0.7"])
    with pytest.raises(SceneError) as b:
        Scene.build(**PAPER_SLIP | {"beam": dataclasses.replace(PAPER_BEAM,
                                                                  poisson_ratio=0.7)})
    assert str(a.value) == str(b.value) == file_route


def test_replace():
    scene = Scene.build(**PAPER_SLIP, numerics=COARSE, title="base")
    stronger = scene.replace(contact=dataclasses.replace(scene.contact, max_friction=2e5))
    assert stronger.contact.max_friction == 2e5 and scene.contact.max_friction == 1e5
    assert stronger.beam == scene.beam and stronger.numerics == COARSE
    assert stronger.params.fstar == 2e5 and stronger.title == "base"
    # None removes an optional section or the title; a required one cannot go
    bare = scene.replace(numerics=None, title=None)
    assert bare == Scene.build(**PAPER_SLIP) and "numerics" not in bare.to_dict()
    with pytest.raises(SceneError, match=r"^\[beam\]: missing section$"):
        scene.replace(beam=None)
    with pytest.raises(SceneError, match="^physic: unknown section"):
        scene.replace(physic=Physics(inertia=False))
    # a change the rules refuse is refused as a file's is
    with pytest.raises(SceneError, match='^contact.max_friction: only for contact.friction = '
                                         '"coulomb"'):
        scene.replace(contact=dataclasses.replace(scene.contact, friction="stick"))
    with pytest.raises(dataclasses.FrozenInstanceError):
        scene.contact.max_friction = 3e5


def test_sections_take_numpy_values():
    speeds = np.linspace(121.0, 122.0, 3)
    rows = np.column_stack([[0.0, 0.05, 0.1], speeds])
    scene = Scene.build(**PAPER_SLIP | {"motion": Motion(np.float64(120.0), rows)},
                        numerics=NumericsSection(elements=np.int64(60)))
    assert scene.numerics.elements == 60 and type(scene.numerics.elements) is int
    assert scene.motion.surface_speed[-1] == (0.1, 122.0)


# ---------------------------------------------------------------------------
# results as arrays


@pytest.fixture(scope="module")
def slip_result():
    return beltsim.run(Scene.build(**PAPER_SLIP, numerics=COARSE))


def test_results_are_arrays(slip_result, tmp_path):
    r = slip_result
    assert r.converged
    f = r.fields
    assert list(f) == ["x", "u", "theta", "strain", "tension", "moment", "friction"]
    assert all(isinstance(v, np.ndarray) and v.shape == r.x.shape for v in f.values())
    np.testing.assert_array_equal(f["x"], r.x)
    # the same numbers a notebook would otherwise read back from the CSV files
    beltsim.save_run(r, tmp_path)
    stored = read_csv(tmp_path / "fields.csv")
    for key, column in stored.items():
        np.testing.assert_allclose(f[key], column, rtol=1e-12, atol=0)
    hist = read_csv(tmp_path / "history.csv")
    assert list(r.history) == list(hist)
    for key, column in hist.items():
        np.testing.assert_allclose(r.history[key], column, rtol=1e-12, atol=0)
    # the last check is the final state
    assert r.history["total_friction"][-1] == r.solution.total_friction
    # the fields are copies: changing them leaves the result as it was
    f["u"][:] = 0.0
    assert np.any(r.fields["u"] != 0.0)


def test_the_analytic_solution_has_the_same_fields(slip_result):
    exact = slip_result.reference
    assert isinstance(exact, beltsim.AnalyticSolution)
    on_grid = exact.fields(slip_result.x)
    assert list(on_grid) == list(slip_result.fields)[1:]
    x, sampled = exact.sample(201)
    assert x[0] == 0.0 and x[-1] == 1.0 and set(sampled) == set(on_grid)


# ---------------------------------------------------------------------------
# plots


@pytest.fixture
def pyplot_state():
    """pyplot with a backend other than the Agg the old code forced, and its figures
    closed afterwards."""
    import matplotlib.pyplot as plt

    old = matplotlib.get_backend()
    plt.switch_backend("pdf")
    before = set(plt.get_fignums())
    yield plt
    for num in set(plt.get_fignums()) - before:
        plt.close(num)
    plt.switch_backend(old)


def test_plots_draw_on_given_axes_and_leave_the_backend(slip_result, pyplot_state, tmp_path):
    plt = pyplot_state
    fig, ax = plt.subplots()
    figures = set(plt.get_fignums())
    assert beltsim.plot_fields(slip_result, keys="theta", ax=ax) is fig
    assert len(ax.lines) == 2  # the run and the analytic curve
    np.testing.assert_array_equal(ax.lines[0].get_ydata(), slip_result.fields["theta"])
    fig2, axes = plt.subplots(2, 1)
    assert beltsim.plot_history(slip_result, keys=("total_friction", "rate"), ax=axes) is fig2
    assert set(plt.get_fignums()) == figures | {fig2.number}  # no figure of its own
    fig3, ax3 = plt.subplots()
    assert beltsim.plot_fields(slip_result.reference, keys=["u"], ax=ax3) is fig3
    with pytest.raises(ValueError, match="ax: this figure has 5 panels, got 1 Axes"):
        beltsim.plot_fields(slip_result, ax=ax)
    with pytest.raises(ValueError, match="keys: the fields has no 'stress'"):
        beltsim.plot_fields(slip_result, keys="stress", ax=ax)
    # without ax: a new pyplot figure with one panel per field
    new = beltsim.plot_fields(slip_result)
    assert new.number in plt.get_fignums() and len(new.axes) == 5
    # drawing to files goes off screen: no pyplot figure, the backend as it was
    count = len(plt.get_fignums())
    from beltsim.plots.run import plot_run
    beltsim.save_run(slip_result, tmp_path)
    plot_run(tmp_path)
    assert len(plt.get_fignums()) == count
    assert matplotlib.get_backend() == "pdf"


def test_study_and_paper_figures_take_axes(pyplot_state):
    from beltsim.plots.paper import fig7, two_panel
    from beltsim.plots.studies import error_vs_runtime
    from beltsim.studies.paper import solutions

    plt = pyplot_state
    sols = solutions()
    fig, axes = plt.subplots(1, 2)
    assert two_panel("theta", sols, axes=axes) is fig
    fig, ax = plt.subplots()
    assert fig7(sols, ax=ax) is fig
    rows = [{"scheme": "implicit", "converged": True, "wall_time": w, "elements": n,
             "error_total_friction": e} for w, n, e in ((0.1, 100, 1e-3), (0.3, 200, 2.5e-4))]
    fig, ax = plt.subplots()
    assert error_vs_runtime(rows, ax=ax) is fig
    np.testing.assert_array_equal(ax.lines[0].get_xdata(), [0.1, 0.3])
    assert matplotlib.get_backend() == "pdf"


# ---------------------------------------------------------------------------
# progress and trackers


def test_progress_shows_without_a_terminal(capsys):
    """tqdm.auto writes its bar wherever stderr goes (a notebook's output, here a capture)."""
    beltsim.run(Scene.build(**PAPER_SLIP, numerics=COARSE), progress=True)
    assert "to steady" in capsys.readouterr().err
    beltsim.run(Scene.build(**PAPER_SLIP, numerics=COARSE))
    assert capsys.readouterr().err == ""


def test_the_cli_keeps_its_log_free_of_bars(tmp_path, capsys):
    """The CLI asks for a bar only on a terminal (and never with --quiet)."""
    from beltsim.cli import main

    assert main(["run", "paper_slip", "--set", "numerics.elements=60", "--out",
                 str(tmp_path)]) == 0
    assert "to steady" not in capsys.readouterr().err


class FrictionLog(Tracker):
    """Records the total friction at every check."""

    def initialize(self, sim):
        self.t, self.friction, self.status = [], [], None

    def handle(self, sim):
        self.t.append(sim.t)
        self.friction.append(sim.total_friction())

    def finalize(self, sim, status):
        self.status = status


class StopAt(Tracker):
    """Stops a run at the first check past a simulated time."""

    def __init__(self, t_stop):
        self.t_stop = t_stop

    def handle(self, sim):
        if sim.t >= self.t_stop:
            return Stop(reason=f"enough at t = {sim.t:.4g} s")
        return None


def test_a_user_tracker_sees_every_check(slip_result):
    log = FrictionLog()
    result = beltsim.run(Scene.build(**PAPER_SLIP, numerics=COARSE), trackers=[log])
    assert result.converged and log.status is RunStatus.CONVERGED
    # every check, the last too: the run's own history holds the same numbers
    np.testing.assert_array_equal(log.t, result.history["t"])
    np.testing.assert_array_equal(log.friction, result.history["total_friction"])
    # and it changes nothing in the run
    np.testing.assert_array_equal(result.fields["u"], slip_result.fields["u"])


def test_a_user_tracker_stops_a_run():
    scene = Scene.build(**PAPER_SLIP, numerics=COARSE)
    log = FrictionLog()
    sim = beltsim.Simulation(scene)
    result = sim.run(trackers=[log, StopAt(0.01)])
    assert result.status is RunStatus.INTERRUPTED and result.interrupted
    assert log.status is RunStatus.INTERRUPTED
    assert result.simulated_time >= 0.01 and log.t[-1] == result.simulated_time
    assert result.simulated_time - 0.01 < sim.check * (1 + 1e-9)  # the first check past it
    assert result.reason == f"enough at t = {result.simulated_time:.4g} s"
    # a Stop without a reason says which tracker stopped the run
    quiet = type("Quiet", (Tracker,), {"handle": lambda self, sim: Stop()})
    result = beltsim.run(scene, trackers=[quiet()])
    assert result.reason.startswith("stopped by Quiet at t = ")


def test_trackers_must_be_trackers():
    scene = Scene.build(**PAPER_SLIP, numerics=COARSE)
    with pytest.raises(TypeError, match="trackers: each must be a beltsim.Tracker"):
        beltsim.run(scene, trackers=[lambda sim: None])
    truthy = type("Truthy", (Tracker,), {"handle": lambda self, sim: True})
    with pytest.raises(TypeError, match="Truthy.handle: must return None or a beltsim.Stop"):
        beltsim.run(scene, trackers=[truthy()])
    with pytest.raises(TypeError, match="status must be a RunStatus"):
        Stop("a reason in the status's place")


def test_a_steady_solve_starts_and_ends_the_trackers():
    log = FrictionLog()
    result = beltsim.run(Scene.build(**PAPER_SLIP, numerics=NumericsSection(
        elements=60, integrator="steady")), trackers=[log])
    assert result.converged and log.status is RunStatus.CONVERGED and log.t == []
    assert math.isfinite(result.solution.total_friction)


class TimeLog(Tracker):
    """Records the time of every check and the status the run ended in."""

    def __init__(self):
        self.t, self.status = [], None

    def handle(self, sim):
        self.t.append(sim.t)

    def finalize(self, sim, status):
        self.status = status


@pytest.mark.parametrize("name, elements", [("paper_slip", 60), ("drive_flat", 100)])
def test_user_trackers_see_and_stop_either_layout(name, elements):
    """The same tracker on both layouts: it sees every check of a run (the run's own
    history has the same times) and its Stop ends a run at the first check past it."""
    scene = beltsim.load_scene(name, {"numerics.elements": elements})
    log = TimeLog()
    result = beltsim.run(scene, trackers=[log])
    assert result.converged and log.status is RunStatus.CONVERGED
    np.testing.assert_array_equal(log.t, result.history["t"])
    stop_at = 0.25 * result.simulated_time
    cut = beltsim.run(scene, trackers=[StopAt(stop_at)])
    assert cut.status is RunStatus.INTERRUPTED and cut.simulated_time >= stop_at
    assert cut.reason == f"enough at t = {cut.simulated_time:.4g} s"
