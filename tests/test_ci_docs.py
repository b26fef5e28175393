"""CI's static check of the built documentation's MathJax (.ci/local_mathjax.py), on small
sites written here: it passes a site with its own MathJax and fails each way a page can
depend on the network or miss its MathJax. (CI runs it on the real build, after the
Sphinx build of .ci/run's docs stage.)"""

import importlib.util
from pathlib import Path

import pytest

pytestmark = pytest.mark.unit

ROOT = Path(__file__).resolve().parents[1]

PAGE = """<!DOCTYPE html><html><head>
<script src="../_static/documentation_options.js"></script>
{scripts}
</head><body><p>The stiffness
<span class="math notranslate nohighlight">\\(b_1 = E w h\\)</span>.</p></body></html>
"""


def _checker():
    spec = importlib.util.spec_from_file_location("local_mathjax",
                                                  ROOT / ".ci" / "local_mathjax.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def _site(tmp_path, scripts, mathjax_file=True):
    (tmp_path / "theory").mkdir()
    (tmp_path / "_static" / "mathjax").mkdir(parents=True)
    (tmp_path / "_static" / "documentation_options.js").write_text("")
    if mathjax_file:
        (tmp_path / "_static" / "mathjax" / "tex-chtml.js").write_text("// MathJax")
    (tmp_path / "theory" / "model.html").write_text(PAGE.format(scripts=scripts))
    (tmp_path / "index.html").write_text("<html><body>no maths</body></html>")
    return tmp_path


LOCAL = '<script defer="defer" src="../_static/mathjax/tex-chtml.js"></script>'
CDN = ('<script defer="defer" '
       'src="https://cdn.jsdelivr.net/npm/mathjax@3/es5/tex-mml-chtml.js"></script>')


def test_a_site_with_its_own_mathjax_passes(tmp_path, capsys):
    check = _checker()
    site = _site(tmp_path, LOCAL)
    assert check.problems(site) == []
    assert check.main([str(site)]) == 0
    assert "2 pages" in capsys.readouterr().out


@pytest.mark.parametrize("scripts, mathjax_file, says", [
    (CDN, True, "loads a script from the network: https://cdn.jsdelivr.net"),
    (LOCAL + '<script src="//example.org/x.js"></script>', True,
     "loads a script from the network: //example.org"),
    (LOCAL + '<link rel="stylesheet" href="https://maxcdn.bootstrapcdn.com/font-awesome/'
              '4.4.0/css/font-awesome.min.css">', True,
     "loads a stylesheet from the network: https://maxcdn.bootstrapcdn.com"),
    (LOCAL, False, "its MathJax script ../_static/mathjax/tex-chtml.js is not in the built"),
    ("", True, "has maths but loads no MathJax"),
])
def test_a_page_that_needs_the_network_or_misses_its_mathjax_fails(
        tmp_path, capsys, scripts, mathjax_file, says):
    check = _checker()
    site = _site(tmp_path, scripts, mathjax_file)
    found = check.problems(site)
    assert len(found) == 1 and found[0].startswith("theory/model.html: ")
    assert says in found[0]
    assert check.main([str(site)]) == 1
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and says in err


def test_an_empty_folder_is_not_a_built_site(tmp_path):
    assert _checker().main([str(tmp_path)]) == 1


def test_an_animations_cdn_icons_become_the_sites_own_style():
    """The docs' extension swaps the Font Awesome link of matplotlib's animation controls
    for a local style that draws every button of the control bar. (It needs Sphinx, the
    docs extra; CI's docs stage checks the built site itself: no page loads a stylesheet
    from the network.)"""
    import sys

    pytest.importorskip("sphinx", reason="the docs extra (pip install -e '.[docs]')")
    sys.path.insert(0, str(ROOT / "docs" / "_ext"))
    try:
        import beltsim_html
    finally:
        sys.path.pop(0)
    link = ('<link rel="stylesheet" href="https://maxcdn.bootstrapcdn.com/font-awesome/'
            '4.4.0/css/font-awesome.min.css">')
    buttons = "".join(f'<button><i class="fa fa-{n}"></i></button>'
                      for n in ("fast-backward", "step-backward", "play", "pause",
                                "step-forward", "fast-forward", "minus", "plus"))
    context = {"body": f"<div>{link}{buttons}</div>"}
    beltsim_html._offline_buttons(None, "examples/x", None, context, None)
    assert "maxcdn" not in context["body"] and "<style>" in context["body"]
    for name in beltsim_html.BUTTONS:
        assert f".fa-{name}::before" in context["body"]


# the Python tutorial's shown values (.ci/run_tutorial.py; CI runs the page as a notebook)

def _tutorial():
    spec = importlib.util.spec_from_file_location("run_tutorial",
                                                  ROOT / ".ci" / "run_tutorial.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


@pytest.mark.parametrize("comment, shown", [
    (" 100000.0", "100000.0"),
    (" None: the default time step applies", "None"),
    (" (7123.6..., 0.6341...): N, and the slip start in m", "(7123.6..., 0.6341...)"),
    (" (<RunStatus.CONVERGED: 'converged'>, None)", "(<RunStatus.CONVERGED: 'converged'>, None)"),
    (" 'newton', as summary.json records it", "'newton'"),
    (" 'a: b, c'", "'a: b, c'"),
    (" the grid's nodes (m)", None),
    (" b1 - rho c^2 = 284000.0 N", None),
])
def test_a_comment_shows_the_value_before_its_prose(comment, shown):
    assert _tutorial().shown_value(comment) == shown


def test_an_ellipsis_stands_for_any_text_and_nothing_else_does():
    match = _tutorial().ellipsis_match
    names = "('drive_flat', 'drive_load_step', 'load_drop', 'paper_slip', 'speed_step')"
    assert match("('drive_flat', 'drive_load_step', 'load_drop', ..., 'speed_step')", names)
    assert not match("('drive_flat', 'load_drop', ..., 'speed_step')", names)
    assert not match("('drive_flat', ..., 'speed_sine')", names)
    assert match("(7123.6..., 0.6341...)", "(7123.61, 0.63415)")
    assert not match("(7123.6..., 0.6341...)", "(7123.7, 0.63415)")
    assert not match("ab...ba", "aba")  # the two ends may not overlap
    assert match("True", "True") and not match("True", "False")


def test_a_line_that_shows_a_value_is_checked_and_keeps_its_value():
    tutorial = _tutorial()
    source = "\n".join([
        "x = 2                 # 2: an assignment shows nothing",
        "x, x + 1              # (2, 3)",
        "print(x)              # 2: printed, not a value",
        "for i in ():",
        "    i                 # 1",
        "x                     # the value, in words",
        "x * 2                 # 5",
    ])
    lines = tutorial.checked(source, 10).splitlines()
    assert lines[0] == source.splitlines()[0] and lines[2:6] == source.splitlines()[2:6]
    assert lines[1].startswith("_shown((x, x + 1), '(2, 3)', 11)")
    assert lines[6].startswith("_shown((x * 2), '5', 16)")
    namespace = {"_shown": tutorial._shown}
    exec("\n".join(lines[:6]), namespace)
    assert eval(lines[1].split("  #")[0], namespace) == (2, 3)
    with pytest.raises(AssertionError, match="tutorial line 16 shows 5, the code gives 4"):
        exec(lines[6], namespace)
