"""Assembly of the global tangent K from COO triplets: dense, sparse or banded.

Small systems (at most DENSE_MAX unknowns: the rings of the sloping impact and the funnel) get K as a
dense numpy array: the triplets are summed with one ``bincount`` and Newton factorises
K with LAPACK (numpy.linalg.solve). For 48 unknowns that takes about 16 us, where
SuperLU's factors and solve take about 35 us and, with a scipy matrix built from the
triplets, about 90 us (measured on a banded 48 x 48 matrix like the ring's).

Larger systems get K as a scipy CSC matrix on a FIXED sparsity pattern: the pattern
(sorted keys ``col * n + row``, the CSC order) is computed at the first assembly and
kept; each assembly only scatters the values into it. Where a contact couples dofs the
pattern does not hold yet (a slave reaching a new master segment), the pattern grows
once (merged) and is kept from then on. The diagonal is always in the pattern, so a time
stepper can add its mass term M / (beta dt^2) there. Every K is a shallow copy of one
CSC matrix made with the pattern (its index arrays shared and read-only, its own values):
scipy's constructor checks the arrays again at every call (17-40 us for 360 unknowns, the
copy 3 us). What changes K's structure in place (``eliminate_zeros``) raises; copy K first.

The pattern is built by one sort of the keys and a mask of the first of each run of equal
keys (Hertz on 65k quads, 2.4M keys: 0.04-0.2 s, where numpy's union1d took 2.5 s).

Banded: when the pattern is (re)built, its free block is renumbered by reverse
Cuthill-McKee and its band measured (banded.py), unless (from banded.BOUND_MIN free dofs
on) a breadth-first search shows that no numbering can give a band narrow enough
(banded.band_too_wide: a fine 2-D mesh, whose plan would cost more than the bound's few
milliseconds and never be used). If the band LU's work per unknown,
kl (kl + ku), is at most banded.BANDED_WORK (a band of up to ~86 on each side), K
carries that plan (``K.band_plan``) and Newton solves with LAPACK's banded LU instead of
SuperLU, 3-8x faster: the bar impact (kl = 7), the patch test (47), the paper's rolling
ring (360 unknowns, a ring of beams, kl = ku = 8: 55 us against SuperLU's 320 us), the
block (468, 35: 170 against 700 us) and the cork (259 free, 28: 84 against 495 us); not
Hertz (8385 free, kl = ku = 258: 38 against 30 ms), where SuperLU's orderings fill in
less than the band. (Hertz at the fast preset, 2145 unknowns, kl = 130, would still
solve 1.5x faster banded, 3.8 against 5.8 ms: the limit keeps a margin.)
The band is made for the free dofs (the System's Dirichlet dofs are left out), so a
partly fixed system is solved banded too; any other free set falls back to SuperLU.
K stays a CSC matrix for every other use (products, ``toarray``, slicing).

The positions of a contribution in the pattern are cached when it arrives with the same
index arrays as before (a body's constant connectivity, ``key`` = the body).
"""

import numpy as np

from .. import lazy
from .banded import BANDED_WORK, BOUND_MIN, BandPlan, band_too_wide
from .dissection import DISSECTION_MIN, DissectionPlan
from .newton import DENSE_ORDERING, ORDERING

sp = lazy.module("scipy.sparse")

# Up to this many unknowns K is dense. Measured on the paper's ring matrices (banded, 3
# dofs per node): LAPACK beats SuperLU below about 100-150 unknowns (48: 16 us against
# 43 us; 96: 55 against 62 us; 198: 284 against 145 us), and above ~100 a multi-threaded
# BLAS on a loaded machine makes dense solves erratic (BENCHMARKS.md, `contactfem bench`).
DENSE_MAX = 100
KINDS = ("auto", "dense", "sparse", "banded")


def choose_linear_algebra(n, requested="auto", plan=None):
    """'dense', 'sparse' or 'banded' for a system of n unknowns. 'auto': dense up to
    DENSE_MAX; above, banded when the band plan of the pattern (banded.BandPlan, None
    while the pattern is not known) needs at most BANDED_WORK per unknown, else sparse."""
    if requested not in KINDS:
        raise ValueError(f"parameter linear_algebra = {requested!r} is not allowed: one of {'|'.join(KINDS)}")
    if requested != "auto":
        return requested
    if n <= DENSE_MAX:
        return "dense"
    return "banded" if plan is not None and plan.work <= BANDED_WORK else "sparse"


def shallow_copy(matrix):
    """A new matrix object sharing every attribute of `matrix` (its index and value arrays):
    what copy.copy makes of a scipy matrix, without the pickling protocol it goes through."""
    K = object.__new__(type(matrix))
    K.__dict__.update(matrix.__dict__)
    return K


def _keys(rows, cols, offset, n):
    """Pattern keys (col + offset) n + row + offset, in 64 bits: a body's int32 index arrays
    (scipy's) would overflow from n = 46341 unknowns on."""
    cols, rows = np.asarray(cols, dtype=np.int64), np.asarray(rows, dtype=np.int64)
    return (cols + offset) * n + (rows + offset) if offset else cols * n + rows


class TangentAssembler:
    """Sums COO contributions into K (n x n), dense or on a fixed CSC pattern.

    ``linear_algebra``: auto|dense|sparse|banded (choose_linear_algebra); ``free``: the
    dofs Newton solves for (None: all), the block a band plan is made for. ``kind`` is
    the current choice, ``used`` maps each kind used so far to its ordering."""

    def __init__(self, n, linear_algebra="auto", free=None):
        self.n, self.requested = int(n), linear_algebra
        self.kind = choose_linear_algebra(self.n, linear_algebra)
        self.free = None if free is None or len(free) == self.n else np.asarray(free)
        self.keys = None  # sparse: sorted pattern keys col * n + row
        self.plan = None  # the BandPlan of the pattern (None where the band cannot be chosen)
        self.banded_plan = None  # the plan of the last K solved banded
        self.dissection = None  # the DissectionPlan of the pattern, where it is solved sparse and large
        self.used = {}  # kind -> ordering, of every assembly so far
        self._cache = {}  # key -> (rows, cols, positions) of a constant contribution
        self.pattern_builds = 0  # how often the pattern was (re)computed

    # -- the pattern (sparse) ---------------------------------------------------------
    def _grow(self, keys):
        """Make the pattern hold `keys` (and the diagonal); positions cached so far are void.
        Returns the position of each of `keys` in the new pattern."""
        diag = np.arange(self.n) * (self.n + 1)
        old = diag if self.keys is None else self.keys
        merged = np.concatenate([old, np.asarray(keys, dtype=np.int64)])
        order = np.argsort(merged, kind="stable")  # sorted runs (old keys, a body's CSR rows): near-linear
        merged = merged[order]
        first = np.empty(merged.size, dtype=bool)  # the first of each run of equal keys
        first[:1] = True
        np.not_equal(merged[1:], merged[:-1], out=first[1:])
        self.keys = merged[first]
        self._ends = np.append(self.keys, -1)  # a position beyond the last key finds no key there
        where = np.empty(merged.size, dtype=np.int64)
        where[order] = np.cumsum(first) - 1  # each merged key's place in the pattern
        indices = self.keys % self.n  # row of each entry
        indptr = np.searchsorted(self.keys, np.arange(self.n + 1) * self.n)
        self._template = sp.csc_matrix((np.zeros(self.keys.size), indices, indptr), shape=(self.n, self.n))
        self.indices, self.indptr = self._template.indices, self._template.indptr  # scipy's index dtype
        self.indices.flags.writeable = self.indptr.flags.writeable = False  # shared by every K
        self.diag_pos = np.searchsorted(self.keys, diag)
        n_free = self.n if self.free is None else len(self.free)
        if self.requested == "banded" or (
            self.requested == "auto"
            and (n_free < BOUND_MIN or not band_too_wide(self.indptr, self.indices, self.n, self.free, BANDED_WORK))
        ):
            self.plan = BandPlan(self.indptr, self.indices, self.n, self.free)
        else:  # no plan where the band cannot be chosen
            self.plan = None
        if self.requested in ("auto", "banded"):
            self.kind = choose_linear_algebra(self.n, self.requested, self.plan)
        self.dissection = (
            DissectionPlan(self.indptr, self.indices, self.n, self.free)
            if self.kind == "sparse" and n_free >= DISSECTION_MIN
            else None
        )
        self._cache.clear()
        self.pattern_builds += 1
        return where[old.size :]

    def _positions(self, rows, cols, offset, key):
        """Index of each (row + offset, col + offset) in the pattern, growing it if need be."""
        if key is not None:
            hit = self._cache.get(key)
            if hit is not None and hit[0] is rows and hit[1] is cols:
                return hit[2]
        keys = _keys(rows, cols, offset, self.n)
        pos = np.searchsorted(self.keys, keys)
        if keys.size and (self._ends[pos] != keys).any():  # (_ends: keys and one beyond the last)
            pos = self._grow(keys)
        if key is not None:
            self._cache[key] = (rows, cols, pos)
        return pos

    def _flat(self, rows, cols, offset, key):
        """Dense: the flat index (row + offset) n + col + offset of each entry; cached for a
        contribution whose index arrays come back the same (``key``), and for the diagonal
        (rows None)."""
        hit = self._cache.get(key) if key is not None else None
        if hit is not None and hit[0] is rows and hit[1] is cols:
            return hit[2]
        n = self.n
        if rows is None:
            flat = np.arange(n) * (n + 1)
        else:
            flat = (rows + offset) * n + (cols + offset) if offset else rows * n + cols
        if key is not None:
            self._cache[key] = (rows, cols, flat)
        return flat

    # -- assembly ---------------------------------------------------------------------------
    def assemble(self, blocks, diagonal=None):
        """K from blocks [(rows, cols, vals, offset, key), ...] plus diag(diagonal) if given.

        A block adds vals at (rows + offset, cols + offset); ``key`` (or None) names a
        contribution whose index arrays are the same objects at every call (cached).
        Dense: an (n, n) array. Sparse: a CSC matrix on the pattern; banded: the same, with
        the band plan as ``K.band_plan`` (newton.solve_free). Duplicates are summed.
        """
        n = self.n
        if self.kind == "dense":
            self.used["dense"] = DENSE_ORDERING
            index = [self._flat(r, c, o, key) for r, c, _, o, key in blocks]
            vals = [v for _, _, v, _, _ in blocks]
            if diagonal is not None:  # the diagonal last: summed after the blocks, as K + diag
                index.append(self._flat(None, None, 0, "diagonal"))
                vals.append(diagonal)
            K = np.bincount(
                np.concatenate(index or [np.zeros(0, int)]), np.concatenate(vals or [np.zeros(0)]), minlength=n * n
            ).reshape(n, n)
            return K
        if self.keys is None:  # the first assembly: the whole pattern at once
            keys = [_keys(r, c, o, n) for r, c, _, o, _ in blocks]
            pos = np.split(
                self._grow(np.concatenate(keys + [np.zeros(0, np.int64)])), np.cumsum([k.size for k in keys])[:-1]
            )
            for (r, c, _, _, key), p in zip(blocks, pos):
                if key is not None:
                    self._cache[key] = (r, c, p)
        else:
            for _ in range(2):  # a grown pattern voids positions found before it
                builds = self.pattern_builds
                pos = [self._positions(r, c, o, key) for r, c, _, o, key in blocks]
                if self.pattern_builds == builds:
                    break
        vals = [v for _, _, v, _, _ in blocks]
        if diagonal is not None:  # the diagonal last: summed after the blocks, as K + diag
            pos.append(self.diag_pos)
            vals.append(diagonal)
        data = np.bincount(
            np.concatenate(pos or [np.zeros(0, int)]), np.concatenate(vals or [np.zeros(0)]), minlength=self.keys.size
        )
        K = shallow_copy(self._template)  # shares the pattern's index arrays (docstring)
        K.data = data
        if self.kind == "banded":
            K.band_plan = self.banded_plan = self.plan
            self.used["banded"] = self.plan.description
        elif self.dissection is not None:
            K.dissection_plan = self.dissection
            self.used["sparse"] = self.dissection.description
        else:
            self.used["sparse"] = ORDERING
        return K

    def describe(self):
        """(linear_algebra, ordering) of the assemblies so far ('+'-joined if the choice
        changed as the pattern grew); the current choice before the first one."""
        if not self.used:
            kind = self.kind
            sparse = ORDERING if self.dissection is None else self.dissection.description
            return kind, {"dense": DENSE_ORDERING, "sparse": sparse}.get(kind, "reverse Cuthill-McKee")
        return "+".join(self.used), "+".join(self.used.values())
