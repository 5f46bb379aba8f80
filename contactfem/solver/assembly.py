"""Assembly of the global tangent K from COO triplets, dense or sparse.

Small systems (at most DENSE_MAX unknowns: the beam rings of the paper) get K as a
dense numpy array: the triplets are summed with one ``bincount`` and Newton factorises
K with LAPACK (numpy.linalg.solve). For 48 unknowns that takes about 15 us, where
building a scipy sparse matrix and its SuperLU factors costs ten times more.

Larger systems get K as a scipy CSC matrix on a FIXED sparsity pattern: the pattern
(sorted keys ``col * n + row``, the CSC order) is computed at the first assembly and
kept; each assembly only scatters the values into it. Where a contact couples dofs the
pattern does not hold yet (a slave reaching a new master segment), the pattern grows
once (union) and is kept from then on. The diagonal is always in the pattern, so a time
stepper can add its mass term M / (beta dt^2) there.

The positions of a contribution in the pattern are cached when it arrives with the same
index arrays as before (a body's constant connectivity, ``key`` = the body).
"""

import numpy as np

# Up to this many unknowns K is dense. Measured on the paper's ring matrices (banded, 3
# dofs per node): LAPACK beats SuperLU below about 100-150 unknowns (48: 16 us against
# 43 us; 96: 55 against 62 us; 198: 284 against 145 us), and above ~100 a multi-threaded
# BLAS on a loaded machine makes dense solves erratic (BENCHMARKS.md, `contactfem bench`).
DENSE_MAX = 100


def choose_linear_algebra(n, requested="auto"):
    """'dense' or 'sparse' for a system of n unknowns ('auto': dense up to DENSE_MAX)."""
    if requested not in ("auto", "dense", "sparse"):
        raise ValueError(f"parameter linear_algebra = {requested!r} is not allowed: one of auto|dense|sparse")
    if requested != "auto":
        return requested
    return "dense" if n <= DENSE_MAX else "sparse"


class TangentAssembler:
    """Sums COO contributions into K (n x n), dense or on a fixed CSC pattern."""

    def __init__(self, n, kind):
        self.n, self.kind = int(n), kind
        self.keys = None            # sparse: sorted pattern keys col * n + row
        self._cache = {}            # key -> (rows, cols, positions) of a constant contribution
        self.pattern_builds = 0     # how often the pattern was (re)computed

    # -- the pattern (sparse) ---------------------------------------------------------
    def _grow(self, keys):
        """Make the pattern hold `keys` (and the diagonal); positions cached so far are void."""
        diag = np.arange(self.n) * (self.n + 1)
        old = diag if self.keys is None else self.keys
        self.keys = np.union1d(old, keys)
        self.indices = self.keys % self.n                                    # row of each entry
        self.indptr = np.searchsorted(self.keys, np.arange(self.n + 1) * self.n)
        self.diag_pos = np.searchsorted(self.keys, diag)
        self._cache.clear()
        self.pattern_builds += 1

    def _positions(self, rows, cols, offset, key):
        """Index of each (row + offset, col + offset) in the pattern, growing it if need be."""
        if key is not None:
            hit = self._cache.get(key)
            if hit is not None and hit[0] is rows and hit[1] is cols:
                return hit[2]
        keys = (cols + offset) * self.n + (rows + offset)
        if self.keys is None:
            self._grow(keys)
        pos = np.searchsorted(self.keys, keys)
        if keys.size and (pos.max() >= self.keys.size or np.any(self.keys[pos] != keys)):
            self._grow(keys)
            pos = np.searchsorted(self.keys, keys)
        if key is not None:
            self._cache[key] = (rows, cols, pos)
        return pos

    # -- assembly ---------------------------------------------------------------------------
    def assemble(self, blocks, diagonal=None):
        """K from blocks [(rows, cols, vals, offset, key), ...] plus diag(diagonal) if given.

        A block adds vals at (rows + offset, cols + offset); ``key`` (or None) names a
        contribution whose index arrays are the same objects at every call (cached).
        Dense: an (n, n) array. Sparse: a CSC matrix on the pattern. Duplicates are summed.
        """
        n = self.n
        if self.kind == "dense":
            index = np.concatenate([(r + o) * n + (c + o) for r, c, _, o, _ in blocks] + [np.zeros(0, int)])
            vals = np.concatenate([v for _, _, v, _, _ in blocks] + [np.zeros(0)])
            K = np.bincount(index, vals, minlength=n * n).reshape(n, n)
            if diagonal is not None:
                K.flat[::n + 1] += diagonal
            return K
        if self.keys is None:                     # the first assembly: the whole pattern at once
            self._grow(np.concatenate([(c + o) * n + (r + o) for r, c, _, o, _ in blocks] + [np.zeros(0, int)]))
        for _ in range(2):                        # a grown pattern voids positions found before it
            builds = self.pattern_builds
            pos = [self._positions(r, c, o, key) for r, c, _, o, key in blocks]
            if self.pattern_builds == builds:
                break
        data = np.bincount(np.concatenate(pos + [np.zeros(0, int)]),
                           np.concatenate([v for _, _, v, _, _ in blocks] + [np.zeros(0)]),
                           minlength=self.keys.size)
        if diagonal is not None:
            data[self.diag_pos] += diagonal
        from scipy.sparse import csc_matrix

        return csc_matrix((data, self.indices, self.indptr), shape=(n, n))
