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
leaving the loop. The loop estimates each dynamic step's local error (estimate.py; the record's
``error``), which a schedule at a tolerance sizes the next step from and may reject a step by
(``resume``: and its flights). ``integrate`` collects a march into a ``History`` of arrays.
"""

import dataclasses
import numbers
from dataclasses import dataclass, field, replace

import numpy as np

from .. import lazy
from .estimate import Slope, StepError, error_vector, momentum_norm, norm
from .newton import NewtonError
from .rounding import perturbed
from .schedule import StepRejected, Steps
from .system import SystemState

sparse = lazy.module("scipy.sparse")
linalg = lazy.module("scipy.sparse.linalg")


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
    error           the step's StepError (estimate.py: its local error, and the share of a
                    tolerance it may have); None at k = 0 and for a static stepper
    stage           which of its model's stages made it (0 for a model of one stage)

    Two records are equal (``==``) when their values are, bit for bit: what save_record keeps of
    them and a run goes on from (k, t, dt, u, v, a, the energies, cuts and failures, the residual
    G with its reactions and the loads P, Newton's iterations and residuals, the step's error
    estimate and stage, the SystemState). Their tangents and contact states, which follow from those, are
    not compared: a record read back by load_record equals the one saved.
    evaluations     the System evaluations the record cost: its step's, those of the failed
                    tries before it too (1 at k = 0); each evaluates every contact once
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
    error: StepError | None = None
    stage: int = 0
    evaluations: int = 0

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
        (rec.error, rec.stage, rec.state),
    )


def same_value(a, b):
    """Whether a and b hold the same values, bit for bit (NaN equal to NaN): numbers, text, arrays,
    sparse matrices, and tuples, lists, dicts and dataclasses of them, compared element by element."""
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


def march(stepper, schedule, t0, u0, v0=None, *, a0=None, label=None, state=None, stage=0):
    """Step from (t0, u0, v0) as the schedule says; yield the initial Record, then one per
    accepted step. A step whose Newton fails, or whose local error the schedule rejects, is
    retried with the size ``schedule.cut`` gives, until it gives None: then the NewtonError is
    raised with the last record as ``record``.
    ``a0``: the initial acceleration (default: M a0 = -G(u0), eq 29; 0 for a static stepper).
    ``label(k, t1, dt)``: the text naming a step in an error (default: step k, t, dt).
    ``state``: the SystemState to start from (default: ``system.start(u0, t0)``; e.g. the
    contacts' histories a previous stage ended with). ``stage``: the records' ``stage``."""
    rec = initial(stepper, schedule, t0, u0, v0, a0, state, stage)
    yield rec
    yield from resume(stepper, schedule, rec, label=label)


def resume(stepper, schedule, record, *, label=None):
    """The records after ``record`` (not itself), stepped as ``march`` steps: from a record of
    a run (its u, v, a, energies, reactions and SystemState), the rest of that run exactly.

    A run at a tolerance (``schedule.share``) flies optimistically: the steps of a flight (from a
    record without contact) hold only the error of the bodies' momentum, the only error a flight
    that ends the run hands to its results (no contact or load changes a body's momentum while no
    force acts, and the integrators keep it); such steps are held back until the flight has ended
    the run. A flight that ends in a contact is stepped again from the record it started at, in
    the kinetic energy's norm (the contact sees the vibrations the flight carried), marked
    ``careful`` in its Slope until the contact, so a run resumed from any record goes on as it went."""
    rec = record
    if not isinstance(rec.state, SystemState):
        raise ValueError(f"record {rec.k} has no SystemState to resume from (state = {type(rec.state).__name__})")
    ndof = stepper.system.ndof
    if np.shape(rec.u) != (ndof,):
        raise ValueError(
            f"record {rec.k} holds {np.size(rec.u)} unknowns, the model {ndof}: a record resumes only a model "
            "of the run that made it (the same mesh and bodies)"
        )
    start, flight, lost = None, [], 0  # an optimistic flight: the record it started at, its records held back,
    # and the evaluations of a flight stepped again
    try:
        while (dt := schedule.next_dt(rec)) is not None:
            optimistic = _optimistic(schedule, rec, dt)
            cuts, failures, spent, lost = 0, [], lost, 0
            while True:
                name = (
                    label(rec.k + 1, rec.t + dt, dt)
                    if label
                    else f"step {rec.k + 1}, t = {rec.t + dt:.6g}, dt = {dt:.3g}"
                )
                try:
                    trial = stepper.step(rec.t, rec.u, rec.v, rec.a, dt, name, state=rec.state)
                    error, slope = estimate(stepper, schedule, rec, trial, dt, optimistic)
                    if error is not None and schedule.rejects(error, dt):
                        raise StepRejected(
                            f"local error {error.local:.3g} is past twice its share {error.share:.3g}",
                            [],
                            name,
                            trial[3].evaluations,
                        )
                    break
                except NewtonError as err:
                    spent += err.evaluations
                    failures.append(str(err).splitlines()[0][:200] if str(err) else "Newton failed")
                    smaller = schedule.cut(dt, cuts)
                    if smaller is None:
                        err.record = rec
                        raise
                    dt, cuts = smaller, cuts + 1
            new = accept(
                stepper.system, rec, schedule.end_time(rec.t, dt), dt, trial, cuts, failures, error, slope, spent
            )
            if optimistic and _touching(new):  # the flight ended in a contact: again from its start, carefully
                lost = new.evaluations + sum(r.evaluations for r in flight)  # (counted in the next record)
                rec, start, flight = _careful(start or rec), None, []
                continue
            if optimistic:
                start, rec = start or rec, new
                flight.append(new)
                continue
            rec = new
            yield rec
        yield from flight  # the flight ended the run
    except KeyboardInterrupt as interrupt:  # Ctrl-C: say where (the innermost loop names it)
        if not hasattr(interrupt, "step"):
            interrupt.t, interrupt.step, interrupt.n_steps = rec.t, rec.k + 1, schedule.n_steps
        raise


def _touching(rec):
    return any(st.n_active for st in rec.contacts)


def _optimistic(schedule, rec, dt):
    """Whether the step after ``rec`` flies optimistically (resume): a run at a tolerance, a record
    without contact, not a flight stepped again after its optimistic try (its Slope's ``careful``)."""
    careful = rec.state.slope is not None and rec.state.slope.careful
    return schedule.share(dt) is not None and not careful and not _touching(rec)


def _careful(rec):
    """The record a flight started at, marked to step the flight again in the kinetic energy's norm."""
    slope = rec.state.slope or Slope(None, rec.dt)
    return replace(rec, state=replace(rec.state, slope=replace(slope, careful=True)))


def estimate(stepper, schedule, rec, trial, dt, optimistic=False):
    """A converged step's StepError (estimate.py: its local error, and the share of the schedule's
    tolerance it may have) and the Slope it hands to the next step; (None, None) for a stepper
    without an error model (a static one). The error is the kinetic energy's norm of the error
    vector, or its bodies' momentum's in an optimistic flight (resume); a Slope stays ``careful``
    until the step that touches."""
    model = stepper.error_model
    if model is None:
        return None, None
    s = stepper.system
    d, slope = error_vector(model, rec.a, trial[2], dt, rec.state.slope)
    mass = s.lumped_mass()
    if optimistic:
        e = momentum_norm(mass, d, [s.offset(b) + np.asarray(b.xdofs) for b in s.bodies])
    else:
        e = norm(mass, d)
    if slope.careful and any(st.n_active for st in trial[3].evaluation.contacts):
        slope = replace(slope, careful=False)
    return StepError(e, schedule.share(dt), model), slope


def initial(stepper, schedule, t0, u0, v0=None, a0=None, state=None, stage=0):
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
    return Record(
        k=0, t=t0, dt=0.0, u=u, v=v, a=a, evaluation=ev, energy=energy, state=state, stage=stage, evaluations=1
    )


def accept(system, rec, t1, dt, trial, cuts=0, failures=(), error=None, slope=None, spent=0):
    """Commit a converged step and make its Record: the next SystemState from the converged
    evaluation (with the ``slope`` the step hands on, estimate.py; ``spent``: the System evaluations
    of the tries before it that it replaces); the energies are those of the
    converged state, the dissipation that of its contact states, the external work the trapezoidal
    rule 1/2 (F_n + F_n+1) . (u_n+1 - u_n) over the loads P and the support reactions (the
    prescribed-dof part of G)."""
    u1, v1, a1, result = trial
    ev = result.evaluation
    fixed = system.fixed_dofs
    du = u1 - rec.u
    P0, F0 = rec.evaluation.P, rec.evaluation.G[fixed] if rec.result is None else rec.result.G[fixed]
    P1, F1 = ev.P, result.G[fixed]
    work = rec.energy["external_work"] + 0.5 * (P0 + P1) @ du + 0.5 * (F0 + F1) @ du[fixed]
    dissipation = rec.energy["dissipation"] + sum(st.dissipation for st in ev.contacts)
    state = system.commit(ev, u1, t1, dt)
    if slope is not None:
        state = replace(state, slope=slope)
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
        error=error,
        stage=rec.stage,
        evaluations=spent + result.evaluations,
    )


def evaluations(records):
    """How often the records' Systems were evaluated: ``residual_evaluations`` (one per residual
    Newton needed, failed and rejected tries included) and ``contact_evaluations`` (one per contact in each)."""
    records = list(records)
    return dict(
        residual_evaluations=int(sum(r.evaluations for r in records)),
        contact_evaluations=int(sum(r.evaluations * len(r.contacts) for r in records)),
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
    free = system.free_dofs[M.diagonal()[system.free_dofs] > 0]
    a[free] = linalg.spsolve(M[free][:, free].tocsc(), -G[free])
    return a


def watch(records, progress, t0, t_end, name):
    """The records, passed through a progress display: ``progress(t0, t_end, name)`` makes a
    callback (e.g. contactfem.io.ProgressBar) called with each record's (t, u, v, a) and
    closed at the end. None: the records unchanged. Records that end before t_end with a text
    (a generator's return value: a Stage's ``until``) draw the bar full with that text (``finish``)."""
    if progress is None:
        return (yield from records)
    bar = progress(t0, t_end, name)
    try:
        records = iter(records)
        while True:
            try:
                rec = next(records)
            except StopIteration as stop:
                if stop.value and hasattr(bar, "finish"):
                    bar.finish(stop.value)
                return stop.value
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
