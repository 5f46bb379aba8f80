"""K_ff du_f = b by SuperLU after a nested-dissection renumbering (METIS) of a fixed pattern.

SuperLU orders the columns itself (minimum degree of A^T + A, newton.ORDERING) at every
factorisation. On a fine 2-D mesh nested dissection fills in less: split the mesh's graph by a
small set of dofs (a separator) into two halves, number the halves first, each split again the
same way, and the separator last; then eliminating one half never fills into the other, and
the factors of an n-dof 2-D mesh hold O(n log n) entries. METIS (Karypis & Kumar) computes
such orderings by multilevel graph partitioning; ``pymetis`` is its Python binding.

Measured on Hertz's tangent (plane strain, 2 dofs a node), the ordering + factorisation +
solve, against SuperLU with its own MMD_AT_PLUS_A ordering (best of 3, loaded 2 cores):
33k unknowns 0.20 s (fill 4.6M entries) against 0.22-0.24 s (5.7M); 132k unknowns 1.1-1.2 s
(22M) against 1.7-1.9 s (32M). Below ~10^4 unknowns the ordering costs what it saves:
DISSECTION_MIN.

The graph METIS orders is the pattern's free block with the dofs of a node merged (dofs
whose columns in the pattern are the same, a "supervariable": a continuum node's two dofs),
each weighted by its dof count: half the vertices and a quarter of the edges of the dof graph.
A DissectionPlan is made once per pattern (assembly.py), like banded.BandPlan: the
permutation and, for every stored entry of K, its place in the permuted free block. A solve
scatters the values there and calls SuperLU with that column order (NATURAL), with its
partial pivoting (the tangent with friction is not symmetric).
"""

import numpy as np

from .. import lazy
from .banded import BandPlan

sp = lazy.module("scipy.sparse")
linalg = lazy.module("scipy.sparse.linalg")
pymetis = lazy.module("pymetis")

DISSECTION_MIN = 10_000  # free unknowns from which the sparse path is renumbered by METIS


def supervariables(indptr, indices, m):
    """sv[j]: the supervariable of column j of an (m x m) CSC pattern, columns with the same
    row indices sharing one (numbered in order of their first column); and its count."""
    count = np.diff(indptr)
    col = np.repeat(np.arange(m), count)
    weight = np.random.default_rng(12345).random(m)  # a hash of each column's rows
    h = np.bincount(col, weight[indices], minlength=m) + count
    first = np.r_[True, h[1:] != h[:-1]]  # merge only neighbouring columns
    sv = np.cumsum(first) - 1
    rep = np.flatnonzero(first)[sv]  # each column's first column
    same = count == count[rep]
    at = np.repeat(indptr[rep] - indptr[:-1], count) + np.arange(indices.size)  # the same place in rep's column
    check = same[col]
    same[col[check & (indices[np.where(check, at, 0)] != indices)]] = False
    if not same.all():  # a hash collision (never seen): no merging
        sv = np.arange(m)
    return sv, int(sv[-1]) + 1 if m else 0


class DissectionPlan:
    """A METIS nested-dissection numbering of the block ``free`` (None: all dofs) of a CSC
    pattern (indptr, indices, n x n), and where each stored entry goes in the renumbered block."""

    def __init__(self, indptr, indices, n, free=None):
        self.indptr, self.indices, self.free = indptr, indices, free
        rows = np.asarray(indices, dtype=np.int64)
        cols = np.repeat(np.arange(n), np.diff(indptr))
        entry = np.arange(rows.size)
        m = n
        if free is not None:  # the block: its entries keep the CSC order (free is ascending)
            local = np.full(n, -1)
            local[free] = np.arange(len(free))
            inside = (local[rows] >= 0) & (local[cols] >= 0)
            entry, m = entry[inside], len(free)
            rows, cols = local[rows[inside]], local[cols[inside]]
            if np.any(np.diff(free) <= 0):  # free not ascending: back to CSC order
                o = np.lexsort((rows, cols))
                rows, cols, entry = rows[o], cols[o], entry[o]
        self.n = m
        b_indptr = np.searchsorted(cols, np.arange(m + 1))
        sv, k = supervariables(b_indptr, rows, m)
        # the graph of the supervariables: one edge per (representative column, representative row),
        # made undirected (METIS wants it so; the pattern of a System is symmetric anyway)
        rep = np.zeros(m, dtype=bool)
        rep[np.flatnonzero(np.r_[True, sv[1:] != sv[:-1]])] = True
        edge = rep[rows] & rep[cols] & (rows != cols)
        a, c = sv[rows[edge]], sv[cols[edge]]
        graph = sp.csr_matrix((np.ones(2 * a.size), (np.r_[a, c], np.r_[c, a])), shape=(k, k))
        order = pymetis.nested_dissection(
            pymetis.CSRAdjacency(graph.indptr, graph.indices), vweights=np.bincount(sv, minlength=k)
        )[0]
        place = np.empty(k, dtype=np.int64)
        place[np.asarray(order)] = np.arange(k)
        self.perm = np.lexsort((np.arange(m), place[sv]))  # new -> old: a supervariable's dofs together
        new = np.empty(m, dtype=np.int64)
        new[self.perm] = np.arange(m)
        # the renumbered block's CSC arrays, and the stored entry each of its entries takes: its
        # columns gathered in the new order, then each column's rows sorted (scipy, in C)
        count = np.diff(b_indptr)[self.perm]
        p_indptr = np.concatenate([[0], np.cumsum(count)])
        at = np.repeat(b_indptr[self.perm] - p_indptr[:-1], count) + np.arange(rows.size)
        numbered = sp.csc_matrix((entry[at].astype(float), new[rows[at]], p_indptr), shape=(m, m))
        numbered.sort_indices()
        self.take = numbered.data.astype(np.int64)
        self.p_indptr, self.p_indices = numbered.indptr, numbered.indices
        self.description = "nested dissection (METIS), SuperLU"

    # whether K has this plan's pattern and free its free dofs: the band plan's test (the same
    # attributes: indptr, indices, free, n)
    fits = BandPlan.fits

    def solve(self, data, b):
        """x from A x = b, A the matrix with values ``data`` (of the CSC pattern), on the block.
        Raises RuntimeError on an exactly singular matrix, as SuperLU does."""
        A = sp.csc_matrix((data[self.take], self.p_indices, self.p_indptr), shape=(self.n, self.n))
        y = linalg.splu(A, permc_spec="NATURAL").solve(np.asarray(b, dtype=float)[self.perm])
        out = np.empty(self.n)
        out[self.perm] = y
        return out
