"""Quantities carried together with their linearisation.

The consistent tangent of a contact element needs, for every quantity f of the
element's unknowns v (its nodal positions), the value f and its linearisation
Delta f = grad f . Delta v (the paper writes them out by hand for node-to-segment,
eqs 27, 31-32, 37-38; Popp, Gee & Wall (IJNME 79, 2009) do the same for the mortar
quantities: Delta n, Delta xi, Delta D, Delta M). For the mortar segmentation the
bookkeeping runs through several steps (segment frame, projections, clipping,
quadrature), so each intermediate quantity is a ``Jet``: its value and its gradient
with respect to the element's unknowns, vectorised over elements. The arithmetic below
is only the sum, product, quotient and chain rules; nothing is approximated, so a
quantity built from jets has the exact gradient (to round-off), for the branch of every
``where`` taken at the current values.

Shapes: ``val`` (n,), ``grad`` (n, k) for n elements with k unknowns. A plain number or
an array of shape (n,) mixes with jets as a constant.
"""

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class Jet:
    """A scalar per element with its gradient w.r.t. the element's unknowns."""

    val: np.ndarray
    grad: np.ndarray

    __array_ufunc__ = None  # array * jet: numpy defers to Jet.__rmul__

    @staticmethod
    def variables(v):
        """The unknowns themselves: v (n, k) -> k jets, the i-th with gradient e_i."""
        n, k = v.shape
        eye = np.eye(k)
        return [Jet(v[:, i].copy(), np.repeat(eye[i][None], n, axis=0)) for i in range(k)]

    def _lift(self, c):
        """A constant (number or (n,) array) as a jet with zero gradient."""
        if isinstance(c, Jet):
            return c
        return Jet(np.broadcast_to(np.asarray(c, dtype=float), self.val.shape).copy(), np.zeros_like(self.grad))

    def __add__(self, other):
        o = self._lift(other)
        return Jet(self.val + o.val, self.grad + o.grad)

    __radd__ = __add__

    def __neg__(self):
        return Jet(-self.val, -self.grad)

    def __sub__(self, other):
        return self + (-self._lift(other))

    def __rsub__(self, other):
        return self._lift(other) - self

    def __mul__(self, other):
        if not isinstance(other, Jet):  # a constant factor
            c = np.asarray(other, dtype=float)
            return Jet(self.val * c, self.grad * c[..., None])
        # product rule: Delta(fg) = Delta f g + f Delta g
        return Jet(self.val * other.val, self.grad * other.val[:, None] + self.val[:, None] * other.grad)

    __rmul__ = __mul__

    def reciprocal(self):
        """Delta(1/f) = -Delta f / f^2."""
        r = 1.0 / self.val
        return Jet(r, -self.grad * (r**2)[:, None])

    def __truediv__(self, other):
        if not isinstance(other, Jet):
            return self * (1.0 / np.asarray(other, dtype=float))
        return self * other.reciprocal()

    def __rtruediv__(self, other):
        return self.reciprocal() * other

    def sqrt(self):
        """Delta sqrt(f) = Delta f / (2 sqrt(f))."""
        s = np.sqrt(self.val)
        return Jet(s, self.grad / (2.0 * s)[:, None])

    @staticmethod
    def where(mask, a, b):
        """a where mask, else b (elementwise; a or b may be constants). The gradient is
        that of the branch taken: exact away from the switch, as for any kink."""
        like = a if isinstance(a, Jet) else b
        a, b = like._lift(a), like._lift(b)
        return Jet(np.where(mask, a.val, b.val), np.where(mask[:, None], a.grad, b.grad))
