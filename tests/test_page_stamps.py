"""The generated pages' source stamps (validation.pages.stamps): a hash of the code each
page's numbers depend on, blind to comments and docstrings."""

import pytest

from validation.pages import stamps
from validation.pages.kit import Page

pytestmark = [pytest.mark.unit, pytest.mark.lab]

CODE = '''"""A module."""

def f(x):
    """Twice x."""
    return 2 * x  # doubled
'''


def test_comments_docstrings_and_blank_lines_do_not_count():
    prose = CODE.replace("Twice x.", "x, doubled.").replace("# doubled", "# twice") + "\n\n"
    assert stamps.code_of(prose) == stamps.code_of(CODE) == "def f(x):\n    return 2 * x"


def test_a_change_of_code_changes_the_hash(tmp_path):
    (tmp_path / "pkg").mkdir()
    module = tmp_path / "pkg" / "m.py"
    module.write_text(CODE)
    before = stamps.source_hash(["pkg"], tmp_path)
    module.write_text(CODE.replace("Twice", "Double"))
    assert stamps.source_hash(["pkg"], tmp_path) == before
    module.write_text(CODE.replace("2 * x", "3 * x"))
    assert stamps.source_hash(["pkg"], tmp_path) != before


def test_every_declared_source_exists():
    for key, sources in stamps.SOURCES.items():
        assert (stamps.ROOT / "docs" / key).is_file(), key
        for src in sources:
            assert (stamps.ROOT / src).exists(), (key, src)


def test_every_generated_page_declares_its_sources():
    import validation.pages as vpages

    pages = {f"verification/{name}.md" for name, _, _ in vpages._pages()}
    assert pages | {"performance/timings.md"} == set(stamps.SOURCES)


def test_a_page_carries_its_stamp(tmp_path):
    page = Page("p", "A page", "python -m x", "abc1234", tmp_path, source_hash="0123456789abcdef")
    text = page.markdown()
    assert stamps.STAMP.search(text).group(1) == "0123456789abcdef"
    assert "source hash `0123456789abcdef`" in text


def test_a_stale_page_fails_the_check_and_is_only_named_in_report_mode(monkeypatch, capsys):
    monkeypatch.setattr(stamps, "check", lambda key, restamp=False: "its sources changed")
    assert stamps.main([]) == 1
    assert stamps.main(["--report"]) == 0
    out = capsys.readouterr().out
    assert "docs/verification/drive.md is stale" in out and "0 of" in out
    monkeypatch.setattr(stamps, "check", lambda key, restamp=False: None)
    assert stamps.main([]) == 0
