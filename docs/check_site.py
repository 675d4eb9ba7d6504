"""Look at the built site in a headless browser, as a reader would (``make docs`` runs this).

Serves ``docs/_build/html`` on 127.0.0.1 and opens pages in headless Chromium with every other
host unresolvable, so what it sees is what an offline reader sees:

* the theory page: MathJax typeset its math (``mjx-container`` elements, no raw ``\\(``), from
  the site's own copy (``_static/mathjax``, docs/conf.py);
* the API page: the ``solve`` entry shows no raw reST role (``:math:``, ``:class:`` ...);
* a gallery page: its figure is in the page and the browser fetched it.

It saves a screenshot of each page in ``docs/_build/screenshots/`` for a person to look at, and
exits nonzero with one line per failed check. Chromium is ``/usr/bin/chromium`` (Debian's
``chromium`` package), or the program named by the ``CHROMIUM`` environment variable.
"""

from __future__ import annotations

import functools
import http.server
import os
import re
import shutil
import subprocess
import sys
import tempfile
import threading
from html.parser import HTMLParser
from pathlib import Path

DOCS = Path(__file__).resolve().parent
SITE = DOCS / "_build" / "html"
SHOTS = DOCS / "_build" / "screenshots"
#: a reST role left as text
RAW_ROLE = re.compile(r":(?:py:)?(?:math|class|func|meth|attr|data|mod|obj|exc|ref|doc):`")
#: the wait for MathJax: virtual time, so a slow machine waits as long as a fast one needs
BUDGET_MS = 10_000
#: seconds before a Chromium run counts as hung
TIMEOUT_S = 120


class _Server(http.server.ThreadingHTTPServer):
    """The site on 127.0.0.1 (a free port), recording the paths the browser asked for."""

    def __init__(self):
        self.requested = []          # (path, status)
        handler = functools.partial(_Handler, directory=str(SITE))
        super().__init__(("127.0.0.1", 0), handler)


class _Handler(http.server.SimpleHTTPRequestHandler):
    def log_request(self, code="-", size="-"):
        self.server.requested.append((self.path.split("?")[0], int(code) if str(code).isdigit() else code))

    def log_message(self, *args):
        pass


class _Text(HTMLParser):
    """A page's text outside code, scripts and styles, and its elements' tags."""

    def __init__(self):
        super().__init__(convert_charrefs=True)
        self.text, self.tags, self._literal = [], [], 0

    def handle_starttag(self, tag, attrs):
        self.tags.append((tag, dict(attrs)))
        if tag in ("code", "pre", "script", "style", "kbd", "samp"):
            self._literal += 1

    def handle_endtag(self, tag):
        if tag in ("code", "pre", "script", "style", "kbd", "samp"):
            self._literal = max(self._literal - 1, 0)

    def handle_data(self, data):
        if not self._literal:
            self.text.append(data)


def _chromium():
    program = os.environ.get("CHROMIUM") or shutil.which("chromium") or shutil.which("chromium-browser")
    if not program:
        sys.exit("check_site: no Chromium; install Debian's chromium package "
                 "(apt-get install chromium) or name the browser in CHROMIUM")
    return program


def _run_chromium(program, url, *extra):
    """Chromium's output for ``url`` after MathJax had time to run; offline but for 127.0.0.1."""
    with tempfile.TemporaryDirectory() as profile:
        command = [program, "--headless", "--no-sandbox", "--disable-gpu", "--disable-quic",
                   "--disable-background-networking", "--disable-component-update", "--disable-sync",
                   "--no-first-run", "--hide-scrollbars", f"--user-data-dir={profile}",
                   "--host-resolver-rules=MAP * ~NOTFOUND, EXCLUDE 127.0.0.1",
                   f"--virtual-time-budget={BUDGET_MS}", *extra, url]
        done = subprocess.run(command, capture_output=True, text=True, timeout=TIMEOUT_S)
    if done.returncode != 0:
        raise RuntimeError(f"chromium exited {done.returncode} on {url}: {done.stderr.strip()[-500:]}")
    return done.stdout


def _dom(program, url):
    parser = _Text()
    parser.feed(_run_chromium(program, url, "--dump-dom"))
    return parser


def _screenshot(program, url, name, height=1600):
    SHOTS.mkdir(parents=True, exist_ok=True)
    path = SHOTS / name
    _run_chromium(program, url, f"--screenshot={path}", f"--window-size=1280,{height}")
    if not path.is_file() or path.stat().st_size == 0:
        raise RuntimeError(f"no screenshot of {url}")
    return path


def _entry(dom_html, anchor):
    """The HTML of the API entry whose signature has the id ``anchor``: up to the next entry."""
    start = dom_html.find(f'id="{anchor}"')
    if start < 0:
        return None
    end = dom_html.find('<dt class="sig sig-object py"', start + 1)
    return dom_html[start:end if end > 0 else len(dom_html)]


def check_theory(program, base, server):
    failures = []
    page = _dom(program, f"{base}/theory.html")
    containers = sum(1 for tag, _ in page.tags if tag == "mjx-container")
    text = "".join(page.text)
    raw = [m.start() for m in re.finditer(r"\\\(|\\\[", text)]
    scripts = [a.get("src", "") for tag, a in page.tags if tag == "script" and "mathjax" in a.get("src", "")]
    if containers == 0:
        failures.append("theory.html: MathJax typeset nothing (no mjx-container)")
    if raw:
        failures.append(f"theory.html: {len(raw)} raw TeX delimiters left, e.g. {text[raw[0]:raw[0] + 60]!r}")
    if not scripts or any("://" in s and not s.startswith(base) for s in scripts):
        failures.append(f"theory.html: MathJax is not loaded from the site: {scripts}")
    fetched = [p for p, code in server.requested if p.startswith("/_static/mathjax/") and code == 200]
    _screenshot(program, f"{base}/theory.html", "theory.png")
    return failures, f"theory.html: {containers} formulas typeset, {len(raw)} raw, MathJax files served: {len(fetched)}"


def check_api(program, base):
    failures = []
    html = _run_chromium(program, f"{base}/api.html", "--dump-dom")
    entry = _entry(html, "tubefsi.solve")
    if entry is None:
        return ["api.html: no entry tubefsi.solve"], "api.html: solve entry missing"
    parser = _Text()
    parser.feed(entry)
    text = "".join(parser.text)
    roles = [text[max(m.start() - 30, 0):m.end() + 30] for m in RAW_ROLE.finditer(text)]
    if roles:
        failures.append(f"api.html: raw roles in the solve entry: {roles[:5]}")
    if "Parameters" not in text or "flow_rate" not in text:
        failures.append("api.html: the solve entry lacks its parameters")
    _screenshot(program, f"{base}/api.html#tubefsi.solve", "api_solve.png")
    return failures, f"api.html: solve entry, {len(roles)} raw roles"


def check_gallery(program, base, server):
    index = (SITE / "gallery" / "index.html").read_text(encoding="utf-8")
    pages = sorted(set(re.findall(r'href="(plot_[^"#]+\.html)"', index)))
    if not pages:
        return ["gallery/index.html: no example pages"], "gallery: empty"
    page = pages[0]
    dom = _dom(program, f"{base}/gallery/{page}")
    images = [a.get("src", "") for tag, a in dom.tags if tag == "img" and "sphx-glr" in a.get("class", "")
              and "thumbnail" not in a.get("class", "")]
    served = {p for p, code in server.requested if code == 200}
    loaded = [src for src in images if "/_images/" + src.rsplit("/_images/", 1)[-1] in served]
    failures = []
    if not images:
        failures.append(f"gallery/{page}: no figure in the page")
    elif not loaded:
        failures.append(f"gallery/{page}: the browser fetched none of its figures {images}")
    _screenshot(program, f"{base}/gallery/{page}", "gallery.png", height=1400)
    return failures, f"gallery/{page}: {len(images)} figure(s), {len(loaded)} fetched"


def main():
    if not (SITE / "index.html").is_file():
        sys.exit(f"check_site: {SITE} is not built (make docs)")
    program = _chromium()
    server = _Server()
    threading.Thread(target=server.serve_forever, daemon=True).start()
    base = f"http://127.0.0.1:{server.server_address[1]}"
    failures = []
    try:
        for check in (lambda: check_theory(program, base, server), lambda: check_api(program, base),
                      lambda: check_gallery(program, base, server)):
            found, summary = check()
            failures += found
            print(f"check_site: {summary}")
    finally:
        server.shutdown()
        server.server_close()
    print(f"check_site: screenshots in {SHOTS.relative_to(DOCS.parent)}/")
    for failure in failures:
        print(f"check_site: FAILED {failure}", file=sys.stderr)
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
