"""Random closed drives for the random study (`python -m validation.random_scenes N
--drives`): two pulleys, a flat belt, from rest to a load below the drive's capacity.

Drive i of seed S is drawn from its own generator ``default_rng([S, i, DRIVE_STREAM])``:
the same seed draws the same drives whatever N, apart from the straight scenes of that
seed. What is drawn (log-uniform unless said otherwise):

* geometry: driver radius R1 0.03 .. 0.3 m, R2 / R1 0.3 .. 3, centre distance
  (R1 + R2) times 1.2 .. 6;
* belt: height 1 .. 6 mm, width / height 3 .. 30, E 1e8 .. 5e9 Pa, density 900 .. 1500
  kg/m^3, poisson_ratio uniform 0.3 .. 0.49, shear_factor 5/6;
* installation tension: strain N0 / b1 1e-3 .. 1e-2;
* speed: an inertial drive's rim speed from rho c^2 / N0 = 0.01 .. 0.5 (the slack span's
  tension falls with rho c^2), a quasistatic one's 1 .. 30 m/s;
* friction coefficient 0.2 .. 0.6, the load 0.1 .. 0.9 of the capacity (the creep
  theory's, at the drawn speed), the driven pulley's inertia 1e-4 .. 1 kg m^2;
* model "beam" or "string", inertia on, each for half the drives; an inertial drive's
  physics.damping 5 .. 100 1/s.
"""

from __future__ import annotations

import math

import numpy as np

from beltsim.beltdrive.analytic import capacity
from beltsim.beltdrive.scene import DriveScene

#: the third entry of a drive's seed: its draws are apart from the straight scenes'
DRIVE_STREAM = 1


def _log_uniform(rng, lo, hi):
    return float(math.exp(rng.uniform(math.log(lo), math.log(hi))))


def _sig(x, digits=4):
    """Drawn inputs rounded to a few digits: a readable scene file."""
    return float(f"{x:.{digits - 1}e}")


def draw_drive(seed: int, index: int) -> DriveScene:
    """Drive ``index`` of ``seed``: valid by construction (DriveScene validates it)."""
    rng = np.random.default_rng([seed, index, DRIVE_STREAM])
    r1 = _sig(_log_uniform(rng, 0.03, 0.3))
    r2 = _sig(r1 * _log_uniform(rng, 0.3, 3.0))
    distance = _sig((r1 + r2) * _log_uniform(rng, 1.2, 6.0))
    h = _sig(_log_uniform(rng, 1e-3, 6e-3))
    w = _sig(h * _log_uniform(rng, 3.0, 30.0))
    E = _sig(_log_uniform(rng, 1e8, 5e9))
    density = _sig(_log_uniform(rng, 900.0, 1500.0))
    nu = _sig(rng.uniform(0.3, 0.49))
    b1, rho = E * w * h, density * w * h
    N0 = _sig(b1 * _log_uniform(rng, 1e-3, 1e-2))
    inertia = bool(rng.random() < 0.5)
    rim = (math.sqrt(_log_uniform(rng, 0.01, 0.5) * N0 / rho) if inertia
           else _log_uniform(rng, 1.0, 30.0))
    mu = _sig(_log_uniform(rng, 0.2, 0.6))
    load_share = _log_uniform(rng, 0.1, 0.9)
    J2 = _sig(_log_uniform(rng, 1e-4, 1.0))
    model = "beam" if rng.random() < 0.5 else "string"
    damping = _sig(_log_uniform(rng, 5.0, 100.0))
    data = {
        "title": f"random drive {index} (seed {seed})",
        "belt": {"height": h, "width": w, "youngs_modulus": E, "poisson_ratio": nu,
                 "density": density, "shear_factor": 5.0 / 6.0},
        "drive": {"driver_radius": r1, "driven_radius": r2, "centre_distance": distance,
                  "installation_tension": N0, "driver_speed": _sig(rim / r1),
                  "load_torque": 0.0, "driven_inertia": J2},
        "contact": {"friction": "coulomb", "friction_coefficient": mu},
        "physics": {"model": model, "inertia": inertia,
                    **({"damping": damping} if inertia else {})},
    }
    unloaded = DriveScene(data)
    data["drive"]["load_torque"] = _sig(load_share * capacity(unloaded.params))
    return DriveScene(data)
