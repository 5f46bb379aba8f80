"""The course as a website: the lectures executed (fast preset; the student version,
without solutions, or with --instructor the instructor version), the gallery of the
paper's examples, the equation index linked into the API reference, the benchmarks.

    contactfem site [--out DIR]        # DIR/index.html; default build/site in the checkout
    contactfem site --instructor       # the lectures with their solutions: build/site-instructor

``build`` stages a Sphinx source folder (:mod:`contactfem.lab.site.pages`), with the
configuration in ``lectures/_site/conf.py``, and runs Sphinx with warnings as errors.
Every file it writes is under DIR: the pages, the student handout (a zip of the student
version, linked from the index), and its own work in ``DIR/.contactfem-site``: the staged
sources, the figures the lectures draw and the executed notebooks while it runs (removed
after), and its cache, kept so that a rebuild runs only the notebooks that changed (MyST-NB's
cache of executed notebooks and Sphinx's read pages; emptied when the code of the package
changes). DIR is new, empty, or a site built before; the new pages replace the old ones only
once the build has succeeded. The published pages carry no absolute path of the machine
that built them (``scrub``). :mod:`contactfem.lab.site.browser` checks the built site in
headless Chromium as a reader would.

Needs the ``site`` extra (``pip install -e ".[site]"``) and a checkout of the repository
(the lectures are not part of the installed package).
"""

import hashlib
import json
import os
import re
import shutil
import subprocess
import sys
from pathlib import Path

from ...io.outputs import check_output_dir, hold_interrupts
from . import pages

REPO = Path(__file__).resolve().parents[3]


def default_out(instructor=False):
    """build/site in the checkout (build/site-instructor for the instructor version)."""
    return REPO / "build" / ("site-instructor" if instructor else "site")


WORK = ".contactfem-site"
# the parts of the work folder a build makes afresh (removed after it; "cache" is kept)
TRANSIENT = ("src", "course", "html", "jupyter_execute", "kernel", "runtime", "ipython", "figures")


def work_dir(out):
    """The build's own folder inside the site folder `out`: OUT/.contactfem-site."""
    return Path(out) / WORK


def check_out(out, option="--out"):
    """The site folder `out`, checked before any work (ValueError naming the option): a folder
    that can be written, and new, empty, or a site built before (it has the build's work
    folder, or Sphinx's .buildinfo): the build never writes its pages among other files."""
    out = check_output_dir(out, option)
    if out.is_dir() and not (work_dir(out).is_dir() or (out / ".buildinfo").is_file()):
        other = sorted(p.name for p in out.iterdir())
        if other:
            raise ValueError(
                f"{option} {out}: holds files that are not a site built by contactfem site "
                f"({', '.join(other[:3])}{', ...' if len(other) > 3 else ''}): give a new or empty folder"
            )
    return out


# the file Jupyter's kernel gives a cell's code (a warning raised for a cell's line names it): "cell"
CELL_FILE = re.compile(r"[^\s\"'<>]*/ipykernel_\d+/\d+\.py")


def scrub(out, replacements):
    """Replace the builder's absolute paths in the built pages (printed by a lecture, e.g.
    where its figures went, or a warning naming a cell's temporary file) by the names a reader understands:
    {path: name}, and a cell's file by "cell"."""
    pairs = sorted(
        ((str(k), v) for k, v in replacements.items() if str(k) not in ("", "/")), key=lambda kv: -len(kv[0])
    )
    for page in Path(out).rglob("*"):
        if page.suffix not in (".html", ".js", ".txt") or not page.is_file():
            continue
        text = page.read_text(errors="surrogateescape")
        new = text
        for old, name in pairs:
            new = new.replace(old, name)
        new = CELL_FILE.sub("cell", new)
        if new != text:
            page.write_text(new, errors="surrogateescape")


def code_hash(package_dir=None):
    """A hash of the package's source files (the site builder's own excepted): executed
    notebooks are cached per hash."""
    package_dir = Path(package_dir or Path(__file__).resolve().parents[2])
    h = hashlib.sha256()
    for path in sorted(package_dir.rglob("*.py")):
        if path.relative_to(package_dir).parts[:2] == ("lab", "site"):
            continue
        h.update(str(path.relative_to(package_dir)).encode())
        h.update(path.read_bytes())
    return h.hexdigest()[:16]


def _prepare_cache(cache):
    """Empty the cache (executed notebooks, and Sphinx's read pages that hold their
    outputs) if it was made by different package code."""
    stamp = cache / "contactfem-code.txt"
    digest = code_hash()
    if cache.exists() and (not stamp.exists() or stamp.read_text().strip() != digest):
        shutil.rmtree(cache)
    cache.mkdir(parents=True, exist_ok=True)
    stamp.write_text(digest + "\n")


def _kernel_env(work, env):
    """Run the notebooks with *this* interpreter and this checkout, whatever kernel the
    machine has registered as "python3" (the same arrangement as tests/test_lectures.py)."""
    spec = work / "jupyter" / "kernels" / "python3"
    spec.mkdir(parents=True, exist_ok=True)
    (spec / "kernel.json").write_text(
        json.dumps(
            {
                "argv": [sys.executable, "-m", "ipykernel_launcher", "-f", "{connection_file}"],
                "display_name": "Python 3 (contactfem site)",
                "language": "python",
            }
        )
    )
    env["JUPYTER_PATH"] = os.pathsep.join([str(work / "jupyter")] + [p for p in [env.get("JUPYTER_PATH")] if p])
    env["PYTHONPATH"] = os.pathsep.join([str(REPO)] + [p for p in [env.get("PYTHONPATH")] if p])


def build(out=None, repo=None, quiet=True, instructor=False, only=None, on_write=None):
    """Build the site into `out` (default: build/site of the checkout, build/site-instructor
    for the instructor version); returns the path of its index.html. The lectures are the
    course's student version (no solutions) unless `instructor`; `only`: the lectures (file
    stems) to put on the site, default all. Every file of the build is written under `out`:
    the pages, and in OUT/.contactfem-site the build's work (staged sources, the executed
    notebooks and Sphinx's read pages, kept for the next build, the lectures' figures). The
    pages are built there and moved into `out` at the end, together, with Ctrl-C held back
    (`on_write` is called first): an interrupted or failed build leaves the pages in `out` as
    they were. Raises RuntimeError with Sphinx's output if the build fails (a warning, a
    failing notebook cell, a missing reference)."""
    repo = Path(repo or REPO)
    if not (repo / "lectures" / "_site" / "conf.py").exists():
        raise RuntimeError(f"contactfem site needs a checkout of the repository: no lectures/_site in {repo}")
    out = check_out(out or default_out(instructor))
    work = work_dir(out)
    src, cache, html = work / "src", work / "cache", work / "html"
    try:
        pages.stage(repo, src, instructor=instructor, only=only, work=work / "course")
        _prepare_cache(cache)
        env = dict(os.environ)
        _kernel_env(work / "kernel", env)
        env.update(
            CONTACTFEM_PRESET="fast",
            CONTACTFEM_FIGURES=str(work / "figures"),
            CONTACTFEM_SITE_CACHE=str(cache / "notebooks"),
            MPLBACKEND="module://matplotlib_inline.backend_inline",
            JUPYTER_RUNTIME_DIR=str(work / "runtime"),
            IPYTHONDIR=str(work / "ipython"),
        )
        if html.exists():  # what an interrupted build left
            shutil.rmtree(html)
        # Sphinx writes into work/html; MyST-NB puts its executed notebooks beside that, in
        # work/jupyter_execute, and its cache and Sphinx its read pages in work/cache
        cmd = [
            sys.executable,
            "-m",
            "sphinx",
            "-b",
            "html",
            "-W",
            "--keep-going",
            "-q",
            "-d",
            str(cache / "doctrees"),
            str(src),
            str(html),
        ]
        proc = subprocess.run(cmd, env=env, cwd=str(src), capture_output=quiet, text=True)
        if proc.returncode != 0:
            msg = (proc.stdout or "")[-6000:] + (proc.stderr or "")[-6000:] if quiet else ""
            raise RuntimeError(f"the site build failed (Sphinx exit code {proc.returncode}):\n{msg}")
        scrub(
            html,
            {
                (work / "figures").resolve(): "figures",
                work / "figures": "figures",
                work.resolve(): WORK,
                work: WORK,
                out.resolve(): ".",
                repo.resolve(): ".",
                Path.home(): "~",
            },
        )
        with hold_interrupts():  # the new pages replace the old ones together
            if on_write:
                on_write()
            for page in sorted(html.iterdir()):
                dst = out / page.name
                if dst.is_dir() and not dst.is_symlink():
                    shutil.rmtree(dst)
                elif dst.exists() or dst.is_symlink():
                    dst.unlink()
                os.replace(page, dst)
    finally:  # keep the cache only: the rest is made again by the next build
        for part in TRANSIENT:
            shutil.rmtree(work / part, ignore_errors=True)
    return out / "index.html"
