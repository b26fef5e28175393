"""The convergence and bench commands run and give sane outputs (no timing asserted)."""

import json

import numpy as np
import pytest

from beltsim.api import load_scene
from beltsim.physics.friction import LINEAR
from beltsim.simulation.controller import Simulation
from beltsim.studies import convergence, stability
from benchmarks import peers
from helpers import ERROR_FACTOR, cli, module, scene_path


@pytest.mark.cli
def test_a_refused_rung_is_reported_and_the_ladder_goes_on(tmp_path):
    # max_work 2e7 refuses the 240-element explicit run (~9e7 node-steps), admits 60 (~6e6)
    proc = cli("convergence", scene_path("paper_slip"), "--ladder", "240,60", "--schemes",
               "explicit", "--set", "numerics.max_work=2e7", "--out", str(tmp_path))
    assert proc.returncode == 0, proc.stderr
    table = read_csv_text(tmp_path / "convergence.csv")
    refused, done = table
    assert float(refused["converged"]) == 0.0
    assert refused["reason"].startswith("numerics.max_work:")
    assert float(done["converged"]) == 1.0 and done["reason"] == ""
    assert "refused: numerics.max_work" in proc.stdout


@pytest.mark.cli
@pytest.mark.verification
def test_convergence_command_small_ladder(tmp_path):
    proc = cli("convergence", scene_path("paper_slip"), "--ladder", "60,120,240", "--out",
                str(tmp_path))
    assert proc.returncode == 0, proc.stderr
    table = read_csv_text(tmp_path / "convergence.csv")
    schemes = [r["scheme"] for r in table]
    assert schemes[-3:] == ["richardson"] * 3  # each registered scheme, then extrapolation
    assert sorted(schemes[:-3]) == sorted(
        [s for s in ("esdirk3", "explicit", "implicit", "pseudo", "steady") for _ in range(3)])
    assert all(float(r["converged"]) == 1.0 for r in table)  # booleans as numbers
    for scheme in ("esdirk3", "explicit", "implicit", "pseudo", "steady"):
        errs = [float(r["error_total_friction"]) for r in table if r["scheme"] == scheme]
        assert errs[0] > errs[1] > errs[2]  # refining shrinks the error
        assert all(float(r["wall_time"]) > 0 for r in table if r["scheme"] == scheme)
    # extrapolation cancels the leading second-order error: far below the plain solve's
    for plain, ext in zip([r for r in table if r["scheme"] == "steady"],
                          [r for r in table if r["scheme"] == "richardson"]):
        assert float(ext["error_total_friction"]) < 0.2 * float(plain["error_total_friction"])
        assert float(ext["error_u"]) < 0.2 * float(plain["error_u"])
    assert (tmp_path / "error_vs_runtime.png").stat().st_size > 10_000
    assert "observed order" in proc.stdout and "total_friction" in proc.stdout


def read_csv_text(path):
    import csv
    with open(path, newline="") as fh:
        return list(csv.DictReader(fh))


@pytest.mark.unit
def test_observed_orders_recover_a_known_rate():
    rows = [{"scheme": "x", "converged": True, "h_min": h, "error_u": 3.0 * h**1.5}
            for h in (0.1, 0.05, 0.025)]
    o = convergence.observed_orders(rows, "u")["x"]
    np.testing.assert_allclose(o["pairs"], [1.5, 1.5])
    assert abs(o["fit"] - 1.5) < 1e-12


@pytest.mark.lab
def test_peer_rhs_is_the_semi_discrete_model():
    """The peer's right-hand side and the implicit residual describe one model: a
    backward-Euler residual built from the peer's accelerations vanishes."""
    sim = Simulation(load_scene(scene_path("paper_slip"), ["numerics.elements=40"]))
    peer = peers.PeerSystem(sim)
    rng = np.random.default_rng(0)
    n = peer.n
    y = 1e-4 * rng.standard_normal(4 * n)
    f = peer.rhs(0.3, y)
    from beltsim.physics.discrete import State
    from beltsim.physics.reference import residual
    dt = 1e-3

    def nodal(part):  # y's (u, theta) pairs of the interior nodes as nodal arrays
        return [np.concatenate([[0], part[k::2], [0]]) for k in (0, 1)]

    u, th = nodal(y[:2 * n])
    ud, td = nodal(y[2 * n:])
    acc_u, acc_t = nodal(f[2 * n:])
    # choose the "old" state so that the backward-Euler velocities are ud, td and the
    # accelerations are the peer's
    zero = np.zeros_like(u)
    old = State(u - dt * ud, th - dt * td, zero, ud - dt * acc_u, td - dt * acc_t, zero)
    d = sim.disc
    R, _ = residual(u, th, old, 1 / dt, 0.3, d.mesh, d.model, d.drive)
    scale = sim.params.B * d.scales.theta
    assert np.abs(R).max() < 1e-9 * scale
    np.testing.assert_array_equal(f[:2 * n], y[2 * n:])  # the drift q' = q'


@pytest.mark.cli
def test_bench_command_prints_json_last():
    proc = cli("bench", "paper_slip", "--elements", "20", "--repeat", "1", "--no-cold")
    assert proc.returncode == 0, proc.stderr
    last = json.loads(proc.stdout.strip().splitlines()[-1])
    assert last["elements"] == 20 and last["ours_converged"] is True
    assert last["ours_wall_time"] > 0 and last["ours_steady_wall_time"] > 0
    assert last["explicit_node_steps_per_s"] > 0 and last["cold_start_time"] is None
    # what a user waits for, each in a fresh process: the import is part of the run
    assert 0 < last["import_time"] < last["warm_run_time"]
    # 20 elements, second order: total friction measured 7.8e-3 (both schemes)
    assert last["ours_error"] < ERROR_FACTOR * 7.8e-3
    assert last["ours_steady_error"] < ERROR_FACTOR * 7.8e-3


@pytest.mark.lab
@pytest.mark.cli
def test_lab_bench_against_peers_and_port():
    proc = module("benchmarks.bench", "paper_slip", "--elements", "20", "--repeat", "1",
                  "--peer-cap", "60")
    assert proc.returncode == 0, proc.stderr
    last = json.loads(proc.stdout.strip().splitlines()[-1])
    for key in ("ours_wall_time", "ours_error", "peer_wall_time", "peer_error", "speedup",
                "peers", "steady_speedup", "kernel_speedup"):
        assert key in last
    assert last["ours_wall_time"] > 0 and last["peer_wall_time"] > 0
    assert last["peer_converged"] is True and last["peer"] in ("radau", "bdf")
    # the peer compared with is the fastest transient peer that converged, as reported
    # in its own row of the table
    converged = [k for k in ("radau", "bdf") if last["peers"][k]["converged"]]
    assert last["peer"] == min(converged, key=lambda k: last["peers"][k]["wall_time"])
    chosen = last["peers"][last["peer"]]
    assert (chosen["wall_time"], chosen["error"]) == (last["peer_wall_time"],
                                                      last["peer_error"])
    for name in ("radau", "bdf", "newton"):
        row = last["peers"][name]
        assert {"wall_time", "error", "converged", "tolerance"} <= row.keys()
    assert last["peers"]["newton"]["converged"] is True and last["steady_speedup"] > 0
    # same grid, same discretisation, same steady criterion: the same steady state
    assert abs(last["ours_error"] - last["peer_error"]) < 1e-4
    # the port of BDF2 against our BDF2 run: the same steps, Newton iterations and end
    # time, and the same state (total friction: measured 9e-16 relative from ours; other
    # arithmetic in the linear solves, so a bound well above round-off)
    row = last["port"]
    assert row["converged"] is True and row["steps"] == row["ours_steps"]
    assert row["newton_iterations"] == row["ours_newton_iterations"]
    assert row["simulated_time"] == row["ours_simulated_time"]
    assert row["total_friction_vs_ours"] < 1e-10


@pytest.mark.unit
def test_bench_refuses_a_bad_repeat_count(capsys):
    from beltsim.cli import main
    assert main(["bench", "paper_slip", "--repeat", "0", "--no-cold"]) == 2
    assert "--repeat" in capsys.readouterr().err


@pytest.mark.lab
def test_peer_jacobian_is_the_derivative_of_its_rhs():
    """The analytic sparse Jacobian against 4th-order central differences of the rhs, at a
    random state whose contact nodes sit on the steep part of the friction law."""
    sim = Simulation(load_scene(scene_path("paper_slip"), ["numerics.elements=30",
                                                           "numerics.regularisation=0.05"]))
    sysm = peers.PeerSystem(sim)
    n, t = sysm.n, 0.002  # early in the speed ramp: the mismatch is still near v_reg
    scale = peers._state_scale(sim, n)
    y = 1e-3 * scale * np.random.default_rng(0).standard_normal(4 * n)
    J = sysm.jacobian(t, y).toarray()
    fd = np.empty_like(J)
    for k in range(4 * n):
        e = np.zeros(4 * n)
        e[k] = 1e-4 * 1e-3 * scale[k]
        f = [sysm.rhs(t, y + m * e) for m in (-2, -1, 1, 2)]
        fd[:, k] = (f[0] - 8 * f[1] + 8 * f[2] - f[3]) / (12 * e[k])
    # in the unknowns' own units, each row relative to its largest entry
    err = (np.abs(J - fd) * scale).max(axis=1) / (np.abs(J) * scale).max(axis=1)
    assert err.max() < 1e-6
    # the friction part was exercised: several contact nodes are far from saturation
    linear = sim.disc.model._replace(law=LINEAR)  # slope 1 everywhere
    slopes = sysm.friction_entries(t, y) / sysm.friction_entries(t, y, p=linear)
    assert (slopes > 0.3).sum() >= 6 * 12  # at least 6 of the 12 contact nodes, 12 entries each


@pytest.mark.lab
def test_steady_peer_lands_on_the_steady_scheme_state():
    scene = load_scene(scene_path("paper_slip"), ["numerics.elements=100",
                                                  "numerics.integrator=steady"])
    ours = Simulation(scene).run().solution.total_friction
    res = peers.run_steady_peer(Simulation(scene))
    assert res.converged, res.reason
    assert abs(res.total_friction - ours) < 1e-8 * abs(ours)


@pytest.mark.lab
def test_radau_peer_reaches_the_steady_state_on_a_tiny_grid():
    scene = load_scene(scene_path("paper_slip"), ["numerics.elements=20"])
    res = peers.run_transient_peer(Simulation(scene), "Radau", max_wall=60.0)
    assert res.converged, res.reason
    steady = Simulation(scene.with_overrides(["numerics.integrator=steady"])).run()
    ref = steady.solution.total_friction
    assert abs(res.total_friction - ref) < peers.SAME_STATE * abs(ref)


@pytest.mark.unit
def test_bisected_grid_is_nested():
    from beltsim.physics.grid import bisect, make_grid
    g = make_grid(1.0, 1 / 3, 2 / 3, 50, 8.0)
    f = bisect(g)
    assert f.n_elements == 100 and np.array_equal(f.x[::2], g.x)
    assert f.x[f.j1] == 1 / 3 and f.x[f.j2] == 2 / 3
    np.testing.assert_allclose(f.he[0::2], g.he / 2)


@pytest.mark.verification
def test_richardson_extrapolation_beats_second_order_on_the_stick_scene():
    """The plain errors are second order, so (4 q(h/2) - q(h)) / 3 leaves a higher order.
    Below the default adhesion layer's own error (~2e-6) only with a thinner layer:
    delta = 1e-8 L, 0.5 -> 0.25 mm elements cut them by 11, 11, 7.4 (measured; second
    order: 4)."""
    errs = [convergence.richardson(load_scene(scene_path("paper_inertia"),
                                          [f"numerics.elements={n}",
                                           "numerics.adhesion_layer=1e-8"]))[2]
            for n in (125, 250)]
    for key in ("total_friction", "u", "concentrated_force"):
        assert errs[0][key] / errs[1][key] > 6.0, key


@pytest.mark.unit
def test_a_discrete_reference_measures_states_on_its_own_grid():
    """A coarse matrix compares each scheme with the steady scheme's state on the same
    grid: a state 1e-4 off in u is out of DISCRETE_BOUNDS, the state itself is not."""
    from beltsim.simulation.solution import DiscreteReference, DiscreteSolution, compare
    from beltsim.studies.stability import DISCRETE_BOUNDS
    sol = Simulation(load_scene(scene_path("paper_slip"), ["numerics.elements=60",
                                                           "numerics.integrator=steady"])
                     ).run().solution
    ref = DiscreteReference(sol)
    assert all(v == 0.0 for v in compare(sol, ref).values() if v is not None)
    off = DiscreteSolution(sol.params, sol.grid, sol.u * (1 + 1e-4), sol.theta, sol.fnode,
                           sol.law_code, sol.friction_scale)
    err = compare(off, ref)
    assert err["u"] == pytest.approx(1e-4) and err["u"] > DISCRETE_BOUNDS["u"]
    with pytest.raises(ValueError, match="own grid"):
        ref.fields(sol.x[:-1])


@pytest.mark.verification
@pytest.mark.parametrize("case", [stability.STABILITY_CASES[2], stability.DRIVE_CASES[0]],
                         ids=["paper slip", "drive"])
def test_a_coarse_cell_reaches_its_grids_steady_state_on_either_layout(case):
    """A stability cell of each layout, on a coarse grid against the steady scheme's state
    on that grid: the layout's own errors within its DISCRETE_BOUNDS."""
    cell = stability.stability_cell(case, "esdirk3", extra=[("numerics.elements", 60)],
                                    discrete=True)
    assert cell["status"] is stability.CellStatus.CONVERGED, cell["reason"]
    errors = {k for k, v in cell.items() if k.startswith("error_") and np.isfinite(v)}
    layout = ("error_tight_tension" in errors, "error_total_friction" in errors)
    assert layout == ((True, False) if case in stability.DRIVE_CASES else (False, True))
    md = stability.stability_markdown([{"case": case.name, **cell}])
    assert case.name in md and md.count("\n|") >= 2
