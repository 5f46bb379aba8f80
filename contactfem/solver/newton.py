"""Full Newton iteration within a step (paper Sec. 4.3).

Solves G(u) = 0 on the free dofs, where ``fun(u) -> (G, K, ...)`` returns the full
residual vector and its tangent K = dG/du (a dense numpy array, or a scipy CSC matrix
that may carry a band plan for LAPACK's band LU: solve_free), possibly followed by more
(a System's Evaluation carries the contacts' states): what ``fun`` returned at the
converged iterate is the result's ``evaluation``, so nothing needs to evaluate it again.
The prescribed dofs keep the values they have in the initial guess.

Linear solver: dense K by LAPACK's LU with partial pivoting (``numpy.linalg.solve``),
a banded K (a CSC matrix carrying ``band_plan``, assembly.py: the paper's rings and small
meshes) by LAPACK's banded LU with partial pivoting after a reverse Cuthill-McKee
renumbering (dgbsv, banded.py), any other sparse K by ``scipy.sparse.linalg.splu``
(SuperLU, ordering ORDERING). The contact tangent with friction is non-symmetric (paper
eq 49-50), so no symmetric solver applies; splu rather than spsolve because splu *raises*
on an exactly singular matrix, while spsolve only warns and returns NaNs (numpy.linalg.solve
and the banded solve raise as well).

Convergence test, in the units of the problem (as Abaqus/Standard's, with tighter defaults):

    max |G_k|        <= atol + OPERANDS roundoff_k + rtol * F_k      (the residual, against the step's forces)
    max |du_(k-1)|   <= ctol * max |u_k - u_start|        (the last correction, against the increment)

over the free dofs. F_k (``force_scale``) is the largest nodal force of the iterate among the
loads P, the support reactions (G at the prescribed dofs), the contact forces and the inertia
M a (what the evaluation carries of them), never the first residual: a first guess with a
deep penetration (a huge spurious contact force) does not loosen the test. ``u_start`` is the
state at the step's start (``start``; default the initial guess). The correction test is
waived at k = 0, when the residual is below atol or NEGLIGIBLE (1e-3) times its tolerance (the
iterate's own error, K^-1 G, is then negligible whatever the last correction was), and when the
correction is at the round-off of u (1e3 machine epsilon of max |u_k|); there the residual cannot fall further, and
ROUNDOFF_RTOL F is accepted instead of rtol F (a very stiff penalty: one round-off of a gap is a
force; ``residual_ratio`` says what was reached: max |G| / (F + floor / ROUNDOFF_RTOL), the floor
atol plus the round-off of G's own terms). atol (force units) is a floor for a step in which
nothing carries a force. ``residuals`` keeps the Euclidean
norms ||G_k|| for reports.

The round-off of a time step's residual. A stepper's inertia is c M times a difference of
displacements, c = 1 / (beta dt^2) (Newmark; 2 / dt^2 the midpoint rule). Written in the total
displacement u, that difference carries u's round-off, eps |u|, and G a round-off c M eps |u| that
grows as 1 / dt^2: the sloping impact's ring (a node's mass 0.039, |u| = 0.05 at first touch) at
dt = 3e-6, halved to 4.7e-8 by the failed tries, has 3e-4 there, a hundred times the contact force
of the step (3e-6): Newton's corrections fall below u's round-off and the residual stays at the
force scale. So the steppers iterate on the step's increment d = u+ - u (``base``: u), whose
round-off is eps |d|, eps |v| dt: the inertia's becomes c M eps |d| ~ M eps |v| / (beta dt), which
the stepper reports (``Evaluation.roundoff``: eps times the inertia's largest operand) and the test
adds to atol (OPERANDS of it: a few ulps). Below that no iterate can go: a contact force that
changes the step's increment by less than its own round-off (F beta dt^2 / M < eps |d|) is a
step converged to round-off, and the test accepts it. The static terms keep their own round-off,
K eps |u|, which the correction test above sees (corrections below u's round-off: ``stalled``).

Defaults (RTOL = 1e-8, CTOL = 1e-6), measured on the fast presets of the scenes (their headline
results against a run with 1e-10 / 1e-8, and the residual evaluations): Abaqus' 5e-3 / 1e-2 saves
10-25 % of the evaluations and moves the headlines by 14-40 % (rolling ring, sloping impact,
funnel: a stick/slip or contact state decided by an unconverged iterate is kept); 1e-6 / 1e-4
still moves them by 2-6 %; 1e-8 / 1e-6 gives the 1e-10 / 1e-8 results exactly at the same cost
(Newton's quadratic rate: one iteration takes the residual from ~1e-5 F below 1e-10 F). The
correction test is the binding one in the dynamic scenes.

Failures raise NewtonError: maxit reached, NaN/inf residual or correction, singular
tangent, or a FloatingPointError raised by fun (the bodies' InvertedElementError and
the contact's ReturnMapError derive from it), so a driver can cut the step back.
"""

import math
from dataclasses import dataclass, field

import numpy as np

from .. import lazy
from .instrument import timed

sp = lazy.module("scipy.sparse")
linalg = lazy.module("scipy.sparse.linalg")

# Column ordering of SuperLU. The tangents here have a symmetric sparsity pattern (the
# contact element couples the same dofs both ways), for which the minimum degree
# ordering of A^T + A fills in less than scipy's default COLAMD: 1.6-2x faster
# factorisations from 1e3 to 1e5 unknowns (BENCHMARKS.md, `contactfem bench`).
ORDERING = "MMD_AT_PLUS_A"
DENSE_ORDERING = "natural (LAPACK LU, partial pivoting)"  # what a dense K gets


def solve_free(K, b, free, all_free):
    """du_f from K_ff du_f = b on the free dofs; K dense (LAPACK), banded (LAPACK's band
    LU, when K's ``band_plan`` is made for K's pattern and these free dofs) or sparse
    (SuperLU). Raises RuntimeError on an exactly singular K_ff."""
    if isinstance(K, np.ndarray):
        Kff = K if all_free else K[np.ix_(free, free)]
        try:
            return np.linalg.solve(Kff, b)
        except np.linalg.LinAlgError as err:  # "Singular matrix"
            raise RuntimeError(f"Factor is exactly singular ({err})") from None
    plan = getattr(K, "band_plan", None) or getattr(K, "dissection_plan", None)
    if plan is not None and plan.fits(K, None if all_free else free):
        return plan.solve(K.data, b)
    if all_free:
        Kff = K if K.format == "csc" else sp.csc_matrix(K)
    else:
        Kff = sp.csr_matrix(K)[free][:, free].tocsc()
    return linalg.splu(Kff, permc_spec=ORDERING).solve(b)


class NewtonError(RuntimeError):
    """Newton did not converge. ``history`` holds the (finite) residual norms of
    all iterations done, ``label`` names the step/time (the message states the cause
    only: print ``history`` to see the residuals); ``evaluations``: the calls of the residual it
    made before it failed."""

    def __init__(self, message, history, label="", evaluations=0):
        super().__init__(message)
        self.history = list(history)
        self.label = label
        self.evaluations = evaluations


@dataclass
class NewtonResult:
    u: np.ndarray  # the converged solution
    residuals: list = field(default_factory=list)  # ||G|| of every iterate, first = initial guess
    iterations: int = 0  # number of linear solves
    G: np.ndarray | None = None  # full residual at u (its fixed-dof part = reactions)
    evaluation: object = None  # what fun returned at u (G, K, contact states, ...)
    evaluations: int = 0  # calls of fun (residuals + line-search trials)
    force_scale: float = 0.0  # F at u (module docstring)
    residual_ratio: float = 0.0  # max |G_f| / (F + floor / ROUNDOFF_RTOL) at u, floor = atol + the round-off of G's
    # terms: at most ROUNDOFF_RTOL when the loosest test passes; the force scale where F >> floor / ROUNDOFF_RTOL
    correction_ratio: float = 0.0  # the last correction / the step's increment (0 at k = 0)
    ratios: list = field(default_factory=list)  # max |G_f| / F of every iterate


# The default tolerances of the convergence test (module docstring; BENCHMARKS.md argues them)
RTOL = 1e-8  # the largest residual over the step's force scale
CTOL = 1e-6  # the largest correction over the step's largest increment
ROUNDOFF = 1e3 * np.finfo(float).eps  # a correction below this times max |u| is at u's round-off
ROUNDOFF_RTOL = 1e-6  # accepted when the corrections are at u's round-off: Newton can do no better
OPERANDS = 4.0  # the round-off of G's own terms (Evaluation.roundoff, eps times its largest operand) is a few
# ulps: one for the unknown's quantisation, one for the subtraction d - d_pred, one for the product with c M
NEGLIGIBLE = 1e-3  # a residual this far below its tolerance: the iterate's own error (K^-1 G) is negligible
# whatever the last correction was; one more iteration could only flip a contact
# node sitting at g_N = 0 (and cycle: a disc on a polyline wall did)


def force_scale(evaluation, free):
    """F, the step's force scale at one evaluation: the largest nodal force among the loads P,
    the support reactions (the residual G at the dofs not in ``free``), the contact forces (each
    contact state's element forces R) and the inertia M a (``evaluation.inertia``, which a time
    stepper's effective evaluation carries); each read only where the evaluation has it."""
    G = evaluation[0]
    F = 0.0
    fixed = np.ones(len(G), bool)
    fixed[free] = False
    if fixed.any():
        F = max(F, float(np.max(np.abs(G[fixed]))))
    for part in (getattr(evaluation, "P", None), getattr(evaluation, "inertia", None)):
        if part is not None and len(part):
            F = max(F, float(np.max(np.abs(part))))
    for state in getattr(evaluation, "contacts", ()) or ():
        R = getattr(state, "R", None)
        if R is not None and np.size(R):
            F = max(F, float(np.max(np.abs(R))))
    return F


def newton(
    fun,
    u0,
    free,
    atol=1e-12,
    rtol=RTOL,
    maxit=25,
    label="",
    line_search=0,
    instrument=None,
    ctol=CTOL,
    start=None,
    base=None,
):
    """Full Newton method: K_ff du_f = -G_f, u_f += du_f, until converged.

    Parameters
    ----------
    fun   : u -> (G, K, ...), full residual (n,) and tangent (n, n), dense or sparse
    u0    : (n,) initial guess, prescribed dofs already set
    free  : indices (or boolean mask) of the unknown dofs
    atol, rtol, ctol : convergence test max |G_k| <= atol + rtol F_k and max |du| <= ctol max |u_k - start|
            (module docstring): atol in force units, rtol against the step's force scale F_k, ctol
            against the step's increment
    start : the state at the step's start (default u0), for the increment
    base  : None, or the state the unknowns are increments over (a time step's start): fun then takes the
            increment x = u - base, the correction test measures x itself (``start`` unused), and a
            correction is at round-off when it is below the round-off of base + x (module docstring)
    maxit : maximal number of linear solves
    label : names the step/time in error messages
    line_search : 0 (default: full Newton steps, the paper's method) or the number of
            step halvings allowed when a full step does not lower ||G_f|| (backtracking:
            accept u + s du at the first s = 1, 1/2, 1/4, ... with ||G_f|| < (1 - 1e-4 s) ||G_f,k||,
            else the smallest step). It helps where stick/slip switching makes full steps cycle;
            near the solution full steps are accepted, so the quadratic rate is kept.
    instrument : None or a solver.instrument.Timings: times the linear solves ("solve") and the
            whole of newton ("newton"), counts the solves

    Returns a NewtonResult; raises NewtonError (never returns NaN).
    """
    with timed(instrument, "newton"):
        result = _newton(fun, u0, free, atol, rtol, maxit, label, line_search, instrument, ctol, start, base)
    if instrument is not None:
        instrument.solves += result.iterations
    return result


def _newton(fun, u0, free, atol, rtol, maxit, label, line_search, instrument, ctol=CTOL, start=None, base=None):
    if maxit < 0:
        raise ValueError(f"maxit must be >= 0, got {maxit}")
    if not (atol >= 0 and rtol >= 0 and ctol >= 0):
        raise ValueError(f"atol, rtol and ctol must be >= 0, got atol={atol}, rtol={rtol}, ctol={ctol}")
    u = np.array(u0, dtype=float)
    free = np.asarray(free)
    if free.dtype == bool:
        free = np.flatnonzero(free)
    where = f" ({label})" if label else ""
    all_free = len(free) == len(u) and bool((free == np.arange(len(u))).all())
    if int(line_search) != line_search or line_search < 0:
        raise ValueError(f"parameter line_search = {line_search} is out of range: allowed integers [0, inf)")
    history, largest, ratios = [], [], []  # ||G_f||, max |G_f| and max |G_f| / F of every iterate
    calls = 0
    if base is not None:  # u is an increment over base: it starts from 0, and u's round-off is that of base + u
        start, base = np.zeros(len(u)), np.asarray(base, dtype=float)[free]
    u_start = (u if start is None else np.asarray(start, dtype=float))[free]
    du, tol, F = None, atol, 0.0

    def evaluate(v, k):
        nonlocal calls
        calls += 1
        try:
            return fun(v)
        except FloatingPointError as err:  # inverted element, failed return map
            raise NewtonError(
                f"Newton: {type(err).__name__} at iteration {k}{where}: {err}", history, label, calls
            ) from err

    evaluated = None  # fun's value at u from the line search
    for k in range(maxit + 1):
        out = evaluated if evaluated is not None else evaluate(u, k)
        evaluated = None
        G = out[0]
        G_f = G if all_free else G[free]
        r = math.sqrt(G_f.dot(G_f))  # ||G_f|| (as np.linalg.norm computes it)
        if not math.isfinite(r):
            raise NewtonError(f"Newton: non-finite residual at iteration {k}{where}", history, label, calls)
        history.append(r)
        r_max = float(np.max(np.abs(G_f), initial=0.0))
        largest.append(r_max)
        F = force_scale(out, free)
        floor = atol + OPERANDS * getattr(out, "roundoff", 0.0)  # atol and the round-off of G's own terms
        tol = floor + rtol * F
        ratios.append(r_max / F if F > 0 else (0.0 if r_max == 0 else math.inf))
        c_ratio = _correction(du, u[free], u_start)
        stalled = _at_roundoff(du, u[free] if base is None else base + u[free])  # the corrections no longer move u
        if r_max <= tol or (stalled and r_max <= floor + max(rtol, ROUNDOFF_RTOL) * F):
            if k == 0 or r_max <= floor or r_max <= NEGLIGIBLE * tol or c_ratio <= ctol or stalled:
                return NewtonResult(
                    u=u,
                    residuals=history,
                    iterations=k,
                    G=G,
                    evaluation=out,
                    evaluations=calls,
                    force_scale=F,
                    residual_ratio=r_max / (F + floor / ROUNDOFF_RTOL) if r_max > 0 else 0.0,
                    correction_ratio=c_ratio if k else 0.0,
                    ratios=ratios,
                )
        if k == maxit:
            break
        try:
            with timed(instrument, "solve"):
                du = solve_free(out[1], -G_f, free, all_free)
        except RuntimeError as err:  # "Factor is exactly singular"
            raise NewtonError(
                f"Newton: singular tangent at iteration {k}{where}: {err}", history, label, calls
            ) from err
        # every value finite: du.du is, unless a value is not (or the sum overflows: then each is checked)
        if not (math.isfinite(du.dot(du)) or np.isfinite(du).all()):
            raise NewtonError(f"Newton: non-finite correction at iteration {k}{where}", history, label, calls)
        if line_search:
            step = 1.0
            for _ in range(int(line_search) + 1):
                trial = u.copy()
                trial[free] += step * du
                evaluated = evaluate(trial, k + 1)
                r_trial = float(np.linalg.norm(evaluated[0][free]))
                if np.isfinite(r_trial) and r_trial < (1.0 - 1e-4 * step) * r:
                    break
                step /= 2
            u = trial
        elif all_free:
            u = u + du  # a new iterate: the last evaluation keeps its own u
        else:
            u = u.copy()
            u[free] += du

    share = f" ({largest[-1] / F:.1e} of the step's force scale {F:.3g})" if F > 0 else ""
    raise NewtonError(
        f"Newton: no convergence in {maxit} iterations{where}: largest residual {largest[-1]:.3g}"
        f"{share} against the tolerance {tol:.3g}{_stall(largest, tol)}",
        history,
        label,
        calls,
    )


def _correction(du, u_f, u_start):
    """The last correction's largest entry over the step's largest increment (inf for a
    correction in a step that has not moved)."""
    if du is None:
        return 0.0
    c = float(np.max(np.abs(du), initial=0.0))
    incr = float(np.max(np.abs(u_f - u_start), initial=0.0))
    return c / incr if incr > 0 else (0.0 if c == 0 else math.inf)


def _at_roundoff(du, u_f):
    """Whether the last correction is at the round-off of u itself."""
    if du is None:
        return False
    return float(np.max(np.abs(du), initial=0.0)) <= ROUNDOFF * float(np.max(np.abs(u_f), initial=0.0))


def _stall(history, tol):
    """': the residual stalls at ...' when the last iterations neither fall nor grow (within a
    factor 3, 5 or more of them) below 1e-3 of the first residual: Newton sits on the round-off of
    the residual (its corrections no longer move u), above the tolerance; else ''."""
    k = len(history)
    while k > 0 and max(history[k - 1 :]) <= 3.0 * min(history[k - 1 :]):
        k -= 1
    tail = history[k:]
    if len(tail) < 5 or max(tail) > 1e-3 * history[0]:
        return ""
    return (
        f"; it stalls near {float(np.median(tail)):.1e} from iteration {k} on: the round-off of this "
        "system's residual (a penalty this stiff makes one round-off of a gap a force above the tolerance)"
    )
