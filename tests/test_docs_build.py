"""The built documentation site shows no raw markup (issue 27, item 4).

``sphinx -W`` passes a docstring whose closing paragraph follows a numpydoc section: numpydoc
reads each of its lines as one more parameter, which the API page shows as bold names with the
reST roles left raw (``:math:`z```, ``:class:`~tubefsi.Profile```). Only the built HTML shows
it, so these tests read ``docs/_build/html``; ``make docs`` runs them after Sphinx, and they
are skipped where the site has not been built.
"""

from __future__ import annotations

import re
from html.parser import HTMLParser
from pathlib import Path

import pytest

SITE = Path(__file__).resolve().parents[1] / "docs" / "_build" / "html"

pytestmark = pytest.mark.skipif(not (SITE / "index.html").is_file(),
                                reason="the documentation site is not built (make docs)")

#: a reST role left as text, e.g. :math:`z` or :py:class:`~tubefsi.Tube`
RAW_ROLE = re.compile(r":(?:py:)?(?:math|class|func|meth|attr|data|mod|obj|exc|ref|doc|term|eq|numref):`")
#: the name part of a parameter entry: identifiers (``*args``, ``**kwargs``), comma-separated
PARAMETER_NAMES = re.compile(r"\*{0,2}[A-Za-z_]\w*(?:, \*{0,2}[A-Za-z_]\w*)*")
#: where markup is meant literally: code, and the pages that list source files
LITERAL_TAGS = {"code", "pre", "script", "style", "kbd", "samp", "tt"}
SKIPPED_DIRS = {"_modules", "_sources", "_static", "_downloads", "_images"}


class _Text(HTMLParser):
    """The prose of a page (outside code), and the names of its parameter entries."""

    def __init__(self):
        super().__init__(convert_charrefs=True)
        self.prose = []            # (line, text)
        self.names = []            # (line, text of a <dt><strong> parameter name)
        self._literal = 0
        self._in_dt = False
        self._strong = None

    def handle_starttag(self, tag, attrs):
        if tag in LITERAL_TAGS:
            self._literal += 1
        elif tag == "dt":
            self._in_dt = True
        elif tag == "strong" and self._in_dt:
            self._strong = []

    def handle_endtag(self, tag):
        if tag in LITERAL_TAGS:
            self._literal = max(self._literal - 1, 0)
        elif tag == "dt":
            self._in_dt = False
        elif tag == "strong" and self._strong is not None:
            self.names.append((self.getpos()[0], "".join(self._strong).strip()))
            self._strong = None

    def handle_data(self, data):
        if self._literal:
            return
        self.prose.append((self.getpos()[0], data))
        if self._strong is not None:
            self._strong.append(data)


def _pages():
    return sorted(p for p in SITE.rglob("*.html") if p.relative_to(SITE).parts[0] not in SKIPPED_DIRS)


def _parse(page):
    parser = _Text()
    parser.feed(page.read_text(encoding="utf-8"))
    return parser


def test_no_raw_roles_in_the_built_pages():
    """Checks the contract "no reST role shows as text": every role outside code was rendered."""
    found = []
    for page in _pages():
        for line, text in _parse(page).prose:
            for match in RAW_ROLE.finditer(text):
                found.append(f"{page.relative_to(SITE)}:{line}: {text[max(match.start() - 40, 0):match.end() + 40]!r}")
    assert not found, "raw reST roles in the built site:\n" + "\n".join(found[:40])


def test_api_parameter_entries_are_names():
    """Every bold entry of a Parameters/Attributes list on the API page is a parameter name (or
    names separated by commas): a sentence there is a paragraph numpydoc misread."""
    parser = _parse(SITE / "api.html")
    misread = [f"api.html:{line}: {name!r}" for line, name in parser.names
               if name and not PARAMETER_NAMES.fullmatch(name)]
    assert not misread, "docstring paragraphs rendered as parameters:\n" + "\n".join(misread[:40])


def test_the_checks_catch_a_misread_paragraph():
    """The checks themselves, on the HTML that numpydoc writes for a closing paragraph after a
    Parameters section (the form of the pages before the fix): they must find it."""
    html = ('<dl class="field-list"><dt><strong>radius</strong></dt><dd><p>Undeformed radius.</p></dd>'
            '<dt><strong>inlet): a callable, a :class:`~tubefsi.Profile` or a</strong></dt><dd></dd>'
            '<p>literal <code>:math:`a`</code> in code is fine</p></dl>')
    parser = _Text()
    parser.feed(html)
    roles = [text for _, text in parser.prose if RAW_ROLE.search(text)]
    names = [name for _, name in parser.names if not PARAMETER_NAMES.fullmatch(name)]
    assert roles == ["inlet): a callable, a :class:`~tubefsi.Profile` or a"]
    assert names == ["inlet): a callable, a :class:`~tubefsi.Profile` or a"]


def test_no_page_shows_the_build_machines_paths():
    """The site is the same wherever it is built: no page (the gallery's captured output included)
    shows the absolute path of the clone it was built from."""
    root = str(Path(__file__).resolve().parents[1])
    found = [str(page.relative_to(SITE)) for page in _pages() if root in page.read_text(encoding="utf-8")]
    assert not found, f"pages showing {root}: {found}"
