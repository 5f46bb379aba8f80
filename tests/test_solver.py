"""Tests of contactfem.solver with small fake bodies, loads and contacts defined here
(a nonlinear spring chain, a one-node penalty wall, a dead load and a spring-like load):
written only to the protocols (contactfem.bodies.interfaces, contactfem.contact.interfaces),
which they are checked to satisfy."""

from dataclasses import dataclass

import numpy as np
import pytest
import scipy.sparse as sp

from contactfem.contact.placement import start_of
from contactfem.solver.system import as_array
from contactfem.solver import (
    CentralDifference,
    Dirichlet,
    Newmark,
    NewtonError,
    Static,
    System,
    initial_acceleration,
    integrate,
    newton,
)


class SpringChain:
    """n nodes on the x axis; consecutive nodes joined, per component, by springs with
    force f = k d + k3 d^3 (d = difference of displacements). Lumped mass m per dof."""

    def __init__(self, n, k=1.0, k3=0.0, m=1.0, name="chain"):
        self.name, self.k, self.k3, self.m = name, k, k3, m
        self.X = np.c_[np.arange(n, dtype=float), np.zeros(n)]
        self.ndof = 2 * n
        self.xdofs = np.arange(2 * n).reshape(n, 2)
        self.dt = None
        self.hyperelastic = True
        self.quadratic_energy = k3 == 0.0
        self.mass_matrix = "lumped"

    def mass(self, consistent=False):
        return sp.diags(np.full(self.ndof, self.m)).tocsr() if consistent else np.full(self.ndof, self.m)

    def internal_coo(self, u, dt=None, state=None):
        self.dt = dt  # like a rate-dependent body: the step's dt
        R, K = self.internal(u)
        K = K.tocoo()
        return R, K.row, K.col, K.data

    def internal(self, u, dt=None, state=None):
        U = u.reshape(-1, 2)
        d = U[1:] - U[:-1]
        f = self.k * d + self.k3 * d**3
        kt = (self.k + 3 * self.k3 * d**2).ravel()
        R = np.zeros_like(U)
        R[1:] += f
        R[:-1] -= f
        i, j = self.xdofs[:-1].ravel(), self.xdofs[1:].ravel()
        K = sp.coo_matrix(
            (np.r_[kt, -kt, -kt, kt], (np.r_[i, i, j, j], np.r_[i, j, i, j])), shape=(self.ndof, self.ndof)
        )
        return R.ravel(), K.tocsr()

    def strain_energy(self, u, dt=None, state=None):
        d = np.diff(u.reshape(-1, 2), axis=0)
        return float(np.sum(self.k * d**2 / 2 + self.k3 * d**4 / 4))

    def start(self, u):
        return 0  # its state: how many steps were committed

    def commit(self, u, dt=None, state=None):
        return state + 1

    rotation_dofs = np.zeros(0, dtype=int)

    def discrete_gradient(self, u0, u1):
        """Gonzalez's discrete gradient kept off the translations (a body of one's own)."""
        from contactfem.bodies.discrete_gradient import gonzalez

        Q = np.zeros((self.ndof, 2))
        Q[0::2, 0] = Q[1::2, 1] = 1.0
        return gonzalez(self, u0, u1, Q)


@dataclass(frozen=True)
class WallState:
    """What the wall knows at one u (the contact state protocol: scatter, energy, dissipation,
    next_history)."""

    dof: int
    g: float
    c: float
    dissipation: float
    next_history: int

    def scatter(self, ndof):
        R = np.zeros(ndof)
        if self.g >= 0:
            return R, [], [], []
        R[self.dof] = self.c * self.g
        return R, [self.dof], [self.dof], [self.c]

    @property
    def energy(self):
        return 0.5 * self.c * min(self.g, 0.0) ** 2


class Wall:
    """Penalty wall y >= y_wall for one node: R_c = c g on its y dof when g < 0; its history
    is the number of commits (a value, in the SystemState), and every step dissipates
    ``dissipation_per_commit``."""

    integration = "standard"
    unknowns = 0

    def __init__(self, body, node, y_wall, c, dissipation_per_commit=0.0):
        self.body, self.node, self.y_wall, self.c = body, node, y_wall, c
        self.per_commit = dissipation_per_commit
        self.name = "wall"

    def start(self, u, t=0.0, *, offsets=None):
        return 0

    def evaluate(self, u, t=0.0, dt=None, u0=None, phase=None, *, history, offsets=None):
        dof = start_of(self.body, offsets) + self.body.xdofs[self.node, 1]
        return WallState(dof, self.body.X[self.node, 1] + u[dof] - self.y_wall, self.c, self.per_commit, history + 1)

    def commit(self, state):
        return state.next_history


class DeadLoad:
    """P = value * f(t) on some local dofs of a body; no tangent."""

    def __init__(self, body, local_dofs, value, f=lambda t: 1.0):
        self.body, self.local_dofs, self.f = body, np.asarray(local_dofs), f
        self.value = np.asarray(value, dtype=float)

    def start(self, u, t=0.0, offsets=None):
        return None

    def assemble(self, u, t, state=None, offsets=None):
        P = np.zeros(u.size)
        P[start_of(self.body, offsets) + self.local_dofs] = self.value * self.f(t)
        return P, [], [], []

    def commit(self, u, t, state=None, offsets=None):
        return state


class SpringLoad:
    """A displacement-dependent load P = f0 - kl u on one dof: dP/du = -kl."""

    def __init__(self, body, local_dof, f0, kl):
        self.body, self.local_dof, self.f0, self.kl = body, local_dof, f0, kl

    def start(self, u, t=0.0, offsets=None):
        return None

    def assemble(self, u, t, state=None, offsets=None):
        g = start_of(self.body, offsets) + self.local_dof
        P = np.zeros(u.size)
        P[g] = self.f0 - self.kl * u[g]
        return P, [g], [g], [-self.kl]

    def commit(self, u, t, state=None, offsets=None):
        return state


def test_the_fakes_are_what_the_solver_asks_for():
    """The protocols of contactfem.*.interfaces are all the solver relies on."""
    from contactfem.bodies.interfaces import Body, Load
    from contactfem.contact.interfaces import Contact

    body = SpringChain(2)
    assert isinstance(body, Body) and isinstance(Wall(body, 0, 0.0, 1.0), Contact)
    assert isinstance(DeadLoad(body, [0], 1.0), Load) and isinstance(SpringLoad(body, 0, 1.0, 1.0), Load)


def oscillator(k=4.0, m=1.0):
    """Node 1 of a two-node chain, node 0 clamped: omega = sqrt(k / m) in x and y."""
    body = SpringChain(2, k=k, m=m)
    return body, System([body], fixed=[Dirichlet(body, [0, 1])])


def total_energy(hist):
    return hist.kinetic + hist.strain + hist.contact


# -- System -------------------------------------------------------------------------


def test_offsets_global_dofs_and_fixed():
    a, b = SpringChain(3, name="a"), SpringChain(2, name="b")
    s = System([a, b], fixed=[Dirichlet(b, [1, 2], 0.5), Dirichlet(a, [0])])
    assert (s.offset(a), s.offset(b), s.ndof) == (0, 6, 10)
    assert not hasattr(a, "dof_offset") and not hasattr(b, "dof_offset")  # the System's, not theirs
    assert list(s.global_dofs(b, [0, 3])) == [6, 9]
    assert list(s.fixed_dofs) == [0, 7, 8]
    assert list(s.free_dofs) == [1, 2, 3, 4, 5, 6, 9]
    assert np.allclose(s.prescribed(0.0), [0.0, 0.5, 0.5])
    assert np.allclose(s.mass(), 1.0)


@pytest.mark.parametrize("linear_algebra", ["dense", "sparse", "banded"])
def test_tangent_matches_finite_differences(linear_algebra):
    a, b = SpringChain(3, k=2.0, k3=5.0, name="a"), SpringChain(2, k=1.0, k3=1.0, name="b")
    s = System(
        [a, b],
        contacts=[Wall(b, 1, y_wall=0.0, c=30.0)],
        loads=[SpringLoad(a, 4, f0=1.0, kl=3.0), DeadLoad(b, [2], 0.7)],
        linear_algebra=linear_algebra,
    )
    state = s.start(np.zeros(s.ndof))
    u = np.random.default_rng(0).normal(scale=0.3, size=s.ndof)
    u[s.global_dofs(b, b.xdofs[1, 1])] = -0.4  # wall contact active
    G, K = s.residual_tangent(u, 0.0, state=state)
    assert sp.issparse(K) == (linear_algebra != "dense")
    assert hasattr(K, "band_plan") == (linear_algebra == "banded")
    h, K_fd = 1e-6, np.zeros((s.ndof, s.ndof))
    for j in range(s.ndof):
        e = np.zeros(s.ndof)
        e[j] = h
        K_fd[:, j] = (
            s.residual_tangent(u + e, 0.0, state=state)[0] - s.residual_tangent(u - e, 0.0, state=state)[0]
        ) / (2 * h)
    assert np.linalg.norm(as_array(K) - K_fd) <= 1e-6 * np.linalg.norm(K_fd)
    # the effective tangent of a time stepper: K + c M on the diagonal
    _, K_eff = s.residual_tangent(u, 0.0, mass_coefficient=7.0, state=state)
    assert np.allclose(as_array(K_eff), as_array(K) + 7.0 * np.diag(s.mass()), rtol=1e-14, atol=1e-12)


def test_initial_acceleration_solves_M_a_equals_P_minus_R():
    body = SpringChain(3, k=2.0, k3=1.0, m=0.5)
    s = System([body], loads=[DeadLoad(body, [4, 5], 1.5)], fixed=[Dirichlet(body, [0, 1])])
    u0 = np.linspace(0.0, 0.3, s.ndof)
    u0[:2] = 0.0
    a0 = initial_acceleration(s, 0.0, u0)
    R, _ = body.internal(u0)
    P = s.external_force(u0, 0.0, s.start(u0))
    assert np.allclose((s.mass() * a0)[s.free_dofs], (P - R)[s.free_dofs])
    assert np.all(a0[s.fixed_dofs] == 0)


# -- Newton -------------------------------------------------------------------------


def nonlinear_chain():
    body = SpringChain(4, k=1.0, k3=10.0)
    return System([body], loads=[DeadLoad(body, [6, 7], [5.0, -3.0])], fixed=[Dirichlet(body, [0, 1])])


def test_newton_converges_quadratically():
    s = nonlinear_chain()
    state = s.start(np.zeros(s.ndof))
    res = newton(lambda u: s.residual_tangent(u, 0.0, state=state), np.zeros(s.ndof), s.free_dofs)
    r = np.array(res.residuals)
    assert res.iterations == len(r) - 1 >= 4
    assert r[-1] <= 1e-10 * r[0] + 1e-10
    G, _ = s.residual_tangent(res.u, 0.0, state=state)
    assert np.linalg.norm(G[s.free_dofs]) == pytest.approx(r[-1])
    # asymptotic quadratic rate: r_k+1 / r_k^2 bounded in the last iterations
    tail = [k for k in range(len(r) - 1) if r[k] < 1.0 and r[k + 1] > 1e-13]  # above roundoff
    assert len(tail) >= 2
    assert max(r[k + 1] / r[k] ** 2 for k in tail) < 1.0


def test_newton_error_on_maxit_carries_history():
    s = nonlinear_chain()
    with pytest.raises(NewtonError, match="step 7") as info:
        newton(
            lambda u: s.residual_tangent(u, 0.0, state=s.start(u)),
            np.zeros(s.ndof),
            s.free_dofs,
            maxit=2,
            label="step 7, t = 0.7",
        )
    assert len(info.value.history) == 3
    assert np.all(np.isfinite(info.value.history))


def test_newton_error_on_nan_and_singular():
    def nan_after_first(u):
        G = np.array([1.0 - u[0], np.nan if u[0] != 0 else 1.0])
        return G, sp.identity(2, format="csr")

    with pytest.raises(NewtonError, match="non-finite residual") as info:
        newton(nan_after_first, np.zeros(2), [0, 1])
    assert info.value.history == [pytest.approx(np.sqrt(2.0))]

    def singular(u):
        return np.ones(2), sp.csr_matrix((2, 2))

    with pytest.raises(NewtonError, match="singular") as info:
        newton(singular, np.zeros(2), np.array([True, True]))
    assert len(info.value.history) == 1

    def inverted(u):  # bodies/contacts signal trouble by FloatingPointError
        raise FloatingPointError("det F <= 0")

    with pytest.raises(NewtonError, match="det F"):
        newton(inverted, np.zeros(2), [0, 1])


# -- Newmark, Static, CentralDifference -------------------------------------------------


def zero_crossing_period(t, x):
    i = np.flatnonzero(np.sign(x[:-1]) != np.sign(x[1:]))
    tc = t[i] - x[i] * (t[i + 1] - t[i]) / (x[i + 1] - x[i])
    return 2 * np.mean(np.diff(tc))


def test_average_acceleration_conserves_energy_and_gives_the_period():
    k, m = 4.0, 1.0
    body, s = oscillator(k, m)
    w = np.sqrt(k / m)
    dt = 2 * np.pi / w / 40
    hist = integrate(Newmark(s, delta=0.5, beta=0.25), 0.0, np.array([0, 0, 1.0, 0]), n_steps=400, dt=dt)
    xs = [r.u[2] for r in hist.records[1:]]
    E = total_energy(hist)
    assert np.max(np.abs(E - E[0])) < 1e-12 * E[0]
    # trapezoidal rule: tan(theta / 2) = omega dt / 2, so the period is 2 pi dt / theta
    T_h = 2 * np.pi * dt / (2 * np.arctan(w * dt / 2))
    T = zero_crossing_period(hist.t[1:], np.array(xs))
    assert T == pytest.approx(T_h, rel=1e-4)
    assert T == pytest.approx(2 * np.pi / w, rel=(w * dt) ** 2 / 12 * 1.1)
    assert np.all(hist.iterations[1:] == 1)  # linear: one Newton solve a step


def test_paper_parameters_dissipate_at_the_spectral_rate():
    k, m, delta, beta = 4.0, 1.0, 0.7, 0.4
    body, s = oscillator(k, m)
    w = np.sqrt(k / m)
    dt, n = 2 * np.pi / w / 10, 60
    hist = integrate(Newmark(s, delta=delta, beta=beta), 0.0, np.array([0, 0, 1.0, 0]), n_steps=n, dt=dt)
    E = total_energy(hist)
    # amplification matrix of (u, v) for u'' = -w^2 u
    W = (w * dt) ** 2
    A_u = np.array([1 - (0.5 - beta) * W, dt]) / (1 + beta * W)
    A_v = np.array([-dt * w**2 * (1 - delta), 1.0]) - dt * w**2 * delta * A_u
    rho = max(abs(np.linalg.eigvals(np.array([A_u, A_v]))))
    assert rho < 1
    assert E[-1] < 0.5 * E[0]
    assert E[-1] / E[0] == pytest.approx(rho ** (2 * n), rel=0.05)
    assert np.all(E[10::10] < E[:-10:10])  # decreasing, one period to the next


def test_energy_balance_with_loads_and_moving_support():
    body = SpringChain(3, k=3.0, m=0.5)
    s = System(
        [body],
        loads=[DeadLoad(body, [4], 0.8, f=np.cos)],
        fixed=[Dirichlet(body, [0], lambda t: 0.2 * np.sin(2 * t)), Dirichlet(body, [1])],
    )
    hist = integrate(Newmark(s, delta=0.5, beta=0.25), 0.0, np.zeros(s.ndof), t_end=3.0, dt=0.05)
    assert hist.t[-1] == pytest.approx(3.0) and len(hist.t) == 61
    balance = total_energy(hist) - hist.external_work
    assert np.max(np.abs(balance - balance[0])) < 1e-10
    assert np.max(np.abs(hist.external_work)) > 0.1


def test_dirichlet_values_are_honoured():
    body = SpringChain(3, k=2.0, k3=1.0)
    move = lambda t: [0.1 * np.sin(2 * t), -0.05 * t]
    s = System([body], fixed=[Dirichlet(body, [0, 1], move), Dirichlet(body, [5], 0.3)])
    hist = integrate(Newmark(s), 0.0, np.zeros(s.ndof), n_steps=20, dt=0.1)
    for r in hist.records:
        assert np.allclose(r.u[[0, 1, 5]], move(r.t) + [0.3])
    u = Static(s).step(0.0, np.zeros(s.ndof), None, None, 1.0, state=s.start(np.zeros(s.ndof)))[0]
    assert np.allclose(u[[0, 1, 5]], move(1.0) + [0.3])


def test_static_linear_problem_in_one_iteration():
    body = SpringChain(4, k=2.0)
    s = System([body], loads=[DeadLoad(body, [6, 7], [1.0, -0.5], f=lambda t: t)], fixed=[Dirichlet(body, [0, 1])])
    hist = integrate(Static(s), 0.0, np.zeros(s.ndof), n_steps=2, dt=0.5)
    assert list(hist.iterations) == [0, 1, 1]
    assert all(len(r) == 2 for r in hist.residuals[1:])
    # three springs in series under the end load 1 * (1.0, -0.5) at t = 1
    assert np.allclose(hist.u.reshape(-1, 2)[-1], np.array([1.0, -0.5]) * 3 / 2.0)
    assert np.all(hist.kinetic == 0)


def test_static_penalty_wall_and_dissipation_bookkeeping():
    body = SpringChain(2, k=1.0, k3=2.0)
    wall = Wall(body, 1, y_wall=-0.1, c=100.0, dissipation_per_commit=0.125)
    s = System([body], contacts=[wall], loads=[DeadLoad(body, [3], -2.0)], fixed=[Dirichlet(body, [0, 1])])
    hist = integrate(Static(s), 0.0, np.zeros(s.ndof), n_steps=3, dt=1.0)
    uy = hist.u[3]
    # equilibrium: spring (k uy + k3 uy^3) + wall c (uy + 0.1) = -2
    assert uy + 2 * uy**3 + 100 * (uy + 0.1) == pytest.approx(-2.0, abs=1e-9)
    assert hist.contact[-1] == pytest.approx(50 * (uy + 0.1) ** 2)
    assert np.allclose(hist.dissipation, [0, 0.125, 0.25, 0.375])
    assert hist.records[-1].state.bodies == (3,) and hist.records[-1].state.contacts == (3,)  # once per step


def test_central_difference_oscillator():
    k, m = 4.0, 1.0
    body, s = oscillator(k, m)
    w = np.sqrt(k / m)
    dt = 2 * np.pi / w / 40
    hist = integrate(CentralDifference(s), 0.0, np.array([0, 0, 1.0, 0]), n_steps=400, dt=dt)
    xs = [r.u[2] for r in hist.records[1:]]
    # central differences: sin(theta / 2) = omega dt / 2
    T_h = 2 * np.pi * dt / (2 * np.arcsin(w * dt / 2))
    assert zero_crossing_period(hist.t[1:], np.array(xs)) == pytest.approx(T_h, rel=1e-4)
    E = total_energy(hist)
    assert np.max(np.abs(E - E[0])) < (w * dt) ** 2 * E[0]


class FussyNewmark(Newmark):
    """Fails (like a diverging Newton) whenever dt exceeds max_dt."""

    max_dt = 0.03

    def step(self, t, u, v, a, dt, label="", *, state):
        if dt > self.max_dt:
            raise NewtonError(f"too large ({label})", [1.0, 2.0], label)
        return super().step(t, u, v, a, dt, label=label, state=state)


def test_cutback_halves_the_step_and_keeps_the_time_grid():
    body, s = oscillator()
    hist = integrate(FussyNewmark(s), 0.0, np.array([0, 0, 1.0, 0]), n_steps=3, dt=0.1, cutback=True, max_cuts=4)
    assert np.allclose(hist.dt[1:], 0.025) and len(hist.t) == 1 + 3 * 4
    assert hist.t[-1] == pytest.approx(0.3) and hist.cuts[1] == 2 and hist.cuts.sum() == 3 * 2
    assert hist.records[-1].state.bodies == (12,) and body.dt == pytest.approx(0.025)  # the body was given the cut dt
    with pytest.raises(NewtonError, match="step 1") as info:
        integrate(FussyNewmark(s), 0.0, np.zeros(4), n_steps=3, dt=0.1, cutback=True, max_cuts=1)
    assert info.value.history == [1.0, 2.0] and len(info.value.partial.t) == 1
    with pytest.raises(NewtonError):
        integrate(FussyNewmark(s), 0.0, np.zeros(4), n_steps=3, dt=0.1)


# -- bad input ------------------------------------------------------------------------


def test_bad_input_raises():
    body, s = oscillator()
    for dt in (0.0, -1.0, np.nan):
        with pytest.raises(ValueError, match="dt"):
            integrate(Newmark(s), 0.0, np.zeros(4), n_steps=2, dt=dt)
        with pytest.raises(AssertionError, match="Schedule"):  # a step's size is the schedule's, checked there
            Newmark(s).step(0.0, np.zeros(4), np.zeros(4), np.zeros(4), dt, state=s.start(np.zeros(4)))
    for beta in (0.0, -0.1, 0.6):
        with pytest.raises(ValueError, match="beta"):
            Newmark(s, beta=beta)
    for delta in (-0.1, 0.4, 1.1):  # below 1/2 every step amplifies
        with pytest.raises(ValueError, match="delta"):
            Newmark(s, delta=delta)
    with pytest.warns(UserWarning, match="unconditionally stable"):
        Newmark(s, delta=0.5, beta=0.2)
    with pytest.raises(ValueError, match="local_dofs"):
        System([body], fixed=[Dirichlet(body, [4])])
    with pytest.raises(ValueError, match="Dirichlet value"):
        System([body], fixed=[Dirichlet(body, [0, 1], [1.0, 2.0, 3.0])]).prescribed(0.0)
    with pytest.raises(ValueError, match="n_steps"):
        integrate(Static(s), 0.0, np.zeros(4), dt=0.1)
    with pytest.raises(ValueError, match="n_steps"):
        integrate(Static(s), 0.0, np.zeros(4), n_steps=2, t_end=1.0, dt=0.1)
    with pytest.raises(ValueError, match="n_steps"):
        integrate(Static(s), 0.0, np.zeros(4), n_steps=0, dt=0.1)
    with pytest.raises(ValueError, match="mass"):
        CentralDifference(System([SpringChain(2, m=0.0)]))


def test_line_search_rescues_newton_where_full_steps_diverge():
    """G(u) = atan(u) from u0 = 2: full Newton steps overshoot and diverge; backtracking
    converges, and near the solution takes full steps (quadratic, here cubic, rate)."""
    import scipy.sparse as sp_

    def fun(u):
        return np.arctan(u), sp_.csr_matrix(np.diag(1.0 / (1.0 + u**2)))

    with pytest.raises(NewtonError), np.errstate(over="ignore"):
        newton(fun, np.array([2.0]), [0], maxit=10)
    res = newton(fun, np.array([2.0]), [0], maxit=20, line_search=10)
    assert abs(res.u[0]) < 1e-10 and res.residuals[-1] < 1e-10
    with pytest.raises(ValueError, match="line_search"):
        newton(fun, np.array([2.0]), [0], line_search=-1)


def test_gonzalez_discrete_gradient_of_a_nonlinear_chain(rng):
    """bodies.discrete_gradient.gonzalez on a chain of cubic springs (its energy is not
    quadratic: the correction c w acts): the work on d is W(u1) - W(u0) to rounding, no
    resultant, and the tangent matches central differences."""
    from fd import fd_jacobian, rel_error

    body = SpringChain(5, k=1.0, k3=10.0)
    u0, u1 = 0.1 * rng.standard_normal(body.ndof), 0.3 * rng.standard_normal(body.ndof)
    F, rows, cols, vals = body.discrete_gradient(u0, u1)
    W0, W1 = body.strain_energy(u0), body.strain_energy(u1)
    midpoint = body.internal(0.5 * (u0 + u1))[0]
    assert abs(midpoint @ (u1 - u0) - (W1 - W0)) > 1e-6 * (W0 + W1)  # the midpoint rule alone is not exact
    assert abs(F @ (u1 - u0) - (W1 - W0)) <= 1e-13 * (W0 + W1)
    assert abs(F[0::2].sum()) <= 1e-13 * np.abs(F).max() and abs(F[1::2].sum()) <= 1e-13 * np.abs(F).max()
    K = np.zeros((body.ndof, body.ndof))
    np.add.at(K, (rows, cols), vals)
    assert rel_error(K, fd_jacobian(lambda x: body.discrete_gradient(u0, x)[0], u1, h=1e-6)) < 1e-7


def test_the_system_keeps_its_offsets_and_writes_nothing_on_its_objects():
    """Bodies, contacts and loads hold configuration only: a System places them in its own
    offsets (by identity), writes no attribute on them, and a second System of the same objects
    in another order leaves the first one's evaluation as it was, bit for bit."""
    from contactfem.bodies.continuum import Continuum
    from contactfem.bodies.loads import Pressure
    from contactfem.bodies.meshes import block_mesh
    from contactfem.contact import BodySurface
    from contactfem.contact.lagrange import LagrangeNodeToSegment
    from contactfem.laws import PowerLaw

    lower = Continuum(block_mesh(1.0, 0.5, 4, 2), E=100.0, nu=0.3, rho=1.0, name="lower")
    upper = Continuum(block_mesh(1.0, 0.5, 3, 2), E=100.0, nu=0.3, rho=1.0, name="upper")
    upper_bottom = upper.boundary_nodes("bottom")
    lower_top = lower.boundary_nodes("top")
    contact = LagrangeNodeToSegment(upper, upper_bottom, BodySurface(lower, lower_top[::-1]), normal=PowerLaw(c_N=1e3))
    load = Pressure(upper, "top", 1.0)
    objects = (lower, upper, contact, load)
    before = [dict(vars(o)) for o in objects]
    s = System([lower, upper], [contact], [load])
    assert [vars(o) for o in objects] == before and all(
        vars(o)[k] is v for o, b in zip(objects, before) for k, v in b.items()
    )
    assert (s.offset(lower), s.offset(upper), s.offset(contact)) == (0, lower.ndof, lower.ndof + upper.ndof)
    rng = np.random.default_rng(5)
    u = np.zeros(s.ndof)
    u[s.global_dofs(upper, upper.xdofs[:, 1])] = -0.01 * (1 + rng.random(len(upper.X)))
    u[s.contact_dofs] = -rng.random(len(s.contact_dofs))
    G = s.evaluate(u, 1.0, state=s.start(u)).G
    other = System([upper, lower], [contact], [load])  # the same objects, placed otherwise
    assert (other.offset(upper), other.offset(lower)) == (0, upper.ndof)
    assert np.array_equal(s.evaluate(u, 1.0, state=s.start(u)).G, G)
    v = np.concatenate([s.local(upper, u), s.local(lower, u), u[s.contact_dofs]])  # u in the other's order
    H = other.evaluate(v, 1.0, state=other.start(v)).G
    assert np.allclose(
        np.concatenate([H[upper.ndof : other.body_ndof], H[: upper.ndof], H[other.body_ndof :]]),
        G,
        rtol=1e-12,
        atol=1e-12,
    )


def test_a_copied_system_places_its_own_objects():
    """A System pickled or deep-copied (the grader hands a stepper to a notebook's process) places the
    copies of its bodies and contacts anew (its offsets are keyed by identity) and evaluates as the
    original, bit for bit."""
    import copy
    import pickle

    from contactfem.scenes import get_scene

    model = get_scene("funnel").build(get_scene("funnel").resolve("fast", {"variant": "frictional"}))
    s = model.system
    u = np.zeros(s.ndof)
    u[1::2] = -0.05
    G = s.evaluate(u, 0.0, 1e-3, state=s.start(u, 0.0)).G
    for c in (pickle.loads(pickle.dumps(s)), copy.deepcopy(s)):
        assert c.offset(c.bodies[0]) == 0 and len(c.offsets) == len(s.offsets)
        assert np.array_equal(c.evaluate(u, 0.0, 1e-3, state=c.start(u, 0.0)).G, G)
