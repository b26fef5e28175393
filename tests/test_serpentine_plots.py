"""Pictures of a drive on any layout: drive_flat's two pulleys and serpentine_accessory's
seven (two back-side idlers) drawn by the one code path, against the creep theory; and
``beltsim plot`` / ``beltsim animate`` on a short serpentine run."""

from __future__ import annotations

import json
import math

import matplotlib
import numpy as np
import pytest
from matplotlib.figure import Figure
from matplotlib.patches import Circle, FancyArrowPatch
from matplotlib.path import Path as MplPath
from PIL import Image

import beltsim
from beltsim.beltdrive import drawing
from beltsim.beltdrive.exact import string_state
from beltsim.beltdrive.figures import figure_keys, hub_loads
from beltsim.beltdrive.io import animate_drive_run, plot_drive_run
from beltsim.beltdrive.plots import draw_drive, plot_drive_history, plot_loop_fields
from beltsim.cli import main
from beltsim.io.results import save_run
from beltsim.plots.common import offscreen
from helpers import BACK_IDLER, scene_path, serpentine_scene

matplotlib.use("Agg")

pytestmark = pytest.mark.unit

PNG_MAGIC = b"\x89PNG\r\n\x1a\n"
#: nodes per unit of loop length (1/m): about 120 on drive_flat, 110 on the accessory drive
NODES_PER_M = 60.0


def _state(name):
    """A drive's params, its creep theory and that state at nodes along the loop."""
    P = beltsim.load_scene(scene_path(name)).params
    sol = string_state(P)
    g = P.layout
    x = np.linspace(0.0, g.loop_length, round(NODES_PER_M * g.loop_length), endpoint=False)
    # the span tensions at the spans' middles: the theory's hub loads on any layout
    middles = 0.5 * (g.bounds[1:-1:2] + g.bounds[2::2])
    hubs = hub_loads(g, P.rho, sol.c, sol.tension(middles))
    return {"P": P, "sol": sol, "x": x, "T": sol.tension(x), "f": sol.friction(x),
            "hubs": hubs}


@pytest.fixture(scope="module", params=["drive_flat", "serpentine_accessory"])
def state(request):
    return _state(request.param)


def _by_gid(ax, gid):
    return [a for a in ax.get_children() if a.get_gid() == gid]


def test_the_drive_is_drawn_to_scale_on_two_and_on_seven_pulleys(state):
    P, x = state["P"], state["x"]
    g = P.layout
    n = len(g)
    with offscreen():
        fig = draw_drive(P, x, state["T"], state["f"] != 0, hub_loads=state["hubs"],
                         title="a drive")
    # returned, not shown: a plain Figure with no pyplot manager
    assert type(fig) is Figure and fig.canvas.manager is None
    ax = fig.axes[0]
    # one circle per pulley, at its centre and radius; the back-side idlers shaded
    pulleys = [p for p in ax.patches if isinstance(p, Circle)]
    assert len(pulleys) == n
    assert sorted(p.get_gid() for p in pulleys) == sorted(f"pulley {m}" for m in g.names)
    for p in pulleys:
        i = g.index(p.get_gid().removeprefix("pulley "))
        np.testing.assert_allclose(p.center, g.centres[i], rtol=0, atol=1e-15)
        assert p.radius == g.radii[i]
        back = matplotlib.colors.to_rgba(drawing.BACK_FACE)
        assert (p.get_facecolor() == back) == (g.sides[i] < 0)
    # the names beside them
    names = [t.get_text().split("\n")[0] for t in _by_gid(ax, "pulley name")]
    assert sorted(names) == sorted(g.names)
    # a hub-load arrow on every pulley, from its centre along the belt's force on it
    arrows = _by_gid(ax, "hub load")
    assert len(arrows) == n and all(isinstance(a, FancyArrowPatch) for a in arrows)
    lengths = []
    for arrow, c, F in zip(arrows, g.centres, state["hubs"]):
        # the ends as given, in data units (matplotlib has no public getter for them;
        # get_path() is shrunk by a few points at each end)
        (x0, y0), (x1, y1) = arrow._posA_posB
        np.testing.assert_allclose((x0, y0), c, atol=1e-15)
        d = np.array([x1 - x0, y1 - y0])
        assert abs(d[0] * F[1] - d[1] * F[0]) <= 1e-9 * np.hypot(*d) * np.hypot(*F)
        assert d @ F > 0
        lengths.append(np.hypot(*d))
    assert max(lengths) == pytest.approx(drawing.HUB_ARROW * drawing.extent(g)[2])
    # the coloured belt follows the whole loop: its pieces add up to the loop's length
    (belt,) = _by_gid(ax, "belt")
    seg = np.asarray(belt.get_segments())
    total = np.sum(np.hypot(*(seg[:, 1] - seg[:, 0]).T))
    assert total == pytest.approx(g.loop_length, rel=1e-4)  # chords on the arcs: shorter
    assert belt.get_array().min() >= state["T"].min() - 1e-9
    # the inner pulleys lie inside the loop, the back-side idlers outside it, on the
    # belt's outer face
    loop = MplPath(np.column_stack(g.path(np.linspace(0, g.loop_length, 2000))))
    for i in range(n):
        assert loop.contains_point(g.centres[i]) == (g.sides[i] > 0), g.names[i]
    # the figure's size follows the layout's aspect
    w, h = fig.get_size_inches()
    lo, hi, _ = drawing.extent(g)
    tall = (hi - lo)[1] > (hi - lo)[0]
    assert (h > w - 1.8) == tall


def test_slip_is_marked_on_the_slipping_arcs_only(state):
    P, x = state["P"], state["x"]
    g = P.layout
    with offscreen():
        fig = draw_drive(P.layout, x, state["T"], state["f"] != 0)
    (line,) = _by_gid(fig.axes[0], "slip")
    X, Y = (np.asarray(v, dtype=float) for v in line.get_data())
    keep = np.isfinite(X)
    pts = np.column_stack([X[keep], Y[keep]])
    # each marked point lies just off a slipping pulley's rim, none near an idler
    d = np.hypot(*(pts[:, None, :] - g.centres[None]).transpose(2, 0, 1)) - g.radii
    nearest = np.argmin(np.abs(d), axis=1)
    slipping = state["f"] != 0
    assert set(nearest) == set(g.segment_of(x[slipping]) // 2)
    assert set(nearest) <= set(np.flatnonzero(np.broadcast_to(state["sol"].phi_s, len(g))))
    # at the gap off the rim, but where a slipping node's cell reaches past the arc's
    # exit onto the span
    gap = drawing.SLIP_OFFSET * drawing.extent(g)[2]
    off = np.abs(d[np.arange(len(pts)), nearest])
    assert np.median(off) == pytest.approx(gap, rel=1e-6)
    assert np.all((off > gap * (1 - 1e-6)) & (off < 1.5 * gap))


def test_tension_along_the_loop_against_the_exact_state(state, tmp_path):
    P, x, sol = state["P"], state["x"], state["sol"]
    g = P.layout
    with offscreen():
        fig = plot_loop_fields(x, {"tension": state["T"], "friction": state["f"]}, P,
                               analytic=sol)
    top = fig.axes[0]
    exact = [ln for ln in top.get_lines() if ln.get_label() == "analytic steady state"]
    np.testing.assert_array_equal(exact[0].get_ydata(), sol.tension(exact[0].get_xdata()))
    assert len(exact[0].get_xdata()) > 2000  # sampled finely, each breakpoint either side
    (ends,) = [ln for ln in top.get_lines()
               if ln.get_label() == "analytic start of the slip arcs"]
    assert len(ends.get_xdata()) == len(sol.stick_ends) == int(np.sum(np.broadcast_to(
        sol.phi_s, len(g)) > 0))
    # every boundary of an arc and a span marked, every pulley named over its arc
    vertical = [ln for ln in top.get_lines() if ln.get_xdata()[0] == ln.get_xdata()[-1]
                and len(ln.get_xdata()) == 2]
    assert len(vertical) == 2 * len(g) - 1
    labels = " ".join(t.get_text() for t in top.texts)
    assert all(name in labels for name in g.names)
    assert top.get_xlim() == pytest.approx((0.0, g.loop_length))


def test_history_draws_every_pulley_speed_and_every_span_tension():
    P = beltsim.load_scene("serpentine_accessory").params
    names = P.layout.names
    t = np.linspace(0.0, 1.0, 30)
    ramp = 1.0 - np.exp(-t / 0.2)
    theory = string_state(P).summary()
    h = {k: theory[k] * ramp for k in figure_keys(names)}
    h["belt_speed"] = theory["belt_speed"] * ramp
    h["driver_torque"] = theory["driver_torque"] * ramp  # the torque[...] family instead
    with offscreen():
        fig = plot_drive_history(t, h, steady=theory)
    speed, tension, torque = fig.axes[1], fig.axes[2], fig.axes[3]
    assert len(fig.axes) == 4
    for ax, family in ((speed, "speed"), (tension, "tension"), (torque, "torque")):
        keys = [k for k in figure_keys(names) if k.startswith(family + "[")]
        drawn = [ln for ln in ax.get_lines() if not ln.get_label().endswith(
            "steady state") and ln.get_linestyle() == "-"]
        assert len(drawn) == len(names)
        for ln, k in zip(drawn, keys):
            np.testing.assert_array_equal(ln.get_ydata(), h[k])
    spans = [ln.get_label() for ln in tension.get_lines() if ln.get_linestyle() == "-"]
    assert spans[0] == f"{names[0]}-{names[1]}"


@pytest.fixture(scope="module")
def short_run(tmp_path_factory):
    """A short start-up of a drive with a back-side idler on a coarse grid, stored with
    its snapshots."""
    out = tmp_path_factory.mktemp("serpentine_run")
    scene = serpentine_scene(BACK_IDLER, model="string", **{
        "numerics.elements": 90, "numerics.t_end": 0.08})
    result = beltsim.run(scene, snapshot_interval=0.02)
    save_run(result, out)
    return out


def test_the_plot_command_draws_a_serpentine_run(short_run, tmp_path, capsys):
    import time

    start = time.perf_counter()
    assert main(["plot", str(short_run), "--out", str(tmp_path)]) == 0
    wall = time.perf_counter() - start
    assert "wrote" in capsys.readouterr().out
    for name in ("drive.png", "fields.png", "history.png"):
        assert (tmp_path / name).read_bytes()[:8] == PNG_MAGIC, name
    assert wall < 10.0  # three figures of a seven-pulley drive take about 3 s
    # the drawing's hub loads are the summary's
    summary = json.loads((short_run / "summary.json").read_text())
    with offscreen():
        paths = plot_drive_run(short_run, tmp_path / "again")
    assert [p.name for p in paths] == ["drive.png", "fields.png", "history.png"]
    assert len(summary["pulleys"]) == 3


def test_a_serpentine_run_animates_with_its_hub_loads(short_run, tmp_path):
    path = animate_drive_run(short_run, tmp_path / "drive.gif", fps=5)
    frames = np.load(short_run / "snapshots.npz")["t"]
    with Image.open(path) as im:
        assert im.n_frames == len(frames) > 1


def test_the_two_pulley_geometry_draws_as_its_layout():
    """A Geometry is read as the layout of two inner pulleys, the driver at the origin,
    so the two-pulley drawing is the N-pulley one."""
    P = beltsim.load_scene(scene_path("drive_flat")).params
    from beltsim.beltdrive.plot_input import drive_layout

    layout, roles = drive_layout(P.geometry)
    assert roles == ("driver", "driven") and layout.names == roles
    np.testing.assert_allclose(layout.bounds, P.geometry.bounds, rtol=1e-14, atol=1e-15)
    xs = np.linspace(0, layout.loop_length, 50, endpoint=False)
    for a, b in zip(layout.path(xs), P.geometry.path(xs)):
        np.testing.assert_allclose(a, b, atol=1e-12)
    with pytest.raises(ValueError, match=r"^layout: must be a PulleyLayout"):
        drive_layout(object())
    with pytest.raises(ValueError, match=r"^hub_loads: shape \(3, 2\) for 2 pulleys"):
        with offscreen():
            draw_drive(P, np.linspace(0, 1, 10), np.ones(10), hub_loads=np.ones((3, 2)))
    assert math.isfinite(layout.loop_length)


def test_a_tensioner_run_is_drawn_with_its_arm_at_rest(tmp_path):
    """serpentine_tensioner's steady state: the drawing's layout is the run's (the pulley
    where the arm rests, not where the scene draws it), with the arm from its pivot."""
    scene = beltsim.load_scene("serpentine_tensioner", {"numerics.elements": 200})
    res = beltsim.run(scene)
    save_run(res, tmp_path)
    travel = res.summary()["arm_travel"]
    assert abs(travel) > 0.01  # the arm moved: the check below can tell the layouts apart
    P = scene.params.at_arm(travel)
    k = P.tensioner.index
    arm = (P.tensioner.pivot, P.layout.centres[k], scene.params.layout.centres[k])
    f = res.fields
    with offscreen():
        fig = draw_drive(P, res.x, f["tension"], arm=arm)
    line = next(a for a in fig.axes[0].lines if a.get_gid() == "arm")
    np.testing.assert_allclose(line.get_xydata()[-1], P.layout.centres[k], rtol=0,
                               atol=1e-15)
    assert [p.name for p in plot_drive_run(tmp_path)] == ["drive.png", "fields.png",
                                                         "history.png"]


# ---------------------------------------------------------------------------
# a tensioner's arm moving in a transient


@pytest.fixture(scope="module")
def arm_run(tmp_path_factory):
    """A short start-up of serpentine_tensioner whose arm moves (esdirk3), coarse, stored
    with its snapshots (about 3 s)."""
    out = tmp_path_factory.mktemp("arm_run")
    scene = beltsim.load_scene("serpentine_tensioner", {
        "numerics.integrator": "esdirk3", "numerics.elements": 200, "numerics.t_end": 0.1})
    result = beltsim.run(scene, snapshot_interval=0.02)
    save_run(result, out)
    return out


def _spy_frames(monkeypatch):
    """Record, frame by frame as the animation draws them, the drawing's tensioner
    circle, the arm's bar and the title (no file written)."""
    from beltsim.beltdrive import animation

    made, seen = [], []
    real = drawing.DriveDrawing.__init__

    def spy(self, *args, **kwargs):
        made.append(self)
        real(self, *args, **kwargs)

    def record(path, frames_rgb, fps):
        d = made[-1]
        for _ in frames_rgb:
            seen.append({"centres": np.array([p[0].center for p in d.pulleys]),
                         "bar": None if d.arm is None else d.arm[2].get_xydata().copy(),
                         "title": d.belt.axes.get_title(),
                         "belt": np.concatenate([s for s in d.belt.get_segments()])})
        return path

    monkeypatch.setattr(drawing.DriveDrawing, "__init__", spy)
    monkeypatch.setattr(animation, "write_frames", record)
    return made, seen


def test_a_moving_arm_is_animated_at_each_frames_angle(arm_run, tmp_path, monkeypatch):
    """Each frame draws the tensioner pulley, its arm and the belt's path where
    Tensioner.turned puts them at that frame's travel, the drawn arm dashed."""
    snaps = np.load(arm_run / "snapshots.npz")
    travel = snaps["arm_travel"]
    assert travel.shape == snaps["t"].shape and abs(travel[0] - travel[-1]) > 5e-3
    made, seen = _spy_frames(monkeypatch)
    animate_drive_run(arm_run, tmp_path / "arm.gif", fps=5)
    assert len(seen) == len(travel)
    scene = beltsim.load_scene(arm_run / "scene.toml")
    drawn = scene.params.layout  # the scene's layout: the arm as drawn
    ten = scene.params.tensioner
    k = ten.index
    for frame, beta in zip(seen, travel):
        at = ten.turned(drawn, float(beta))
        np.testing.assert_allclose(frame["centres"][k], at.centres[k], rtol=0, atol=1e-9)
        np.testing.assert_allclose(frame["bar"], [ten.pivot, at.centres[k]], rtol=0,
                                   atol=1e-9)
        # the belt runs round the turned pulley: its path touches the rim
        gap = np.hypot(*(frame["belt"] - at.centres[k]).T).min() - at.radii[k]
        assert abs(gap) < 1e-6
        assert f"arm travel β = {beta:.4g} rad" in frame["title"]
        others = np.delete(frame["centres"], k, axis=0)
        np.testing.assert_array_equal(others, np.delete(drawn.centres, k, axis=0))
    # two frames, two places: the first and the last frame's pulley moved apart
    assert math.dist(seen[0]["centres"][k], seen[-1]["centres"][k]) > 3e-4
    dashed = next(a for a in made[-1].belt.axes.lines if a.get_gid() == "arm drawn")
    np.testing.assert_allclose(dashed.get_xydata()[-1], drawn.centres[k], atol=1e-12)


def test_a_fixed_layout_animates_as_before(short_run, tmp_path, monkeypatch):
    """No tensioner: no arm, every pulley where the layout has it in every frame, and
    the blitted frames redraw only the belt's state (the pulleys stay in the
    background)."""
    made, seen = _spy_frames(monkeypatch)
    animate_drive_run(short_run, tmp_path / "d.gif", fps=5)
    layout = made[-1].layout
    assert made[-1].arm is None and "arm travel" not in seen[-1]["title"]
    for frame in seen:
        np.testing.assert_array_equal(frame["centres"], layout.centres)
        np.testing.assert_array_equal(frame["belt"], seen[0]["belt"])
    assert not any(isinstance(a, Circle) for a in made[-1].moving())
    assert "arm_travel" not in np.load(short_run / "snapshots.npz").files


def test_carried_keeps_each_segments_fraction():
    P = beltsim.load_scene("serpentine_tensioner").params
    g, h = P.layout, P.tensioner.turned(P.layout, 0.05)
    assert h.loop_length != g.loop_length
    assert drawing.carried(g, g, g.bounds) is not None
    np.testing.assert_allclose(drawing.carried(g, h, g.bounds[:-1]), h.bounds[:-1],
                               atol=1e-14)
    mid = 0.5 * (g.bounds[3] + g.bounds[4])
    np.testing.assert_allclose(drawing.carried(g, h, [mid, mid + g.loop_length]),
                               [0.5 * (h.bounds[3] + h.bounds[4]),
                                0.5 * (h.bounds[3] + h.bounds[4]) + h.loop_length])


def test_a_transient_runs_plot_draws_its_end_state_arm_and_its_history(arm_run, tmp_path):
    """The run's grid is laid at the rest angle (summary grid_arm_travel), its end state
    has the arm elsewhere (arm_travel): drive.png draws the nodes on the grid's layout
    carried over to the end state's, the arm at arm_travel; history.png has the arm."""
    from beltsim.beltdrive.io import read_drive_run

    scene, x, f, hist, summary = read_drive_run(arm_run)
    assert summary["grid_arm_travel"] != summary["arm_travel"]
    assert "arm_travel" in hist
    paths = plot_drive_run(arm_run, tmp_path)
    assert [p.name for p in paths] == ["drive.png", "fields.png", "history.png"]
    P = scene.params
    k = P.tensioner.index
    end = P.at_arm(summary["arm_travel"])
    with offscreen():
        fig = draw_drive(P.at_arm(summary["grid_arm_travel"]), x, f["tension"],
                         arm=(P.tensioner.pivot, end.layout.centres[k],
                              P.layout.centres[k]), at=end)
        bar = next(a for a in fig.axes[0].lines if a.get_gid() == "arm")
        np.testing.assert_allclose(bar.get_xydata()[-1], end.layout.centres[k], atol=1e-12)
        history = plot_drive_history(hist["t"], hist)
    labels = [ax.get_ylabel() for ax in history.axes]
    assert any("arm travel" in s for s in labels)
    ax = next(ax for ax in history.axes if "arm travel" in ax.get_ylabel())
    np.testing.assert_array_equal(ax.lines[0].get_ydata(), hist["arm_travel"])
