"""The time loop (the algorithm of paper Sec. 4.3) as a generator of records.

    for rec in march(Newmark(system), Steps(dt=0.1, n_steps=200), t0, u0, v0):
        rec.t, rec.u, rec.v, rec.contacts, rec.energy, rec.iterations

``march`` yields one ``Record`` per accepted step, the initial state first (k = 0). A
record is a value: the converged state of the step (u, v, a), the System's converged
evaluation (residual and the contacts' states, contact/state.py), the energies, the Newton
iterations and the SystemState the next step starts from (``state``: the contacts'
histories, the bodies' internal variables, the loads' states; solver/system.py). The loop
commits the converged evaluation into that state before it yields the record, so a scene
reads the step from the record, never by evaluating the contact again.

Nothing of a run is kept on the System or its parts: marching the same model twice gives
the same records, bit for bit, and ``resume(stepper, schedule, record)`` continues a run from
any of its records (a saved one too: contactfem.io.runs.save_record) exactly as the
uninterrupted run went on.

The schedule (schedule.py) decides the step sizes: fixed steps, or an adaptive rule of
the last record, with the halving of a failed step; the scene decides when to stop, by
leaving the loop. ``integrate`` collects a march into a ``History`` of arrays.
"""

from dataclasses import dataclass, field, replace

import numpy as np

from .newton import NewtonError
from .rounding import perturbed
from .schedule import Steps
from .system import SystemState


@dataclass(frozen=True, eq=False)
class Record:
    """One accepted step (k >= 1) or the initial state (k = 0).

    k, t, dt        step number, time at its end, its size (0 at k = 0)
    u, v, a         the converged displacement, velocity and acceleration
    evaluation      the System's converged Evaluation (G, K, contact states, loads)
    energy          kinetic, strain, contact (stored in the interfaces), dissipation and
                    external_work (both summed since the start)
    result          the stepper's NewtonResult (None at k = 0)
    cuts, failures  halvings before the step converged, the first line of each failure
    state           the SystemState after the step (solver/system.py): what the next step
                    starts from

    Two records are equal (``==``) when their values are, bit for bit: what save_record keeps of
    them and a run goes on from (k, t, dt, u, v, a, the energies, cuts and failures, the residual
    G with its reactions and the loads P, Newton's iterations and residuals, the step's error
    estimate, the SystemState). Their tangents and contact states, which follow from those, are
    not compared: a record read back by load_record equals the one saved.
    """

    k: int
    t: float
    dt: float
    u: np.ndarray
    v: np.ndarray
    a: np.ndarray
    evaluation: object
    energy: dict
    result: object = None
    cuts: int = 0
    failures: tuple = ()
    state: object = None

    def __eq__(self, other):
        if not isinstance(other, Record):
            return NotImplemented
        return self is other or same_value(_kept(self), _kept(other))

    def __hash__(self):  # equal records have equal k, t and dt
        return hash((self.k, self.t, self.dt))

    @property
    def contacts(self):
        """The converged contact states (contact/state.py), one per contact of the System."""
        return self.evaluation.contacts

    @property
    def iterations(self):
        return self.result.iterations if self.result is not None else 0

    @property
    def residuals(self):
        return list(self.result.residuals) if self.result is not None else []


def _kept(rec):
    """What a record is as a value (Record.__eq__): what save_record keeps of it."""
    result, ev = rec.result, rec.evaluation
    return (
        (rec.k, rec.t, rec.dt, rec.u, rec.v, rec.a, rec.energy, rec.cuts, tuple(rec.failures)),
        (ev.G if result is None else result.G, getattr(ev, "P", None), rec.iterations, rec.residuals),
        (getattr(result, "local_error", None), getattr(result, "error_share", None), rec.state),
    )


def same_value(a, b):
    """Whether a and b hold the same values, bit for bit (NaN equal to NaN): numbers, text, arrays,
    sparse matrices, and tuples, lists, dicts and dataclasses of them, compared element by element."""
    import dataclasses
    import numbers

    from scipy import sparse

    if a is b:
        return True
    if isinstance(a, (numbers.Number, np.generic)) and isinstance(b, (numbers.Number, np.generic)):
        return bool(a == b) or (a != a and b != b)  # NaN: the same value
    if isinstance(a, np.ndarray) or isinstance(b, np.ndarray):
        a, b = np.asarray(a), np.asarray(b)
        return a.shape == b.shape and np.array_equal(a, b, equal_nan=a.dtype.kind in "fc" and b.dtype.kind in "fc")
    if sparse.issparse(a) or sparse.issparse(b):
        return sparse.issparse(a) and sparse.issparse(b) and a.shape == b.shape and (a != b).nnz == 0
    if isinstance(a, dict) and isinstance(b, dict):
        return a.keys() == b.keys() and all(same_value(a[k], b[k]) for k in a)
    if isinstance(a, (tuple, list)) and isinstance(b, (tuple, list)):
        return len(a) == len(b) and all(same_value(x, y) for x, y in zip(a, b))
    if dataclasses.is_dataclass(a) and not isinstance(a, type):
        fields = [f.name for f in dataclasses.fields(a)]
        return type(a) is type(b) and all(same_value(getattr(a, f), getattr(b, f)) for f in fields)
    return type(a) is type(b) and bool(a == b)


def march(stepper, schedule, t0, u0, v0=None, *, a0=None, label=None, state=None):
    """Step from (t0, u0, v0) as the schedule says; yield the initial Record, then one per
    accepted step. A step whose Newton fails is retried with the size ``schedule.cut`` gives,
    until it gives None: then the NewtonError is raised with the last record as ``record``.
    ``a0``: the initial acceleration (default: M a0 = -G(u0), eq 29; 0 for a static stepper).
    ``label(k, t1, dt)``: the text naming a step in an error (default: step k, t, dt).
    ``state``: the SystemState to start from (default: ``system.start(u0, t0)``; e.g. the
    contacts' histories a previous stage ended with)."""
    rec = initial(stepper, schedule, t0, u0, v0, a0, state)
    yield rec
    yield from resume(stepper, schedule, rec, label=label)


def resume(stepper, schedule, record, *, label=None):
    """The records after ``record`` (not itself), stepped as ``march`` steps: from a record of
    a run (its u, v, a, energies, reactions and SystemState), the rest of that run exactly."""
    rec = record
    if not isinstance(rec.state, SystemState):
        raise ValueError(f"record {rec.k} has no SystemState to resume from (state = {type(rec.state).__name__})")
    ndof = stepper.system.ndof
    if np.shape(rec.u) != (ndof,):
        raise ValueError(
            f"record {rec.k} holds {np.size(rec.u)} unknowns, the model {ndof}: a record resumes only a model "
            "of the run that made it (the same mesh and bodies)"
        )
    try:
        while (dt := schedule.next_dt(rec)) is not None:
            cuts, failures = 0, []
            while True:
                name = (
                    label(rec.k + 1, rec.t + dt, dt)
                    if label
                    else f"step {rec.k + 1}, t = {rec.t + dt:.6g}, dt = {dt:.3g}"
                )
                try:
                    trial = stepper.step(rec.t, rec.u, rec.v, rec.a, dt, name, state=rec.state)
                    break
                except NewtonError as err:
                    failures.append(str(err).splitlines()[0][:200] if str(err) else "Newton failed")
                    smaller = schedule.cut(dt, cuts)
                    if smaller is None:
                        err.record = rec
                        raise
                    dt, cuts = smaller, cuts + 1
            rec = accept(stepper.system, rec, schedule.end_time(rec.t, dt), dt, trial, cuts, failures)
            yield rec
    except KeyboardInterrupt as interrupt:  # Ctrl-C: say where (the innermost loop names it)
        if not hasattr(interrupt, "step"):
            interrupt.t, interrupt.step, interrupt.n_steps = rec.t, rec.k + 1, schedule.n_steps
        raise


def initial(stepper, schedule, t0, u0, v0=None, a0=None, state=None):
    """The Record of the initial state: the SystemState started at u0 (or ``state``), one
    evaluation (with the schedule's first dt, for rate-dependent bodies and laws), a0 from eq 29."""
    s = stepper.system
    dt = schedule.dt
    v = np.zeros(s.ndof) if v0 is None else np.array(v0, dtype=float)
    u, v = perturbed(s, s.apply_dirichlet(u0, t0), v)  # as it is, outside solver.rounding's conditions
    state = s.start(u, t0) if state is None else state
    ev = s.evaluate(u, t0, dt, state=state)
    if a0 is not None:
        a = np.array(a0, dtype=float)
    else:
        a = acceleration(s, ev.G) if stepper.dynamic else np.zeros(s.ndof)
    energy = dict(s.energies(u, v, ev, dt), dissipation=0.0, external_work=0.0)
    return Record(k=0, t=t0, dt=0.0, u=u, v=v, a=a, evaluation=ev, energy=energy, state=state)


def accept(system, rec, t1, dt, trial, cuts=0, failures=()):
    """Commit a converged step and make its Record: the next SystemState from the converged
    evaluation; the energies are those of the converged state, the dissipation that of its
    contact states, the external work the trapezoidal rule 1/2 (F_n + F_n+1) . (u_n+1 - u_n)
    over the loads P and the support reactions (the prescribed-dof part of G)."""
    u1, v1, a1, result = trial
    ev = result.evaluation
    fixed = system.fixed_dofs
    du = u1 - rec.u
    P0, F0 = rec.evaluation.P, rec.evaluation.G[fixed] if rec.result is None else rec.result.G[fixed]
    P1, F1 = ev.P, result.G[fixed]
    work = rec.energy["external_work"] + 0.5 * (P0 + P1) @ du + 0.5 * (F0 + F1) @ du[fixed]
    dissipation = rec.energy["dissipation"] + sum(st.dissipation for st in ev.contacts)
    state = system.commit(ev, u1, t1, dt)
    if getattr(result, "carry", None) is not None:  # what the stepper hands to its next step
        state = replace(state, stepper=result.carry)
    energy = dict(system.energies(u1, v1, ev, dt, state), dissipation=dissipation, external_work=float(work))
    return Record(
        k=rec.k + 1,
        t=t1,
        dt=dt,
        u=u1,
        v=v1,
        a=a1,
        evaluation=ev,
        energy=energy,
        result=result,
        cuts=cuts,
        failures=tuple(failures),
        state=state,
    )


def acceleration(system, G):
    """a from M a = -G (= P - R) on the free dofs with mass (a diagonal solve for a lumped M, a
    sparse one for a consistent M); 0 on prescribed and massless dofs."""
    M = system.mass()
    a = np.zeros(system.ndof)
    if isinstance(M, np.ndarray):
        free = system.free_dofs[M[system.free_dofs] > 0]
        a[free] = -G[free] / M[free]
        return a
    from scipy.sparse.linalg import spsolve

    free = system.free_dofs[M.diagonal()[system.free_dofs] > 0]
    a[free] = spsolve(M[free][:, free].tocsc(), -G[free])
    return a


def watch(records, progress, t0, t_end, name):
    """The records, passed through a progress display: ``progress(t0, t_end, name)`` makes a
    callback (e.g. contactfem.io.ProgressBar) called with each record's (t, u, v, a) and
    closed at the end. None: the records unchanged."""
    if progress is None:
        yield from records
        return
    bar = progress(t0, t_end, name)
    try:
        for rec in records:
            bar(rec.t, rec.u, rec.v, rec.a)
            yield rec
    finally:
        close = getattr(bar, "close", None)
        if close is not None:
            close()


@dataclass
class History:
    """A march collected into arrays (``integrate``, ``History.of(records)``): ``t``, ``dt``,
    ``iterations``, ``cuts``, the energies (``kinetic``, ``strain``, ``contact``, ``dissipation``,
    ``external_work``) and ``residuals`` hold one entry per record, entry 0 the initial state;
    ``u``, ``v``, ``a`` and ``result`` are the last record's (the state the run ended in: read
    another step's from ``records[k].u``); ``failures`` lists every step's; ``records`` keeps
    the records themselves."""

    t: np.ndarray | None = None
    dt: np.ndarray | None = None
    iterations: np.ndarray | None = None
    cuts: np.ndarray | None = None
    kinetic: np.ndarray | None = None
    strain: np.ndarray | None = None
    contact: np.ndarray | None = None
    dissipation: np.ndarray | None = None
    external_work: np.ndarray | None = None
    residuals: list = field(default_factory=list)
    failures: list = field(default_factory=list)
    records: list = field(default_factory=list)
    u: np.ndarray | None = None
    v: np.ndarray | None = None
    a: np.ndarray | None = None
    result: object = None

    @classmethod
    def of(cls, records):
        records = list(records)
        h = cls(records=records)
        h.t = np.array([r.t for r in records])
        h.dt = np.array([r.dt for r in records])
        h.iterations = np.array([r.iterations for r in records])
        h.cuts = np.array([r.cuts for r in records])
        for key in ("kinetic", "strain", "contact", "dissipation", "external_work"):
            setattr(h, key, np.array([r.energy[key] for r in records]))
        h.residuals = [r.residuals for r in records]
        h.failures = [f for r in records for f in r.failures]
        last = records[-1]
        h.u, h.v, h.a, h.result = last.u, last.v, last.a, last.result
        return h


def integrate(
    stepper,
    t0,
    u0,
    v0=None,
    n_steps=None,
    t_end=None,
    *,
    dt,
    cutback=False,
    max_cuts=4,
    min_dt=None,
    a0=None,
    progress=None,
    label=None,
    name=None,
):
    """March over n_steps steps of dt, or up to t_end, and collect the records into a History
    (a convenience over ``march`` with a fixed schedule, ``Steps``). With ``cutback``, a step
    whose Newton fails is halved (up to ``max_cuts`` times, never below ``min_dt``) and the
    rest of the step is covered with the smaller size. ``progress``: see ``watch``.
    A NewtonError that ends the run carries the History so far as ``error.partial``."""
    schedule = Steps(dt, n_steps=n_steps, t_end=t_end, t0=t0, max_cuts=max_cuts if cutback else 0, min_dt=min_dt)
    records = []
    try:
        for rec in watch(
            march(stepper, schedule, t0, u0, v0, a0=a0, label=label),
            progress,
            t0,
            schedule.t_end,
            name or type(stepper).__name__,
        ):
            records.append(rec)
    except NewtonError as err:
        err.partial = History.of(records) if records else None
        raise
    return History.of(records)
