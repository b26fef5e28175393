"""The convergence and bench commands run and give sane outputs (no timing asserted)."""

import json

import numpy as np

from beltsim.problem.scene import load_scene
from beltsim.simulation.controller import Simulation
from beltsim.studies import bench, convergence
from helpers import cli, scene_path


def test_convergence_command_small_ladder(tmp_path):
    proc = cli("convergence", scene_path("paper_slip"), "--ladder", "60,120,240", "--out",
                str(tmp_path))
    assert proc.returncode == 0, proc.stderr
    table = read_csv_text(tmp_path / "convergence.csv")
    assert [r["scheme"] for r in table] == (["explicit"] * 3 + ["implicit"] * 3
                                             + ["pseudo"] * 3 + ["steady"] * 3
                                             + ["richardson"] * 3)
    assert all(float(r["converged"]) == 1.0 for r in table)  # booleans as numbers
    for scheme in ("explicit", "implicit", "pseudo", "steady"):
        errs = [float(r["error_total_friction"]) for r in table if r["scheme"] == scheme]
        assert errs[0] > errs[1] > errs[2]  # refining shrinks the error
        assert all(float(r["wall_time"]) > 0 for r in table if r["scheme"] == scheme)
    # extrapolation cancels the leading first-order error: far below the plain solve's
    for plain, ext in zip([r for r in table if r["scheme"] == "steady"],
                          [r for r in table if r["scheme"] == "richardson"]):
        assert float(ext["error_total_friction"]) < 0.2 * float(plain["error_total_friction"])
        assert float(ext["error_u"]) < 0.2 * float(plain["error_u"])
    assert (tmp_path / "error_vs_runtime.png").stat().st_size > 10_000
    assert "observed order" in proc.stdout and "total_friction" in proc.stdout


def read_csv_text(path):
    lines = path.read_text().splitlines()
    header = lines[0].split(",")
    return [dict(zip(header, line.split(","))) for line in lines[1:]]


def test_observed_orders_recover_a_known_rate():
    rows = [{"scheme": "x", "converged": True, "h_min": h, "error_u": 3.0 * h**1.5}
            for h in (0.1, 0.05, 0.025)]
    o = convergence.observed_orders(rows, "u")["x"]
    np.testing.assert_allclose(o["pairs"], [1.5, 1.5])
    assert abs(o["fit"] - 1.5) < 1e-12


def test_peer_rhs_is_the_semi_discrete_model():
    """The peer's right-hand side and the implicit residual describe one model: a
    backward-Euler residual built from the peer's accelerations vanishes."""
    sim = Simulation(load_scene(scene_path("paper_slip"), ["numerics.elements=40"]))
    peer = bench.PeerSystem(sim)
    rng = np.random.default_rng(0)
    y = 1e-4 * rng.standard_normal(4 * peer.n)
    f = peer.rhs(0.3, y)
    n = peer.n
    from beltsim.physics.model import State, residual_numpy
    dt = 1e-3
    u, th, ud, td = (np.concatenate([[0], part, [0]]) for part in np.split(y, 4))
    acc_u = np.concatenate([[0], f[2 * n:3 * n], [0]])
    acc_t = np.concatenate([[0], f[3 * n:], [0]])
    # choose the "old" state so that the backward-Euler velocities are ud, td and the
    # accelerations are the peer's
    zero = np.zeros_like(u)
    old = State(u - dt * ud, th - dt * td, zero, ud - dt * acc_u, td - dt * acc_t, zero)
    d = sim.disc
    R, _ = residual_numpy(u, th, old, 1 / dt, 0.3, d.mesh, d.model, d.drive)
    scale = sim.params.B * d.scales.theta
    assert np.abs(R).max() < 1e-9 * scale


def test_bench_command_prints_json_last(tmp_path):
    # a coarse grid and a soft regularisation keep the peer to seconds
    # (and a strong physical damping: the peer has no adaptive damping of its own)
    proc = cli("bench", scene_path("paper_slip"), "--set", "numerics.elements=40",
               "--set", "numerics.regularisation=0.05", "--set", "physics.damping=650",
               "--no-cold")
    assert proc.returncode == 0, proc.stderr
    last = json.loads(proc.stdout.strip().splitlines()[-1])
    for key in ("ours_wall_time", "ours_error", "peer_wall_time", "peer_error", "speedup",
                "explicit_node_steps_per_s", "cold_start_time"):
        assert key in last
    assert last["ours_wall_time"] > 0 and last["peer_wall_time"] > 0
    assert last["peer_converged"] is True
    # same grid, same discretisation, same steady criterion: the same steady state
    assert abs(last["ours_error"] - last["peer_error"]) < 1e-4
    assert last["explicit_node_steps_per_s"] > 0


def test_bisected_grid_is_nested():
    from beltsim.physics.grid import bisect, make_grid
    g = make_grid(1.0, 1 / 3, 2 / 3, 50, 8.0)
    f = bisect(g)
    assert f.n_elements == 100 and np.array_equal(f.x[::2], g.x)
    assert f.x[f.j1] == 1 / 3 and f.x[f.j2] == 2 / 3
    np.testing.assert_allclose(f.he[0::2], g.he / 2)


def test_richardson_extrapolation_is_second_order_on_the_stick_scene():
    """Until the regularisation's own error (~2e-6) the extrapolated errors fall at
    second order: 0.5 -> 0.25 mm elements cut them by ~4 (first order: 2)."""
    errs = [convergence.richardson(load_scene(scene_path("paper_inertia"),
                                          [f"numerics.elements={n}"]))[2]
            for n in (125, 250)]
    for key in ("total_friction", "u", "concentrated_force"):
        assert errs[0][key] / errs[1][key] > 3.0, key
