"""What the ring scenes share (Secs 5.2-5.4; not a scene itself): the ring of Secs 5.3-5.4,
the size of a ring model, and the measures a ring scene reads from its records.

    history = ring_history(ring, records)     # t, x_c, v_c, omega, n_contact, n_slip per record
    shots = snapshot_indices(history["t"], every=20)   # which records the figures draw

The contact counts are read from each record's converged contact state: the nodes in contact
and the nodes that slipped in that step, as the return map decided it (before the friction
history moved on).
"""

import numpy as np

from ..laws.return_map import OPEN, SLIP
from .base import Param

# The ring of Sec. 5.3; Sec. 5.4 (the funnel) uses "the same ring".
RING_PARAMS = (
    Param("kind", "beam", choices=("beam", "continuum"),
          doc="beam: the paper's finite-deformation beam; continuum: annulus of quads (plane strain, SVK)"),
    Param("R", 10.0, "L", 0.0, None, low_open=True, doc="mean radius of the ring (paper, Sec. 5.3). The paper gives no "
          "units: any consistent set of length L, time T, force F (mass M = F T^2 / L)"),
    Param("thickness", 1.0, "L", 0.0, None, low_open=True, doc="radial wall thickness h (paper: square section A = 1)"),
    Param("width", 1.0, "L", 0.0, None, low_open=True, doc="out-of-plane depth b (paper: square section A = 1)"),
    Param("E", 100.0, "F/L^2", 0.0, None, low_open=True, doc="Young's modulus (paper)"),
    Param("nu", 0.0, "", -1.0, 0.5, low_open=True, high_open=True, doc="Poisson's ratio (paper)"),
    Param("rho", 0.01, "M/L^3", 0.0, None, low_open=True, doc="density (paper)"),
)


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
    out = dict(t=np.array([r.t for r in records]),
               x_c=np.array([ring.center_of_mass(r.u) for r in records]),
               v_c=np.array([ring.velocity_of_mass(r.v) for r in records]),
               omega=np.array([ring.angular_velocity(r.u, r.v) for r in records]))
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
