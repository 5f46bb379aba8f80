"""What `contactfem course build` leaves in its output folder, and what it never destroys.

* **No student work lost.** A build records what it wrote in ``OUT/.contactfem-course.json``
  (each notebook's SHA-256). A later build replaces a notebook only if it is the one an
  earlier build wrote, unchanged, or already what the build would write; any other notebook
  of that name (answered, edited, or a file the build did not make) is a conflict: the build
  stops with one line naming it, before writing anything. With ``force`` the conflicting
  notebooks are moved to ``OUT/backup-<UTC time>/`` first.
* **A handout.** The student version is also one zip, :data:`STUDENT_ZIP`: its notebooks
  and a short README for students. It holds no solution (the notebooks are otter's student
  version).
"""

import hashlib
import json
import os
import time
import zipfile
from pathlib import Path

MANIFEST = ".contactfem-course.json"
STUDENT_ZIP = "contactfem-course-student.zip"


def digest(path):
    return hashlib.sha256(Path(path).read_bytes()).hexdigest()


def _record(out):
    try:
        found = json.loads((Path(out) / MANIFEST).read_text())
        return found if isinstance(found, dict) else {}
    except (OSError, ValueError):
        return {}


def manifest(out):
    """{file name: sha256} of what the builds wrote into `out` ({} if none, or unreadable)."""
    files = _record(out).get("files", {})
    return dict(files) if isinstance(files, dict) else {}


def check_version(out, version):
    """ValueError if `out` holds the other version: the instructor version (the solutions)
    never replaces a student folder unnoticed, nor the other way round."""
    other = _record(out).get("version")
    if other in ("student", "instructor") and other != version and manifest(out):
        raise ValueError(
            f"--out {out}: holds the {other} version of the course; build the {version} version into another folder"
        )


def changed_since_built(out, names):
    """The names (of `names`) whose file in `out` an earlier build wrote and that changed since:
    student work for certain, found before any work."""
    known = manifest(out)
    return [n for n in names if n in known and (Path(out) / n).is_file() and digest(Path(out) / n) != known[n]]


def conflicts(out, new):
    """The names of `new` ({file name: path of the file the build would write}) whose file in
    `out` would be lost: there, not what the build would write, and not unchanged since an
    earlier build wrote it."""
    known = manifest(out)
    found = []
    for name, src in new.items():
        dst = Path(out) / name
        if not dst.exists():
            continue
        if dst.is_dir():
            found.append(name)
            continue
        have = digest(dst)
        if have != digest(src) and have != known.get(name):
            found.append(name)
    return found


def refusal(out, names, force_option="--force"):
    """The one line that refuses to overwrite `names` in `out`."""
    more = (
        f" (and {len(names) - 1} more: {', '.join(names[1:4])}{', ...' if len(names) > 4 else ''})"
        if len(names) > 1
        else ""
    )
    return (
        f"--out {out}: {names[0]}{more} differs from what the build would write (answers or edits in it "
        f"would be lost): move it away, or add {force_option} to keep it in {Path(out) / 'backup-TIME'}/"
    )


def back_up(out, names):
    """Move the files `names` of `out` into a new folder OUT/backup-<UTC time>/; returns it."""
    stamp = time.strftime("%Y%m%d-%H%M%S", time.gmtime())
    folder, k = Path(out) / f"backup-{stamp}", 1
    while folder.exists():
        k += 1
        folder = Path(out) / f"backup-{stamp}-{k}"
    folder.mkdir()
    for name in names:
        os.replace(Path(out) / name, folder / name)
    return folder


def write_manifest(out, version, names):
    """Record the files of this build (after they are written), beside those of earlier builds
    still there unchanged (a build of some lectures keeps the record of the others)."""
    files = {n: h for n, h in manifest(out).items() if (Path(out) / n).is_file() and digest(Path(out) / n) == h}
    files.update({n: digest(Path(out) / n) for n in names})
    files = dict(sorted(files.items()))
    (Path(out) / MANIFEST).write_text(json.dumps({"version": version, "files": files}, indent=1) + "\n")


STUDENT_GUIDE = "README.md"  # the handout's page for students, beside the notebooks
STUDENT_README = """\
# contactfem: the course, student notebooks

One notebook per lecture, in course order, without the solutions. Each exercise has a cell
where your answer goes (`...` marks what to write) and, after it, a check cell
`grader.check("exNN_...")` that runs the exercise's checks and shows your score and hints.

You need the package with its course extra, installed as your instructor tells you (for
example from the wheel file they hand out:
`python -m pip install "contactfem-VERSION-py3-none-any.whl[course]"`), then, in this folder:

    jupyter lab

Keep the check cells and the file names as they are, run each notebook from top to bottom
before you hand it in, and hand in the .ipynb file.
"""


def student_zip(notebooks, path, extras=()):
    """The student handout: `notebooks` (the student version), a README and `extras` (name, file:
    the lectures' example files), in one zip at `path` (the same bytes for the same notebooks: no
    time stamps). Returns `path`."""
    path = Path(path)
    tmp = path.with_name(f".{path.name}.part")
    with zipfile.ZipFile(tmp, "w", compression=zipfile.ZIP_DEFLATED) as z:
        entries = [(f"contactfem-course/{STUDENT_GUIDE}", STUDENT_README.encode())]
        entries += [(f"contactfem-course/{Path(nb).name}", Path(nb).read_bytes()) for nb in sorted(notebooks)]
        entries += [(f"contactfem-course/{name}", Path(f).read_bytes()) for name, f in sorted(extras)]
        for name, data in entries:
            info = zipfile.ZipInfo(name, date_time=(1980, 1, 1, 0, 0, 0))
            info.compress_type = zipfile.ZIP_DEFLATED
            info.external_attr = 0o644 << 16
            z.writestr(info, data)
    os.replace(tmp, path)
    return path
