"""The closed belt drive: a belt loop on a driver and a driven pulley.

The belt is the paper's axially moving extensible, shear-deformable beam (or the
extensible string) on a periodic Eulerian coordinate along the loop; the belt speed c(t)
and the driven pulley's speed omega2(t) are unknowns of the loop.
"""
