"""Test-session setup, before any test module imports numba.

The README's test command sets NUMBA_BOUNDSCHECK=1, which compiles the kernels with
bounds checks. numba's on-disk cache does not key its entries on that flag, so kernels
cached by a bounds-checked test run were loaded by later ordinary runs in the same tree,
which then ran at half speed: the default paper slip run took 0.89 s after a test run
against 0.43-0.47 s from a clean cache. A bounds-checked session therefore keeps its
kernels in a cache directory of its own, named after the sources' contents: numba's cache
checks only the timestamp of a kernel's own file, so a kernel cached before a function it
calls in another file changed would be loaded with the old callee.
"""

import hashlib
import os
import sys
import tempfile
from pathlib import Path

import pytest

# the lab beside the package (benchmarks/, validation/) is imported from the checkout
sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

if os.environ.get("NUMBA_BOUNDSCHECK", "0") not in ("", "0"):
    from importlib.util import find_spec

    # found without importing beltsim, which imports numba before the variable is set
    _package = Path(find_spec("beltsim").submodule_search_locations[0])
    _sources = sorted(_package.rglob("*.py"))
    _digest = hashlib.sha256(b"".join(p.read_bytes() for p in _sources)).hexdigest()[:16]
    os.environ.setdefault("NUMBA_CACHE_DIR", os.path.join(
        tempfile.gettempdir(), f"beltsim-numba-boundscheck-{_digest}"))


# The runs' stability check (beltsim.simulation.stability) costs seconds per scene on a
# clean cache: the suite's runs leave it off, and keep their cache out of the user's;
# tests/test_stability.py turns it on where it is tested.
os.environ.setdefault("BELTSIM_STABILITY", "0")
os.environ.setdefault("BELTSIM_CACHE_DIR", tempfile.mkdtemp(prefix="beltsim-cache-"))


#: The markers of pyproject.toml's [tool.pytest.ini_options]; a test carries one at least.
KINDS = ("unit", "verification", "cli", "lab")


@pytest.hookimpl(tryfirst=True)  # before -m deselects: every collected test is checked
def pytest_collection_modifyitems(config, items):
    """Refuse to run when a test carries none of KINDS: `pytest -m unit` would silently
    leave it out of every selection."""
    bare = [item.nodeid for item in items
            if not any(item.get_closest_marker(kind) for kind in KINDS)]
    if bare:
        raise pytest.UsageError(
            f"{len(bare)} test(s) carry none of the markers {', '.join(KINDS)} (add one, "
            f"e.g. a module-level pytestmark): {', '.join(bare[:5])}"
            + (" ..." if len(bare) > 5 else ""))

# CI draws the same property-test examples every run: a clean clone has no hypothesis
# database, and a random draw must not decide whether a change lands (run locally
# without CI set, the draws stay random and keep finding new cases)
if os.environ.get("CI"):
    from hypothesis import settings

    settings.register_profile("ci", derandomize=True, print_blob=True)
    settings.load_profile("ci")
