"""K_ff du_f = b by LAPACK's banded LU on a fixed sparsity pattern (reverse Cuthill-McKee).

A ring of beam elements (3 dofs a node, the last element closing on the first) couples
each node with its two neighbours only: renumbered by reverse Cuthill-McKee (RCM), its
tangent is a band matrix with a half-bandwidth of a few nodes' dofs (the paper's rolling
ring: kl = ku = 8 for 360 unknowns), and a small continuum mesh is banded too (the block
of Sec. 5.1, 468 unknowns: 35). LAPACK's general band LU with partial pivoting (dgbsv)
then costs about n kl (kl + ku) flops, 55-170 microseconds here, where SuperLU spends
0.3-0.7 ms on the same matrices (its symbolic analysis is redone at every call).

The tangent with friction is not symmetric (paper eqs 49-50): a general LU with row
interchanges, not a Cholesky factorisation. Pivoting widens the upper band to kl + ku,
hence LAPACK's storage of (2 kl + ku + 1) x n.

A BandPlan is made once per sparsity pattern (the fixed pattern of assembly.py, restricted
to the free dofs): the permutation, kl and ku, and for every stored entry of K the place
it takes in the band storage. A solve only scatters the values there and calls LAPACK.
"""

import numpy as np

# Above this many flops (n kl (kl + ku), the work of the band LU) SuperLU is used instead.
# Measured, factorisation + solve (best of 7-30, 2 cores shared, so +-30 %): the paper's
# rolling ring (n = 360, kl = ku = 8, 4.6e4 flops) 55 us against SuperLU's 320 us; cork
# (259 free, 28, 4.1e5) 84 against 495 us; block (468, 35, 1.2e6) 170 against 700 us.
# The block refined (studies/bench/cost.py): 992 unknowns (kl 63, 7.9e6 flops) 1.5 ms
# against 2.6 ms; 1722 (83, 2.4e7) 2.6 against 5.3 ms; 3782 (123, 1.1e8) even; 10302
# (203, 8.5e8) 65 against 38 ms; Hertz (8385 free, 258, 1.1e9) 38 against 30 ms. The band
# wins clearly (at least 1.7x) up to ~2e7 flops; the limit keeps a margin below that.
BANDED_FLOPS = 1.0e7


class BandPlan:
    """Where each entry of a CSC pattern (indptr, indices, n x n) goes in LAPACK band
    storage after an RCM renumbering of the block ``free`` (None: all dofs)."""

    def __init__(self, indptr, indices, n, free=None):
        import scipy.sparse as sp
        from scipy.sparse.csgraph import reverse_cuthill_mckee

        self.indptr, self.indices, self.free = indptr, indices, free
        rows = np.asarray(indices, dtype=np.int64)
        cols = np.repeat(np.arange(n), np.diff(indptr))
        if free is None:
            self.take, m = None, n                             # every stored entry
        else:
            local = np.full(n, -1)
            local[free] = np.arange(len(free))
            inside = (local[rows] >= 0) & (local[cols] >= 0)
            self.take, m = np.flatnonzero(inside), len(free)
            rows, cols = local[rows[inside]], local[cols[inside]]
        self.n = m
        graph = sp.csr_matrix((np.ones(rows.size), (rows, cols)), shape=(m, m))
        self.perm = reverse_cuthill_mckee((graph + graph.T).tocsr(), symmetric_mode=True).astype(np.int64)
        new = np.empty(m, dtype=np.int64)
        new[self.perm] = np.arange(m)
        r, c = new[rows], new[cols]
        self.kl = int(max(np.max(r - c, initial=0), 0))
        self.ku = int(max(np.max(c - r, initial=0), 0))
        self.ldab = 2 * self.kl + self.ku + 1
        # LAPACK: A(i, j) at ab(kl + ku + i - j, j); ab is held as its transpose (m, ldab), C order
        self.slot = c * self.ldab + (self.kl + self.ku + r - c)

    @property
    def flops(self):
        """The work of the band LU, n kl (kl + ku) (the choice of assembly.py)."""
        return self.n * self.kl * (self.kl + self.ku)

    def describe(self):
        return f"reverse Cuthill-McKee, LAPACK banded LU (kl={self.kl}, ku={self.ku})"

    def fits(self, K, free):
        """Whether K has this plan's pattern (the same index arrays) and free its free dofs."""
        if K.indptr is not self.indptr or K.indices is not self.indices:
            return False
        if self.free is None:
            return free is None or (len(free) == self.n and np.array_equal(free, np.arange(self.n)))
        return free is self.free or np.array_equal(free, self.free)

    def solve(self, data, b):
        """x from A x = b, A the matrix with values ``data`` (of the CSC pattern), on the block.
        Raises RuntimeError on an exactly singular matrix (a zero pivot), like SuperLU."""
        from scipy.linalg.lapack import dgbsv

        band = np.zeros((self.n, self.ldab))
        band.ravel()[self.slot] = data if self.take is None else data[self.take]
        _, _, x, info = dgbsv(self.kl, self.ku, band.T, np.asarray(b, dtype=float)[self.perm],
                              overwrite_ab=True, overwrite_b=True)
        if info > 0:
            raise RuntimeError(f"Factor is exactly singular (banded LU: zero pivot U({info}, {info}))")
        if info < 0:
            raise ValueError(f"dgbsv: argument {-info} is invalid")
        out = np.empty(self.n)
        out[self.perm] = x
        return out
