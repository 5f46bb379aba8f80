"""The course website: built from lectures/ and checked in headless Chromium as a reader
would (equations typeset, images loaded, no broken link), and the checker itself shown
to fail on a page with a missing image, a broken equation, a raw '$$' or a dead link.

The tests marked `site` need the site extra and Debian's Chromium (/usr/bin/chromium);
they skip where either is missing, except under pytest's --require-browser (given by
.ci/run, which installs both), where a missing piece is a failure.
"""

import json
import os
import re
import shutil
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest
from conftest import OPTIONS

REPO = Path(__file__).resolve().parents[1]
LECTURES = sorted((REPO / "lectures").glob("*.ipynb"))

pytestmark = [pytest.mark.site, pytest.mark.slow]


def _require(ok, why):
    if not ok:
        if OPTIONS["require_browser"]:
            pytest.fail(why, pytrace=False)
        pytest.skip(why)


@pytest.fixture(scope="module")
def chromium():
    from contactfem.lab.site.browser import find_chromium

    path = find_chromium()
    _require(path is not None, "Chromium not installed (apt-get install -y chromium)")
    return path


@pytest.fixture(scope="module")
def mathjax_dir(tmp_path_factory):
    from contactfem.lab.site.pages import copy_mathjax

    root = tmp_path_factory.mktemp("pages")
    try:
        copy_mathjax(root / "_static" / "mathjax")
    except RuntimeError as err:
        _require(False, str(err))
    return root


# -- the checker's own tests: small hand-made sites, one thing broken in each -------------


def _png(path, w=12, h=8):
    import numpy as np
    from PIL import Image

    Image.fromarray((np.arange(w * h * 3) % 255).astype("uint8").reshape(h, w, 3)).save(path)


def _page(body):
    return (
        "<!DOCTYPE html><html><head><meta charset='utf-8'>"
        "<script>window.MathJax = {tex: {inlineMath: [['\\\\(', '\\\\)']], displayMath: [['\\\\[', '\\\\]']],"
        "packages: {'[-]': ['noundefined']}}};</script>"
        "<script defer src='_static/mathjax/tex-chtml.js'></script></head>"
        f"<body>{body}</body></html>"
    )


GOOD = (
    "<h1 id='top'>A page</h1><p>Hertz: <span class='math'>\\(p_0 = \\sqrt{{P E^*/(\\pi R)}}\\)</span></p>"
    "<div class='math'>\\[ g_N = (\\mathbf x_s - \\mathbf x_1) \\cdot \\mathbf n \\tag{{17}} \\]</div>"
    "<img src='fig.png' alt='a figure'><p><a href='other.html#sec'>other</a> <a href='#top'>top</a></p>"
    "<pre>price = '$$' in code is fine</pre>{extra}"
)
OTHER = "<h2 id='sec'>Other</h2><p><a href='index.html'>back</a></p>"


def _site(root, extra="", image=True):
    site = root / f"site{len(list(root.glob('site*')))}"
    site.mkdir()
    shutil.copytree(root / "_static", site / "_static")
    (site / "index.html").write_text(_page(GOOD.format(extra=extra)))
    (site / "other.html").write_text(_page(OTHER))
    if image:
        _png(site / "fig.png")
    return site


def _check(site, chromium):
    from contactfem.lab.site.browser import check_site

    return check_site(site, pages=["index.html"], math_pages=["index.html"], chromium=chromium)


def test_checker_passes_a_good_page(mathjax_dir, chromium):
    report = _check(_site(mathjax_dir), chromium)
    assert report["problems"] == []
    found = report["pages"]["index.html"]
    assert found["mathjax"] == "typeset" and found["typeset"] == 2
    assert [i["naturalWidth"] for i in found["images"]] == [12]
    assert Path(found["screenshot"]).stat().st_size > 1000
    assert report["crawled"] == ["index.html", "other.html"]


def test_checker_fails_when_an_image_is_removed(mathjax_dir, chromium):
    problems = _check(_site(mathjax_dir, image=False), chromium)["problems"]
    assert any("image(s) did not load" in p and "fig.png" in p for p in problems), problems
    assert any("broken link fig.png (HTTP 404)" in p for p in problems), problems


@pytest.mark.parametrize(
    "tex, expect",
    [
        ("\\frac{a}", "1 equation(s) failed to typeset"),  # TeX error: MathJax shows an error box
        ("\\notamacro{x}", "1 equation(s) failed to typeset"),  # undefined control sequence
        ("\\frac{a}{", "1 untypeset \\( or \\[ left"),  # unbalanced: the delimiters stay raw
    ],
)
def test_checker_fails_on_a_broken_equation(mathjax_dir, chromium, tex, expect):
    problems = _check(_site(mathjax_dir, extra=f"<div class='math'>\\[ {tex} \\]</div>"), chromium)["problems"]
    assert any(expect in p for p in problems), problems


def test_checker_fails_on_raw_dollars(mathjax_dir, chromium):
    problems = _check(_site(mathjax_dir, extra="<p>$$ t_T = c_T g_T $$</p>"), chromium)["problems"]
    assert any("raw '$$'" in p for p in problems), problems


def test_checker_fails_without_mathjax(mathjax_dir, chromium):
    site = _site(mathjax_dir)
    shutil.rmtree(site / "_static" / "mathjax")
    problems = _check(site, chromium)["problems"]
    assert any("MathJax did not run" in p for p in problems), problems
    assert any("tex-chtml.js (HTTP 404)" in p for p in problems), problems


def test_checker_fails_on_dead_links_and_offsite_scripts(mathjax_dir, chromium):
    extra = (
        "<a href='missing.html'>x</a><a href='other.html#nowhere'>y</a>"
        "<script src='https://cdn.example.org/mathjax.js'></script>"
    )
    problems = _check(_site(mathjax_dir, extra=extra), chromium)["problems"]
    assert any("broken link missing.html (HTTP 404)" in p for p in problems), problems
    assert any("no #nowhere in other.html" in p for p in problems), problems
    assert any("from another host" in p for p in problems), problems


# -- the real site --------------------------------------------------------------------


def _site_extra():
    pytest.importorskip("nbclient")
    try:
        import myst_nb  # noqa: F401
        import otter  # noqa: F401
        import sphinx  # noqa: F401
    except ImportError:
        _require(False, "the site extra is not installed: pip install -e '.[site]'")


@pytest.fixture(scope="module")
def site(chromium, tmp_path_factory):
    _site_extra()
    from contactfem.lab.site import build

    before = _tree(REPO)
    index = build(tmp_path_factory.mktemp("site") / "out")  # all its files under out (its cache: out/.contactfem-site)
    assert _tree(REPO) == before, "the site build wrote into the checkout"
    return index.parent


def _tree(root):
    """The files of the checkout outside .git and the virtual environment (name, size)."""
    skip = {".git", ".venv", ".pytest_cache", "__pycache__", ".hypothesis"}
    out = set()
    for dirpath, dirnames, filenames in os.walk(root):
        dirnames[:] = [d for d in dirnames if d not in skip and not d.endswith(".egg-info")]
        out |= {os.path.join(dirpath, f) for f in filenames}
    return out


def test_site_pages_carry_no_absolute_path(site):
    """No page shows a path of the machine that built it: the checkout, the cache, home, /tmp."""
    import tempfile

    from contactfem.lab.site import work_dir

    needles = {str(REPO), str(work_dir(site)), str(Path.home()) + "/", tempfile.gettempdir() + "/"}
    for page in site.rglob("*.html"):
        text = page.read_text()
        found = [n for n in needles if n in text]
        assert not found, f"{page.relative_to(site)} shows {found}"


def test_a_warning_naming_a_cells_file_shows_cell(tmp_path):
    """A lecture's AccuracyWarning points at the cell's line, a temporary file of Jupyter's kernel: the page
    says "cell"; the other replacements still apply."""
    from contactfem.lab.site import scrub

    page = tmp_path / "09.html"
    page.write_text("<pre>/tmp/ipykernel_4321/2718281828.py:3: AccuracyWarning: accuracy: x\n/home/u/f.png</pre>")
    scrub(tmp_path, {"/home/u": "~"})
    assert page.read_text() == "<pre>cell:3: AccuracyWarning: accuracy: x\n~/f.png</pre>"


def test_site_has_a_page_per_lecture_with_outputs_and_figures(site):
    assert (site / "index.html").exists()
    for nb in LECTURES:
        page = site / (nb.stem + ".html")
        assert page.exists(), f"no page for {nb.name}"
        text = page.read_text()
        assert 'class="cell_output' in text, f"{page.name}: no executed output"
    with_images = [nb.stem for nb in LECTURES if "<img" in (site / (nb.stem + ".html")).read_text()]
    assert len(with_images) >= len(LECTURES) // 2, with_images
    index = (site / "index.html").read_text()
    for nb in LECTURES:
        assert f'href="{nb.stem}.html"' in index, f"{nb.stem} not linked from the index"


def test_site_publishes_the_student_version(site):
    """No line of any solution is on the site; every exercise has its check cell there."""
    import html

    import nbformat

    from contactfem.lab.course import questions, solution_lines

    for nb_path in LECTURES:
        nb = nbformat.read(nb_path, as_version=4)
        page = (site / (nb_path.stem + ".html")).read_text()
        text = html.unescape(re.sub(r"<[^>]+>", "", page))
        for line in solution_lines(nb):
            assert line not in text, f"{nb_path.stem}.html shows the solution line {line!r}"
        for name, _ in questions(nb):
            assert f'grader.check("{name}")' in text, f"{nb_path.stem}.html: no check cell for {name}"
    _assert_student_zip(site, LECTURES)


def _assert_student_zip(site, lectures):
    """The front page links the student handout; the zip holds the student notebooks of
    `lectures` and no line of their solutions, nor any solution marker."""
    import zipfile

    import nbformat

    from contactfem.lab.course import solution_lines
    from contactfem.lab.course.handout import STUDENT_GUIDE, STUDENT_ZIP

    link = re.search(rf'href="(_downloads/[^"]+/{re.escape(STUDENT_ZIP)})"', (site / "index.html").read_text())
    assert link, "the front page does not link the student zip"
    with zipfile.ZipFile(site / link.group(1)) as z:
        files = {Path(n).name: z.read(n).decode() for n in z.namelist()}
    examples = [f.name for f in (REPO / "lectures" / "examples").glob("*.*")]  # the files lectures read
    assert sorted(files) == sorted([STUDENT_GUIDE] + [nb.name for nb in lectures] + examples)
    for nb_path in lectures:
        text = files[nb_path.name]
        assert not re.search(r"BEGIN\s+SOLUTION", text, re.I), nb_path.name
        for line in solution_lines(nbformat.read(nb_path, as_version=4)):
            assert line not in text and json.dumps(line)[1:-1] not in text, f"the zip's {nb_path.name} holds {line!r}"


def test_equation_index_links_every_entry_to_the_api(site):
    from contactfem.equations import INDEX

    text = (site / "equations.html").read_text()
    api = {p.name: p.read_text() for p in (site / "api").glob("*.html")}
    for k, e in INDEX.items():
        m = re.search(rf'href="(api/[^"#]+\.html)#((?:module-)?{re.escape(e.where)})"', text)
        assert m, f"eq ({k}): no link to the API entry of {e.where}"
        page = Path(m.group(1)).name
        assert f'id="{m.group(2)}"' in api[page], f"eq ({k}): {e.where} has no entry in api/{page}"


def _tables(text):
    """The Markdown tables of a page: lists of rows, each row a list of cells."""
    tables, cur = [], []
    for ln in text.splitlines() + [""]:
        if ln.startswith("|"):
            cur.append([c.strip() for c in ln.strip().strip("|").split("|")])
        elif cur:
            tables.append(cur)
            cur = []
    return tables


def test_gallery_page_keeps_the_tables_intact():
    """The gallery page (generated, no build needed): the summary table is the generated block's, row for
    row, and so is Table 2's table of readings (not merged into the summary); every other table keeps its
    own columns; one section per summary row, none made of a table's separator."""
    from contactfem.lab import readme
    from contactfem.lab.site.pages import gallery_page

    page = gallery_page(REPO)
    summary_block, readings_block = (_tables(readme.BLOCKS[name](REPO))[0] for name in ("summary", "sloping-table"))
    tables = _tables(page)
    summary = tables[0]
    assert [r[:4] for r in summary] == [r[:4] for r in summary_block]
    for t in tables:
        assert all(len(r) == len(t[0]) for r in t), t[0]
        assert all(set(c) <= set("-: ") for c in t[1]), t[1]  # the separator is the second row
    readings = [t for t in tables if t[0][0] == "reading"]
    assert len(readings) == 1 and readings[0] == readings_block
    heads = [ln for ln in page.splitlines() if ln.startswith("## ")]
    assert not any(set(h[3:].replace(":", "").strip()) <= set("- ") for h in heads), heads
    assert len([h for h in heads if h != "## Verification problems and more"]) == len(summary_block) - 2


def test_gallery_shows_the_figures_beside_the_papers_values(site):
    text = (site / "gallery.html").read_text()
    assert "paper’s value" in text or "paper's value" in text
    imgs = re.findall(r'<img[^>]+src="([^"]+)"', text)
    assert len(imgs) >= 10, imgs
    for src in imgs:
        assert (site / src).exists(), src
    assert (site / "benchmarks.html").exists()


def test_site_in_the_browser(site, chromium):
    """The index and two lectures opened in headless Chromium: equations typeset, every
    image loaded, and a crawl of the whole site finds no broken internal link."""
    from contactfem.lab.site.browser import check_site

    lectures = [LECTURES[0].stem + ".html", LECTURES[len(LECTURES) // 2].stem + ".html"]
    report = check_site(site, pages=["index.html"] + lectures, chromium=chromium)
    assert report["problems"] == [], "\n".join(report["problems"])
    for name in lectures:
        found = report["pages"][name]
        assert found["typeset"] > 5 and found["images"], (name, found)
    assert len(report["crawled"]) >= len(LECTURES) + 5
    assert (site / "_check" / "index.png").exists()


def test_browser_check_fails_on_the_real_site_broken(site, chromium, tmp_path):
    """The same check on a copy of the built site with one figure deleted and one
    equation of a lecture broken: both are reported."""
    from contactfem.lab.site.browser import check_site

    broken = tmp_path / "site"
    shutil.copytree(site, broken, ignore=shutil.ignore_patterns("_check"))
    name = LECTURES[0].stem + ".html"
    page = broken / name
    text = page.read_text()
    img = re.search(r'<img[^>]+src="(_images/[^"]+)"', text).group(1)
    (broken / img).unlink()
    text, n = re.subn(r'(<span class="math[^"]*">)\\\((.*?)\\\)', r"\1\\(\\frac{\2}\\)", text, count=1)  # one argument
    assert n == 1
    page.write_text(text)
    problems = check_site(broken, pages=[name], chromium=chromium)["problems"]
    assert any(f"{name}: 1 image(s) did not load" in p for p in problems), problems
    assert any(f"{name}: 1 equation(s) failed to typeset" in p for p in problems), problems


def test_site_command_line():
    from contactfem.cli import build_parser

    args = build_parser().parse_args(["site", "--out", "somewhere"])
    assert args.out == "somewhere" and args.func.__name__ == "cmd_site" and not args.instructor
    assert build_parser().parse_args(["site", "--instructor"]).instructor


# -- every file under --out -------------------------------------------------------------


def _everything(root, skip=None):
    """Every path under `root` (folders too), with each file's size, outside `skip`."""
    out = set()
    for dirpath, dirnames, filenames in os.walk(root):
        if skip is not None:
            dirnames[:] = [d for d in dirnames if Path(dirpath, d) != skip]
        out |= {(os.path.join(dirpath, d), None) for d in dirnames}
        out |= {(os.path.join(dirpath, f), os.path.getsize(os.path.join(dirpath, f))) for f in filenames}
    return out


@pytest.mark.slow
def test_an_instructor_site_writes_nothing_outside_out(tmp_path):
    """`site --instructor --out X` (one lecture, in its own process) on a fresh folder tree:
    home, temporary folder, $CONTACTFEM_CACHE and working folder all inside one parent,
    which holds exactly what it held before outside X (the checkout too); X holds the pages,
    the executed solutions among them, and of the build's work only its cache."""
    _site_extra()
    import nbformat

    from contactfem.lab.course import solution_lines

    lecture = REPO / "lectures" / "01_interface_laws.ipynb"
    parent = tmp_path / "fresh"
    for d in ("home", "tmp", "cache", "cwd"):
        (parent / d).mkdir(parents=True)
    out = parent / "X"
    env = dict(
        os.environ,
        HOME=str(parent / "home"),
        TMPDIR=str(parent / "tmp"),
        PYTHONPATH=str(REPO),
        CONTACTFEM_CACHE=str(parent / "cache"),
        MPLBACKEND="Agg",
    )
    env.pop("MPLCONFIGDIR", None)
    env.pop("IPYTHONDIR", None)
    # the tools' own per-user caches exist on any machine that ran matplotlib once: made here first
    subprocess.run([sys.executable, "-c", "import matplotlib.font_manager"], env=env, cwd=parent / "cwd", check=True)
    before, checkout = _everything(parent), _tree(REPO)
    t0 = time.monotonic()
    p = subprocess.run(
        [
            sys.executable,
            "-c",
            f"from contactfem.lab.site import build; build({str(out)!r}, instructor=True, only=[{lecture.stem!r}])",
        ],
        env=env,
        cwd=parent / "cwd",
        capture_output=True,
        text=True,
        timeout=1200,
    )
    print(f"\ninstructor site of one lecture built in {time.monotonic() - t0:.0f} s")
    assert p.returncode == 0, p.stderr[-3000:]
    assert _everything(parent, skip=out) == before, sorted(_everything(parent, skip=out) ^ before)[:20]
    assert _tree(REPO) == checkout, "the site build wrote into the checkout"
    assert all(out in q.parents for q in parent.rglob("jupyter_execute"))
    assert sorted(q.name for q in (out / ".contactfem-site").iterdir()) == ["cache"]
    import html

    page = html.unescape(re.sub(r"<[^>]+>", "", (out / f"{lecture.stem}.html").read_text()))
    lines = solution_lines(nbformat.read(lecture, as_version=4))
    assert all(ln in page for ln in lines), "the instructor page lacks solution lines"
    _assert_student_zip(out, [lecture])


def test_ctrl_c_during_the_site_build_leaves_the_old_pages(tmp_path):
    """SIGINT (to the whole process group, as from a terminal) while Sphinx runs: one line
    that says the site in OUT is unchanged, exit 130; the old pages are there as they were
    and of the new build only the cache is left."""
    _site_extra()
    out = tmp_path / "X"
    out.mkdir()
    (out / ".buildinfo").write_text("# an earlier build\n")
    (out / "index.html").write_text("<p>the old site</p>")
    env = dict(os.environ, PYTHONPATH=str(REPO), TMPDIR=str(tmp_path))
    p = subprocess.Popen(
        [sys.executable, "-m", "contactfem", "site", "--out", str(out)],
        env=env,
        text=True,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        start_new_session=True,
        preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL),
    )
    stamp = out / ".contactfem-site" / "cache" / "contactfem-code.txt"  # Sphinx starts next
    t0 = time.monotonic()
    while p.poll() is None and not stamp.exists() and time.monotonic() - t0 < 300:
        time.sleep(0.05)
    time.sleep(2.0)
    assert p.poll() is None, p.communicate()
    os.killpg(p.pid, signal.SIGINT)
    _, err = p.communicate(timeout=120)
    assert p.returncode == 130, err
    assert err.strip() == (
        f"contactfem: interrupted during the site build; the site in {out} is unchanged "
        f"(notebooks executed so far are cached in {out / '.contactfem-site'})"
    ), err
    assert sorted(q.name for q in out.iterdir()) == [".buildinfo", ".contactfem-site", "index.html"]
    assert (out / "index.html").read_text() == "<p>the old site</p>"
    assert sorted(q.name for q in (out / ".contactfem-site").iterdir()) == ["cache"]
