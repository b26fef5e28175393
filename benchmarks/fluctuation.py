"""One simulated second of the crankshaft's speed fluctuation on a closed drive.

``python -m benchmarks.fluctuation [SCENE] [--laws tanh,exact] [--seconds S]
[--amplitude A] [--frequency F] [--set KEY=VALUE ...]`` from the repository root (SCENE
defaults to the shipped ``serpentine_accessory``) runs the drive from rest with its
driver's speed a sine (``{mean, amplitude, period}``, the mean the scene's speed; default
+-1.5 rad/s at 40 Hz) through its start-up ramp (``numerics.settle_time``) and then S
simulated seconds more (default 1; the periodic test is held off with
``numerics.steady_tol`` = 1e-300 so that every run lasts the same), once per friction
law, and prints per law, for those S seconds after the ramp: the wall time and its
ratio to S, the steps, rejected steps, Newton iterations per step; then the periodic
tracker's amplitudes over the last period (``RunResult.periodic``: each span's tension
and each pulley's speed), so that a faster run is seen to give the same answer. Last,
one line of JSON (:func:`bench`'s dict). The kernels are loaded (a short run) before
the timing.
"""

from __future__ import annotations

import sys
import time

LAWS = ("tanh", "exact")
AMPLITUDE = 1.5  # rad/s
FREQUENCY = 40.0  # Hz


def log(text):
    print(text, flush=True)


def fluctuating(scene, seconds=1.0, amplitude=AMPLITUDE, frequency=FREQUENCY, law="tanh",
                sets=()):
    """The scene with its driver's speed a sine about its own, run for ``seconds`` after
    its start-up ramp; with that ramp's end (s)."""
    from beltsim.beltdrive.scene import driver_speed_key
    from beltsim.solvers import discretise

    P = scene.params
    sine = {"mean": float(P.pulleys[P.driver].speed), "amplitude": amplitude,
            "period": 1.0 / frequency}
    s = scene.with_overrides([(driver_speed_key(scene.to_dict()), sine),
                              ("numerics.friction_law", law),
                              ("numerics.steady_tol", 1e-300), *sets])
    settle = discretise(s).numerics.settle_time
    return s.with_overrides({"numerics.t_end": settle + float(seconds)}), settle


class Mark:
    """A tracker that notes the wall clock, steps and Newton iterations at the first check
    at or after ``t``."""

    def __new__(cls, t):
        import beltsim

        class _Mark(beltsim.Tracker):
            def initialize(self, sim):
                self.at = None

            def handle(self, sim):
                if self.at is None and sim.t >= t - 1e-12:
                    st = sim.scheme.statistics()
                    self.at = (time.perf_counter(), sim.t, st["steps"],
                               st.get("newton_iterations", 0),
                               st.get("rejected_steps", 0))

        return _Mark()


def one(scene, settle) -> dict:
    """One run of ``scene`` (kernels loaded): its figures after ``settle`` and its
    periodic amplitudes."""
    import beltsim

    mark = Mark(settle)
    r = beltsim.run(scene, raise_on_failure=False, trackers=[mark], stability=False)
    end = time.perf_counter()
    st = r.statistics
    w0, t0, s0, n0, r0 = mark.at if mark.at is not None else (end, r.simulated_time,
                                                             r.steps, r.newton_iterations,
                                                             0)
    wall, steps = end - w0, r.steps - s0
    amps = {k: v["amplitude"] for k, v in (r.periodic or {}).items()
            if isinstance(v, dict)}
    means = {k: v["mean"] for k, v in (r.periodic or {}).items() if isinstance(v, dict)}
    return {"law": r.numerics.friction_law, "integrator": r.numerics.integrator,
            "elements": r.numerics.elements, "status": r.status.value, "reason": r.reason,
            "simulated_time": r.simulated_time, "settle_time": t0,
            "run_wall_time": r.wall_time, "run_steps": r.steps, "wall_time": wall,
            "wall_per_second": wall / max(r.simulated_time - t0, 1e-300),
            "steps": steps, "rejected_steps": st.get("rejected_steps", 0) - r0,
            "newton_iterations": r.newton_iterations - n0,
            "newton_per_step": (r.newton_iterations - n0) / max(steps, 1),
            "amplitudes": amps, "means": means}


def report(out: dict) -> None:
    log(f"{out['law']} law ({out['integrator']}, {out['elements']} elements): "
        f"{out['status']} at t = {out['simulated_time']:.4g} s (the run: wall "
        f"{out['run_wall_time']:.4g} s, {out['run_steps']} steps); after the ramp (t = "
        f"{out['settle_time']:.4g} s): wall {out['wall_time']:.4g} s "
        f"({out['wall_per_second']:.4g} s per simulated second), {out['steps']} steps, "
        f"{out['rejected_steps']} rejected, {out['newton_per_step']:.3g} Newton iterations "
        f"a step")
    for k, a in out["amplitudes"].items():
        log(f"    {k:40s} amplitude {a:.6g}  (mean {out['means'][k]:.6g})")


def bench(scene, laws=LAWS, seconds=1.0, amplitude=AMPLITUDE, frequency=FREQUENCY,
          sets=()) -> dict:
    """Each law's run (:func:`one`) after a short warm-up run that loads its kernels."""
    import beltsim

    out = {"seconds": seconds, "amplitude": amplitude, "frequency": frequency, "runs": []}
    for law in laws:
        s, settle = fluctuating(scene, seconds, amplitude, frequency, law, sets)
        beltsim.run(s.with_overrides({"numerics.t_end": 2.0 / frequency}),
                    raise_on_failure=False)  # the kernels, loaded
        res = one(s, settle)
        report(res)
        out["runs"].append(res)
    return out


def main(argv=None) -> int:
    import argparse

    from beltsim.api import load_scene
    from beltsim.problem.tomlio import parse_toml

    from .drive import emit

    p = argparse.ArgumentParser(prog="python -m benchmarks.fluctuation")
    p.add_argument("scene", nargs="?", default="serpentine_accessory")
    p.add_argument("--laws", default=",".join(LAWS))
    p.add_argument("--seconds", type=float, default=1.0)
    p.add_argument("--amplitude", type=float, default=AMPLITUDE)
    p.add_argument("--frequency", type=float, default=FREQUENCY)
    p.add_argument("--set", action="append", default=[], metavar="KEY=VALUE",
                   help="a scene override (TOML value), e.g. numerics.elements=400")
    p.add_argument("--json", default=None, help="also write the dict to this file")
    args = p.parse_args(argv)
    sets = []
    for item in args.set:
        key, _, text = item.partition("=")
        sets.append((key, parse_toml(f"v = {text}")["v"]))
    out = bench(load_scene(args.scene), tuple(x for x in args.laws.split(",") if x),
                args.seconds, args.amplitude, args.frequency, sets)
    emit(out, args.json)
    return 0


if __name__ == "__main__":
    sys.exit(main())
