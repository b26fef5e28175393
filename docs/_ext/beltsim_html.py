"""The built site's own MathJax, viewcode's back-links that find their targets, and
animations whose buttons need no network.

MathJax
    The pages load MathJax from ``_static/mathjax/``, copied at the end of the build from
    the MathJax 3 release that the ``django-static-mathjax`` wheel vendors (plain files;
    the wheel needs no Django). A CDN would leave the maths as raw TeX offline. Only the
    CommonHTML component and what it loads on demand are copied.

viewcode back-links
    viewcode writes every ``[docs]`` link of a source page with the module path under which
    it first met that module: after the package page documents ``beltsim.Tracker``, the
    links of ``beltsim.simulation.trackers`` read ``#beltsim.HistoryTracker`` where the
    anchor is ``beltsim.simulation.trackers.HistoryTracker``. Each such link is pointed at
    the anchor its page has; one that still has none fails the build.

Animations
    The gallery embeds a matplotlib animation as HTML whose play buttons are Font Awesome
    icons from a CDN: offline they would be blank. The stylesheet's link is replaced by
    a few rules that draw the same buttons as Unicode symbols.
"""

from __future__ import annotations

import importlib.util
import posixpath
import re
import shutil
from pathlib import Path

from sphinx.util import logging

LOG = logging.getLogger(__name__)

MATHJAX_PATH = "mathjax/tex-chtml.js"
# the component and what it loads on demand: TeX extensions (autoload), fonts, the menu
# and its accessibility parts
MATHJAX_PARTS = ("tex-chtml.js", "input/tex", "output/chtml", "ui", "a11y", "sre", "adaptors")

BACKLINK = re.compile(r'(<a class="viewcode-back" href=")([^"#]*)#([^"]+)(")')

FONT_AWESOME = re.compile(r'<link rel="stylesheet"\s+href="https://maxcdn\.bootstrapcdn\.com/'
                          r'font-awesome/[^"]*"\s*/?>')
# the icons of matplotlib's animation controls, as text in the two triangles and the bar
# that every font has (the media-control symbols U+23EE... are missing from many)
BUTTONS = {"fast-backward": "|\\25C0\\25C0", "step-backward": "\\25C0|", "play": "\\25B6",
           "pause": "||", "step-forward": "|\\25B6", "fast-forward": "\\25B6\\25B6|",
           "minus": "\\2212", "plus": "+"}
BUTTON_STYLE = "<style>" + "".join(
    f'.fa-{name}::before {{ content: "{glyph}"; }}' for name, glyph in BUTTONS.items()
) + (".fa { font-style: normal; } .fa-flip-horizontal { display: inline-block; "
     "transform: scaleX(-1); }</style>")


def mathjax_source() -> Path:
    """The ``es5`` folder of the vendored MathJax 3 release."""
    spec = importlib.util.find_spec("mathjax")
    if spec is None or not spec.submodule_search_locations:
        raise RuntimeError("MathJax is not installed: pip install -e '.[docs]' "
                           "(django-static-mathjax)")
    es5 = Path(next(iter(spec.submodule_search_locations))) / "static" / "mathjax" / "es5"
    if not (es5 / "tex-chtml.js").is_file():
        raise RuntimeError(f"no tex-chtml.js in {es5}: the MathJax package is not MathJax 3")
    return es5


def _copy_mathjax(app, exception):
    if exception is not None or app.builder.format != "html":
        return
    source, target = mathjax_source(), Path(app.outdir) / "_static" / "mathjax"
    for part in MATHJAX_PARTS:
        src, dst = source / part, target / part
        if src.is_dir():
            shutil.copytree(src, dst, dirs_exist_ok=True)
        else:
            dst.parent.mkdir(parents=True, exist_ok=True)
            shutil.copy2(src, dst)


def _anchors(env) -> dict[str, set[str]]:
    """The anchors of the Python objects, by document."""
    by_doc: dict[str, set[str]] = {}
    for entry in env.get_domain("py").objects.values():
        by_doc.setdefault(entry.docname, set()).add(entry.node_id)
    return by_doc


def _fix_backlinks(app, pagename, templatename, context, doctree):
    if not pagename.startswith("_modules/") or "body" not in context:
        return
    module = pagename.removeprefix("_modules/").replace("/", ".")
    anchors = _anchors(app.env)

    def fix(match):
        head, url, anchor, tail = match.groups()
        docname = posixpath.normpath(posixpath.join(posixpath.dirname(pagename), url))
        known = anchors.get(docname.removesuffix(".html"), set())
        if anchor in known:
            return match.group(0)
        parts = anchor.split(".")
        for i in range(1, len(parts)):
            candidate = f"{module}.{'.'.join(parts[i:])}"
            if candidate in known:
                return f"{head}{url}#{candidate}{tail}"
        LOG.warning("viewcode back-link of %s has no target: %s#%s", module, url, anchor)
        return match.group(0)

    context["body"] = BACKLINK.sub(fix, context["body"])


def _offline_buttons(app, pagename, templatename, context, doctree):
    if "body" in context and FONT_AWESOME.search(context["body"]):
        context["body"] = FONT_AWESOME.sub(lambda _: BUTTON_STYLE, context["body"])


def setup(app):
    app.connect("html-page-context", _fix_backlinks)
    app.connect("html-page-context", _offline_buttons)
    app.connect("build-finished", _copy_mathjax)
    return {"version": "1", "parallel_read_safe": True, "parallel_write_safe": True}
