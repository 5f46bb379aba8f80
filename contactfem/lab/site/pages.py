"""The pages of the course website that are written from the repository, not by hand.

``stage(repo, dst)`` lays out a Sphinx source folder in `dst`: every notebook of
``lectures/`` (glob, so a new lecture appears by itself) in its student version (the
course's build: no solutions, a check cell after each exercise), the hand-written pages and
the configuration of ``lectures/_site/``, the student handout (the zip of the student
version that ``contactfem course build`` writes, linked from the index), and four
generated pages:

* ``gallery.md``   -- the README's table of the paper's examples, each row with the
  paper's value beside ours and its figures shown (copied from ``figures/``);
* ``equations.md`` -- the equation index of :mod:`contactfem.equations`, every entry a
  link into the API reference;
* ``api/``         -- the API reference, one page per folder of the package, generated
  by autodoc from the docstrings;
* ``benchmarks.md`` -- BENCHMARKS.md as it is (with the figures it shows).
"""

import importlib
import importlib.util
import inspect
import pkgutil
import re
import shutil
from pathlib import Path

from ... import lazy
from ...equations import INDEX, NOT_MAPPED, resolve

# the course (lazy: the students' edition a submission is graded with leaves it out, and imports this module)
course = lazy.module("contactfem.lab.course")
handout = lazy.module("contactfem.lab.course.handout")

GALLERY_HEADING = "## The paper's examples"
_LINK = re.compile(r"\[([^\]]+)\]\((figures/[^)\s]+)\)")
_IMAGE_LINE = re.compile(r"^!\[([^\]]*)\]\((figures/[^)\s]+)\)\s*$")


def notebooks(lectures):
    """The lectures: every notebook in the folder, in file-name order."""
    return sorted(Path(lectures).glob("*.ipynb"))


def readme_section(text, heading=GALLERY_HEADING):
    """The lines of the README section starting with `heading`, up to the next '## '."""
    lines = text.splitlines()
    try:
        start = next(i for i, ln in enumerate(lines) if ln.startswith(heading))
    except StopIteration:
        raise ValueError(f"README.md has no section starting with {heading!r}") from None
    end = next((i for i in range(start + 1, len(lines)) if lines[i].startswith("## ")), len(lines))
    return lines[start + 1 : end]


_COMMENT = re.compile(r"^\s*<!--.*-->\s*$")
_ANY_LINK = re.compile(r"\[([^\]]+)\]\(([^)\s]+)\)")
_IMAGE_SUFFIXES = (".png", ".jpg", ".jpeg", ".gif", ".svg")


def _repo_link(line):
    """A link of the README to a repository file that is not a figure: the file's path as
    text (the site does not carry it)."""

    def sub(m):
        label, target = m.groups()
        if re.match(r"[a-z]+:", target) or target.startswith("#") or target.lower().endswith(_IMAGE_SUFFIXES):
            return m.group(0)
        return f"`{target}`" if label == target else f"{label} (`{target}` in the repository)"

    return _ANY_LINK.sub(sub, line)


def _cells(row):
    return [c.strip() for c in row.strip().strip("|").split("|")]


def _figure_block(label, target, repo):
    """MyST for one linked figure: an image, or a markdown table file shown inline."""
    path = repo / target
    if path.suffix.lower() in (".png", ".jpg", ".jpeg", ".gif", ".svg"):
        return [f"```{{figure}} {target}", ":width: 90%", "", f"{label}: `{target}`", "```", ""]
    if path.suffix == ".md":
        body = path.read_text().splitlines()
        out = []
        for ln in body:
            if ln.startswith("#"):  # the table's own title: a caption, not a section
                out.append(f"**{ln.lstrip('#').strip()}**")
            else:
                out.append(ln)
        return out + [""]
    return [f"[{label}]({target})", ""]


def gallery_page(repo):
    """The README's gallery section as a page: the intro, the table as it is, then one
    section per row with the paper's value, ours, and the row's figures shown."""
    repo = Path(repo)
    section = readme_section((repo / "README.md").read_text())
    out = ["# Gallery: the paper's examples, ours beside the paper's", ""]
    rows, rest = [], []  # the summary table (the section's first), and what follows it
    for ln in section:
        if rest or (rows and not ln.startswith("|")):
            rest.append(ln)  # later tables (Table 2's readings) stay tables, in the text below
        elif ln.startswith("|"):
            rows.append(ln)
        else:
            out.append(ln)
    for i, row in enumerate(rows):  # tables (.md) are shown inline in the row's section below
        out.append(
            re.sub(
                r"\[([^\]]+)\]\(figures/[^)\s]+\.md\)", lambda m, i=i: f"{{ref}}`{m.group(1)} <gallery-row-{i}>`", row
            )
        )
    out.append("")
    header = [h.lower() for h in _cells(rows[0])] if rows else []
    for i, row in enumerate(rows[2:], start=2):
        cells = dict(zip(header, _cells(row)))
        what = cells.get("what", "")
        paper = cells.get("paper", "")
        out += [f"(gallery-row-{i})=", f"## {paper}: {what}" if what else f"## {paper}", ""]
        theirs = cells.get("paper's value", "-")
        out += ["| paper's value | ours |", "|---|---|", f"| {theirs} | {cells.get('ours', '-')} |", ""]
        for label, target in _LINK.findall(cells.get("figure", "")):
            out += _figure_block(label, target, repo)
    out[2:] = [_repo_link(ln) for ln in out[2:] if not _COMMENT.match(ln)]
    rest = [_repo_link(ln) for ln in rest if not _COMMENT.match(ln)]
    extra = []
    for ln in rest:
        m = _IMAGE_LINE.match(ln)
        if m:
            continue  # the README's showcase images are in the rows above
        extra.append(ln)
    if any(ln.strip() for ln in extra):
        out += ["## Verification problems and more", ""] + extra + [""]
        for label, target in _LINK.findall("\n".join(extra)):
            out += _figure_block(label, target, repo)
    return "\n".join(out) + "\n"


def figures_used(page_text):
    """Repository-relative figure paths a generated page refers to."""
    found = set(re.findall(r"\((figures/[^)\s]+)\)", page_text))
    found |= set(re.findall(r"\{figure\} (figures/\S+)", page_text))
    return sorted(f for f in found if not f.endswith(".md"))


def _role(dotted):
    obj = resolve(dotted)
    if inspect.ismodule(obj):
        return f"{{py:mod}}`{dotted}`"
    return f"{{py:obj}}`{dotted}`"


def _escape_bars(text):
    return text.replace("|", "\\|")


def equations_page():
    """The equation index: each equation of the paper, what it is, and a link to the
    API entry of the function, class or module that implements it."""
    out = [
        "# Equation index",
        "",
        "For each numbered equation of Wriggers, Vu Van & Stein (1990), the function, class or "
        "module of `contactfem` that implements it (the same index as `contactfem equations`). "
        "Each name links to its entry in the [API reference](api/index.md), where the docstring "
        "cites the equation.",
        "",
        "| eq | what | implemented in |",
        "|---:|---|---|",
    ]
    for k in sorted(INDEX):
        e = INDEX[k]
        out.append(f"| ({k}) | `{_escape_bars(e.what)}` | {_role(e.where)} |")
    out += ["", "## Equations without an entry of their own", "", "| eq | why |", "|---:|---|"]
    for k in sorted(NOT_MAPPED):
        out.append(f"| ({k}) | {_escape_bars(NOT_MAPPED[k])} |")
    return "\n".join(out) + "\n"


def package_modules(package="contactfem"):
    """Dotted names of every module of the package (``__main__`` excluded), sorted."""
    pkg = importlib.import_module(package)
    names = [package]
    for info in pkgutil.walk_packages(pkg.__path__, package + "."):
        if info.name.rsplit(".", 1)[-1] == "__main__":
            continue
        names.append(info.name)
    return sorted(names)


def api_pages(package="contactfem"):
    """{file name: MyST text}: an index and one page per folder of the package; every
    module documented once with autodoc (members that have docstrings)."""
    subpackages = _packages(package)
    groups = {}
    for name in package_modules(package):
        parts = name.split(".")
        key = parts[1] if len(parts) > 1 and f"{package}.{parts[1]}" in subpackages else "core"
        groups.setdefault(key, []).append(name)
    pages = {}
    order = sorted(groups, key=lambda k: (k == "core", k))
    index = (
        [
            "# API reference",
            "",
            "Generated from the docstrings. The layers, low to high: laws, contact, bodies, "
            "solver, scenes, plots and io, the lab (benchmarks, reconstruction, sweeps, this site), the command line.",
            "",
            "```{toctree}",
            ":maxdepth: 2",
            "",
        ]
        + [f"{k}" for k in order]
        + ["```", ""]
    )
    pages["index.md"] = "\n".join(index)
    for key in order:
        title = f"`{package}.{key}`" if key != "core" else f"`{package}`: package, equation index, command line"
        text = [f"# {title}", ""]
        for mod in groups[key]:
            text += ["```{eval-rst}", f".. automodule:: {mod}", "   :members:", "```", ""]
        pages[f"{key}.md"] = "\n".join(text)
    return pages


def _packages(package):
    pkg = importlib.import_module(package)
    return {f"{package}.{i.name}" for i in pkgutil.iter_modules(pkg.__path__) if i.ispkg}


def copy_mathjax(dst):
    """Copy MathJax 3 (the browser part: tex-chtml.js and the components and fonts it
    loads) from the installed ``django-static-mathjax`` package into `dst`. Returns the
    path of the entry script relative to `dst`."""
    spec = importlib.util.find_spec("mathjax")
    roots = list(spec.submodule_search_locations or []) if spec else []
    es5 = next(
        (
            Path(r) / "static" / "mathjax" / "es5"
            for r in roots
            if (Path(r) / "static" / "mathjax" / "es5" / "tex-chtml.js").exists()
        ),
        None,
    )
    if es5 is None:
        raise RuntimeError(
            "MathJax not found: install the site extra, pip install -e '.[site]' "
            "(the package django-static-mathjax ships MathJax 3)"
        )
    dst = Path(dst)
    if dst.exists():
        shutil.rmtree(dst)
    dst.mkdir(parents=True)
    shutil.copy2(es5 / "tex-chtml.js", dst / "tex-chtml.js")
    for sub in ("input", "output", "ui", "a11y", "adaptors", "sre"):
        if (es5 / sub).exists():
            shutil.copytree(es5 / sub, dst / sub)
    return "tex-chtml.js"


def stage(repo, dst, instructor=False, only=None, work=None):
    """Lay out the Sphinx source folder `dst` from the repository `repo` (see the module
    docstring): the lectures in their student version (no solutions; with `instructor`,
    the instructor version), built by :func:`contactfem.lab.course.build_versions`, and the
    student handout (the zip of the student version) for the index to link. `only`: the
    lectures (stems) to stage, default all; `work`: a folder for the course build's work
    (default: beside `dst`). Returns the list of lecture notebooks staged."""
    repo, dst = Path(repo), Path(dst)
    work = Path(work) if work else dst.parent / f"{dst.name}-course"
    lectures = repo / "lectures"
    for folder in (dst, work):
        if folder.exists():
            shutil.rmtree(folder)
    dst.mkdir(parents=True)
    shutil.copytree(lectures / "_site", dst, dirs_exist_ok=True)
    if not notebooks(lectures):
        raise RuntimeError(f"no notebooks in {lectures}")
    outs = {"instructor": dst, "student": work / "student"} if instructor else {"student": dst}
    nbs = course.build_versions(outs, repo=repo, only=only, work=work)["instructor" if instructor else "student"]
    if instructor:
        shutil.copy2(work / "student" / handout.STUDENT_ZIP, dst / handout.STUDENT_ZIP)
    shutil.rmtree(dst / "autograder", ignore_errors=True)  # grading configurations: not pages
    (dst / handout.MANIFEST).unlink(missing_ok=True)
    shutil.copy2(lectures / "README.md", dst / "course.md")
    gallery = gallery_page(repo)
    (dst / "gallery.md").write_text(gallery)
    benchmarks = (repo / "BENCHMARKS.md").read_text()
    for rel in figures_used(gallery + benchmarks):  # images only: markdown tables are shown inline
        (dst / rel).parent.mkdir(parents=True, exist_ok=True)
        shutil.copy2(repo / rel, dst / rel)
    (dst / "equations.md").write_text(equations_page())
    (dst / "api").mkdir()
    for name, text in api_pages().items():
        (dst / "api" / name).write_text(text)
    (dst / "benchmarks.md").write_text(benchmarks)
    copy_mathjax(dst / "_static" / "mathjax")
    return nbs
