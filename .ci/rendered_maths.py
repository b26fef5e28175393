"""Check a page's DOM, as a browser left it, for maths that MathJax did not typeset.

Usage: ``python .ci/rendered_maths.py DOM_FILE PAGE_NAME``. Exits 1, naming the first raw
TeX it finds, when the visible text still holds ``\\(``, ``\\[`` or ``\\begin``, or when
the page has no typeset formula at all (MathJax did not run).
"""

import sys
from html.parser import HTMLParser

RAW_TEX = ("\\(", "\\[", "\\begin")


class VisibleText(HTMLParser):
    """The text a reader sees: no scripts, styles, or MathJax's hidden MathML copy."""

    HIDDEN = {"script", "style", "mjx-assistive-mml", "noscript", "template"}

    def __init__(self):
        super().__init__()
        self.depth = 0
        self.parts = []
        self.formulas = 0

    def handle_starttag(self, tag, attrs):
        if tag == "mjx-container":
            self.formulas += 1
        if tag in self.HIDDEN:
            self.depth += 1

    def handle_endtag(self, tag):
        if tag in self.HIDDEN and self.depth:
            self.depth -= 1

    def handle_data(self, data):
        if not self.depth:
            self.parts.append(data)


def main(dom_file: str, page: str) -> int:
    with open(dom_file, encoding="utf-8") as f:
        parser = VisibleText()
        parser.feed(f.read())
    text = "".join(parser.parts)
    for raw in RAW_TEX:
        at = text.find(raw)
        if at >= 0:
            snippet = " ".join(text[at:at + 60].split())
            print(f"docs maths: FAILED: {page} shows raw TeX: {snippet!r}", file=sys.stderr)
            return 1
    if not parser.formulas:
        print(f"docs maths: FAILED: {page} has no typeset formula (did MathJax load?)",
              file=sys.stderr)
        return 1
    print(f"docs maths: {page}: {parser.formulas} formulas typeset, no raw TeX")
    return 0


if __name__ == "__main__":
    sys.exit(main(*sys.argv[1:3]))
