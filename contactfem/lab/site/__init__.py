"""The course as a website: the lectures executed (fast preset; the student version,
without solutions, or with --instructor the instructor version), the gallery of the
paper's examples, the equation index linked into the API reference, the benchmarks.

    contactfem site [--out DIR]        # DIR/index.html; default build/site in the checkout
    contactfem site --instructor       # the lectures with their solutions: build/site-instructor

``build`` stages a Sphinx source folder (:mod:`contactfem.lab.site.pages`), with the
configuration in ``lectures/_site/conf.py``, and runs Sphinx with warnings as errors.
It writes only into DIR and into its cache folder, ``$CONTACTFEM_CACHE/site`` (default
``~/.cache/contactfem/site``): the staged sources, the figures the lectures draw, and the
executed notebooks (emptied when the code of the package changes, so a rebuild takes
seconds). The published pages carry no absolute path of the machine that built them
(``scrub``). :mod:`contactfem.lab.site.browser` checks the built site in headless
Chromium as a reader would.

Needs the ``site`` extra (``pip install -e ".[site]"``) and a checkout of the repository
(the lectures are not part of the installed package).
"""

import hashlib
import json
import os
import shutil
import subprocess
import sys
from pathlib import Path

REPO = Path(__file__).resolve().parents[3]


def default_out(instructor=False):
    """build/site in the checkout (build/site-instructor for the instructor version)."""
    return REPO / "build" / ("site-instructor" if instructor else "site")


def cache_dir():
    """The site's work and cache folder: $CONTACTFEM_CACHE/site, default ~/.cache/contactfem/site."""
    return Path(os.environ.get("CONTACTFEM_CACHE") or Path.home() / ".cache" / "contactfem") / "site"


def scrub(out, replacements):
    """Replace the builder's absolute paths in the built pages (printed by a lecture, e.g.
    where its figures went) by the names a reader understands: {path: name}."""
    pairs = sorted(((str(k), v) for k, v in replacements.items() if str(k) not in ("", "/")),
                   key=lambda kv: -len(kv[0]))
    for page in Path(out).rglob("*"):
        if page.suffix not in (".html", ".js", ".txt") or not page.is_file():
            continue
        text = page.read_text(errors="surrogateescape")
        new = text
        for old, name in pairs:
            new = new.replace(old, name)
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
    (spec / "kernel.json").write_text(json.dumps({
        "argv": [sys.executable, "-m", "ipykernel_launcher", "-f", "{connection_file}"],
        "display_name": "Python 3 (contactfem site)", "language": "python"}))
    env["JUPYTER_PATH"] = os.pathsep.join([str(work / "jupyter")] + [p for p in [env.get("JUPYTER_PATH")] if p])
    env["PYTHONPATH"] = os.pathsep.join([str(REPO)] + [p for p in [env.get("PYTHONPATH")] if p])


def build(out=None, repo=None, quiet=True, instructor=False):
    """Build the site into `out` (default: build/site of the checkout, build/site-instructor
    for the instructor version); returns the path of its index.html. The lectures are the
    course's student version (no solutions) unless `instructor`. Its own files go to
    cache_dir(). Raises RuntimeError with Sphinx's output if the build fails (a warning, a
    failing notebook cell, a missing reference)."""
    repo = Path(repo or REPO)
    if not (repo / "lectures" / "_site" / "conf.py").exists():
        raise RuntimeError(f"contactfem site needs a checkout of the repository: no lectures/_site in {repo}")
    work = cache_dir()
    out = Path(out) if out else default_out(instructor)
    version = "site-instructor" if instructor else "site"
    src, cache = work / f"{version}-src", work / "cache"
    from .pages import stage

    stage(repo, src, instructor=instructor)
    _prepare_cache(cache)
    env = dict(os.environ)
    _kernel_env(work / "kernel", env)
    env.update(CONTACTFEM_PRESET="fast", CONTACTFEM_FIGURES=str(work / "figures"),
               CONTACTFEM_SITE_CACHE=str(cache / "notebooks"), MPLBACKEND="module://matplotlib_inline.backend_inline")
    cmd = [sys.executable, "-m", "sphinx", "-b", "html", "-W", "--keep-going", "-q",
           "-d", str(cache / "doctrees"), str(src), str(out)]   # read pages live with the cache
    proc = subprocess.run(cmd, env=env, cwd=str(src), capture_output=quiet, text=True)
    if proc.returncode != 0:
        msg = (proc.stdout or "")[-6000:] + (proc.stderr or "")[-6000:] if quiet else ""
        raise RuntimeError(f"the site build failed (Sphinx exit code {proc.returncode}):\n{msg}")
    scrub(out, {work.resolve(): "$CONTACTFEM_CACHE/site", work: "$CONTACTFEM_CACHE/site",
                repo.resolve(): ".", Path.home(): "~"})
    return out / "index.html"
