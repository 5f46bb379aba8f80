"""The equation index (contactfem/equations.py) cannot drift from the code:
every entry imports and its docstring cites its equation; every equation cited in a
docstring of the contact core and the laws has an entry."""

import inspect
from pathlib import Path

import pytest

import contactfem
from contactfem import equations as E

PKG = Path(contactfem.__file__).parent
SCANNED = [PKG / "contact", PKG / "laws", PKG / "plots" / "laws.py"]


def _doc(obj):
    return obj.__doc__ if inspect.ismodule(obj) else inspect.getdoc(obj)


def test_every_entry_imports_and_cites_its_equation():
    """One check over the whole index (not one test item an equation): every entry resolves to
    an object of the code, whose docstring cites the equation."""
    wrong = []
    for number, entry in sorted(E.INDEX.items()):
        _, covered = E.parse_citations(_doc(E.resolve(entry.where)))
        if number not in covered:
            wrong.append(
                f"{entry.where} implements eq ({number}) according to the index, but its docstring "
                f"cites only {sorted(covered)}"
            )
    assert not wrong, "\n".join(wrong)


def _scanned_docstrings():
    out = []
    for path in SCANNED:
        if path.is_dir():
            out += E.docstrings(path)
        else:
            out += [d for d in E.docstrings(path.parent) if d[0] == str(path)]
    return out


def test_every_cited_equation_is_indexed():
    docs = _scanned_docstrings()
    assert len(docs) > 20, "the scan found almost no docstrings: wrong folder?"
    missing = []
    for path, line, doc in docs:
        explicit, _ = E.parse_citations(doc)
        missing += [f"eq ({k}) cited in {Path(path).relative_to(PKG)}:{line}" for k in sorted(explicit - set(E.INDEX))]
    assert not missing, "cited in a docstring but not in contactfem.equations.INDEX:\n" + "\n".join(missing)


def test_index_covers_1_to_50_once():
    mapped, reasons = set(E.INDEX), set(E.NOT_MAPPED)
    assert not mapped & reasons, f"both mapped and 'not mapped': {sorted(mapped & reasons)}"
    assert mapped | reasons == set(range(1, 51)), (
        f"equations without an entry: {sorted(set(range(1, 51)) - mapped - reasons)}"
    )
    assert all(e.number == k for k, e in E.INDEX.items())


@pytest.mark.parametrize(
    "text, explicit, covered",
    [
        ("Eq (4): |t_N| = c_N", {4}, {4}),
        ("Eqs (17)-(19): length l", {17, 19}, {17, 18, 19}),
        ("(eqs 33, 39, 49, 50)", {33, 39, 49, 50}, {33, 39, 49, 50}),
        ("the stick law (eqs 5 and 10)", {5, 10}, {5, 10}),
        ("Eq (42), the elastic predictor; eqn (8) and eqs 40-48)", {42, 8, 40, 48}, {42, 8} | set(range(40, 49))),
        ("no equation here: equal, sequence 3", set(), set()),
    ],
)
def test_parse_citations(text, explicit, covered):
    assert E.parse_citations(text) == (explicit, covered)


def test_where_and_table():
    assert E.where(17) == "contactfem.contact.kinematics.segment_geometry"
    with pytest.raises(KeyError, match="eq \\(21\\)"):
        E.where(21)
    table = E.markdown_table()
    assert table.count("\n") == 1 + len(E.INDEX) + len(E.NOT_MAPPED)
    for line in table.splitlines()[2:]:
        assert line.count("|") - line.count("\\|") == 4, f"broken markdown row: {line}"
