"""Check the built site as a reader would: served on 127.0.0.1, opened in headless
Chromium (Debian's package, /usr/bin/chromium), every internal link crawled.

    from contactfem.lab.site.browser import check_site
    report = check_site("build/site", pages=["index.html", "01_interface_laws.html"])
    assert not report["problems"], report["problems"]

For each page opened in the browser it asserts what a reader needs:

* the equations were typeset: MathJax ran (its output elements ``mjx-container`` are
  present), no TeX error box (``mjx-merror``) and no raw ``$$``, ``\\(`` or ``\\[`` left in
  the text a reader sees (code blocks excluded);
* every image loaded (``naturalWidth > 0``);

and for the whole site (a crawl from the index over HTTP): every internal link, image,
script and stylesheet answers 200, every ``#fragment`` exists in its target page, and
no page loads a script or stylesheet from another host (the site works offline).
A screenshot of each opened page is written to `shots` (default ``SITE/_check/``).

The page is read with Chromium's own ``--headless --dump-dom``: the test server adds a
small probe script to each HTML page it serves; once MathJax has finished, the probe
writes its findings into the DOM, which ``--dump-dom`` returns.
"""

import html.parser
import json
import os
import re
import shutil
import subprocess
import tempfile
import threading
import urllib.error
import urllib.parse
import urllib.request
from contextlib import contextmanager
from functools import partial
from http.server import SimpleHTTPRequestHandler, ThreadingHTTPServer
from pathlib import Path

CHROMIUM_FLAGS = [
    "--headless",
    "--no-sandbox",
    "--disable-gpu",
    "--disable-quic",
    "--no-first-run",
    "--disable-background-networking",
    "--disable-component-update",
    "--disable-sync",
    "--disable-dev-shm-usage",
    "--hide-scrollbars",
    "--mute-audio",
]
PROBE_PATH = "/__contactfem_probe.js"
PROBE_ID = "contactfem-probe"

PROBE_JS = r"""
(function () {
  function visibleText() {
    var clone = document.body.cloneNode(true);
    clone.querySelectorAll('pre, code, script, style, mjx-container, #%(id)s').forEach(function (e) { e.remove(); });
    return clone.textContent || '';
  }
  function count(text, needle) { return text.split(needle).length - 1; }
  function report(mathjaxState) {
    var imgs = Array.prototype.map.call(document.images, function (i) {
      return {src: i.getAttribute('src'), naturalWidth: i.naturalWidth};
    });
    var text = visibleText();
    var out = {
      mathjax: mathjaxState,
      typeset: document.querySelectorAll('mjx-container').length,
      tex_errors: Array.prototype.map.call(document.querySelectorAll('mjx-merror'),
                                           function (e) { return e.textContent.slice(0, 120); }),
      raw_dollars: count(text, '$$'),
      raw_tex: count(text, '\\(') + count(text, '\\['),
      images: imgs
    };
    var pre = document.createElement('pre');
    pre.id = '%(id)s';
    pre.style.display = 'none';
    pre.textContent = JSON.stringify(out);
    document.body.appendChild(pre);
  }
  function imagesSettled() {
    return Promise.all(Array.prototype.map.call(document.images, function (i) {
      i.loading = 'eager';
      if (i.complete) return null;
      return new Promise(function (r) { i.addEventListener('load', r); i.addEventListener('error', r); });
    }));
  }
  window.addEventListener('load', function () {
    var mj = window.MathJax;
    var started = (mj && mj.startup && mj.startup.promise) ? mj.startup.promise : null;
    var math = started ? started.then(function () { return 'typeset'; }, function (e) { return 'failed: ' + e; })
                       : Promise.resolve('not loaded');
    Promise.all([math, imagesSettled()]).then(function (r) { report(r[0]); });
  });
})();
""" % {"id": PROBE_ID}


def find_chromium():
    """Debian's Chromium (or CHROMIUM=path); None if it is not installed."""
    for cand in [
        os.environ.get("CHROMIUM"),
        "/usr/bin/chromium",
        shutil.which("chromium"),
        shutil.which("chromium-browser"),
    ]:
        if cand and Path(cand).exists():
            return cand
    return None


class _Handler(SimpleHTTPRequestHandler):
    """Serves the site folder; adds the probe script to every HTML page."""

    def log_message(self, *args):
        pass

    def do_GET(self):
        path = urllib.parse.urlsplit(self.path).path
        if path == PROBE_PATH:
            return self._send(200, "application/javascript", PROBE_JS.encode())
        local = Path(self.translate_path(self.path))
        if local.is_dir():
            local = local / "index.html"
        if local.suffix == ".html" and local.is_file():
            text = local.read_text(encoding="utf-8")
            tag = f'<script src="{PROBE_PATH}"></script>'
            text = text.replace("</body>", tag + "</body>", 1) if "</body>" in text else text + tag
            return self._send(200, "text/html; charset=utf-8", text.encode("utf-8"))
        return super().do_GET()

    def _send(self, code, ctype, body):
        self.send_response(code)
        self.send_header("Content-Type", ctype)
        self.send_header("Content-Length", str(len(body)))
        self.end_headers()
        self.wfile.write(body)


@contextmanager
def serve(root):
    """Serve folder `root` on 127.0.0.1 (a free port); yields the base URL."""
    server = ThreadingHTTPServer(("127.0.0.1", 0), partial(_Handler, directory=str(root)))
    thread = threading.Thread(target=server.serve_forever, daemon=True)
    thread.start()
    try:
        yield f"http://127.0.0.1:{server.server_address[1]}/"
    finally:
        server.shutdown()
        server.server_close()
        thread.join(timeout=10)


def _chromium(args, chromium, timeout):
    with tempfile.TemporaryDirectory(prefix="contactfem-chromium-") as profile:
        cmd = [chromium, *CHROMIUM_FLAGS, f"--user-data-dir={profile}", *args]
        proc = subprocess.run(cmd, capture_output=True, text=True, timeout=timeout)
    return proc


def open_page(url, chromium=None, screenshot=None, timeout=120, budget_ms=30000):
    """Open `url` in headless Chromium; return the probe's findings (a dict). With
    `screenshot`, also write a PNG of the page there."""
    chromium = chromium or find_chromium()
    if chromium is None:
        raise RuntimeError("Chromium not found: apt-get install -y chromium (or set CHROMIUM=path)")
    proc = _chromium([f"--virtual-time-budget={budget_ms}", "--dump-dom", url], chromium, timeout)
    m = re.search(rf'<pre id="{PROBE_ID}"[^>]*>(.*?)</pre>', proc.stdout, re.S)
    if not m:
        raise RuntimeError(
            f"the page {url} did not finish loading in the browser "
            f"(no probe report; exit code {proc.returncode}):\n{proc.stderr[-2000:]}"
        )
    found = json.loads(html.unescape(m.group(1)))
    if screenshot:
        Path(screenshot).parent.mkdir(parents=True, exist_ok=True)
        _chromium(
            [f"--virtual-time-budget={budget_ms}", "--window-size=1280,1600", f"--screenshot={screenshot}", url],
            chromium,
            timeout,
        )
        found["screenshot"] = str(screenshot) if Path(screenshot).exists() else None
    return found


def page_problems(name, found, expect_math=True):
    """What a reader would see wrong on a page, from `open_page`'s findings."""
    out = []
    if expect_math:
        if found["mathjax"] != "typeset":
            out.append(f"{name}: MathJax did not run ({found['mathjax']})")
        if found["typeset"] == 0:
            out.append(f"{name}: no typeset equation (no mjx-container)")
    if found["tex_errors"]:
        out.append(f"{name}: {len(found['tex_errors'])} equation(s) failed to typeset: {found['tex_errors'][:3]}")
    if found["raw_dollars"]:
        out.append(f"{name}: {found['raw_dollars']} raw '$$' left in the text")
    if found["raw_tex"]:
        out.append(f"{name}: {found['raw_tex']} untypeset \\( or \\[ left in the text")
    broken = [i["src"] for i in found["images"] if not i["naturalWidth"]]
    if broken:
        out.append(f"{name}: {len(broken)} image(s) did not load: {broken[:5]}")
    return out


class _Links(html.parser.HTMLParser):
    def __init__(self):
        super().__init__()
        self.links, self.ids = [], set()

    def handle_starttag(self, tag, attrs):
        a = dict(attrs)
        for key in ("id", "name") if tag == "a" else ("id",):
            if a.get(key):
                self.ids.add(a[key])
        if tag in ("a", "link") and a.get("href"):
            self.links.append((tag, a["href"]))
        elif tag in ("img", "script", "iframe", "source") and a.get("src"):
            self.links.append((tag, a["src"]))


def _fetch(url):
    try:
        with urllib.request.urlopen(url, timeout=30) as resp:
            return resp.status, resp.headers.get_content_type(), resp.read()
    except urllib.error.HTTPError as err:
        return err.code, None, b""


def crawl(base, start="index.html", max_pages=2000):
    """Follow every link inside the site from `start`; returns (pages visited, problems)."""
    host = urllib.parse.urlsplit(base).netloc
    todo, seen, pages, problems = [urllib.parse.urljoin(base, start)], set(), {}, []
    fragments = []
    status = {}
    while todo and len(pages) < max_pages:
        url = todo.pop()
        if url in seen:
            continue
        seen.add(url)
        code, ctype, body = _fetch(url)
        status[url] = code
        if code != 200 or ctype != "text/html":
            continue
        parser = _Links()
        parser.feed(body.decode("utf-8", "replace"))
        pages[url] = parser.ids
        for tag, ref in parser.links:
            parts = urllib.parse.urlsplit(ref)
            if parts.scheme in ("mailto", "javascript", "data"):
                continue
            target = urllib.parse.urljoin(url, ref)
            tparts = urllib.parse.urlsplit(target)
            if tparts.netloc != host:
                if tag in ("script", "link", "img", "iframe", "source"):
                    problems.append(f"{_rel(base, url)}: loads {ref} from another host (the site must work offline)")
                continue
            clean = urllib.parse.urlunsplit((tparts.scheme, tparts.netloc, tparts.path, "", ""))
            if clean not in seen:
                todo.append(clean)
            frag = urllib.parse.unquote(tparts.fragment) if tparts.fragment else None
            fragments.append((url, clean, frag, ref))
    for src, clean, frag, ref in fragments:
        code = status.get(clean)
        if code is None:
            code = status[clean] = _fetch(clean)[0]
        if code != 200:
            problems.append(f"{_rel(base, src)}: broken link {ref} (HTTP {code})")
        elif frag is not None and clean in pages and frag not in pages[clean]:
            problems.append(f"{_rel(base, src)}: link {ref}: no #{frag} in {_rel(base, clean)}")
    return sorted(_rel(base, p) for p in pages), sorted(set(problems))


def _rel(base, url):
    return url[len(base) :] if url.startswith(base) else url


def check_site(root, pages=("index.html",), shots=None, chromium=None, math_pages=None):
    """Serve `root`, open `pages` in headless Chromium (screenshots into `shots`, default
    ROOT/_check) and crawl every internal link. `math_pages` are the pages that must
    contain typeset equations (default: all opened pages but index.html). Returns
    {"pages": {name: findings}, "crawled": [...], "problems": [...]}."""
    root = Path(root)
    shots = Path(shots) if shots else root / "_check"
    math_pages = set(math_pages) if math_pages is not None else {p for p in pages if p != "index.html"}
    report = {"pages": {}, "problems": []}
    with serve(root) as base:
        for name in pages:
            found = open_page(base + name, chromium, screenshot=shots / (Path(name).stem + ".png"))
            report["pages"][name] = found
            report["problems"] += page_problems(name, found, expect_math=name in math_pages)
        report["crawled"], crawl_problems = crawl(base)
        report["problems"] += crawl_problems
    shots.mkdir(parents=True, exist_ok=True)
    (shots / "report.json").write_text(json.dumps(report, indent=1))
    return report
