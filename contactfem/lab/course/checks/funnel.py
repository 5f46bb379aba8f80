"""The checks of lecture 07: the funnel."""

import numpy as np

from .answers import call, compare
from .exercise import exercise
from .runs import ScenePart, as_list, counts, memo, scene_model

LECTURE = "07_funnel"


def _escape(escape_angle, p, alpha=0.3, beta=0.1, n=0.75):
    return np.asarray(call(escape_angle, "escape_angle", p, alpha, beta, n), dtype=float)


def escape_values(escape_angle):
    p = np.array([0.05, 0.1, 0.3, 1.0, 3.0])
    want = np.degrees(np.arctan(0.3 * p**-0.25 + 0.1))
    got = _escape(escape_angle, p)
    if got.shape == want.shape and np.allclose(got, np.radians(want)):
        raise AssertionError("your angles are in radians: give degrees (np.degrees)")
    if got.shape == want.shape and np.allclose(got, np.full(p.shape, np.degrees(np.arctan(0.4)))):
        raise AssertionError(
            "your angle does not depend on the pressure: with eq 10 the coefficient is "
            "mu_eff = Y / p = alpha p^(n-1) + beta, not alpha + beta"
        )
    compare(
        "escape angle (deg; alpha = 0.3, beta = 0.1, n = 0.75)",
        got,
        want,
        {"p": p},
        rule="tan(phi) = mu_eff(p) = alpha p^(n-1) + beta",
    )


def escape_coulomb(escape_angle):
    p = np.array([0.1, 1.0, 10.0])
    got = _escape(escape_angle, p, alpha=0.0, beta=0.3, n=1.0)
    compare(
        "escape angle for Coulomb mu = 0.3 (alpha = 0, n = 1)",
        got,
        np.full(3, np.degrees(np.arctan(0.3))),
        {"p": p},
        rule="tan(phi) = mu whatever the pressure",
    )


def escape_steeper(escape_angle):
    lo, hi = _escape(escape_angle, np.array([0.05])), _escape(escape_angle, np.array([1.0]))
    if not float(np.ravel(lo)[0]) > float(np.ravel(hi)[0]):
        raise AssertionError(
            "with n = 0.75 < 1 the effective coefficient falls as the pressure rises, so a lightly "
            "pressed ring holds at a steeper wall: your angle at p = 0.05 should exceed that at p = 1"
        )


def _census(census):
    def run():
        stage = [
            ScenePart("funnel", {"variant": "frictional"}, "stage", k) for k in ("stepper", "schedule", "u0", "v0")
        ]
        return call(census, "census", *stage, timeout=120.0)

    out = memo(("census", census), run)
    return as_list(out, 3, "census", "the times, the nodes in contact and the slipping nodes of each record")


def _census_ref():
    def run():
        from ....solver.march import march

        model, _ = scene_model("funnel", {"variant": "frictional"})
        st = model.stage
        recs = list(march(st.stepper, st.schedule, st.t0, st.u0, st.v0))
        c = np.array([counts(r) for r in recs], float)
        return np.array([r.t for r in recs]), c[:, 0], c[:, 1]

    return memo(("census_ref",), run)


def census_times(census):
    t, _, _ = _census(census)
    want = _census_ref()[0]
    if t.size == want.size - 1:
        raise AssertionError(
            f"your census has {t.size} entries, the run {want.size} records: keep the initial state (record 0) too"
        )
    if t.size != want.size:
        raise AssertionError(f"census should give one entry per record of the march, {want.size}, got {t.size}")
    compare("time of each record", t, want, {"record": np.arange(t.size)})


def census_contact(census):
    _, n_c, _ = _census(census)
    _, want, slip = _census_ref()
    if n_c.size != want.size:
        raise AssertionError(f"census should give one entry per record of the march, {want.size}, got {n_c.size}")
    if np.allclose(n_c, slip) and not np.allclose(n_c, want):
        raise AssertionError(
            "your contact counts are the slipping nodes: a node is in contact when its state "
            "is not OPEN (stick or slip)"
        )
    compare(
        "nodes in contact",
        n_c,
        want,
        {"record": np.arange(n_c.size)},
        rule="rec.contacts[0].slip != OPEN, from the record's converged state",
    )


def census_slip(census):
    _, n_c, n_s = _census(census)
    _, contact, want = _census_ref()
    if n_s.size != want.size:
        raise AssertionError(f"census should give one entry per record of the march, {want.size}, got {n_s.size}")
    if np.allclose(n_s, contact - want) and not np.allclose(n_s, want):
        raise AssertionError("your slip counts are the sticking nodes: count the state SLIP")
    compare(
        "slipping nodes",
        n_s,
        want,
        {"record": np.arange(n_s.size)},
        rule="rec.contacts[0].slip == SLIP, from the record's converged state",
    )


EXERCISES = [
    exercise(
        "ex07_escape_angle",
        LECTURE,
        "easy",
        False,
        "the steepest funnel wall that holds a wedged ring, from the slip surface of eq 10",
        (escape_values, 2),
        (escape_coulomb, 1),
        (escape_steeper, 1),
    ),
    exercise(
        "ex07_census",
        LECTURE,
        "medium",
        True,
        "the funnel's time loop, counting the nodes in contact and slipping from the converged states",
        (census_times, 1),
        (census_contact, 2),
        (census_slip, 2),
    ),
]


BUILDS_ON = {
    "ex07_census": "the scene's stepper solves each step; the answer is the loop and its counts",
}
