"""No import circle between the modules of contactfem, with the imports inside functions included.

A module depends on another when it imports it anywhere in its text: at the top or inside a
function (a lazy import delays a dependency, it does not remove it), or as a lazy module
(``lazy.module("contactfem.x")``). ``from package import name``
depends on the submodule ``package.name`` where there is one, else on the package (a name its
``__init__`` defines). A circle of such dependencies is a failure, named module by module.
"""

import ast
from pathlib import Path

PACKAGE = Path(__file__).resolve().parents[1] / "contactfem"


def module_names(root=PACKAGE):
    """Dotted name -> file of every module of the package (a package by its ``__init__``)."""
    names = {}
    for path in sorted(root.rglob("*.py")):
        if "__pycache__" in path.parts:
            continue
        parts = [root.name, *path.relative_to(root).with_suffix("").parts]
        if parts[-1] == "__init__":
            parts = parts[:-1]
        names[".".join(parts)] = path
    return names


def imports(name, path, known):
    """The modules of ``known`` that the module ``name`` (file ``path``) imports, anywhere in it."""
    package = name.split(".") if path.name == "__init__.py" else name.split(".")[:-1]
    found = set()
    for node in ast.walk(ast.parse(path.read_text(), filename=str(path))):
        if isinstance(node, ast.Import):
            found.update(a.name for a in node.names)
        elif isinstance(node, ast.ImportFrom):
            base = package[: len(package) - node.level + 1] if node.level else []
            mod = ".".join(base + ([node.module] if node.module else []))
            for alias in node.names:
                sub = f"{mod}.{alias.name}"
                found.add(sub if sub in known else mod)
        elif lazy_name(node):
            found.add(lazy_name(node))
    return {m for m in found if m in known and m != name}


def lazy_name(node):
    """The module of a lazy import, ``lazy.module("contactfem.x.y")`` (contactfem/lazy.py), else None."""
    if isinstance(node, ast.Call) and isinstance(node.func, ast.Attribute) and node.func.attr == "module":
        if node.args and isinstance(node.args[0], ast.Constant) and isinstance(node.args[0].value, str):
            return node.args[0].value
    return None


def graph(root=PACKAGE):
    known = module_names(root)
    return {name: imports(name, path, known) for name, path in known.items()}


def cycles(edges):
    """The strongly connected components of more than one module (each a circle or several),
    each sorted; Tarjan's algorithm, without recursion."""
    index, low, stack, on_stack, found = {}, {}, [], set(), []
    for start in sorted(edges):
        if start in index:
            continue
        work = [(start, iter(sorted(edges[start])))]
        index[start] = low[start] = len(index)
        stack.append(start)
        on_stack.add(start)
        while work:
            node, children = work[-1]
            child = next(children, None)
            if child is not None:
                if child not in index:
                    index[child] = low[child] = len(index)
                    stack.append(child)
                    on_stack.add(child)
                    work.append((child, iter(sorted(edges[child]))))
                elif child in on_stack:
                    low[node] = min(low[node], index[child])
                continue
            work.pop()
            if work:
                low[work[-1][0]] = min(low[work[-1][0]], low[node])
            if low[node] == index[node]:
                component = []
                while True:
                    member = stack.pop()
                    on_stack.discard(member)
                    component.append(member)
                    if member == node:
                        break
                if len(component) > 1:
                    found.append(sorted(component))
    return found


def test_the_cycle_finder_finds_a_circle_through_a_lazy_import(tmp_path):
    pkg = tmp_path / "pkg"
    (pkg / "sub").mkdir(parents=True)
    (pkg / "__init__.py").write_text("")
    (pkg / "a.py").write_text("from .sub import b\n")
    (pkg / "sub" / "__init__.py").write_text("from . import b\n")  # a submodule: no edge to the package
    (pkg / "sub" / "b.py").write_text("def f():\n    from ..a import x\n")
    (pkg / "c.py").write_text("import pkg.a\n")
    assert cycles(graph(pkg)) == [["pkg.a", "pkg.sub.b"]]
    (pkg / "sub" / "b.py").write_text("def f():\n    from .. import a as _\n    from ... import json\n")
    assert cycles(graph(pkg)) == [["pkg.a", "pkg.sub.b"]]  # `from .. import a`: the module a
    (pkg / "sub" / "b.py").write_text("def f():\n    import json\n")
    assert cycles(graph(pkg)) == []


def test_no_import_circle():
    edges = graph()
    assert len(edges) > 100 and any(edges.values())
    found = cycles(edges)
    assert not found, "import circles (imports inside functions included): " + "; ".join(" <-> ".join(c) for c in found)
