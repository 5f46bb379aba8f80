"""The equation index: for each numbered equation of Wriggers, Vu Van & Stein (1990),
the function, class or module of contactfem that implements it.

    from contactfem.equations import INDEX, where
    where(17)                      # 'contactfem.contact.kinematics.segment_geometry'

    python -m contactfem.equations             # the index as a markdown table (for the README)

``INDEX`` maps an equation number to ``Equation(number, what, where)``; ``NOT_MAPPED``
lists the remaining numbers 1-50 with the reason they have no entry of their own
(intermediate steps of a derivation, or implemented inside a function whose docstring
does not cite them). tests/test_equation_index.py keeps this honest in both directions:
every entry imports and its docstring cites the equation, and every equation cited in a
docstring of contactfem.contact and contactfem.laws has an entry.
"""

import ast
import importlib
import re
from dataclasses import dataclass
from pathlib import Path


@dataclass(frozen=True)
class Equation:
    number: int
    what: str
    where: str  # dotted name: a module, or a function/class/method in a module


_K = "contactfem.contact.kinematics"
_E = "contactfem.contact.element.contact_element"
_R = "contactfem.laws.return_map.return_map"
_P = "contactfem.plots.laws"
_REF = "contactfem.contact.reference"  # one pair at a time, in the paper's symbols (not used by the solver)

INDEX = {
    e.number: e
    for e in [
        Equation(3, "true contact area A_r/A = (|t_N|/(A H))^n", f"{_P}.true_contact_area_ratio"),
        Equation(4, "normal interface law |t_N| = c_N |g_N|^m", "contactfem.laws.normal.PowerLaw"),
        Equation(5, "stick law t_T = c_T g_T^e", "contactfem.laws.friction"),
        Equation(6, "junction shear strength |t_T| = tau_0 A_r + beta |t_N|", f"{_P}.junction_shear_strength"),
        Equation(7, "friction coefficient mu = tau_0 / p_r + beta", f"{_P}.friction_coefficient"),
        Equation(8, "eq (3) in eq (6): |t_T| = tau_0 A (|t_N|/(A H))^n + beta |t_N|", f"{_P}.parabolic_alpha"),
        Equation(9, "the same as alpha |t_N|^n + beta |t_N|", f"{_P}.parabolic_alpha"),
        Equation(
            10,
            "parabolic slip surface f = -alpha |t_N|^n - beta |t_N| + ||t_T|| <= 0",
            "contactfem.laws.friction.ParabolicSlip",
        ),
        Equation(11, "Coulomb f = -mu |t_N| + ||t_T|| <= 0 (n = 1)", "contactfem.laws.friction.Coulomb"),
        Equation(13, "associated slip rule dg^s = lambda df/dt (rejected: uplift)", f"{_P}.associated_direction"),
        Equation(14, "non-associated slip rule dg_T^s = lambda t_T/||t_T||, dg_N^s = 0", "contactfem.laws.friction"),
        Equation(17, "gap g_N = (x_s - x_1) . n", f"{_K}.segment_geometry"),
        Equation(18, "l = ||x_2 - x_1||, t = (x_2 - x_1)/l, n = e_3 x t", f"{_K}.segment_geometry"),
        Equation(19, "natural coordinate alpha = (x_s - x_1) . t / l", f"{_K}.segment_geometry"),
        Equation(20, "slip increment Delta g_T = (alpha - alpha_bar) l_bar", "contactfem.contact.masters"),
        Equation(24, "element unknowns v_c = (v_s, v_1, v_2)", _K),
        Equation(25, "N_s, N_0", f"{_K}.segment_vectors"),
        Equation(26, "T_s, T_0", f"{_K}.segment_vectors"),
        Equation(27, "delta g_N = N_s . dv, delta g_T = (l_bar/l)(T_s + g_N/l N_0) . dv", f"{_K}.segment_variations"),
        Equation(28, "contact residual R_c = t_N N_s + t_T (l_bar/l)(T_s + g_N/l N_0)", _E),
        Equation(29, "G = M a + R(v) + R_c - P = 0", "contactfem.solver.system.System.evaluate"),
        Equation(30, "linearisation of t_N delta g_N (its result is eq 33)", f"{_REF}.segment_element"),
        Equation(31, "second variation of the gap (first part)", f"{_K}.segment_variations"),
        Equation(32, "second variation of the gap", f"{_K}.segment_variations"),
        Equation(33, "normal tangent K_N", _E),
        Equation(34, "linearisation of t_T delta g_T while sticking (its result is eq 39)", f"{_REF}.segment_element"),
        Equation(35, "Delta g_T delta g_T = dv^T (l_bar/l)^2 A Dv", f"{_REF}.pair_variations"),
        Equation(36, "A = (T_s + g_N/l N_0)(T_s + g_N/l N_0)^T", f"{_REF}.pair_variations"),
        Equation(37, "second variation of alpha, Delta delta alpha = dv^T B/l^2 Dv", f"{_K}.segment_variations"),
        Equation(38, "matrix B", f"{_K}.segment_variations"),
        Equation(39, "stick tangent K_T = c_T (l_bar/l)^2 A + t_T l_bar/l^2 B", _E),
        Equation(40, "slip function f(t_N, t_T) of the plane case", _R),
        Equation(
            41, "slip rule of the plane case, Delta g_N^s = 0, Delta g_T^s = lambda sign(t_T)", f"{_REF}.return_map"
        ),
        Equation(42, "elastic predictor t_T^tr = t_T_bar + c_T Delta g_T", _R),
        Equation(43, "return t_T = t_T^tr - c_T lambda sign(t_T^tr)", _R),
        Equation(44, "lambda from f(t_N, t_T) = 0 (closed form or local Newton)", _R),
        Equation(45, "inelastic slip increment Delta g_T^s = lambda sign(t_T)", f"{_REF}.return_map"),
        Equation(46, "linearisation of t_T delta g_T while slipping (its result is eq 49)", f"{_REF}.segment_element"),
        Equation(47, "consistent modulus c_T^s = dt_T/dg_T", _R),
        Equation(48, "consistent moduli c_T^s, c_N^s = dt_T/dg_N", _R),
        Equation(49, "slip tangent K_T = c_T^s (l_bar/l)^2 A + t_T l_bar/l^2 B + c_N^s C", _E),
        Equation(50, "non-symmetric coupling C = (l_bar/l)(T_s + g_N/l N_0) N_s^T", _E),
    ]
}

NOT_MAPPED = {
    1: "continuum gap g_N = (x^2 - x^1) . n^2; its discrete form is eq (17)",
    2: "the contact condition g_N >= 0 (enforced here by the interface law, not as a constraint)",
    12: "split dg_T = dg_T^e + dg_T^s: done inside return_map (t_T = c_T g_T^e), not cited there",
    15: "equation of motion without contact; the code has eq (29)",
    16: "definitions of R, P, M of eq (15) (the bodies' internal, the loads' assemble, the lumped mass)",
    21: "virtual work of the contact forces; its matrix form is eq (28)",
    22: "variation of the gap; its matrix form is eq (27)",
    23: "variation of the slip; its matrix form is eq (27)",
}

# -- citations: "eq (17)", "Eq 17", "eqs (17)-(19)", "eqs 33, 39, 49", "eqs 5 and 10", "eqn (8)" --------

_CITE = re.compile(r"\b[Ee]q(?:n|s|ns)?\.?\s*(\(?\d+\)?(?:\s*(?:-|–|,|and|to)\s*\(?\d+\)?)*)")
_TOKEN = re.compile(r"\d+|-|–|to|,|and")


def parse_citations(text):
    """Equation numbers cited in `text`. Returns (explicit, covered): explicit are the
    numbers written out (single numbers, list items and range end points), covered also
    contains every number inside a range such as "eqs (25)-(50)"."""
    explicit, covered = set(), set()
    for m in _CITE.finditer(text or ""):
        last, in_range = None, False
        for tok in _TOKEN.findall(m.group(1)):
            if tok.isdigit():
                k = int(tok)
                explicit.add(k)
                covered.add(k)
                if in_range and last is not None:
                    covered.update(range(min(last, k), max(last, k) + 1))
                last, in_range = k, False
            else:
                in_range = tok in ("-", "–", "to")
    return explicit, covered


def resolve(dotted):
    """Import `dotted` (a module, or an attribute path inside a module) and return the object."""
    parts = dotted.split(".")
    for i in range(len(parts), 0, -1):
        try:
            obj = importlib.import_module(".".join(parts[:i]))
        except ModuleNotFoundError:
            continue
        for name in parts[i:]:
            obj = getattr(obj, name)
        return obj
    raise ImportError(f"cannot import {dotted!r}")


def docstrings(folder):
    """(file, line, docstring) of every module, class and function in the .py files under folder."""
    out = []
    for path in sorted(Path(folder).rglob("*.py")):
        tree = ast.parse(path.read_text())
        for node in ast.walk(tree):
            if isinstance(node, (ast.Module, ast.ClassDef, ast.FunctionDef, ast.AsyncFunctionDef)):
                doc = ast.get_docstring(node)
                if doc:
                    out.append((str(path), getattr(node, "lineno", 1), doc))
    return out


def where(number):
    """Dotted name implementing paper equation `number`; KeyError with the reason if none."""
    if number in INDEX:
        return INDEX[number].where
    raise KeyError(f"eq ({number}): " + NOT_MAPPED.get(number, "not in the paper's range 1-50"))


def markdown_table():
    """The index as a markdown table, every equation 1-50 in order ('|' inside cells escaped)."""

    def cell(text):
        return text.replace("|", "\\|")

    lines = ["| eq | what | implemented by |", "|---|---|---|"]
    for k in range(1, 51):
        if k in INDEX:
            lines.append(f"| ({k}) | {cell(INDEX[k].what)} | `{INDEX[k].where}` |")
        elif k in NOT_MAPPED:
            lines.append(f"| ({k}) | {cell(NOT_MAPPED[k])} | - |")
    return "\n".join(lines)


if __name__ == "__main__":
    print(markdown_table())
