"""The parts the grading stands on, one at a time: the students' edition of the library, the
snapshot of the submissions, the plain data that crosses the sandbox's border, the outputs
written atomically."""

import ast
import json
import os
import subprocess
import sys

import numpy as np
import pytest

from contactfem.lab.course.checks import EXERCISES, LIBRARY
from contactfem.lab.course.edition import PACKAGE, build_edition, leave_out
from contactfem.lab.course.grade import left_out

LECTURES = sorted({EXERCISES[e].lecture for e in LIBRARY})


def _definition(path, qualname):
    body = ast.parse(path.read_text()).body
    node = None
    for part in qualname.split("."):
        node = next(n for n in body if getattr(n, "name", None) == part)
        body = node.body
    return ast.get_source_segment(path.read_text(), node)


def test_leave_out_replaces_a_function_a_class_and_a_method_by_stubs(tmp_path):
    src = tmp_path / "m.py"
    src.write_text(
        "import dataclasses\n\n@dataclasses.dataclass\nclass A:\n    x: float = 1.0\n\n    def f(self):\n"
        "        return 2 * self.x\n\n    def g(self):\n        return 3\n\n\ndef h(y):\n    return y + 1\n\n"
        "B = A  # an alias keeps working\n"
    )
    leave_out(src, "A.g", "g is the exercise")
    leave_out(src, "h", "h is the exercise")
    ns = {}
    exec(src.read_text(), ns)
    assert ns["A"]().f() == 2.0 and ns["B"] is ns["A"]
    for call in (lambda: ns["A"]().g(), lambda: ns["h"](1)):
        with pytest.raises(NotImplementedError, match="is the exercise"):
            call()
    leave_out(src, "A", "A is the exercise")
    ns = {}
    exec(src.read_text(), ns)
    with pytest.raises(NotImplementedError, match="A is the exercise"):
        ns["A"]()
    with pytest.raises(NotImplementedError):  # object.__new__ finds no method either
        object.__new__(ns["A"]).f()
    with pytest.raises(ValueError, match="no definition of C"):
        leave_out(src, "C", "")


@pytest.mark.slow  # imports every module of the package, once per lecture: 5-10 s each
@pytest.mark.parametrize("lecture", LECTURES)
def test_each_lectures_edition_leaves_its_exercises_out_and_still_imports(lecture, tmp_path):
    """The edition of a lecture: no course in it, the definition of every part its exercises ask
    for absent from the source, and every module of the package imports from it."""
    edition = build_edition(tmp_path / "edition", left_out(lecture))
    assert not (edition / "contactfem" / "lab" / "course").exists()
    for spec in left_out(lecture):
        module, _, qualname = spec.partition(":")
        rel = os.path.join(*module.split(".")) + ".py"
        original = _definition(PACKAGE.parent / rel, qualname)
        text = (edition / rel).read_text()
        assert original not in text and "left out while your notebook is graded" in text, spec
    modules = sorted(
        ".".join(p.relative_to(edition).with_suffix("").parts)
        for p in (edition / "contactfem").rglob("*.py")
        if p.stem not in ("__init__", "__main__", "cli")
    )
    code = (
        f"import sys, importlib; sys.path.insert(0, {str(edition)!r})\nfor m in {modules!r}: importlib.import_module(m)"
    )
    out = subprocess.run([sys.executable, "-I", "-c", code], capture_output=True, text=True, timeout=300)
    assert out.returncode == 0, out.stderr[-2000:]


def test_the_snapshot_copies_regular_files_and_refuses_the_rest(tmp_path):
    from contactfem.lab.course.snapshot import take

    subs = tmp_path / "subs"
    (subs / "week1").mkdir(parents=True)
    (subs / "a.ipynb").write_text('{"cells": []}')
    (subs / "week1" / "b.ipynb").write_text('{"cells": [1]}')
    os.utime(subs / "a.ipynb", (1.5e9, 1.5e9))
    (subs / "big.ipynb").write_bytes(b"x" * 2048)
    os.symlink(subs / "a.ipynb", subs / "link.ipynb")
    os.mkfifo(subs / "fifo.ipynb")
    got = take(subs, tmp_path / "staging", max_bytes=1024)
    assert sorted(got) == ["a.ipynb", "big.ipynb", "fifo.ipynb", "link.ipynb", "week1/b.ipynb"]
    assert got["a.ipynb"].copy.read_text() == '{"cells": []}' and got["a.ipynb"].mtime == 1.5e9
    assert got["week1/b.ipynb"].sha256 == __import__("hashlib").sha256(b'{"cells": [1]}').hexdigest()
    assert "symbolic link" in got["link.ipynb"].refused and got["link.ipynb"].copy is None
    assert "not a regular file" in got["fifo.ipynb"].refused
    assert "larger than" in got["big.ipynb"].refused
    assert oct((tmp_path / "staging").stat().st_mode & 0o777) == "0o700"


def test_only_plain_data_crosses_the_border():
    """The sandbox's replies decode to numbers, text, arrays of numbers and containers of them;
    anything else (an object array, an unknown kind, a malformed value) is refused."""
    from contactfem.lab.course.serve import decode, encode

    def refuse(d):
        raise ValueError("not plain")

    value = {"a": [1, 2.5, "x", None, True], "b": (np.arange(3.0), np.float64(2.0)), "c": Ellipsis}
    back = decode(json.loads(json.dumps(encode(value, refuse))), refuse)
    assert back["a"] == value["a"] and back["c"] is Ellipsis and back["b"][1] == 2.0
    np.testing.assert_array_equal(back["b"][0], value["b"][0])
    with pytest.raises(ValueError):
        encode(np.array([object()]), refuse)
    import base64
    import io
    import pickle

    buf = io.BytesIO()
    np.save(buf, np.array([{"x": 1}], dtype=object), allow_pickle=True)
    for bad in (
        {"t": "nd", "v": base64.b64encode(buf.getvalue()).decode()},  # a pickled array
        {"t": "pickle", "v": base64.b64encode(pickle.dumps(1)).decode()},
        {"t": "py", "v": [1]},
        [1, 2],
    ):
        with pytest.raises(ValueError):
            decode(bad, refuse)


def test_outputs_replace_a_planted_link_instead_of_following_it(tmp_path):
    from contactfem.io.outputs import own_dir, write_atomic

    victim = tmp_path / "victim.ipynb"
    victim.write_text("the classmate's notebook")
    folder = own_dir(tmp_path / "feedback", "--feedback")
    os.symlink(victim, folder / "u05.md")
    write_atomic(folder / "u05.md", "feedback")
    assert victim.read_text() == "the classmate's notebook"
    assert not (folder / "u05.md").is_symlink() and (folder / "u05.md").read_text() == "feedback"
    os.symlink(tmp_path, tmp_path / "elsewhere")
    with pytest.raises(ValueError, match="--review .*symbolic link"):
        own_dir(tmp_path / "elsewhere", "--review")
