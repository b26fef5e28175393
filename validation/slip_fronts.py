"""The slip arcs' error envelope of a closed drive: the largest error over a handful of
grids within one octave of element counts.

On a nested ladder (each grid twice as fine) a slip front's place within its cell
doubles from grid to grid, so single errors scatter by orders of magnitude and an order
fitted to them measures that scatter. Grids spread over an octave put the fronts at
places that cover their cells, and the largest error over them is the readout's
envelope, free of one grid's luck.
"""

from __future__ import annotations

import beltsim

#: grids per octave: n, n + n/64, ..., n + 7 n/64 (the fronts' places cover their cells)
OCTAVE = 8


def slip_arc_envelope(scene, elements: int, grids: int = OCTAVE) -> tuple[dict, float]:
    """The largest slip-arc error of each pulley over ``grids`` grids from ``elements``
    up, in the pulley's arc length over the largest element (cells), and that largest
    element (m).

    Each grid is a run of ``scene`` (a drive scene; its scheme as given, usually
    ``numerics.integrator = "steady"``) against the exact steady state it reports as
    its reference. A run that does not converge raises RuntimeError with its reason.
    """
    worst: dict[str, float] = {}
    h = 0.0
    for k in range(grids):
        r = beltsim.run(scene.with_overrides(
            {"numerics.elements": elements + k * elements // 64}))
        if not r.converged:
            raise RuntimeError(f"{elements + k * elements // 64} elements: {r.reason}")
        sol, exact = r.solution, r.reference.summary()
        hk = float(sol.mesh.he.max())
        for arc, ref, pulley in zip(sol.slip_arcs(), exact["pulleys"], sol.params.pulleys):
            cells = abs(arc - ref["slip_arc"]) * pulley.radius / hk
            worst[pulley.name] = max(worst.get(pulley.name, 0.0), cells)
        h = max(h, hk)
    return worst, h
