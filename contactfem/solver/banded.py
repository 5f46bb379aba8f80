"""K_ff du_f = b by LAPACK's banded LU on a fixed sparsity pattern (reverse Cuthill-McKee).

A ring of beam elements (3 dofs a node, the last element closing on the first) couples
each node with its two neighbours only: renumbered by reverse Cuthill-McKee (RCM), its
tangent is a band matrix with a half-bandwidth of a few nodes' dofs (the paper's rolling
ring: kl = ku = 8 for 360 unknowns), and a small continuum mesh is banded too (the block
of Sec. 5.1, 468 unknowns: 35). LAPACK's general band LU with partial pivoting (dgbsv)
then costs about n kl (kl + ku) flops, 55-170 microseconds here, where SuperLU spends
0.3-0.7 ms on the same matrices (its symbolic analysis is redone at every call). Where
the band is wide (a fine 2-D mesh: kl grows like the square root of n) SuperLU's
orderings fill in less and win: BANDED_WORK below.

The tangent with friction is not symmetric (paper eqs 49-50): a general LU with row
interchanges, not a Cholesky factorisation. Pivoting widens the upper band to kl + ku,
hence LAPACK's storage of (2 kl + ku + 1) x n.

A BandPlan is made once per sparsity pattern (the fixed pattern of assembly.py, restricted
to the free dofs): the permutation, kl and ku, and for every stored entry of K the place
it takes in the band storage. A solve only scatters the values there and calls LAPACK.
"""

import numpy as np

from .. import lazy

sp = lazy.module("scipy.sparse")
csgraph = lazy.module("scipy.sparse.csgraph")
lapack = lazy.module("scipy.linalg.lapack")

# The band LU is used while its work per unknown, kl (kl + ku), is at most BANDED_WORK; above,
# SuperLU. What decides is the width of the band, not the number of unknowns: SuperLU's fill
# on these meshes grows like the band's. Measured, factorisation + solve (best of 5-30, 2
# cores shared, so +-30 %), band / SuperLU (MMD_AT_PLUS_A):
#   rolling ring, paper: n = 360, kl = ku = 8 (work 128): 55 / 320 us; 4000 elements: n = 12000,
#     the same band: 1.5 / 9.8 ms;
#   cork (free block): 259, 28 (1568): 84 / 495 us; block: 468, 35 (2450): 170 / 700 us;
#   block strips (lab/bench/cost.py): 200 x 4: 2010, 19 (722): 0.41 / 1.7 ms; 400 x 10: 8822,
#     43 (3698): 7.4 / 16.7 ms; 1000 x 10: 22022, 43: 21 / 42 ms;
#   square blocks: 992, 63 (7938): 1.5 / 2.6 ms; 1722, 83 (13778): 2.6 / 5.3 ms; 3782, 123 (30258):
#     10.8 / 10.6 ms; 6642, 163 (53138): 24 / 27 ms; 10302, 203 (82418): 65 / 38 ms;
#   Hertz, paper: 8385 free, 258 (133128): 38 / 30 ms.
# The band wins by 1.7x or more up to a work of ~1.4e4 and breaks even at ~3e4.
BANDED_WORK = 1.5e4

# Below this many free unknowns the System makes the band plan without asking band_too_wide
# first: the bound excludes the band of a 2-D mesh only from ~1.5e4 dofs on (from a corner it
# gives b >= N / (2 diameter), about the mesh's side in nodes, against sqrt(BANDED_WORK / 2) = 87),
# and a small plan costs what the bound does (Hertz, 2145 unknowns: 0.95 and 0.83 ms).
BOUND_MIN = 10_000


def lapack_dgbsv():
    """LAPACK's general band solver (scipy)."""
    return lapack.dgbsv


def band_too_wide(indptr, indices, n, free=None, work=BANDED_WORK):
    """True when no numbering of the free block of a CSC pattern (indptr, indices, n x n) can
    have a band LU work per unknown kl (kl + ku) of at most ``work``; False when it may (then
    only a BandPlan tells). A few milliseconds where the plan takes a few tenths of a second
    (Hertz on 65k quads: 132098 unknowns, kl = ku = 1026; its plan 0.35-0.45 s).

    The bound: in any numbering whose half-bandwidth is b, the dofs reached within k steps of
    one dof v (a breadth-first search over the pattern) carry numbers within k b of v's, so
    their count is at most 2 k b + 1 and b >= (|B_k(v)| - 1) / (2 k) at every level k. For a
    structurally symmetric pattern kl = ku = b after any symmetric renumbering, so the work is
    2 b^2 at least. An unsymmetric pattern gets no verdict (False): kl alone is not bounded."""
    free = np.arange(n) if free is None else np.asarray(free)
    if free.size < 2:
        return False
    seen = np.ones(n, dtype=bool)  # fixed dofs are never entered
    seen[free] = False
    frontier = free[:1]
    seen[frontier] = True
    last = np.zeros(n, dtype=np.int64)  # to keep one of repeated neighbours
    reached, level, b = 1, 0, 0.0
    while frontier.size:
        start, count = indptr[frontier], indptr[frontier + 1] - indptr[frontier]
        at = np.repeat(start - np.cumsum(count) + count, count) + np.arange(count.sum())
        nxt = indices[at]
        nxt = nxt[~seen[nxt]]
        last[nxt] = np.arange(nxt.size)
        frontier = nxt[last[nxt] == np.arange(nxt.size)]
        seen[frontier] = True
        level += 1
        reached += frontier.size
        b = max(b, (reached - 1) / (2 * level))
        if 2.0 * np.ceil(b) ** 2 > work:  # the bound only grows: no need to search on
            break
    if 2.0 * np.ceil(b) ** 2 <= work:
        return False
    # structural symmetry: the pattern equals its transpose
    t = sp.csr_matrix((np.ones(len(indices)), indices, indptr), shape=(n, n)).tocsc()
    return bool(np.array_equal(t.indptr, indptr) and np.array_equal(t.indices, indices))


class BandPlan:
    """Where each entry of a CSC pattern (indptr, indices, n x n) goes in LAPACK band
    storage after an RCM renumbering of the block ``free`` (None: all dofs)."""

    def __init__(self, indptr, indices, n, free=None):
        self.indptr, self.indices, self.free = indptr, indices, free
        rows = np.asarray(indices, dtype=np.int64)
        cols = np.repeat(np.arange(n), np.diff(indptr))
        if free is None:
            self.take, m = None, n  # every stored entry
        else:
            local = np.full(n, -1)
            local[free] = np.arange(len(free))
            inside = (local[rows] >= 0) & (local[cols] >= 0)
            self.take, m = np.flatnonzero(inside), len(free)
            rows, cols = local[rows[inside]], local[cols[inside]]
        self.n = m
        graph = sp.csr_matrix((np.ones(rows.size), (rows, cols)), shape=(m, m))
        self.perm = csgraph.reverse_cuthill_mckee((graph + graph.T).tocsr(), symmetric_mode=True).astype(np.int64)
        new = np.empty(m, dtype=np.int64)
        new[self.perm] = np.arange(m)
        r, c = new[rows], new[cols]
        self.kl = int(max(np.max(r - c, initial=0), 0))
        self.ku = int(max(np.max(c - r, initial=0), 0))
        self.ldab = 2 * self.kl + self.ku + 1
        self.description = f"reverse Cuthill-McKee, LAPACK banded LU (kl={self.kl}, ku={self.ku})"
        # LAPACK: A(i, j) at ab(kl + ku + i - j, j); ab is held as its transpose (m, ldab), C order
        self.slot = c * self.ldab + (self.kl + self.ku + r - c)

    @property
    def work(self):
        """The band LU's work per unknown, kl (kl + ku) flops (the choice of assembly.py)."""
        return self.kl * (self.kl + self.ku)

    def describe(self):
        return self.description

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
        band = np.zeros((self.n, self.ldab))
        band.ravel()[self.slot] = data if self.take is None else data[self.take]
        _, _, x, info = lapack_dgbsv()(
            self.kl, self.ku, band.T, np.asarray(b, dtype=float)[self.perm], overwrite_ab=True, overwrite_b=True
        )
        if info > 0:
            raise RuntimeError(f"Factor is exactly singular (banded LU: zero pivot U({info}, {info}))")
        if info < 0:
            raise ValueError(f"dgbsv: argument {-info} is invalid")
        out = np.empty(self.n)
        out[self.perm] = x
        return out
