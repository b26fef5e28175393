"""The sparse modes search (physics.loop_modes: shift-invert about 0, then a sweep up the
imaginary axis) against the dense QZ algorithm on small grids of several layouts: the
same listed modes, shapes and least stable eigenvalue."""

from __future__ import annotations

import numpy as np
import pytest

from beltsim import load_scene
from beltsim.physics.loop_modes import drive_modes
from helpers import BACK_IDLER, SERPENTINE_BACK, serpentine_scene

#: Agreement bound on each eigenvalue, relative to its modulus. The dense QZ's backward
#: error is round-off of the pencil's largest entries (the stuck nodes' penalty, 1e10
#: times the masses' scale), so its eigenvalues carry an absolute error near
#: 1e-16 * 1e10 ~ 1e-6 of the spectrum's scale; ARPACK's are solved to 1e-10 of
#: 1 / (lambda - sigma). Measured on these scenes (60 and 120 elements, 2026-12-03): at
#: most MEASURED (the accessory drive's 10th mode on 60 elements; the least stable
#: eigenvalues 3.5e-7 at most); the bound leaves a factor of ten. The shapes (scaled so
#: their largest displacement is 1): 5e-5 at most, bound SHAPE.
MEASURED = 2.6e-6
BOUND = 10 * MEASURED
SHAPE = 5e-4

SCENES = {
    "drive_flat": lambda: load_scene("drive_flat"),
    "accessory": lambda: load_scene("serpentine_accessory"),
    "accessory_tanh": lambda: load_scene("serpentine_accessory",
                                         {"numerics.friction_law": "tanh"}),
    "back_idler": lambda: serpentine_scene(BACK_IDLER),
    "four_pulleys_back": lambda: serpentine_scene(SERPENTINE_BACK),
}


def _both(name, elements, **kw):
    scene = SCENES[name]()
    return (drive_modes(scene, elements=elements, method="dense", **kw),
            drive_modes(scene, elements=elements, method="sparse", **kw))


def _close(a, b):
    return abs(a - b) <= BOUND * max(abs(a), abs(b))


@pytest.mark.verification
@pytest.mark.parametrize(("name", "elements"), [(name, 60) for name in SCENES
                                                if name != "accessory_tanh"]
                         + [(name, 120) for name in SCENES])
def test_the_sparse_search_finds_the_dense_modes_and_least_stable(name, elements):
    """The ten lowest listed modes (eigenvalue and shape) and the least stable eigenvalue
    of every finite one: sparse as dense within BOUND of the eigenvalue's modulus; the
    shapes (scaled to a real largest displacement 1) within SHAPE."""
    dense, sparse = _both(name, elements)
    assert dense.method == "dense" and sparse.method == "sparse"
    assert len(sparse.modes) == len(dense.modes) == 10
    for d, s in zip(dense.modes, sparse.modes):
        assert _close(d.eigenvalue, s.eigenvalue), (d.eigenvalue, s.eigenvalue)
        assert d.largest == s.largest
        np.testing.assert_allclose(s.u, d.u, atol=SHAPE)
        rot = np.array([[d.pulleys[p][0], s.pulleys[p][0]] for p in d.pulleys])
        np.testing.assert_allclose(rot[:, 1], rot[:, 0], atol=SHAPE * np.max(np.abs(rot)))
    # the least stable rate; not its frequency: the belt's modes at 15.4 kHz form a
    # cluster at one rate (-d/2), whose member the QZ's round-off (about 1 1/s there)
    # makes the least stable is arbitrary (at 120 elements the dense pick is 38 rad/s
    # from the sparse one)
    assert (abs(dense.least_stable.real - sparse.least_stable.real)
            <= BOUND * abs(dense.least_stable)), (dense.least_stable, sparse.least_stable)


@pytest.mark.verification
def test_the_sparse_search_lists_every_mode_below_a_frequency_bound():
    """With f_max and no count: the same modes up to 3 kHz (the listing's disk about 0
    grows until it holds them all)."""
    dense, sparse = _both("accessory", 60, f_max=3000.0)
    assert len(dense.modes) >= 5 and len(sparse.modes) == len(dense.modes)
    np.testing.assert_allclose(sparse.frequencies, dense.frequencies, rtol=BOUND)


# -- the disks' bookkeeping ---------------------------------------------------------------


@pytest.mark.unit
def test_distinct_keeps_each_eigenvalue_once_and_a_double_one_twice():
    """Two overlapping disks: a copy found by both (1e-9 apart) is kept once, the copy
    nearer its shift with its mode; a double eigenvalue found twice by each disk is kept
    twice; an eigenvalue 1e-2 of the distance from another (distinct) stays."""
    from beltsim.physics.shift_invert import Disk, distinct

    one, double, other = 10.0 + 100.0j, -5.0 + 130.0j, -5.0 + 131.0j
    e = np.eye(4)
    a = Disk(0j, 140.0, np.array([one, double, double]), e[:, :3].astype(complex))
    b = Disk(120j, 30.0, np.array([one + 1e-9, double, double + 1e-12, other]), None)
    lam, V = distinct([a, b])
    assert lam.size == 4
    np.testing.assert_allclose(np.sort_complex(lam), np.sort_complex([one, double, double,
                                                                      other]), atol=1e-8)
    # the copies of `one`: a's is 100.5 from its shift, b's 22.4 from its: b's is nearer,
    # but a's has its mode
    k = int(np.argmin(np.abs(lam - one)))
    assert lam[k] == one and np.array_equal(V[:, k], e[:, 0])
    assert np.isnan(V[:, int(np.argmin(np.abs(lam - other)))]).all()
    # without modes the nearer copy wins
    lam, _ = distinct([a.__class__(a.shift, a.radius, a.eigenvalues), b])
    assert lam[int(np.argmin(np.abs(lam - one)))] == one + 1e-9


@pytest.mark.unit
def test_the_disks_cover_the_listed_cone_up_to_where_they_join():
    """One disk about 0 of radius r covers the listed modes' cone (damping ratio below
    MAX_DAMPING_RATIO = 0.5) up to r sqrt(1 - 0.5^2), as the disk's farthest point on
    the cone's edge; a second disk about i w continues it where the two overlap, and a
    gap stops it."""
    from beltsim.physics.loop_modes import _complete
    from beltsim.physics.shift_invert import Disk

    r = 100.0
    top = r * np.sqrt(0.75)
    assert _complete([Disk(0j, r, np.zeros(1))]) == pytest.approx(top, rel=1e-14)
    # about i w, radius R: t^2 y^2 + (y - w)^2 = R^2 at the top, t^2 = 1/3
    w, R = 150.0, 90.0  # its lowest covered height, 69.4, lies below the first's top
    y = (w + np.sqrt(4.0 / 3.0 * R * R - w * w / 3.0)) / (4.0 / 3.0)
    assert (y / np.sqrt(3.0)) ** 2 + (y - w) ** 2 == pytest.approx(R * R, rel=1e-12)
    both = _complete([Disk(w * 1j, R, np.zeros(1)), Disk(0j, r, np.zeros(1))])
    assert both == pytest.approx(y, rel=1e-14)
    assert _complete([Disk(0j, r, np.zeros(1)), Disk(400j, R, np.zeros(1))]) == top
