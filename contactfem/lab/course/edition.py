"""The students' edition of the library: what a submission of a lecture is graded with.

A copy of the package in which the parts of the method that the lecture's exercises ask for
(``LIBRARY`` of the lecture's checks: "module:Name" or "module:Name.method") are left out of
the source: each is replaced by a stub of the same name whose every call raises
NotImplementedError saying so. Nothing else of the course is in it: no check, no grader, no
solution. A submission's sandbox sees this copy in place of the package, so no import, exec of
a module's source, or ``object.__new__`` of a class can reach what the exercise asks for.

Beside the package, the edition holds the code the sandbox runs (``contactfem_serve.py``, a
copy of :mod:`.serve`) and the files the lectures read (``examples/``).
"""

import ast
import shutil
from pathlib import Path

PACKAGE = Path(__file__).resolve().parents[2]  # contactfem/
LEFT_OUT = ("lab/course",)  # the course: its checks, the grader, the build


def stub_message(spec, exercise):
    name = spec.replace(":", ".")
    return (
        f"the library's own {name} is left out while your notebook is graded: "
        f"exercise {exercise} asks you to implement it yourself"
    )


def _stub(node, message, indent):
    pad = " " * indent
    raise_line = f"{pad}    raise NotImplementedError({message!r})"
    if isinstance(node, ast.ClassDef):
        methods = [n.name for n in node.body if isinstance(n, (ast.FunctionDef, ast.AsyncFunctionDef))]
        lines = [f"{pad}class {node.name}:", f"{pad}    def __init__(self, *args, **kwargs):", "    " + raise_line]
        for m in dict.fromkeys(methods):
            if m != "__init__":
                lines += [f"{pad}    def {m}(self, *args, **kwargs):", "    " + raise_line]
        return lines
    return [f"{pad}def {node.name}(*args, **kwargs):", raise_line]


def _find(body, name):
    for node in body:
        if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef, ast.ClassDef)) and node.name == name:
            return node
    return None


def leave_out(path, qualname, message):
    """Replace the definition `qualname` ("Name" or "Class.method") of the module at `path` by
    a stub raising NotImplementedError(message); ValueError if it is not defined there."""
    source = path.read_text()
    body = ast.parse(source).body
    node = None
    for part in qualname.split("."):
        node = _find(body, part)
        if node is None:
            raise ValueError(f"{path.name}: no definition of {qualname} to leave out")
        body = node.body
    lines = source.split("\n")
    start = min([node.lineno] + [d.lineno for d in node.decorator_list]) - 1
    lines[start : node.end_lineno] = _stub(node, message, node.col_offset)
    path.write_text("\n".join(lines))


def build_edition(out, left_out, examples=None):
    """Write the students' edition into the new folder `out`: the package without the course,
    with the definitions of `left_out` ({"module:Name": exercise}) replaced by stubs, the
    sandbox's server, and a copy of `examples` (a folder). Returns `out`."""
    out = Path(out)
    skip = shutil.ignore_patterns("__pycache__", "*.pyc")
    shutil.copytree(PACKAGE, out / "contactfem", ignore=skip)
    for rel in LEFT_OUT:
        shutil.rmtree(out / "contactfem" / rel)
    for spec, exercise in left_out.items():
        module, _, qualname = spec.partition(":")
        path = out / Path(*module.split("."))
        path = path / "__init__.py" if path.is_dir() else path.with_suffix(".py")
        leave_out(path, qualname, stub_message(spec, exercise))
    shutil.copy2(Path(__file__).with_name("serve.py"), out / "contactfem_serve.py")
    (out / "examples").mkdir()
    if examples is not None and Path(examples).is_dir():
        for f in sorted(Path(examples).iterdir()):
            if f.is_file() and not f.is_symlink():
                shutil.copy2(f, out / "examples" / f.name)
    for p in [out, *out.rglob("*")]:  # readable by the sandbox's user, writable by nobody there
        p.chmod(0o755 if p.is_dir() else 0o644)
    return out
