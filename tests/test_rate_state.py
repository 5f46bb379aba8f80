"""Friction laws with a slip rate and internal variables: the protocol (backward
compatible), the shipped Stribeck, Dieterich-Ruina and Archard-wear laws through the
checker, the return map and the block (consistent tangent against finite differences,
quadratic Newton), history committed only on convergence, derivatives by complex step,
and the checker's sentence for each common mistake."""

import math
from dataclasses import dataclass

import re

import numpy as np
import pytest
from conftest import PointCloud
from fd import fd_jacobian, rel_error

from contactfem import check_law
from contactfem.contact import NodeToSegment, RigidLine
from contactfem.laws import SLIP, STICK, return_map
from contactfem.laws import ArchardWear, Coulomb, DieterichRuina, FrictionLaw, LawError, PowerLaw, Stribeck
from contactfem.scenes import block
from contactfem.solver import Static

C_T = 5.0e4  # the block's stick stiffness per unit length
RATE_LAWS = {
    "stribeck": Stribeck(c_T=C_T, mu_s=0.32, mu_d=0.28, v_s=0.02, mu_v=0.1),
    "rate_state": DieterichRuina(c_T=C_T, mu_0=0.1, a=0.01, b=0.015, d_c=0.01),
    "wear": ArchardWear(c_T=C_T, mu=0.3, k_w=1e-4),
}
SMALL = [
    Stribeck(c_T=30.0, mu_s=0.5, mu_d=0.3, v_s=0.1, mu_v=0.05),
    Stribeck(c_T=30.0, mu_s=0.3, mu_d=0.5, v_s=0.1, delta=1.0),
    DieterichRuina(c_T=30.0, mu_0=0.4, a=0.01, b=0.015, d_c=0.01),
    DieterichRuina(c_T=30.0, mu_0=0.4, a=0.02, b=0.01, d_c=0.1),
    ArchardWear(c_T=30.0, mu=0.3, k_w=1e-3),
]


@pytest.mark.slow
@pytest.mark.parametrize("dt", [1.0, 1e-3])
@pytest.mark.parametrize("law", SMALL, ids=repr)
def test_shipped_rate_and_state_laws_pass_the_checker(law, dt):
    report = check_law(law, dt=dt)
    assert report.ok, str(report)
    assert "supplied by the law: dY/dp" in str(report)


def test_paper_laws_read_through_the_protocol_unchanged():
    L = FrictionLaw(Coulomb(c_T=3.0, mu=0.3))
    assert (L.arity, L.n_state, L.needs_dt) == (2, 0, False)
    Y, Y_p, Y_q, Y_v, Y_z = L.slip_bound(np.array([1.0, 2.0]), 0.0)
    assert np.allclose(Y, [0.3, 0.6]) and np.allclose(Y_p, 0.3) and np.all(Y_v == 0) and Y_z.shape == (2, 0)


def test_rate_law_return_map_and_history():
    """Stribeck: the slip rate lambda/dt enters; at the same slip increment a smaller dt
    (faster slip) gives the kinetic coefficient; the state of a rate-and-state law
    heals while sticking and is renewed by slip."""
    law = Stribeck(c_T=100.0, mu_s=0.5, mu_d=0.3, v_s=0.01)
    t_N = np.array([-1.0])
    slow = return_map(law, t_N, 0.0, 0.5, 0.0, 0.0, dt=1e4)
    fast = return_map(law, t_N, 0.0, 0.5, 0.0, 0.0, dt=1e-3)
    assert slow.state[0] == fast.state[0] == SLIP
    assert abs(abs(slow.t_T[0]) - 0.5) < 1e-3 and abs(abs(fast.t_T[0]) - 0.3) < 1e-6
    with pytest.raises(ValueError, match="time step"):
        return_map(law, t_N, 0.0, 0.5, 0.0, 0.0)
    dr = DieterichRuina(c_T=100.0, mu_0=0.3, a=0.01, b=0.02, d_c=0.01, theta_0=1.0)
    stick = return_map(dr, t_N, 0.0, 1e-6, 0.0, 0.0, dt=2.0)
    assert stick.state[0] == STICK and np.isclose(stick.z[0, 0], 3.0)  # theta = theta_0 + dt: healing
    slip = return_map(dr, t_N, 0.0, 0.5, 0.0, 0.0, dt=2.0)
    assert slip.state[0] == SLIP and slip.z[0, 0] < 0.1  # renewed by the slip
    assert np.isclose(slip.z[0, 0], 3.0 / (1.0 + slip.lam[0] / 0.01))


def test_history_is_committed_only_on_convergence():
    params = block.SCENE.resolve("fast", {"law": "coulomb", "n_steps": 2})
    s = block.solve(params, friction=RATE_LAWS["wear"])
    c, last = s["contact"], s["records"][-1]
    h = last.state.contacts[0]
    assert np.all(h.z_bar >= 0) and h.z_bar.max() > 0  # worn where it slipped
    assert np.all(h.z_bar[h.q_bar == 0] == 0)  # no wear without slip
    before = h.z_bar.copy()
    c.evaluate(s["u"] * 1.01, dt=0.5, history=h)  # evaluations leave it alone
    assert last.state.contacts[0] is h and np.array_equal(h.z_bar, before)


def test_wear_moves_the_surface():
    """The worn depth opens the gap: a worn node carries less pressure at the same position."""
    law = ArchardWear(c_T=30.0, mu=0.3, k_w=0.5)
    body = PointCloud(np.array([[0.0, 0.0], [1.0, 0.0]]), "slave")
    iface = NodeToSegment(body, [0, 1], RigidLine(), normal=PowerLaw(c_N=100.0), friction=law)
    u = np.array([0.0, -0.02, 0.0, -0.02])
    h = iface.start(u)
    t0 = iface.evaluate(u, dt=1.0, history=h).t_N.copy()
    u1 = u.copy()
    u1[0] = 0.3  # node 0 slides
    h = iface.commit(iface.evaluate(u1, dt=1.0, history=h))
    w = h.z_bar[:, 0]
    assert w[0] > 0 and w[1] == 0
    e = iface.evaluate(u1, dt=1.0, history=h)
    assert np.isclose(e.g_N[0], -0.02 + w[0]) and e.t_N[0] > t0[0]  # less compressive
    assert e.t_N[1] == t0[1]


@pytest.mark.parametrize("name", list(RATE_LAWS))
@pytest.mark.parametrize("n_steps", [1, 3])
def test_block_newton_quadratic_with_rate_and_state_laws(name, n_steps):
    """The paper's block (Sec. 5.1) with each law, the whole load in 1 or 3 steps. Newton's
    last steps are quadratic: with e_k = r_k / r_0, e_{k+1} <= 1e3 e_k^2 (or round-off,
    1e-13) over the last two reductions, and the convergence order estimated from the
    last three residuals above round-off (1e-13), log(e_{k+1}/e_k) / log(e_k/e_{k-1}), is > 1.7
    (2 for exact quadratic convergence; a linear rate gives ~1). The wear law is Coulomb
    on a linear block: piecewise linear, so the last step is exact once the stick/slip
    pattern is settled (one reduction checked, as for Coulomb in test_block.py).
    The contact forces balance the loads."""
    # the canonical block (4 x 3.5, 20 x 10) on which these laws were studied
    params = block.SCENE.resolve("canonical", {"law": "coulomb", "n_steps": n_steps})
    s = block.solve(params, friction=RATE_LAWS[name])
    n_last = 1 if name == "wear" else 2
    for res in s["results"]:
        e = np.array(res.residuals) / res.residuals[0]
        assert e[-1] <= 1e-10 + 1e-12 / res.residuals[0]
        for k in range(max(len(e) - 1 - n_last, 0), len(e) - 1):
            assert e[k + 1] <= max(1e3 * e[k] ** 2, 1e-13), (name, e)
        above = e[e > 1e-13]
        if name != "wear" and len(above) >= 4:
            order = np.log(above[-1] / above[-2]) / np.log(above[-2] / above[-3])
            assert order > 1.7, (name, order, e)
    R = s["R_c"][s["body"].xdofs]
    applied_x, applied_y = params["p_x"] * params["height"], params["p_y"] * params["width"]  # 60 H, 200 W
    assert abs(R[:, 0].sum() - applied_x) < 1e-6 and abs(R[:, 1].sum() + applied_y) < 1e-6
    assert np.sum(s["report"]["state"] == "slip") >= 2


@pytest.mark.parametrize("name", list(RATE_LAWS))
def test_block_tangent_against_finite_differences(name):
    """dG/du of the block (bulk + contact) with each law after a committed first step
    (the state has evolved), at the converged second step: all contact dofs, relative
    error < 1e-6."""
    params = block.SCENE.resolve("fast", {"law": "coulomb", "n_steps": 2})
    s = block.solve(params, friction=RATE_LAWS[name])
    # the same two steps, stopped before committing the second
    sc = block.build(params, friction=RATE_LAWS[name])
    c1, system = sc.parts["contact"], sc.system
    st = Static(system, atol=params["atol"], rtol=params["rtol"], maxit=40)
    u = np.zeros(system.ndof)
    state = system.start(u)
    u, _, _, res = st.step(0.0, u, u, u, 0.5, state=state)
    state = system.commit(res.evaluation, u, 0.5, 0.5)
    u, *_ = st.step(0.5, u, u, u, 0.5, state=state)
    assert np.allclose(u, s["u"], atol=1e-9)
    slip = c1.evaluate(u, 1.0, 0.5, history=state.contacts[0]).slip
    assert np.any(slip == STICK) and np.any(slip == SLIP)
    cols = c1.slave_dofs().ravel()
    K = system.residual_tangent(u, 1.0, dt=0.5, state=state)[1].toarray()[:, cols]
    K_fd = fd_jacobian(lambda w: system.residual_tangent(w, 1.0, dt=0.5, state=state)[0], u, cols, h=1e-7)
    assert rel_error(K, K_fd) < 1e-6


# -- derivatives by complex step and the checker's sentences --------------------------


@dataclass(frozen=True)
class RateOnlyY:
    """A rate-dependent law that gives Y alone: its derivatives come by complex step."""

    c_T: float = 30.0
    mu: float = 0.4
    v_0: float = 0.1

    def slip_bound(self, p, q, v):
        return self.mu * p * (1.0 + 0.2 * np.tanh(q)) / (1.0 + v / self.v_0)


def test_complex_step_derivatives_equal_the_analytic_ones():
    law = Stribeck(c_T=30.0, mu_s=0.5, mu_d=0.3, v_s=0.1, mu_v=0.05)

    @dataclass(frozen=True)
    class StribeckYOnly(Stribeck):
        def slip_bound(self, p, q, v):
            x = np.asarray(v) / self.v_s
            return p * (self.mu_d + (self.mu_s - self.mu_d) * np.exp(-(x**self.delta)) + self.mu_v * np.asarray(v))

    rng = np.random.default_rng(3)
    p, q, v = rng.uniform(0.1, 5, 50), rng.uniform(0, 1, 50), rng.uniform(0, 1, 50)
    A = FrictionLaw(law).slip_bound(p, q, v)
    L = FrictionLaw(StribeckYOnly(**vars(law)))
    B = L.slip_bound(p, q, v)
    for a, b in zip(A[:4], B[:4]):
        assert np.allclose(a, b, rtol=1e-14, atol=1e-15)
    assert L.computed == {"dY/dp", "dY/dq", "dY/dv"} and not L.supplied
    report = str(check_law(RateOnlyY()))
    assert "computed by complex step: dY/dp, dY/dq, dY/dv" in report and "all checks pass" in report


@dataclass(frozen=True)
class WrongDYdp:
    c_T: float = 30.0

    def slip_bound(self, p, q):
        p = np.asarray(p, float)
        return 0.1 * p + 0.01 * p**2, 0.1 + 0.01 * p, 0 * p  # dY/dp misses the factor 2


@dataclass(frozen=True)
class WrongDYdv:
    c_T: float = 30.0

    def slip_bound(self, p, q, v):
        p, v = np.asarray(p, float), np.asarray(v, float)
        return 0.3 * p / (1 + v), 0.3 / (1 + v), 0 * p, 0.3 * p / (1 + v) ** 2  # sign of dY/dv


@dataclass(frozen=True)
class MathTanh:
    c_T: float = 30.0

    def slip_bound(self, p, q):
        return 0.3 * math.tanh(p), 0.3 * (1 - math.tanh(p) ** 2), 0.0


@dataclass(frozen=True)
class TwoValues:
    c_T: float = 30.0

    def slip_bound(self, p, q):
        return 0.3 * np.asarray(p), 0.3


@dataclass(frozen=True)
class NoStickStiffness:
    mu: float = 0.3

    def slip_bound(self, p, q):
        return self.mu * np.asarray(p)


@dataclass(frozen=True)
class CastsToFloat:
    c_T: float = 30.0

    def slip_bound(self, p, q):
        return 0.3 * np.asarray(p, dtype=float)


@dataclass(frozen=True)
class NotFinite:
    c_T: float = 30.0

    def slip_bound(self, p, q):
        return 0.3 * np.sqrt(np.asarray(p) - 0.5)


@dataclass(frozen=True)
class IfElse:
    c_T: float = 30.0

    def slip_bound(self, p, q):
        if p > 1.0:
            return 0.3 * p
        return 0.4 * p


MISTAKES = [
    (WrongDYdp(), "dY/dp does not match finite differences"),
    (WrongDYdv(), "dY/dv does not match finite differences"),
    (MathTanh(), "fails on arrays.*np.tanh, not math.tanh"),
    (TwoValues(), "returned 2 values: it must return Y alone or the 3 values"),
    (NoStickStiffness(), "no stick stiffness c_T"),
    (CastsToFloat(), "casts its arguments to float"),
    (NotFinite(), "NaN or inf"),
    (IfElse(), "if/else.*np.where"),
]


@pytest.mark.parametrize("law,sentence", MISTAKES, ids=lambda x: type(x).__name__ if not isinstance(x, str) else "")
def test_checker_names_each_common_mistake(law, sentence, recwarn):
    report = check_law(law, dt=0.1)
    assert not report.ok
    fails = [s for ok, s in report.checks if not ok]
    assert len(fails) == 1, fails
    assert re.search(sentence, fails[0]), fails[0]
    assert "\n" not in fails[0]
    assert not [w for w in recwarn if "numpy" in str(w.filename)]  # no numpy warnings leak out


def test_a_law_error_in_a_run_is_one_sentence():
    with pytest.raises(LawError, match="returned 2 values"):
        return_map(TwoValues(), np.array([-1.0]), 0.0, 0.5, 0.0, 0.0)
