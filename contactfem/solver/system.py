"""The System: bodies, contacts, loads and Dirichlet conditions in one global vector.

The System implements the static part of the paper's equation of motion (eq 29),

    G(u, t) = R(u) + R_c(u) - P(u, t),

with R the internal forces of the bodies, R_c the contact residual (eq 28) and P
the external loads, together with its tangent K = dG/du = K_int + K_c - dP/du.
The inertia term M a of eq 29 is added by the time steppers (newmark.py).

Bodies are placed one after another in the global vector: body b owns the global
dofs ``b.dof_offset + local``.

K is a dense numpy array for small systems and a scipy CSC matrix on a fixed sparsity
pattern above, solved by LAPACK's banded LU where the pattern is a narrow band after
renumbering, else by SuperLU (``System.linear_algebra``, chosen automatically: assembly.py).
"""
import numpy as np

from .assembly import TangentAssembler


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
            raise ValueError(f"Dirichlet value must be a scalar or have {self.local_dofs.size} "
                             f"entries (one per dof), got {value.size}")
        return np.broadcast_to(value.ravel() if value.ndim else value, self.local_dofs.shape)


def _triplets(rows, cols, vals):
    """COO triplets as three flat arrays (accepts lists and empty inputs)."""
    return (np.asarray(rows, dtype=int).ravel(), np.asarray(cols, dtype=int).ravel(),
            np.asarray(vals, dtype=float).ravel())


def as_array(K):
    """A tangent as a dense numpy array, whether the System assembled it dense or sparse."""
    return K.toarray() if hasattr(K, "toarray") else np.asarray(K)


class System:
    """Bodies, contacts, loads and Dirichlet conditions assembled into one problem.

    Parameters
    ----------
    bodies   : list of bodies (the interface of contactfem.bodies)
    contacts : list of contacts, ``assemble(u) -> (R_c, rows, cols, vals)``
    loads    : list of loads, ``assemble(u, t) -> (P, rows, cols, vals)``
    fixed    : list of Dirichlet conditions
    linear_algebra : "auto" (dense up to assembly.DENSE_MAX unknowns; above, banded where the
               band LU is cheap, else sparse), "dense", "sparse" or "banded"; None (default):
               ``System.default_linear_algebra`` ("auto"; ``run_scene(..., linear_algebra=...)``
               and ``contactfem run --linear-algebra`` set it for the Systems a scene builds)

    Attributes: ``ndof``, ``fixed_dofs`` and ``free_dofs`` (global, sorted),
    ``dissipation`` (frictional dissipation summed over all committed steps),
    ``linear_algebra`` ("dense", "sparse" or "banded"; "banded+sparse" if the choice changed
    as the contact pattern grew) and ``ordering`` (of the factorisation).
    """

    built = None     # a list while contactfem.scenes.run_scene records the Systems a scene builds
    default_linear_algebra = "auto"      # what linear_algebra=None means (run_scene may set it)

    def __init__(self, bodies, contacts=(), loads=(), fixed=(), linear_algebra=None):
        self.bodies = list(bodies)
        self.contacts = list(contacts)
        self.loads = list(loads)
        self.fixed = list(fixed)
        if not self.bodies:
            raise ValueError("bodies must contain at least one body")

        offset = 0
        for body in self.bodies:
            body.dof_offset = offset
            offset += body.ndof
        self.ndof = offset

        for d in self.fixed:
            if d.body not in self.bodies:
                raise ValueError(f"Dirichlet condition on body {d.body.name!r}, which is not in bodies")
            if np.any(d.local_dofs < 0) or np.any(d.local_dofs >= d.body.ndof):
                raise ValueError(f"Dirichlet local_dofs of body {d.body.name!r} must be in "
                                 f"[0, {d.body.ndof - 1}]")
        self.fixed_dofs = np.unique(np.concatenate(
            [self.global_dofs(d.body, d.local_dofs) for d in self.fixed] + [np.zeros(0, int)]))
        self.free_dofs = np.setdiff1d(np.arange(self.ndof), self.fixed_dofs)
        self.dissipation = 0.0
        self._mass = None
        if linear_algebra is None:
            linear_algebra = System.default_linear_algebra
        self._tangent = TangentAssembler(self.ndof, linear_algebra, self.free_dofs)
        self._body_coo = {}          # body -> (K, rows, cols) of its last sparse tangent
        if System.built is not None:
            System.built.append(self)

    @property
    def linear_algebra(self):
        """How K is held and solved: dense, sparse or banded (assembly.py)."""
        return self._tangent.describe()[0]

    @property
    def ordering(self):
        """The ordering of the factorisation (e.g. the band's kl and ku)."""
        return self._tangent.describe()[1]

    @property
    def band(self):
        """(kl, ku), the half-bandwidths below and above the diagonal of K renumbered by reverse
        Cuthill-McKee, of the last K solved banded; None when no K was."""
        plan = self._tangent.banded_plan                # of the last K solved banded
        return (plan.kl, plan.ku) if plan is not None else None

    def global_dofs(self, body, local):
        """Global numbers of a body's local dofs."""
        return body.dof_offset + np.asarray(local, dtype=int)

    def local(self, body, u):
        """The body's own part (a view) of a global vector."""
        return u[body.dof_offset:body.dof_offset + body.ndof]

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
        u[self.fixed_dofs] = self.prescribed(t)
        return u

    # -- assembly ---------------------------------------------------------------

    def mass(self):
        """Global lumped (diagonal) mass, (ndof,)."""
        if self._mass is None:
            self._mass = np.concatenate([np.asarray(b.mass(), dtype=float) for b in self.bodies])
        return self._mass

    def external_force(self, u, t):
        """P(u, t), the sum of all loads (ndof,)."""
        P = np.zeros(self.ndof)
        for load in self.loads:
            P += load.assemble(u, t)[0]
        return P

    def _body_triplets(self, body, u_local):
        """R and the COO triplets of a body's tangent. Bodies with ``internal_coo`` (the
        beam) give constant index arrays; a sparse K (the continuum) is converted, reusing
        the index arrays while its pattern stays the same."""
        if hasattr(body, "internal_coo"):
            return body.internal_coo(u_local)
        R, K = body.internal(u_local)
        K = K.tocsr()
        last = self._body_coo.get(body)
        if last is not None and (last[0] is K or (np.array_equal(last[0].indptr, K.indptr)
                                                   and np.array_equal(last[0].indices, K.indices))):
            rows, cols = last[1], last[2]
        else:
            rows = np.repeat(np.arange(K.shape[0]), np.diff(K.indptr))
            cols = K.indices
        self._body_coo[body] = (K, rows, cols)
        return R, rows, cols, K.data

    def residual_tangent(self, u, t, mass_coefficient=0.0):
        """G = R(u) + R_c(u) - P(u, t) (static part of eq 29) and K = dG/du.

        With ``mass_coefficient`` c > 0, K + c M is returned instead (M the lumped mass):
        the effective tangent of an implicit time stepper (Newmark: c = 1 / (beta dt^2)).
        K is a dense array or a CSC matrix (``self.linear_algebra``; banded: a CSC matrix
        that carries its band plan, ``K.band_plan``); all contributions
        arrive as COO triplets and are summed into it once (duplicates add up).
        """
        u = np.asarray(u, dtype=float)
        if u.shape != (self.ndof,):
            raise ValueError(f"u must have shape ({self.ndof},), got {u.shape}")
        G = np.zeros(self.ndof)
        blocks = []                                    # (rows, cols, vals, offset, key)

        for body in self.bodies:                       # block diagonal: internal forces
            off = body.dof_offset
            R, rows, cols, vals = self._body_triplets(body, u[off:off + body.ndof])
            G[off:off + body.ndof] += R
            blocks.append((rows, cols, vals, off, body))

        for contact in self.contacts:                  # contact residual eq 28 and its tangent
            Rc, r, c, v = contact.assemble(u)
            G += Rc
            blocks.append((*_triplets(r, c, v), 0, None))

        for load in self.loads:                        # loads enter with a minus sign
            P, r, c, v = load.assemble(u, t)
            G -= P
            r, c, v = _triplets(r, c, v)
            blocks.append((r, c, -v, 0, None))

        K = self._tangent.assemble(blocks, mass_coefficient * self.mass() if mass_coefficient else None)
        return G, K

    def set_dt(self, dt):
        """Tell rate-dependent bodies (viscoplastic beam) and contacts (friction laws with
        a slip rate or internal variables) the step size: their ``set_dt``."""
        for part in self.bodies + self.contacts:
            if hasattr(part, "set_dt"):
                part.set_dt(dt)

    # -- history and energies ---------------------------------------------------

    def commit(self, u):
        """Accept u as converged: bodies and contacts update their history, and the
        frictional dissipation of the step is added to ``self.dissipation``."""
        for body in self.bodies:
            body.commit(self.local(body, u).copy())
        for contact in self.contacts:
            contact.commit(u)
            self.dissipation += float(contact.dissipation)

    def energies(self, u, v):
        """Kinetic (1/2 v.M v), strain and contact energy, and the accumulated
        frictional dissipation, as a dict of floats."""
        return {
            "kinetic": 0.5 * float(np.dot(v, self.mass() * v)),
            "strain": float(sum(b.strain_energy(self.local(b, u)) for b in self.bodies)),
            "contact": float(sum(c.energy(u) for c in self.contacts)),
            "dissipation": self.dissipation,
        }
