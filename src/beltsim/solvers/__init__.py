"""Solvers: numerical settings, the registry of schemes, one module per scheme.

Importing this package registers every scheme (see :mod:`beltsim.solvers.base`).
"""

from . import esdirk, explicit, implicit, pseudo, steady  # noqa: F401  (each registers its scheme)
from .base import Discretisation, LoopDiscretisation, Scheme, discretise
from .registry import applicable, get, names, register

__all__ = ["Discretisation", "LoopDiscretisation", "Scheme", "applicable", "discretise", "get",
           "names", "register"]
