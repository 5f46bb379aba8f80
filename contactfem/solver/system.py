"""The System: bodies, contacts, loads and Dirichlet conditions in one global vector.

The System implements the static part of the paper's equation of motion (eq 29),

    G(u, t) = R(u) + R_c(u) - P(u, t),

with R the internal forces of the bodies, R_c the contact residual (eq 28) and P
the external loads, together with its tangent K = dG/du = K_int + K_c - dP/du.
The inertia term M a of eq 29 is added by the time steppers (newmark.py). M is the
bodies' lumped (diagonal) mass, a vector, unless a body asks for its consistent mass
(``body.mass_matrix == "consistent"``): then M is one sparse matrix, the consistent
blocks of those bodies and the diagonal of the others (``mass``, ``mass_times``).

Bodies are placed one after another in the global vector: body b owns the global
dofs ``offset(b) + local``. A contact may own unknowns too (``contact.unknowns`` of
them: the Lagrange multipliers of contact/lagrange.py; 0 for a penalty contact): they
follow the bodies' dofs, contact c owning ``offset(c) + range(c.unknowns)``. The System
keeps these offsets (``offsets``, by identity) and hands them to the contacts and loads it
evaluates (contact/placement.py); nothing is written on a body or a contact. They have
no mass (no velocity, no acceleration: the steppers carry them over as values, newmark.py),
no Dirichlet condition, and the contact that owns them writes their rows of G and K; so
the System, Newton and the time loop treat them like any other unknown, and one
evaluation per Newton iteration still gives everything.

K is a dense numpy array for small systems and a scipy CSC matrix on a fixed sparsity
pattern above, solved by LAPACK's banded LU where the pattern is a narrow band after
renumbering, else by SuperLU (``System.linear_algebra``, chosen automatically: assembly.py).

What a run remembers from step to step is a value too, a ``SystemState``: the contacts'
histories, the bodies' internal variables and the loads' states. ``start(u0, t0)`` gives the
first, ``evaluate(u, t, ..., state=state)`` reads it, ``commit(evaluation, u, t, dt)`` returns
the next; bodies, contacts and loads hold their configuration only, so marching the same
System twice, or from any record's state, gives the same records.

One evaluation of the System at a trial u is a value, ``Evaluation(G, K, contacts, P, state)``:
the contacts' states (contact/state.py) travel with it, and the SystemState it was evaluated
with, so the converged one is what the time loop commits, records and reports
(solver/march.py); nothing evaluates it again.
"""

from dataclasses import dataclass
from types import MappingProxyType
from typing import NamedTuple

import numpy as np

from .. import lazy
from .assembly import TangentAssembler
from .instrument import timed
from .rounding import current

sp = lazy.module("scipy.sparse")


@dataclass(frozen=True, eq=False)
class SystemState:
    """What a run carries from one converged step to the next (``System.start``, ``commit``):

    contacts  one history per contact (contact/state.py: ContactHistory, ...)
    bodies    one per body: its internal variables (a viscoplastic beam's plastic strains;
              None for an elastic body)
    loads     one per load: its state (the gas pressure's value; None for most loads)
    slope     what the last step hands to the next step's error estimate (estimate.Slope;
              None at a march's start and for a static stepper)
    """

    contacts: tuple = ()
    bodies: tuple = ()
    loads: tuple = ()
    slope: object = None


class Evaluation(NamedTuple):
    """The System at one trial u: residual G, tangent K, the contacts' states, the loads P and
    the SystemState it was evaluated with (a tuple, so ``G, K = evaluation[:2]`` reads as before);
    a time stepper's effective evaluation also carries the inertia M a it added to G (Newton's
    force scale reads it) and the round-off of that inertia (``roundoff``: eps times its largest
    operand, in force units; Newton's test adds it to atol: solver/newton.py)."""

    G: np.ndarray
    K: object
    contacts: tuple = ()
    P: np.ndarray | None = None
    state: SystemState | None = None
    inertia: np.ndarray | None = None
    roundoff: float = 0.0


class Dirichlet:
    """Prescribed values of some dofs of one body.

    ``value`` is a number, an array of ``len(local_dofs)`` numbers, or a callable
    ``t -> number or array`` for time-dependent (moving) supports.
    """

    def __init__(self, body, local_dofs, value=0.0):
        self.body = body
        self.local_dofs = np.atleast_1d(np.asarray(local_dofs, dtype=int)).ravel()
        self.value = value

    def values(self, t):
        """The prescribed values at time t, one per constrained dof."""
        value = self.value(t) if callable(self.value) else self.value
        value = np.asarray(value, dtype=float)
        if value.ndim > 0 and value.size != self.local_dofs.size:
            raise ValueError(
                f"Dirichlet value must be a scalar or have {self.local_dofs.size} "
                f"entries (one per dof), got {value.size}"
            )
        return np.broadcast_to(value.ravel() if value.ndim else value, self.local_dofs.shape)


def _triplets(rows, cols, vals):
    """COO triplets as three flat arrays (accepts lists and empty inputs); flat arrays of the
    right type are passed on as they are (the same objects: the assembly knows index arrays
    it has seen before by their identity)."""
    rows, cols, vals = np.asarray(rows, dtype=int), np.asarray(cols, dtype=int), np.asarray(vals, dtype=float)
    if rows.ndim != 1 or cols.ndim != 1 or vals.ndim != 1:
        rows, cols, vals = rows.ravel(), cols.ravel(), vals.ravel()
    return rows, cols, vals


def as_array(K):
    """A tangent as a dense numpy array, whether the System assembled it dense or sparse."""
    return K.toarray() if hasattr(K, "toarray") else np.asarray(K)


class System:
    """Bodies, contacts, loads and Dirichlet conditions assembled into one problem.

    Parameters
    ----------
    bodies   : list of bodies (the interface of contactfem.bodies)
    bodies   : list of bodies (contactfem.bodies.interfaces.Body)
    contacts : list of contacts (contactfem.contact.interfaces.Contact): ``evaluate(u, t, dt, u0,
               history=h, offsets=...)`` gives a state, ``state.scatter(ndof) -> (R_c, rows, cols,
               vals)``; ``offsets`` (the System's, by identity) say where each body's dofs and
               each contact's own ``unknowns`` (if any) start (contact/placement.py)
    loads    : list of loads (contactfem.bodies.interfaces.Load), ``assemble(u, t, state,
               offsets=...) -> (P, rows, cols, vals)``
    fixed    : list of Dirichlet conditions
    linear_algebra : "auto" (default: dense up to assembly.DENSE_MAX unknowns; above, banded where
               the band LU is cheap, else sparse), "dense", "sparse" or "banded"
    instrument : None, or a solver.instrument.Timings that times the parts of every evaluation
               and of the Newton solves of the steppers (the bench's split of an iteration)
    plan     : the assembly plan of K (assembly.TangentAssembler for ``ndof`` unknowns and this
               ``linear_algebra``), an explicit cache: K's sparsity pattern, made at the first
               assembly and grown where a contact couples new dofs, and the factorisation's plan of
               it; default: one made here. ``start`` leaves it as it is, so a second run of the
               System starts from the pattern the first one grew (the same records, bit for bit,
               unless a pattern grew and reorders the factorisation; give a new plan to rule it out)

    Attributes: ``ndof``, ``fixed_dofs`` and ``free_dofs`` (global, sorted), ``contact_dofs``
    (the unknowns the contacts own, after the bodies' ``body_ndof`` dofs; module docstring),
    ``linear_algebra`` ("dense", "sparse" or "banded"; "banded+sparse" if the choice changed
    as the contact pattern grew) and ``ordering`` (of the factorisation). How often it was evaluated
    travels in the results (NewtonResult.evaluations, Record.evaluations), not on the System.
    """

    def __init__(self, bodies, contacts=(), loads=(), fixed=(), linear_algebra="auto", instrument=None, plan=None):
        self.bodies = list(bodies)
        self.contacts = list(contacts)
        self.loads = list(loads)
        self.fixed = list(fixed)
        if not self.bodies:
            raise ValueError("bodies must contain at least one body")

        self._place()
        self.contact_dofs = np.arange(self.body_ndof, self.ndof)  # massless, never prescribed

        for d in self.fixed:
            if d.body not in self.bodies:
                raise ValueError(f"Dirichlet condition on body {d.body.name!r}, which is not in bodies")
            if np.any(d.local_dofs < 0) or np.any(d.local_dofs >= d.body.ndof):
                raise ValueError(f"Dirichlet local_dofs of body {d.body.name!r} must be in [0, {d.body.ndof - 1}]")
        self.fixed_dofs = np.unique(
            np.concatenate([self.global_dofs(d.body, d.local_dofs) for d in self.fixed] + [np.zeros(0, int)])
        )
        self.free_dofs = np.setdiff1d(np.arange(self.ndof), self.fixed_dofs)
        self._mass = None
        self._cM = (None, None)  # (c, c M) of the last lumped effective tangent
        if linear_algebra == "auto":  # a solver.rounding condition may name another factorisation
            linear_algebra = current().linear_algebra or "auto"
        self.plan = TangentAssembler(self.ndof, linear_algebra, self.free_dofs) if plan is None else plan
        self.instrument = instrument

    def _place(self):
        """The System's own offsets (nothing is written on the objects): id(body or contact) -> where
        its unknowns start; a contact's own unknowns follow the bodies'."""
        offsets, offset = {}, 0
        for body in self.bodies:
            offsets[id(body)] = offset
            offset += body.ndof
        self.body_ndof = offset
        for contact in self.contacts:
            offsets[id(contact)] = offset
            offset += int(contact.unknowns)
        self.offsets = MappingProxyType(offsets)
        self.ndof = offset

    def __getstate__(self):
        """A copy (pickle, deepcopy: a grader hands a System to a notebook's process) places its
        own objects anew: the offsets are keyed by identity."""
        state = dict(self.__dict__)
        state.pop("offsets")
        return state

    def __setstate__(self, state):
        self.__dict__.update(state)
        self._place()

    @property
    def linear_algebra(self):
        """How K is held and solved: dense, sparse or banded (assembly.py)."""
        return self.plan.describe()[0]

    @property
    def ordering(self):
        """The ordering of the factorisation (e.g. the band's kl and ku)."""
        return self.plan.describe()[1]

    @property
    def band(self):
        """(kl, ku), the half-bandwidths below and above the diagonal of K renumbered by reverse
        Cuthill-McKee, of the last K solved banded; None when no K was."""
        plan = self.plan.banded_plan  # of the last K solved banded
        return (plan.kl, plan.ku) if plan is not None else None

    def offset(self, obj):
        """Where the unknowns of ``obj`` (one of the System's bodies or contacts) start in the
        global vector."""
        return self.offsets[id(obj)]

    def global_dofs(self, body, local):
        """Global numbers of a body's local dofs."""
        return self.offset(body) + np.asarray(local, dtype=int)

    def local(self, body, u):
        """The body's own part (a view) of a global vector."""
        off = self.offset(body)
        return u[off : off + body.ndof]

    # -- Dirichlet conditions -------------------------------------------------

    def prescribed(self, t):
        """Prescribed values at time t, aligned with ``self.fixed_dofs``.
        If several conditions constrain the same dof, the last one wins."""
        full = np.zeros(self.ndof)
        for d in self.fixed:
            full[self.global_dofs(d.body, d.local_dofs)] = d.values(t)
        return full[self.fixed_dofs]

    def apply_dirichlet(self, u, t):
        """A copy of u with the prescribed values at time t written in."""
        u = np.array(u, dtype=float)
        if self.fixed:
            u[self.fixed_dofs] = self.prescribed(t)
        return u

    # -- assembly ---------------------------------------------------------------

    @property
    def mass_matrix(self):
        """ "consistent" if a body's mass is (``body.mass_matrix``), else "lumped"."""
        return "consistent" if any(b.mass_matrix == "consistent" for b in self.bodies) else "lumped"

    def mass(self):
        """The global mass M, 0 at the contacts' own unknowns: its diagonal (ndof,) when every
        body's mass is lumped, else a CSR matrix (ndof, ndof) (``mass_matrix``). Use
        ``mass_times`` for M x, whichever it is."""
        if self._mass is None:
            if self.mass_matrix == "lumped":
                self._mass = np.concatenate(
                    [np.asarray(b.mass(), dtype=float) for b in self.bodies] + [np.zeros(self.ndof - self.body_ndof)]
                )
            else:
                blocks = [
                    b.mass(consistent=True) if b.mass_matrix == "consistent" else sp.diags(b.mass())
                    for b in self.bodies
                ]
                if self.ndof > self.body_ndof:
                    blocks.append(sp.csr_matrix((self.ndof - self.body_ndof,) * 2))
                self._mass = sp.block_diag(blocks, format="csr")
                coo = self._mass.tocoo()
                self._mass_coo = (coo.row, coo.col, coo.data)  # the same arrays at every assembly
        return self._mass

    def mass_times(self, x):
        """M x (M lumped or consistent)."""
        M = self.mass()
        return M * x if isinstance(M, np.ndarray) else M @ x

    def lumped_mass(self):
        """The lumped mass (ndof,): M's row sums (M itself when lumped), the mass of each dof
        that the centre of mass and the momentum sum over."""
        M = self.mass()
        return M if isinstance(M, np.ndarray) else np.asarray(M.sum(axis=1)).ravel()

    def external_force(self, u, t, state):
        """P(u, t), the sum of all loads (ndof,), with the loads' states of the SystemState."""
        P = np.zeros(self.ndof)
        for load, ls in zip(self.loads, state.loads):
            P += load.assemble(u, t, ls, offsets=self.offsets)[0]
        return P

    def _check_state(self, state):
        if not isinstance(state, SystemState):
            raise ValueError(f"state must be a SystemState (System.start or commit), got {type(state).__name__}")
        if (len(state.contacts), len(state.bodies), len(state.loads)) != (
            len(self.contacts),
            len(self.bodies),
            len(self.loads),
        ):
            raise ValueError(
                f"state has {len(state.contacts)} contacts, {len(state.bodies)} bodies and "
                f"{len(state.loads)} loads; the System {len(self.contacts)}, {len(self.bodies)} and "
                f"{len(self.loads)}"
            )
        return state

    def evaluate(self, u, t, dt=None, u0=None, mass_coefficient=0.0, phases=None, *, state):
        """The System at u, time t, at the end of a step of dt from u0 with the committed
        ``state`` (a SystemState): an Evaluation with G = R(u) + R_c(u) - P(u, t) (static part
        of eq 29), K = dG/du, the contacts' states and ``state``.

        With ``mass_coefficient`` c > 0, K + c M is returned instead (M lumped or consistent:
        ``mass``): the effective tangent of an implicit time stepper (Newmark: c = 1 / (beta dt^2)). ``phases``:
        one staggered-algorithm phase per contact (contact/tangents.py), or None. K is a dense
        array or a CSC matrix (``self.linear_algebra``; banded: a CSC matrix that carries its band
        plan, ``K.band_plan``); all contributions arrive as COO triplets and are summed into it
        once (duplicates add up).
        """
        u = np.asarray(u, dtype=float)
        if u.shape != (self.ndof,):
            raise ValueError(f"u must have shape ({self.ndof},), got {u.shape}")
        self._check_state(state)
        G = np.zeros(self.ndof)
        blocks = []  # (rows, cols, vals, offset, key)

        with timed(self.instrument, "bulk"):
            for body, bs in zip(self.bodies, state.bodies):  # block diagonal: internal forces
                off = self.offsets[id(body)]
                R, rows, cols, vals = body.internal_coo(u[off : off + body.ndof], dt, bs)
                G[off : off + body.ndof] += R
                blocks.append((rows, cols, vals, off, body))

        states = []
        with timed(self.instrument, "contact"):
            for i, (contact, h) in enumerate(zip(self.contacts, state.contacts)):  # eq 28 and its tangent
                cs = contact.evaluate(
                    u, t, dt, u0, None if phases is None else phases[i], history=h, offsets=self.offsets
                )
                Rc, r, c, v = cs.scatter(self.ndof)
                G += Rc
                if len(v):  # (a contact in flight adds no tangent entries)
                    blocks.append((*_triplets(r, c, v), 0, contact))  # (r, c: the same arrays while
                states.append(cs)  # its contact set stays)

        with timed(self.instrument, "assembly"):
            P = np.zeros(self.ndof)
            for load, ls in zip(self.loads, state.loads):  # loads enter with a minus sign
                Pl, r, c, v = load.assemble(u, t, ls, offsets=self.offsets)
                P += Pl
                if len(v):  # (a dead load has no tangent)
                    r, c, v = _triplets(r, c, v)
                    blocks.append((r, c, -v, 0, None))
            if self.loads:
                G -= P
            diagonal = None
            if mass_coefficient:
                M = self.mass()
                if isinstance(M, np.ndarray):  # c M, made once for each c (a step's)
                    if self._cM[0] != mass_coefficient:
                        self._cM = (mass_coefficient, mass_coefficient * M)
                    diagonal = self._cM[1]
                else:  # consistent: one more constant block, c M
                    r, c, v = self._mass_coo
                    blocks.append((r, c, mass_coefficient * v, 0, "mass"))
            K = self.plan.assemble(blocks, diagonal)
        return Evaluation(G, K, tuple(states), P, state)

    def residual_tangent(self, u, t, mass_coefficient=0.0, dt=None, u0=None, *, state):
        """(G, K) of ``evaluate`` (for a quick look; the solver keeps the whole Evaluation)."""
        return self.evaluate(u, t, dt, u0, mass_coefficient, state=state)[:2]

    # -- the state carried from step to step ----------------------------------------------
    def start(self, u, t=0.0):
        """The SystemState at the initial state (u, t): each contact's, body's and load's own
        ``start``. The System is left as it is."""
        u = np.asarray(u, dtype=float)
        return SystemState(
            contacts=tuple(c.start(u, t, offsets=self.offsets) for c in self.contacts),
            bodies=tuple(b.start(self.local(b, u).copy()) for b in self.bodies),
            loads=tuple(ld.start(u, t, offsets=self.offsets) for ld in self.loads),
        )

    def commit(self, evaluation, u, t, dt=None):
        """The SystemState after a converged step ending at (u, t) (``evaluation`` the converged
        one, evaluated with the step's committed state): the bodies' internal variables and the
        loads' states updated at u, the contacts' histories from their converged states."""
        state = self._check_state(evaluation.state)
        return SystemState(
            contacts=tuple(c.commit(cs) for c, cs in zip(self.contacts, evaluation.contacts)),
            bodies=tuple(b.commit(self.local(b, u).copy(), dt, bs) for b, bs in zip(self.bodies, state.bodies)),
            loads=tuple(ld.commit(u, t, ls, offsets=self.offsets) for ld, ls in zip(self.loads, state.loads)),
        )

    # -- energies ------------------------------------------------------------------
    def energies(self, u, v, evaluation, dt=None, state=None):
        """Kinetic (1/2 v.M v), strain and interface energy of a converged state, as a dict
        of floats; the interface energy is read from the evaluation's contact states, the strain
        energy with the bodies' internal variables ``state`` (default: the evaluation's)."""
        state = evaluation.state if state is None else state
        return {
            "kinetic": 0.5 * float(np.dot(v, self.mass_times(v))),
            "strain": float(sum(b.strain_energy(self.local(b, u), dt, bs) for b, bs in zip(self.bodies, state.bodies))),
            "contact": float(sum(st.energy for st in evaluation.contacts)),
        }
