"""Tests of contactfem.solver with small fake bodies, loads and contacts defined here
(a nonlinear spring chain, a one-node penalty wall, a dead load and a spring-like load)."""
import numpy as np
import pytest
import scipy.sparse as sp

from contactfem.solver.system import as_array
from contactfem.solver import (CentralDifference, Dirichlet, Newmark, NewtonError, Static, System,
                               initial_acceleration, integrate, newton)


class SpringChain:
    """n nodes on the x axis; consecutive nodes joined, per component, by springs with
    force f = k d + k3 d^3 (d = difference of displacements). Lumped mass m per dof."""

    def __init__(self, n, k=1.0, k3=0.0, m=1.0, name="chain"):
        self.name, self.k, self.k3, self.m = name, k, k3, m
        self.X = np.c_[np.arange(n, dtype=float), np.zeros(n)]
        self.ndof = 2 * n
        self.xdofs = np.arange(2 * n).reshape(n, 2)
        self.commits = 0
        self.dt = None

    def set_dt(self, dt):                 # like a rate-dependent body
        self.dt = dt

    def mass(self):
        return np.full(self.ndof, self.m)

    def internal(self, u):
        U = u.reshape(-1, 2)
        d = U[1:] - U[:-1]
        f = self.k * d + self.k3 * d ** 3
        kt = (self.k + 3 * self.k3 * d ** 2).ravel()
        R = np.zeros_like(U)
        R[1:] += f
        R[:-1] -= f
        i, j = self.xdofs[:-1].ravel(), self.xdofs[1:].ravel()
        K = sp.coo_matrix((np.r_[kt, -kt, -kt, kt], (np.r_[i, i, j, j], np.r_[i, j, i, j])),
                          shape=(self.ndof, self.ndof))
        return R.ravel(), K.tocsr()

    def strain_energy(self, u):
        d = np.diff(u.reshape(-1, 2), axis=0)
        return float(np.sum(self.k * d ** 2 / 2 + self.k3 * d ** 4 / 4))

    def commit(self, u):
        self.commits += 1


class Wall:
    """Penalty wall y >= y_wall for one node: R_c = c g on its y dof when g < 0."""

    def __init__(self, body, node, y_wall, c, dissipation_per_commit=0.0):
        self.body, self.node, self.y_wall, self.c = body, node, y_wall, c
        self.per_commit = dissipation_per_commit
        self.dissipation = 0.0

    def _dof_gap(self, u):
        dof = self.body.dof_offset + self.body.xdofs[self.node, 1]
        return dof, self.body.X[self.node, 1] + u[dof] - self.y_wall

    def assemble(self, u):
        dof, g = self._dof_gap(u)
        R = np.zeros(u.size)
        if g >= 0:
            return R, [], [], []
        R[dof] = self.c * g
        return R, [dof], [dof], [self.c]

    def energy(self, u):
        return 0.5 * self.c * min(self._dof_gap(u)[1], 0.0) ** 2

    def commit(self, u):
        self.dissipation = self.per_commit


class DeadLoad:
    """P = value * f(t) on some local dofs of a body; no tangent."""

    def __init__(self, body, local_dofs, value, f=lambda t: 1.0):
        self.body, self.local_dofs, self.f = body, np.asarray(local_dofs), f
        self.value = np.asarray(value, dtype=float)

    def assemble(self, u, t):
        P = np.zeros(u.size)
        P[self.body.dof_offset + self.local_dofs] = self.value * self.f(t)
        return P, [], [], []


class SpringLoad:
    """A displacement-dependent load P = f0 - kl u on one dof: dP/du = -kl."""

    def __init__(self, body, local_dof, f0, kl):
        self.body, self.local_dof, self.f0, self.kl = body, local_dof, f0, kl

    def assemble(self, u, t):
        g = self.body.dof_offset + self.local_dof
        P = np.zeros(u.size)
        P[g] = self.f0 - self.kl * u[g]
        return P, [g], [g], [-self.kl]


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
    assert (a.dof_offset, b.dof_offset, s.ndof) == (0, 6, 10)
    assert list(s.global_dofs(b, [0, 3])) == [6, 9]
    assert list(s.fixed_dofs) == [0, 7, 8]
    assert list(s.free_dofs) == [1, 2, 3, 4, 5, 6, 9]
    assert np.allclose(s.prescribed(0.0), [0.0, 0.5, 0.5])
    assert np.allclose(s.mass(), 1.0)


@pytest.mark.parametrize("linear_algebra", ["dense", "sparse", "banded"])
def test_tangent_matches_finite_differences(linear_algebra):
    a, b = SpringChain(3, k=2.0, k3=5.0, name="a"), SpringChain(2, k=1.0, k3=1.0, name="b")
    s = System([a, b], contacts=[Wall(b, 1, y_wall=0.0, c=30.0)],
               loads=[SpringLoad(a, 4, f0=1.0, kl=3.0), DeadLoad(b, [2], 0.7)], linear_algebra=linear_algebra)
    u = np.random.default_rng(0).normal(scale=0.3, size=s.ndof)
    u[s.global_dofs(b, b.xdofs[1, 1])] = -0.4            # wall contact active
    G, K = s.residual_tangent(u, 0.0)
    assert sp.issparse(K) == (linear_algebra != "dense")
    assert hasattr(K, "band_plan") == (linear_algebra == "banded")
    h, K_fd = 1e-6, np.zeros((s.ndof, s.ndof))
    for j in range(s.ndof):
        e = np.zeros(s.ndof)
        e[j] = h
        K_fd[:, j] = (s.residual_tangent(u + e, 0.0)[0] - s.residual_tangent(u - e, 0.0)[0]) / (2 * h)
    assert np.linalg.norm(as_array(K) - K_fd) <= 1e-6 * np.linalg.norm(K_fd)
    # the effective tangent of a time stepper: K + c M on the diagonal
    _, K_eff = s.residual_tangent(u, 0.0, mass_coefficient=7.0)
    assert np.allclose(as_array(K_eff), as_array(K) + 7.0 * np.diag(s.mass()), rtol=1e-14, atol=1e-12)


def test_initial_acceleration_solves_M_a_equals_P_minus_R():
    body = SpringChain(3, k=2.0, k3=1.0, m=0.5)
    s = System([body], loads=[DeadLoad(body, [4, 5], 1.5)], fixed=[Dirichlet(body, [0, 1])])
    u0 = np.linspace(0.0, 0.3, s.ndof)
    u0[:2] = 0.0
    a0 = initial_acceleration(s, 0.0, u0)
    R, _ = body.internal(u0)
    P = s.external_force(u0, 0.0)
    assert np.allclose((s.mass() * a0)[s.free_dofs], (P - R)[s.free_dofs])
    assert np.all(a0[s.fixed_dofs] == 0)


# -- Newton -------------------------------------------------------------------------

def nonlinear_chain():
    body = SpringChain(4, k=1.0, k3=10.0)
    return System([body], loads=[DeadLoad(body, [6, 7], [5.0, -3.0])],
                  fixed=[Dirichlet(body, [0, 1])])


def test_newton_converges_quadratically():
    s = nonlinear_chain()
    res = newton(lambda u: s.residual_tangent(u, 0.0), np.zeros(s.ndof), s.free_dofs)
    r = np.array(res.residuals)
    assert res.iterations == len(r) - 1 >= 4
    assert r[-1] <= 1e-10 * r[0] + 1e-10
    G, _ = s.residual_tangent(res.u, 0.0)
    assert np.linalg.norm(G[s.free_dofs]) == pytest.approx(r[-1])
    # asymptotic quadratic rate: r_k+1 / r_k^2 bounded in the last iterations
    tail = [k for k in range(len(r) - 1) if r[k] < 1.0 and r[k + 1] > 1e-13]  # above roundoff
    assert len(tail) >= 2
    assert max(r[k + 1] / r[k] ** 2 for k in tail) < 1.0


def test_newton_error_on_maxit_carries_history():
    s = nonlinear_chain()
    with pytest.raises(NewtonError, match="step 7") as info:
        newton(lambda u: s.residual_tangent(u, 0.0), np.zeros(s.ndof), s.free_dofs,
               maxit=2, label="step 7, t = 0.7")
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

    def inverted(u):                      # bodies/contacts signal trouble by FloatingPointError
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
    xs = []
    hist = integrate(Newmark(s, dt, delta=0.5, beta=0.25), 0.0, np.array([0, 0, 1.0, 0]),
                     n_steps=400, callback=lambda t, u, v, a: xs.append(u[2]))
    E = total_energy(hist)
    assert np.max(np.abs(E - E[0])) < 1e-12 * E[0]
    # trapezoidal rule: tan(theta / 2) = omega dt / 2, so the period is 2 pi dt / theta
    T_h = 2 * np.pi * dt / (2 * np.arctan(w * dt / 2))
    T = zero_crossing_period(hist.t[1:], np.array(xs))
    assert T == pytest.approx(T_h, rel=1e-4)
    assert T == pytest.approx(2 * np.pi / w, rel=(w * dt) ** 2 / 12 * 1.1)
    assert np.all(hist.iterations[1:] == 1)                 # linear: one Newton solve a step


def test_paper_parameters_dissipate_at_the_spectral_rate():
    k, m, delta, beta = 4.0, 1.0, 0.7, 0.4
    body, s = oscillator(k, m)
    w = np.sqrt(k / m)
    dt, n = 2 * np.pi / w / 10, 60
    hist = integrate(Newmark(s, dt, delta=delta, beta=beta), 0.0, np.array([0, 0, 1.0, 0]),
                     n_steps=n)
    E = total_energy(hist)
    # amplification matrix of (u, v) for u'' = -w^2 u
    W = (w * dt) ** 2
    A_u = np.array([1 - (0.5 - beta) * W, dt]) / (1 + beta * W)
    A_v = np.array([-dt * w ** 2 * (1 - delta), 1.0]) - dt * w ** 2 * delta * A_u
    rho = max(abs(np.linalg.eigvals(np.array([A_u, A_v]))))
    assert rho < 1
    assert E[-1] < 0.5 * E[0]
    assert E[-1] / E[0] == pytest.approx(rho ** (2 * n), rel=0.05)
    assert np.all(E[10::10] < E[:-10:10])                   # decreasing, one period to the next


def test_energy_balance_with_loads_and_moving_support():
    body = SpringChain(3, k=3.0, m=0.5)
    s = System([body], loads=[DeadLoad(body, [4], 0.8, f=np.cos)],
               fixed=[Dirichlet(body, [0], lambda t: 0.2 * np.sin(2 * t)), Dirichlet(body, [1])])
    hist = integrate(Newmark(s, 0.05, delta=0.5, beta=0.25), 0.0, np.zeros(s.ndof), t_end=3.0)
    assert hist.t[-1] == pytest.approx(3.0) and len(hist.t) == 61
    balance = total_energy(hist) - hist.external_work
    assert np.max(np.abs(balance - balance[0])) < 1e-10
    assert np.max(np.abs(hist.external_work)) > 0.1


def test_dirichlet_values_are_honoured():
    body = SpringChain(3, k=2.0, k3=1.0)
    move = lambda t: [0.1 * np.sin(2 * t), -0.05 * t]
    s = System([body], fixed=[Dirichlet(body, [0, 1], move), Dirichlet(body, [5], 0.3)])
    seen = []
    integrate(Newmark(s, 0.1), 0.0, np.zeros(s.ndof), n_steps=20,
              callback=lambda t, u, v, a: seen.append((t, u[[0, 1, 5]].copy())))
    for t, got in seen:
        assert np.allclose(got, move(t) + [0.3])
    u = Static(s).step(0.0, np.zeros(s.ndof), None, None)[0]
    assert np.allclose(u[[0, 1, 5]], move(1.0) + [0.3])


def test_static_linear_problem_in_one_iteration():
    body = SpringChain(4, k=2.0)
    s = System([body], loads=[DeadLoad(body, [6, 7], [1.0, -0.5], f=lambda t: t)],
               fixed=[Dirichlet(body, [0, 1])])
    hist = integrate(Static(s, dt=0.5), 0.0, np.zeros(s.ndof), n_steps=2)
    assert list(hist.iterations) == [0, 1, 1]
    assert all(len(r) == 2 for r in hist.residuals[1:])
    # three springs in series under the end load 1 * (1.0, -0.5) at t = 1
    assert np.allclose(hist.u.reshape(-1, 2)[-1], np.array([1.0, -0.5]) * 3 / 2.0)
    assert np.all(hist.kinetic == 0)


def test_static_penalty_wall_and_dissipation_bookkeeping():
    body = SpringChain(2, k=1.0, k3=2.0)
    wall = Wall(body, 1, y_wall=-0.1, c=100.0, dissipation_per_commit=0.125)
    s = System([body], contacts=[wall], loads=[DeadLoad(body, [3], -2.0)],
               fixed=[Dirichlet(body, [0, 1])])
    hist = integrate(Static(s), 0.0, np.zeros(s.ndof), n_steps=3)
    uy = hist.u[3]
    # equilibrium: spring (k uy + k3 uy^3) + wall c (uy + 0.1) = -2
    assert uy + 2 * uy ** 3 + 100 * (uy + 0.1) == pytest.approx(-2.0, abs=1e-9)
    assert hist.contact[-1] == pytest.approx(50 * (uy + 0.1) ** 2)
    assert np.allclose(hist.dissipation, [0, 0.125, 0.25, 0.375])
    assert body.commits == 3


def test_central_difference_oscillator():
    k, m = 4.0, 1.0
    body, s = oscillator(k, m)
    w = np.sqrt(k / m)
    dt = 2 * np.pi / w / 40
    xs = []
    hist = integrate(CentralDifference(s, dt), 0.0, np.array([0, 0, 1.0, 0]), n_steps=400,
                     callback=lambda t, u, v, a: xs.append(u[2]))
    # central differences: sin(theta / 2) = omega dt / 2
    T_h = 2 * np.pi * dt / (2 * np.arcsin(w * dt / 2))
    assert zero_crossing_period(hist.t[1:], np.array(xs)) == pytest.approx(T_h, rel=1e-4)
    E = total_energy(hist)
    assert np.max(np.abs(E - E[0])) < (w * dt) ** 2 * E[0]


class FussyNewmark(Newmark):
    """Fails (like a diverging Newton) whenever dt exceeds max_dt."""
    max_dt = 0.03

    def step(self, t, u, v, a, dt=None, label=""):
        if dt > self.max_dt:
            raise NewtonError(f"too large ({label})", [1.0, 2.0], label)
        return super().step(t, u, v, a, dt=dt, label=label)


def test_cutback_halves_the_step_and_keeps_the_time_grid():
    body, s = oscillator()
    hist = integrate(FussyNewmark(s, 0.1), 0.0, np.array([0, 0, 1.0, 0]), n_steps=3,
                     cutback=True, max_cuts=4)
    assert np.allclose(hist.dt[1:], 0.025) and len(hist.t) == 1 + 3 * 4
    assert hist.t[-1] == pytest.approx(0.3) and hist.cuts[1] == 2
    assert body.commits == 12 and body.dt == pytest.approx(0.025)       # the body was told the cut dt
    with pytest.raises(NewtonError, match="step 1") as info:
        integrate(FussyNewmark(s, 0.1), 0.0, np.zeros(4), n_steps=3, cutback=True, max_cuts=1)
    assert info.value.history == [1.0, 2.0] and len(info.value.partial.t) == 1
    with pytest.raises(NewtonError):
        integrate(FussyNewmark(s, 0.1), 0.0, np.zeros(4), n_steps=3)


# -- bad input ------------------------------------------------------------------------

def test_bad_input_raises():
    body, s = oscillator()
    for dt in (0.0, -1.0, np.nan):
        with pytest.raises(ValueError, match="dt"):
            Newmark(s, dt)
    for beta in (0.0, -0.1, 0.6):
        with pytest.raises(ValueError, match="beta"):
            Newmark(s, 0.1, beta=beta)
    for delta in (-0.1, 1.1):
        with pytest.raises(ValueError, match="delta"):
            Newmark(s, 0.1, delta=delta)
    with pytest.warns(UserWarning, match="unconditionally stable"):
        Newmark(s, 0.1, delta=0.5, beta=0.2)
    with pytest.raises(ValueError, match="local_dofs"):
        System([body], fixed=[Dirichlet(body, [4])])
    with pytest.raises(ValueError, match="Dirichlet value"):
        System([body], fixed=[Dirichlet(body, [0, 1], [1.0, 2.0, 3.0])]).prescribed(0.0)
    with pytest.raises(ValueError, match="n_steps"):
        integrate(Static(s), 0.0, np.zeros(4))
    with pytest.raises(ValueError, match="n_steps"):
        integrate(Static(s), 0.0, np.zeros(4), n_steps=2, t_end=1.0)
    with pytest.raises(ValueError, match="n_steps"):
        integrate(Static(s), 0.0, np.zeros(4), n_steps=0)
    with pytest.raises(ValueError, match="mass"):
        CentralDifference(System([SpringChain(2, m=0.0)]), 0.1)


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
