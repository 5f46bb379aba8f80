"""What the ring scenes share (Secs 5.2-5.4; not a scene itself): the ring of Secs 5.3-5.4,
the size of a ring model, the measures a ring scene reads from its records, the
rigid ring's closed form that the rolling ring is compared with, and the bound of an
impact's penalty pressure (``penalty_pressure``).

    history = ring_history(ring, records)     # t, x_c, v_c, omega, n_contact, n_slip per record
    shots = snapshot_indices(history["t"], every=20)   # which records the figures draw

The contact counts are read from each record's converged contact state: the nodes in contact
and the nodes that slipped in that step, as the return map decided it (before the friction
history moved on).
"""

import numpy as np

from ..laws.return_map import OPEN, SLIP
from ..problem.scene import Limit, Param

# The mass matrix of every ring scene (the scan does not say which the paper used).
MASS_MATRIX_PARAM = Param(
    "mass_matrix",
    "lumped",
    choices=("lumped", "consistent"),
    doc="the ring's mass: lumped (diagonal, row sums; our default) or consistent (the P1 mass matrix of the "
    "beam's translations and rotations, scikit-fem's mass form for the continuum); the scan does not say",
)

# A ring's wall is thinner than its diameter: thickness in (0, 2 R) (the ring builders assert it).
THICKNESS_LIMIT = Limit(("R",), lambda v: (None, 2.0 * v["R"]), "(0, 2 R)")

# The ring of Sec. 5.3; Sec. 5.4 (the funnel) uses "the same ring".
RING_PARAMS = (
    Param(
        "kind",
        "beam",
        choices=("beam", "continuum"),
        doc="beam: the paper's finite-deformation beam; continuum: annulus of quads (plane strain, SVK)",
    ),
    Param(
        "R",
        10.0,
        "L",
        0.0,
        None,
        low_open=True,
        doc="mean radius of the ring (paper, Sec. 5.3). The paper gives no "
        "units: any consistent set of length L, time T, force F (mass M = F T^2 / L)",
    ),
    Param(
        "thickness",
        1.0,
        "L",
        0.0,
        None,
        low_open=True,
        high_open=True,
        limit=THICKNESS_LIMIT,
        doc="radial wall thickness h (paper: square section A = 1)",
    ),
    Param("width", 1.0, "L", 0.0, None, low_open=True, doc="out-of-plane depth b (paper: square section A = 1)"),
    Param("E", 100.0, "F/L^2", 0.0, None, low_open=True, doc="Young's modulus (paper)"),
    Param("nu", 0.0, "", -1.0, 0.5, low_open=True, high_open=True, doc="Poisson's ratio (paper)"),
    Param("rho", 0.01, "M/L^3", 0.0, None, low_open=True, doc="density (paper)"),
)


# a ring of fewer than 8 elements (45 degrees each) is a polygon, not a ring (its sides lie 7.6 % of the radius
# inside the circle): no coarser level of a ladder goes below it
RING_FLOOR = 8


def ring_size(p, half=False):
    """Elements and unknowns of the ring of make_ring (beam: 3 dofs a node; continuum: an
    annulus of n_el x n_radial quads)."""
    n = p["n_el"]
    if p["kind"] == "beam":
        return dict(elements=n, unknowns=3 * (n + (1 if half else 0)))
    nr = p.get("n_radial", 2)
    return dict(elements=n * nr, unknowns=2 * (n + (1 if half else 0)) * (nr + 1))


def ring_history(ring, records, measures=None):
    """Per record (arrays): t, the centre of mass x_c and its velocity v_c (2-vectors, of the
    whole mirrored ring for a half ring), the spin omega, and from the record's first contact
    state the nodes in contact (n_contact) and slipping in the step (n_slip); ``measures``,
    name -> f(u, v), more numbers per record."""
    U, V = np.array([r.u for r in records]), np.array([r.v for r in records])  # one record a row
    out = dict(
        t=np.array([r.t for r in records]),
        x_c=ring.center_of_mass(U),
        v_c=ring.velocity_of_mass(V),
        omega=ring.angular_velocity(U, V),
    )
    if records and records[0].contacts:
        out["n_contact"] = np.array([int(np.count_nonzero(r.contacts[0].slip != OPEN)) for r in records])
        out["n_slip"] = np.array([int(np.count_nonzero(r.contacts[0].slip == SLIP)) for r in records])
    for name, f in (measures or {}).items():
        out[name] = np.array([f(r.u, r.v) for r in records])
    return out


def snapshot_indices(t, every=None, interval=None, tol=0.0):
    """The records a figure draws: every ``every``-th, or one each ``interval`` of time (the
    first record at or after each multiple of it, within ``tol``)."""
    if (every is None) == (interval is None):
        raise ValueError("give exactly one of every (records) and interval (time) for the snapshots")
    if every is not None:
        return list(range(0, len(t), int(every)))
    picked, due = [], 0.0
    for k, tk in enumerate(t):
        if tk >= due - tol:
            picked.append(k)
            due += interval
    return picked


def rigid_ring_exact(v0, mu, g, a, k2=None, t=None):
    """Closed form of the sliding-then-rolling rigid ring (module docstring).

    a: lever arm of the friction force (contact radius), k2: squared radius of gyration
    about the centre (default a^2, the thin hoop). Returns dict t_star, x_star, v_star,
    omega_star, and, if t is given, x(t), v(t), omega(t) as arrays.
    """
    for name, val in (("v0", v0), ("mu", mu), ("g", g), ("a", a)):
        if not (np.isfinite(val) and val > 0):
            raise ValueError(f"parameter {name} = {val!r} is out of range: allowed (0, inf)")
    k2 = a * a if k2 is None else k2
    if not (np.isfinite(k2) and k2 > 0):
        raise ValueError(f"parameter k2 = {k2!r} is out of range: allowed (0, inf)")
    r = a * a / k2
    t_star = v0 / (mu * g * (1 + r))
    x_star = v0 * t_star - 0.5 * mu * g * t_star**2
    v_star = v0 - mu * g * t_star
    out = dict(t_star=t_star, x_star=x_star, v_star=v_star, omega_star=-v_star / a)
    if t is not None:
        t = np.asarray(t, float)
        ts = np.minimum(t, t_star)
        out["x"] = v0 * ts - 0.5 * mu * g * ts**2 + v_star * np.maximum(t - t_star, 0.0)
        out["v"] = v0 - mu * g * ts
        out["omega"] = -mu * g * a * ts / k2
    return out


def detect_rolling(t, slip, v0, lo=0.1, hi=0.9, roll=0.02):
    """t_roll from the slip-velocity history (module docstring): the least-squares line
    through the sliding samples lo v0 < s < hi v0 (before s first drops below roll v0),
    extended to s = 0. Returns None if s never drops below roll v0."""
    t, slip = np.asarray(t, float), np.asarray(slip, float)
    below = np.flatnonzero(slip < roll * v0)
    if below.size == 0:
        return None
    k = below[0]
    sel = np.flatnonzero((slip[:k] > lo * v0) & (slip[:k] < hi * v0))
    if sel.size < 2:  # too few sliding samples: interpolate the crossing
        if k == 0:
            return float(t[0])
        s0, s1 = slip[k - 1], slip[k]
        return float(t[k - 1] + (t[k] - t[k - 1]) * s0 / (s0 - s1)) if s0 > s1 else float(t[k])
    A = np.column_stack([t[sel], np.ones(sel.size)])
    slope, icpt = np.linalg.lstsq(A, slip[sel], rcond=None)[0]
    if not slope < 0:
        return float(t[k])
    return float(-icpt / slope)


def ring_gyration_radius2(ring):
    """k^2 = I_c / m of the undeformed model ring from its masses (and the beam's rotary
    inertia): R^2 + h^2/12 (beam), about R^2 + h^2/4 (continuum annulus); with a consistent
    mass, I_c of that mass (RingModel.moment_of_inertia)."""
    if ring.body.mass_matrix == "consistent":
        return float(ring.moment_of_inertia() / ring.total_mass())
    M = ring.body.mass()
    b = ring.body
    mx = M[b.xdofs[:, 0]]
    r2 = np.sum((b.X - ring.center) ** 2, axis=1)
    J = M[2::3].sum() if ring.kind == "beam" else 0.0
    return float((mx @ r2 + J) / mx.sum())


def penalty_pressure(energy, c_N, m=1.0, weight=1.0):
    """The pressure c_N a^m of the penalty law (eq 4) at the penetration a where one node of
    weight `weight` stores all of `energy`: w c_N a^(m+1) / (m+1) = energy. A bound of the
    pressures of a run whose energy is `energy` (a scene's law_range)."""
    a = ((m + 1.0) * energy / (weight * c_N)) ** (1.0 / (m + 1.0))
    return c_N * a**m
