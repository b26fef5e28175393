"""Check a built site's pages load MathJax from the site itself, never from the network.

Usage: ``python .ci/local_mathjax.py BUILT_HTML_DIR``. Reads every HTML page of the site
(no browser, about a second) and exits 1, naming the page and the script, when a page

- loads a script or a stylesheet from the network (``http:``, ``https:`` or ``//``):
  offline it is missing (an animation's buttons drawn by a CDN's icon font, blank);
- has maths (``class="math``) but no MathJax script;
- names a MathJax script that is not a file of the built site.

The browser check (``.ci/docs-maths``) shows the maths rendered on two theory pages; this
one covers every page, and runs where no browser can be installed.
"""

from __future__ import annotations

import sys
from html.parser import HTMLParser
from pathlib import Path
from urllib.parse import unquote, urlsplit

REMOTE = ("http:", "https:", "//")


class Scripts(HTMLParser):
    """The ``src`` of each script of a page, and whether the page holds maths."""

    def __init__(self):
        super().__init__()
        self.sources: list[str] = []
        self.styles: list[str] = []
        self.maths = False

    def handle_starttag(self, tag, attrs):
        attrs = dict(attrs)
        if tag == "script" and attrs.get("src"):
            self.sources.append(attrs["src"])
        if tag == "link" and "stylesheet" in (attrs.get("rel") or "").split():
            self.styles.append(attrs.get("href") or "")
        if "math" in (attrs.get("class") or "").split():
            self.maths = True


def problems(site: Path) -> list[str]:
    """What is wrong with the site's pages, one line each (empty when nothing is)."""
    found = []
    pages = sorted(site.rglob("*.html"))
    if not pages:
        return [f"{site}: no HTML pages (not a built site?)"]
    for page in pages:
        name = page.relative_to(site).as_posix()
        if name.startswith("_static/"):
            continue  # MathJax's own files and the theme's
        parser = Scripts()
        parser.feed(page.read_text(encoding="utf-8"))
        mathjax = [s for s in parser.sources if "mathjax" in s.lower()]
        for src in parser.sources:
            if src.lower().startswith(REMOTE):
                found.append(f"{name}: loads a script from the network: {src}")
        for href in parser.styles:
            if href.lower().startswith(REMOTE):
                found.append(f"{name}: loads a stylesheet from the network: {href}")
        for src in mathjax:
            if src.lower().startswith(REMOTE):
                continue
            target = (page.parent / unquote(urlsplit(src).path)).resolve()
            if not target.is_file():
                found.append(f"{name}: its MathJax script {src} is not in the built site")
        if parser.maths and not mathjax:
            found.append(f"{name}: has maths but loads no MathJax")
    return found


def main(argv: list[str]) -> int:
    if len(argv) != 1:
        print("usage: python .ci/local_mathjax.py BUILT_HTML_DIR", file=sys.stderr)
        return 2
    site = Path(argv[0])
    found = problems(site)
    for line in found:
        print(f"local mathjax: FAILED: {line}", file=sys.stderr)
    if found:
        return 1
    pages = sum(1 for p in site.rglob("*.html") if not p.is_relative_to(site / "_static"))
    print(f"local mathjax: {pages} pages load no script or stylesheet from the network; "
          f"MathJax is the site's own")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
