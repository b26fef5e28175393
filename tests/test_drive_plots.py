"""Pictures of a closed drive, drawn from the string's steady state of drive_flat."""

import math
from dataclasses import replace

import numpy as np
import pytest
from matplotlib.collections import LineCollection
from matplotlib.figure import Figure
from matplotlib.patches import Circle
from PIL import Image

from beltsim.beltdrive import drawing
from beltsim.beltdrive.analytic import capacity, solve_string
from beltsim.beltdrive.characteristic import plot_characteristic, plot_slip_collapse
from beltsim.beltdrive.drawing import slip_runs
from beltsim.beltdrive.plots import (
    animate_drive,
    draw_drive,
    plot_drive_history,
    plot_loop_fields,
)
from beltsim.beltdrive.scene import DriveScene
from beltsim.plots.common import offscreen, save_figure
from helpers import scene_path

pytestmark = pytest.mark.unit

PNG_MAGIC = b"\x89PNG\r\n\x1a\n"
# drive_flat.toml's pulleys (m), read off the file
R1, R2, C = 0.08, 0.16, 0.6
# the spans leave the pulleys at pi/2 + b (top) with sin b = (R2 - R1) / C
TOP = 0.5 * math.pi + math.asin((R2 - R1) / C)
PER_SEGMENT = 24


@pytest.fixture(scope="module")
def demo():
    """drive_flat's string steady state at 24 nodes per segment, the segment ends nodes."""
    P = DriveScene.load(scene_path("drive_flat")).params
    g = P.geometry
    sol = solve_string(P)
    e = g.bounds
    x = np.concatenate([np.linspace(e[k], e[k + 1], PER_SEGMENT, endpoint=False)
                        for k in range(4)])
    f = sol.friction(x)
    return {"P": P, "g": g, "sol": sol, "x": x, "T": sol.tension(x), "f": f,
            "slip": f != 0}


def _draw(draw, *args, **kwargs):
    with offscreen():
        return draw(*args, **kwargs)


def _png(tmp_path, draw, *args, **kwargs):
    """Render the figure to a PNG (drawing errors only show when rendering)."""
    path = save_figure(draw, tmp_path / "fig.png", *args, dpi=50, **kwargs)
    assert path.read_bytes()[:8] == PNG_MAGIC


def _by_gid(ax, gid):
    return [a for a in ax.get_children() if a.get_gid() == gid]


def _line(ax, label):
    found = [ln for ln in ax.get_lines() if ln.get_label() == label]
    assert len(found) == 1, [ln.get_label() for ln in ax.get_lines()]
    return found[0]


# ---------------------------------------------------------------------------
# the drive to scale


def test_drive_is_two_pulleys_to_scale_and_a_belt_coloured_by_tension(demo, tmp_path):
    fig = _draw(draw_drive, demo["g"], demo["x"], demo["T"], demo["slip"], title="demo",
                rim_speeds=(12.0, 11.97))
    assert isinstance(fig, Figure)
    ax = fig.axes[0]
    circles = [p for p in ax.patches if isinstance(p, Circle)]
    assert sorted((c.center, c.radius) for c in circles) == [((0.0, 0.0), R1), ((C, 0.0), R2)]
    assert ax.get_aspect() == 1.0
    texts = [t.get_text() for t in ax.texts]
    assert any(t.startswith("driver\nrim 12 m/s") for t in texts)
    assert any(t.startswith("driven") for t in texts)
    assert len(_by_gid(ax, "motion")) == 2  # an arrow on each span
    # the colorbar spans the tension's range exactly
    (belt,) = _by_gid(ax, "belt")
    assert isinstance(belt, LineCollection)
    assert (belt.colorbar.norm.vmin, belt.colorbar.norm.vmax) == (demo["T"].min(),
                                                                  demo["T"].max())
    assert belt.colorbar.ax in fig.axes
    # pieces lying on the tight span (top, between the pulleys) carry the tight tension
    seg = np.asarray(belt.get_segments())
    top = np.all(seg[:, :, 1] > 0.5 * R1, axis=1) & np.all(
        (seg[:, :, 0] > 0.1) & (seg[:, :, 0] < C - 0.1), axis=1)
    assert top.sum() > 50
    np.testing.assert_allclose(belt.get_array()[top], demo["sol"].T1, rtol=1e-14)
    # the belt lies on the rims: every piece's end is on a pulley or between them
    r1 = np.hypot(seg[:, 0, 0], seg[:, 0, 1])
    on_driver = (seg[:, 0, 0] <= 0) & np.isclose(r1, R1, rtol=1e-9)
    assert on_driver.sum() > 50
    _png(tmp_path, draw_drive, demo["g"], demo["x"], demo["T"], demo["slip"])


def _slip_points(fig):
    (line,) = _by_gid(fig.axes[0], "slip")
    X, Y = (np.asarray(v, dtype=float) for v in line.get_data())
    keep = np.isfinite(X)
    return X[keep], Y[keep]


def test_slip_is_marked_only_around_the_slipping_nodes(demo):
    x, g, slip = demo["x"], demo["g"], demo["slip"]
    h = g.bounds[1] / PER_SEGMENT  # the driver arc's element
    on_driver = slip & (g.segment_of(x) == 0)
    X, Y = _slip_points(_draw(draw_drive, g, x, demo["T"], on_driver))
    r = np.hypot(X, Y)
    # a line just outside the belt, around the driver only
    assert len(X) > 20 and np.ptp(r) < 1e-9 and R1 < r[0] < R1 + 0.05
    # from halfway before the first slipping node to halfway after the last
    first, last = x[on_driver][[0, -1]]
    angles = np.mod(np.arctan2(Y, X) - TOP, 2 * math.pi)
    assert angles.min() == pytest.approx((first - 0.5 * h) / R1, abs=1e-9)
    assert angles.max() == pytest.approx((last + 0.5 * h) / R1, abs=1e-9)
    # the analytic slip arc starts between the last sticking and the first slipping node
    assert first - h < demo["sol"].stick_ends[0] < first

    on_driven = slip & (g.segment_of(x) == 2)
    X, Y = _slip_points(_draw(draw_drive, g, x, demo["T"], on_driven))
    r = np.hypot(X - C, Y)
    assert len(X) > 20 and np.ptp(r) < 1e-9 and R2 < r[0] < R2 + 0.05

    for none in (None, np.zeros(len(x), dtype=bool)):
        assert len(_slip_points(_draw(draw_drive, g, x, demo["T"], none))[0]) == 0


def test_slip_runs_are_the_slipping_nodes_cells_across_the_loops_end():
    x = np.arange(10.0)  # a loop of length 10, cells of 1 about each node
    mask = np.zeros(10, dtype=bool)
    mask[[8, 9, 0]] = True
    assert slip_runs(x, mask, 10.0) == [(7.5, 10.5)]
    mask[:] = False
    mask[[2, 3, 6]] = True
    assert slip_runs(x, mask, 10.0) == [(1.5, 3.5), (5.5, 6.5)]
    assert slip_runs(x, np.ones(10, dtype=bool), 10.0) == [(-0.5, 9.5)]
    assert slip_runs(x, np.zeros(10, dtype=bool), 10.0) == []


def test_drive_draws_on_the_callers_axes_with_a_given_colour_scale(demo):
    with offscreen():
        fig = Figure()
        ax = fig.add_subplot()
        out = draw_drive(demo["g"], demo["x"], demo["T"], ax=ax, tension_range=(0, 1000))
    assert out is fig and fig.axes[0] is ax
    (belt,) = _by_gid(ax, "belt")
    assert (belt.norm.vmin, belt.norm.vmax) == (0, 1000)
    # a belt at rest (uniform tension) still gets a colour scale
    flat = _draw(draw_drive, demo["g"], demo["x"], np.full(len(demo["x"]), 600.0))
    (belt,) = _by_gid(flat.axes[0], "belt")
    assert belt.norm.vmin < 600.0 < belt.norm.vmax


# ---------------------------------------------------------------------------
# along the loop


def test_loop_fields_show_the_points_the_analytic_curves_and_the_segments(demo, tmp_path):
    x, g, sol = demo["x"], demo["g"], demo["sol"]
    fields = {"tension": demo["T"], "friction": demo["f"], "u": np.zeros(len(x))}
    fig = _draw(plot_loop_fields, x, fields, g, analytic=sol)
    axes = [ax for ax in fig.axes]
    assert len(axes) == 2
    # the Geometry is drawn as its layout, whose wraps come from atan2: the loop's
    # length to round-off
    lam = pytest.approx(g.loop_length, rel=1e-15)
    for ax, key in zip(axes, ("tension", "friction")):
        run = _line(ax, "simulation")
        # the nodes, and the first again at the loop's end
        np.testing.assert_array_equal(run.get_xdata()[:-1], x)
        assert run.get_xdata()[-1] - x[0] == lam
        np.testing.assert_array_equal(run.get_ydata(), np.append(fields[key], fields[key][0]))
        exact = _line(ax, "analytic steady state")
        xs = exact.get_xdata()
        assert xs[0] == 0.0 and xs[-1] == lam and len(xs) > 1000
        ends = _line(ax, "analytic start of the slip arcs")
        np.testing.assert_array_equal(ends.get_xdata(), sol.stick_ends)
        assert ax.get_xlim() == (0.0, lam)
    # the exact curves' extremes: T1 and T2; the friction mu (N - rho c^2) / R at its
    # largest where N = T1 (the driver's slip arc's start, the driven arc's exit)
    T = _line(axes[0], "analytic steady state").get_ydata()
    assert T.max() == pytest.approx(sol.T1, rel=1e-14)
    assert T.min() == pytest.approx(sol.T2, rel=1e-14)
    f = _line(axes[1], "analytic steady state").get_ydata()
    mu = demo["P"].mu
    rc = sol.centrifugal
    assert f.max() == pytest.approx(mu * (sol.T1 - rc) / R1, rel=1e-6)
    assert f.min() == pytest.approx(-mu * (sol.T1 - rc) / R2, rel=1e-6)
    names = {t.get_text() for t in axes[0].texts}
    assert names == {"driver arc", "slack span", "driven arc", "tight span"}
    _png(tmp_path, plot_loop_fields, x, fields, g, analytic=sol)


def test_a_jump_of_perfect_adhesion_is_drawn_upright(demo):
    P = replace(demo["P"], mu=None, friction="stick")
    sol = solve_string(P)
    g = P.geometry
    fig = _draw(plot_loop_fields, demo["x"], {"tension": sol.tension(demo["x"])}, g,
                analytic=sol)
    assert len(fig.axes) == 1
    line = _line(fig.axes[0], "analytic steady state")
    xs, T = line.get_xdata(), line.get_ydata()
    e1 = g.bounds[1]
    k = np.searchsorted(xs, e1)
    assert xs[k] == e1 and e1 - xs[k - 1] < 1e-8  # sampled just before the exit and at it
    assert (T[k - 1], T[k]) == (pytest.approx(sol.T1), pytest.approx(sol.T2))


# ---------------------------------------------------------------------------
# over time


def _history(sol, n=50):
    t = np.linspace(0.0, 0.5, n)
    ramp = 1.0 - np.exp(-t / 0.05)
    s = sol.summary()
    keys = ("belt_speed", "driven_speed", "speed_ratio", "tight_tension", "slack_tension",
            "driver_torque")
    h = {k: s[k] * ramp for k in keys}
    h["load_torque"] = sol.M2 * ramp
    h["slip_power"] = s["slip_power"] * ramp  # not drawn
    return t, h


def test_history_panels_follow_the_keys_given(demo, tmp_path):
    sol = demo["sol"]
    t, h = _history(sol)
    fig = _draw(plot_drive_history, t, h, steady=sol.summary())
    assert len(fig.axes) == 5
    span = fig.axes[3]
    tight = _line(span, "tight span")
    np.testing.assert_array_equal(tight.get_ydata(), h["tight_tension"])
    np.testing.assert_array_equal(tight.get_xdata(), t)
    assert _line(span, "tight span: steady state").get_ydata()[0] == sol.T1
    assert _line(span, "slack span: steady state").get_ydata()[0] == sol.T2
    torque = fig.axes[4]
    assert {ln.get_label() for ln in torque.get_lines()} == {
        "driver torque M1", "driver torque M1: steady state", "load torque M2"}
    # a history of two quantities: two panels
    fig = _draw(plot_drive_history, t, {k: h[k] for k in ("belt_speed", "slack_tension")})
    assert len(fig.axes) == 2
    _png(tmp_path, plot_drive_history, t, h, steady=sol.summary())


# ---------------------------------------------------------------------------
# animation


def test_animation_writes_every_frame_on_one_colour_scale(demo, tmp_path, monkeypatch):
    x, g = demo["x"], demo["g"]
    frames = []
    for M2 in (10.0, 50.0, 90.0):
        s = solve_string(demo["P"], M2=M2)
        frames.append({"tension": s.tension(x), "slip": s.friction(x) != 0,
                       "belt_speed": s.c, "driven_speed": s.omega2})
    norms = []
    real = drawing.DriveDrawing.__init__

    def spy(self, ax, layout, x, norm, **kwargs):
        norms.append(norm)
        real(self, ax, layout, x, norm, **kwargs)

    monkeypatch.setattr(drawing.DriveDrawing, "__init__", spy)
    path = animate_drive(g, x, frames, times=[0.0, 0.1, 0.2], path=tmp_path / "d.gif",
                         fps=5, dpi=40)
    assert path == tmp_path / "d.gif" and path.stat().st_size > 0
    with Image.open(path) as im:
        assert im.n_frames == 3
    # one scale for all frames: the lowest slack and the highest tight tension
    (norm,) = norms
    assert norm.vmin == min(f["tension"].min() for f in frames)
    assert norm.vmax == max(f["tension"].max() for f in frames)
    assert not list(tmp_path.glob(".d.gif*"))  # no temporary file left


def test_animation_writes_an_mp4(demo, tmp_path):
    frames = [{"tension": demo["T"]}, {"tension": demo["T"], "slip": demo["slip"]}]
    path = animate_drive(demo["g"], demo["x"], frames, times=[0.0, 1.0],
                         path=tmp_path / "d.mp4", fps=2, dpi=40)
    assert path.read_bytes()[4:8] == b"ftyp"


# ---------------------------------------------------------------------------
# sweeps


def test_characteristic_draws_points_curves_and_the_capacity(demo, tmp_path):
    P = demo["P"]
    loads = np.array([0.0, 25.0, 50.0, 75.0])
    sols = [solve_string(P, M2=m) for m in loads]
    loss = np.array([1 - s.speed_ratio for s in sols])
    eff = np.array([s.efficiency for s in sols])
    cap = capacity(P)
    exact = {"speed_loss": lambda m: 1 - solve_string(P, M2=m).speed_ratio,
             "efficiency": eff}
    fig = _draw(plot_characteristic, loads, loss, eff, capacity=cap, analytic=exact)
    top, bottom = fig.axes
    points = _line(top, "simulation")
    np.testing.assert_array_equal(points.get_xdata(), loads)
    np.testing.assert_allclose(points.get_ydata(), 100 * loss, rtol=1e-15)
    curve = _line(top, "analytic steady state")  # the callable: sampled up to the capacity
    assert curve.get_xdata()[-1] == pytest.approx(cap, rel=1e-5) and len(curve.get_xdata()) > 100
    assert curve.get_ydata()[0] == 0.0  # no load, no speed loss
    curve = _line(bottom, "analytic steady state")  # the array: beside the loads
    np.testing.assert_array_equal(curve.get_xdata(), loads)
    for ax in (top, bottom):
        (line,) = [ln for ln in ax.get_lines() if ln.get_label().startswith("capacity")]
        assert tuple(line.get_xdata()) == (cap, cap)
    assert bottom.get_xlim()[1] > cap
    _png(tmp_path, plot_characteristic, loads, loss, eff, capacity=cap, analytic=exact)


def test_slip_collapse_draws_both_pulleys_their_wraps_and_the_analytic(demo, tmp_path):
    P, g = demo["P"], demo["g"]
    mus = np.array([0.3, 0.6, 1.2, 2.4, 4.8])
    arcs = np.array([solve_string(replace(P, mu=m)).phi_s for m in mus])
    exact = {"driver": lambda m: solve_string(replace(P, mu=m)).phi_s, "driven": arcs}
    fig = _draw(plot_slip_collapse, mus, arcs, arcs, wraps=g.wraps, analytic=exact)
    ax = fig.axes[0]
    assert ax.get_xscale() == "log"
    for name in ("driver", "driven"):
        np.testing.assert_array_equal(_line(ax, f"{name} pulley").get_ydata(), arcs)
        curve = _line(ax, f"{name} pulley: analytic")
        assert curve.get_xdata()[0] == pytest.approx(0.3) and \
            curve.get_xdata()[-1] == pytest.approx(4.8)
    wraps = sorted(ln.get_ydata()[0] for ln in ax.get_lines() if "wrap" in ln.get_label())
    assert wraps == pytest.approx([math.pi - 2 * (TOP - 0.5 * math.pi),
                                   math.pi + 2 * (TOP - 0.5 * math.pi)])
    _png(tmp_path, plot_slip_collapse, mus, arcs, arcs, wraps=g.wraps, analytic=exact)


# ---------------------------------------------------------------------------
# bad input


def _bad_cases(d):
    x, g, T, n = d["x"], d["g"], d["T"], len(d["x"])
    t = np.linspace(0, 1, 5)
    lam = g.loop_length
    return [
        ("tension: 95 values for 96 nodes", draw_drive, (g, x, T[:-1])),
        ("slip: 95 values", draw_drive, (g, x, T, d["slip"][:-1])),
        ("slip: must be booleans", draw_drive, (g, x, T, np.full(n, 0.5))),
        ("x: the nodes must increase", draw_drive, (g, x[::-1], T[::-1])),
        ("x: nodes must lie in [0,", draw_drive, (g, np.append(x[1:], lam), T)),
        ("tension: must be finite", draw_drive, (g, x, np.full(n, np.nan))),
        ("rim_speeds: 1 values for 2 pulleys", draw_drive, (g, x, T), {"rim_speeds": [1.0]}),
        ("tension_range: must be (low, high)", draw_drive, (g, x, T),
         {"tension_range": (2.0, 1.0)}),
        ("fields['friction']: 95 values", plot_loop_fields,
         (x, {"tension": T, "friction": T[:-1]}, g)),
        ("fields: needs 'tension' or 'friction'", plot_loop_fields, (x, {"u": T}, g)),
        ("ax: this figure has 2 panels", plot_loop_fields, (x, {"tension": T, "friction": T},
                                                            g), {"ax": Figure().subplots()}),
        ("history['tight_tension']: 4 values for 5 times", plot_drive_history,
         (t, {"tight_tension": t[:-1]})),
        ("history: holds none of", plot_drive_history, (t, {"rate": t})),
        ("efficiency: 2 values for 3 loads", plot_characteristic,
         ([0, 1, 2], [0, 0, 0], [1, 1])),
        ("analytic: unknown key 'loss'", plot_characteristic, ([0, 1], [0, 0], [1, 1]),
         {"analytic": {"loss": [0, 0]}}),
        ("analytic['efficiency']: 3 values for 2 points", plot_characteristic,
         ([0, 1], [0, 0], [1, 1]), {"analytic": {"efficiency": [1, 1, 1]}}),
        ("mus: needs at least one friction coefficient, each > 0", plot_slip_collapse,
         ([0.0, 1.0], [1, 1], [1, 1])),
        ("slip_arcs_driven: 1 values for 2 mus", plot_slip_collapse,
         ([0.5, 1.0], [1, 1], [1])),
        ("path: must end in .gif or .mp4", animate_drive, (g, x, [{"tension": T}]),
         {"times": [0.0], "path": "drive.avi"}),
        ("times: 2 values for 1 frames", animate_drive, (g, x, [{"tension": T}]),
         {"times": [0.0, 1.0], "path": "drive.gif"}),
        ("frames[1]: must be a mapping with a 'tension' array", animate_drive,
         (g, x, [{"tension": T}, {"slip": d["slip"]}]), {"times": [0, 1], "path": "d.gif"}),
        ("frames[0]['tension']: 95 values", animate_drive, (g, x, [{"tension": T[1:]}]),
         {"times": [0.0], "path": "drive.gif"}),
    ]


def test_bad_input_is_a_one_line_value_error(demo, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)  # an animation refused must not have written anything
    for expected, draw, args, *kw in _bad_cases(demo):
        with pytest.raises(ValueError) as info, offscreen():
            draw(*args, **(kw[0] if kw else {}))
        message = str(info.value)
        assert message.startswith(expected), (expected, message)
        assert "\n" not in message
    assert not list(tmp_path.iterdir())


def test_figures_made_off_screen_leave_pyplot_alone(demo):
    import matplotlib
    import matplotlib.pyplot as plt

    before = (matplotlib.get_backend(), plt.get_fignums())
    fig = _draw(draw_drive, demo["g"], demo["x"], demo["T"], demo["slip"])
    assert type(fig) is Figure and fig.canvas.manager is None
    assert (matplotlib.get_backend(), plt.get_fignums()) == before
