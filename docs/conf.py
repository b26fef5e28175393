"""Sphinx configuration of the beltsim documentation.

Build (warnings are errors)::

    python -m sphinx -n -W --keep-going -b html docs docs/_build/html

Pages are Markdown (MyST); the examples gallery runs ``examples/plot_*.py`` at build
time (sphinx-gallery); the API reference is generated from numpydoc docstrings
(autodoc, autosummary, numpydoc). Tables of scene keys and of the command line are
generated from the code by ``_ext/beltsim_docs.py``.
"""

import os
import sys
from pathlib import Path

# the gallery's figures do not show the runs' stability check, which would add seconds per
# scene to the build (beltsim.simulation.stability)
os.environ.setdefault("BELTSIM_STABILITY", "0")

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE / "_ext"))

import beltsim  # noqa: E402

project = "beltsim"
author = "the beltsim authors"
copyright = "the beltsim authors"
release = beltsim.__version__
version = release

extensions = [
    "myst_parser",
    "sphinx.ext.autodoc",
    "sphinx.ext.autosummary",
    "sphinx.ext.mathjax",
    "sphinx.ext.viewcode",
    "numpydoc",
    "sphinx_gallery.gen_gallery",
    "beltsim_docs",
    "beltsim_html",
]

source_suffix = {".rst": "restructuredtext", ".md": "markdown"}
exclude_patterns = ["_build", "**.ipynb_checkpoints", "examples/*.ipynb",
                    "examples/*.py", "examples/*.zip", "examples/*.codeobj.json"]
templates_path = ["_templates"]
smartquotes = False  # options like --from stay as typed
# every cross-reference must resolve (the build runs with -n -W); these have no target here:
# the standard library's and matplotlib's own docs are not linked (no intersphinx: the
# build works offline), and two docstrings of modules that are being reworked name a
# function by a short or an old name
nitpick_ignore = [
    ("py:class", "enum.Enum"),
    ("py:class", "enum.StrEnum"),
    ("py:class", "matplotlib.figure.Figure"),
    ("py:func", "resolve"),  # beltdrive.run.DriveNumerics, in the package page's table
    ("py:func", "characteristic_matrix"),  # physics.continuum's module docstring
]

# the site's own copy of MathJax (beltsim_html copies it into _static): maths renders
# offline, where a CDN leaves raw TeX
mathjax_path = "mathjax/tex-chtml.js"

# -- MyST ---------------------------------------------------------------------
myst_enable_extensions = ["dollarmath", "amsmath", "colon_fence", "deflist"]
myst_heading_anchors = 3

# -- API reference ------------------------------------------------------------
autosummary_generate = True
autosummary_imported_members = False
autodoc_typehints = "none"  # numpydoc sections carry the types
autodoc_member_order = "bysource"
numpydoc_show_class_members = False
numpydoc_class_members_toctree = False
numpydoc_xref_param_type = False
# every object of the API reference has a docstring with a summary line
numpydoc_validation_checks = {"GL08", "SS01"}
# the built-in trackers' hooks inherit their docstrings from beltsim.Tracker, the schemes'
# from solvers.base.Scheme (autodoc shows the inherited one; numpydoc validates their own)
# LoopDiscretisation.arm: None by default, documented by its "#:" comment
numpydoc_validation_exclude = {r"\.__init__$", r"\.__repr__$", r"\._",
                               r"LoopDiscretisation\.arm$",
                               r"trackers\.\w+Tracker\.(initialize|handle|finalize|state|"
                               r"restore)$", r"trackers\.DivergenceGuard\.handle$",
                               r"solvers\.\w+\.\w+Scheme\.(advance|solve|dt|statistics|"
                               r"checkpoint|restore)$"}

# -- examples gallery ---------------------------------------------------------
sphinx_gallery_conf = {
    "examples_dirs": "../examples",
    "gallery_dirs": "examples",
    "filename_pattern": r"/plot_",
    "within_subsection_order": "FileNameSortKey",
    "abort_on_example_error": True,
    "download_all_examples": False,
    "write_computation_times": False,
    "remove_config_comments": True,
    "matplotlib_animations": True,
    "image_scrapers": ("matplotlib",),
    "plot_gallery": "True",
}

# -- HTML -----------------------------------------------------------------------
html_theme = "furo"
html_title = f"beltsim {release}"
html_static_path = []
