"""The checks of lecture 04: the block."""

import numpy as np

from .answers import call, compare
from .exercise import exercise
from .runs import ScenePart, as_list, counts, memo, scene_model

LECTURE = "04_block"


def _margin_cases():
    from ....laws import Coulomb, ParabolicSlip

    t_N = -np.array([10.0, 40.0, 90.0, 160.0, 250.0, 2.0])
    t_T = np.array([5.0, -14.0, 20.0, -30.0, 80.0, 1.0])
    return t_N, t_T, (ParabolicSlip(c_T=1e4, alpha=0.2, beta=0.3, n=0.5), Coulomb(c_T=1e4, mu=0.3))


def _margin(slip_margin, t_N, t_T, law):
    return np.asarray(call(slip_margin, "slip_margin", t_N, t_T, law), dtype=float)


def margin_parabolic(slip_margin):
    t_N, t_T, (law, _) = _margin_cases()
    want = np.abs(t_T) - law.slip_bound(-t_N, 0 * t_N)[0]
    got = _margin(slip_margin, t_N, t_T, law)
    at = {"t_N": t_N, "t_T": t_T}
    if got.shape == want.shape and np.allclose(got, t_T - law.slip_bound(-t_N, 0 * t_N)[0]):
        raise AssertionError(
            "your f is wrong where t_T < 0: the slip condition bounds the size of the "
            "friction traction, f = |t_T| - Y(|t_N|)"
        )
    compare(
        "f = |t_T| - Y(|t_N|) (parabolic law, n = 0.5)",
        got,
        want,
        at,
        rule="Y(p) = law.slip_bound(p, q)[0] with the pressure p = |t_N| = -t_N and q = 0",
    )


def margin_coulomb(slip_margin):
    t_N, t_T, (_, law) = _margin_cases()
    got = _margin(slip_margin, t_N, t_T, law)
    compare(
        "f = |t_T| - mu |t_N| (Coulomb, mu = 0.3)",
        got,
        np.abs(t_T) + 0.3 * t_N,
        {"t_N": t_N, "t_T": t_T},
        rule="the pressure is |t_N| = -t_N > 0 in contact",
    )


def margin_block(slip_margin):
    """On the block's converged state: f <= 0 everywhere and f = 0 at the slipping nodes."""
    from ....laws.return_map import SLIP

    def run():
        from ....solver.march import march
        from ....scenes.block import friction_law

        model, P = scene_model("block", {"law": "conical"})
        st = model.stage
        last = list(march(st.stepper, st.schedule, st.t0, st.u0))[-1].contacts[0]
        return last, friction_law(P)

    state, law = memo(("block", "conical"), run)
    f = _margin(slip_margin, state.t_N, state.t_T, law)
    scale = float(np.max(np.abs(state.t_N)))
    slip = state.slip == SLIP
    if f.shape != slip.shape:
        raise AssertionError(f"slip_margin should return one value per node, {slip.size} here, got shape {f.shape}")
    if np.max(f) > 1e-9 * scale:
        i = int(np.argmax(f))
        raise AssertionError(
            f"on the converged block your f is {f[i]:.4g} > 0 at x = {state.x_s[i, 0]:.3g}: "
            "a converged state never violates its slip condition; check |t_N| and the law"
        )
    if np.any(np.abs(f[slip]) > 1e-9 * scale):
        raise AssertionError(
            "on the converged block your f is not 0 at the slipping nodes: a slipping node "
            "sits on its slip surface, |t_T| = Y(|t_N|)"
        )


def _load_steps(load_steps, n):
    def run():
        stepper = ScenePart("block", {"law": "conical"}, "parts", "stepper")
        return call(load_steps, "load_steps", stepper, n, timeout=60.0)

    out = memo(("load_steps", load_steps, n), run)
    return as_list(out, 3, "load_steps", "the pseudo-times, the linear solves and the slipping nodes of each step")


def _load_steps_ref(n):
    def run():
        from ....solver import Steps
        from ....solver.march import march

        model, _ = scene_model("block", {"law": "conical"})
        recs = list(march(model.parts["stepper"], Steps(1.0 / n, n_steps=n), 0.0, np.zeros(model.system.ndof)))[1:]
        return (
            np.array([r.t for r in recs]),
            np.array([r.iterations for r in recs], float),
            np.array([counts(r)[1] for r in recs], float),
            np.array([counts(r)[0] for r in recs], float),
        )

    return memo(("load_steps_ref", n), run)


def load_steps_times(load_steps):
    t, _, _ = _load_steps(load_steps, 4)
    want = _load_steps_ref(4)[0]
    if t.size == want.size + 1 and t[0] == 0.0:
        raise AssertionError(
            "your lists have 5 entries for 4 load steps: the first record of march is the "
            "initial state (k = 0, t = 0); keep the records with k >= 1"
        )
    if t.size != want.size:
        raise AssertionError(f"load_steps(stepper, 4) should give one entry per load step, 4, got {t.size}")
    compare("pseudo-time of each load step", t, want, {"step": np.arange(1, 5)}, rule="Steps(1 / n, n_steps=n)")


def load_steps_solves(load_steps):
    _, its, _ = _load_steps(load_steps, 4)
    want = _load_steps_ref(4)[1]
    if its.size != want.size:
        raise AssertionError(f"load_steps(stepper, 4) should give one entry per load step, 4, got {its.size}")
    compare(
        "linear solves of each load step", its, want, {"step": np.arange(1, 5)}, rule="rec.iterations of each record"
    )


def load_steps_slipping(load_steps):
    _, _, slip = _load_steps(load_steps, 4)
    _, _, want, contact = _load_steps_ref(4)
    if slip.size != want.size:
        raise AssertionError(f"load_steps(stepper, 4) should give one entry per load step, 4, got {slip.size}")
    if np.allclose(slip, contact) and not np.allclose(slip, want):
        raise AssertionError(
            "your counts are the nodes in contact, not the slipping ones: count the nodes "
            "whose state is SLIP (rec.contacts[0].slip == SLIP, or rec.contacts[0].n_slip)"
        )
    if np.allclose(slip, contact - want) and not np.allclose(slip, want):
        raise AssertionError("your counts are the sticking nodes: count the nodes whose state is SLIP")
    compare(
        "slipping nodes after each load step",
        slip,
        want,
        {"step": np.arange(1, 5)},
        rule="read them from the record's converged state, rec.contacts[0].slip == SLIP",
    )


def load_steps_one(load_steps):
    t, its, slip = _load_steps(load_steps, 1)
    want = _load_steps_ref(1)
    compare(
        "the whole load in one step: (t, solves, slipping nodes)",
        np.r_[t, its, slip],
        np.r_[want[0], want[1], want[2]],
        {"entry": ["t", "solves", "slipping"]},
        rule="n = 1 is the paper's single step",
    )


EXERCISES = [
    exercise(
        "ex04_slip_margin",
        LECTURE,
        "easy",
        True,
        "the slip condition of eq 10 at every contact node, on the converged block",
        (margin_parabolic, 2),
        (margin_coulomb, 1),
        (margin_block, 2),
    ),
    exercise(
        "ex04_load_steps",
        LECTURE,
        "medium",
        True,
        "the block's time loop in n load steps, recording the slip from the converged contact states",
        (load_steps_times, 1),
        (load_steps_solves, 1),
        (load_steps_slipping, 2),
        (load_steps_one, 1),
    ),
]


BUILDS_ON = {
    "ex04_slip_margin": "the law's own slip_bound gives the bound Y; the answer is the margin over the nodes",
    "ex04_load_steps": "the scene's stepper solves each step; the answer is the loop and what it records",
}
