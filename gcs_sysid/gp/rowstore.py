"""A capped store of training rows, thinned by region (not by age): the memory of the streaming GP.

The local layer conditions on stored rows and the hyperparameter refresh re-learns from them,
so the store must keep covering every part of the flight envelope already flown, however long
the session. Rows are binned on a grid in the scaled regressor space (standardised inputs divided
by the global length-scales at fit time, cells ``cell_width`` length-scales wide). While the store
holds at most ``capacity`` rows nothing is removed. Beyond it the store is thinned to 95 % of the
capacity: each cell keeps at most ``L`` rows, ``L`` the largest integer with
``sum_c min(n_c, L) <= 0.95 capacity`` (water-filling): sparse cells (the
edge of the envelope, a region just explored) keep every row and only the densest cells (trim,
long straight legs) are thinned. When the occupied cells alone would exceed ``capacity / 4`` the
grid is coarsened (cell width doubled) so every cell keeps at least four rows.

Which rows a cell keeps: each row gets a uniform random priority on arrival and a cell keeps its
``L`` rows of highest priority, so the kept rows are a uniform random sample of *all* rows that
ever fell in that cell (bottom-k / priority sampling; with unit weights it is the weighted reservoir
of Efraimidis and Spirakis 2006, "Weighted random sampling with a reservoir", Inf. Process. Lett.
97(5):181-185). Merging cells when coarsening keeps that property (the top ``L`` of a union lie
within the union of the parts' top ``L``), and old rows are not pushed out by new ones in the same
cell more than uniform sampling requires.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

__all__ = ["RowStore", "per_cell_limit"]

#: a full store is thinned to this fraction of its capacity, so the thinning (a sort of the stored
#: rows) runs once per ``(1 - _HEADROOM) * capacity`` new rows rather than on every update
_HEADROOM = 0.95

#: odd 64-bit multipliers hashing a cell's integer coordinates to one int64 (wrapping arithmetic)
_HASH = np.array([0x9E3779B97F4A7C15, 0xC2B2AE3D27D4EB4F, 0x165667B19E3779F9, 0xD6E8FEB86659FD93,
                  0xFF51AFD7ED558CCD, 0xC4CEB9FE1A85EC53, 0x2545F4914F6CDD1D, 0x94D049BB133111EB,
                  0xBF58476D1CE4E5B9, 0x369DFA47A5F5B7A3], dtype=np.uint64)


def per_cell_limit(counts: np.ndarray, capacity: int) -> int:
    """Largest ``L`` with ``sum(min(counts, L)) <= capacity`` (``counts (C,)`` rows per cell)."""
    c = np.sort(np.asarray(counts, np.int64))
    if c.sum() <= capacity:
        return int(c[-1]) if len(c) else 0
    # sum(min(c, L)) = sum(c[c < L]) + L * #(c >= L); scan the sorted counts
    below = np.concatenate([[0], np.cumsum(c)])          # below[i] = sum of the i smallest counts
    lo, hi = 0, int(c[-1])
    while lo < hi:                                        # binary search on L
        mid = (lo + hi + 1) // 2
        i = int(np.searchsorted(c, mid, side="left"))
        if below[i] + mid * (len(c) - i) <= capacity:
            lo = mid
        else:
            hi = mid - 1
    return lo


@dataclass(frozen=True)
class RowStore:
    """Training rows kept for the local layer and hyperparameter refreshes (immutable).

    Attributes:
        X: ``(N, D)`` standardised regressors. Y: ``(N, P)`` standardised coefficients.
        priority: ``(N,)`` uniform random priorities (higher: kept longer within a cell).
        weight: ``(N,)`` rows seen that each stored row stands for (1 on arrival; when rows leave a
            cell their weight is shared equally by the rows it keeps, so a cell's weights sum to
            the rows seen in it).
        cell_scale: ``(D,)`` multiplier of ``X`` giving grid coordinates (``1 / (lengthscale * width)``).
        capacity: most rows kept.
        seen: rows offered in all (kept or not).
        seed: seed of the priorities (the ``k``-th row offered draws from ``(seed, k)``).
    """

    X: np.ndarray
    Y: np.ndarray
    priority: np.ndarray
    cell_scale: np.ndarray
    capacity: int
    weight: np.ndarray | None = None
    seen: int = 0
    seed: int = 0

    def __post_init__(self):
        if self.weight is None:
            object.__setattr__(self, "weight", np.ones(len(self.X)))

    @classmethod
    def empty(cls, n_inputs: int, n_outputs: int, lengthscale: np.ndarray, cell_width: float, capacity: int,
              seed: int = 0) -> "RowStore":
        """An empty store; cells are ``cell_width`` length-scales ``(D,)`` wide (standardised units)."""
        scale = 1.0 / (np.asarray(lengthscale, float) * float(cell_width))
        return cls(np.zeros((0, n_inputs)), np.zeros((0, n_outputs)), np.zeros(0), scale, int(capacity), np.zeros(0),
                   0, int(seed))

    def __len__(self) -> int:
        return int(self.X.shape[0])

    def cells(self, X: np.ndarray | None = None) -> np.ndarray:
        """Cell id ``(N,)`` (int64 hash of the grid coordinates) of ``X`` (default: the stored rows)."""
        X = self.X if X is None else X
        keys = np.floor(X * self.cell_scale).astype(np.int64).astype(np.uint64)
        h = np.zeros(len(X), np.uint64)
        for d in range(X.shape[1]):
            h = h * np.uint64(0x100000001B3) + keys[:, d] * _HASH[d % len(_HASH)]
        return h.view(np.int64)

    def add(self, Xs: np.ndarray, Ys: np.ndarray) -> "RowStore":
        """The store with the rows ``Xs (E, D)``, ``Ys (E, P)`` (standardised) offered, thinned to capacity.

        Rows keep their arrival order (so a store under capacity is the training rows as given).
        """
        return self.add_dropped(Xs, Ys)[0]

    def add_dropped(self, Xs: np.ndarray, Ys: np.ndarray) -> tuple["RowStore", np.ndarray, np.ndarray]:
        """As :meth:`add`, also returning the rows dropped by the thinning, ``(store, X (K, D), Y (K, P))``."""
        rng = np.random.default_rng((self.seed, self.seen))
        X = np.vstack([self.X, Xs])
        Y = np.vstack([self.Y, Ys])
        pr = np.concatenate([self.priority, rng.random(len(Xs))])
        w = np.concatenate([self.weight, np.ones(len(Xs))])
        out = replace(self, X=X, Y=Y, priority=pr, weight=w, seen=self.seen + len(Xs))
        if len(X) <= self.capacity:
            return out, X[:0], Y[:0]
        store, keep = out._thinned(int(self.capacity * _HEADROOM))
        return store, X[~keep], Y[~keep]

    def _thinned(self, target: int) -> tuple["RowStore", np.ndarray]:
        """Thin to at most ``target`` rows; also returns the mask of the rows kept."""
        scale = self.cell_scale
        while True:
            store = replace(self, cell_scale=scale)
            _, inv, counts = np.unique(store.cells(), return_inverse=True, return_counts=True)
            if len(counts) <= max(self.capacity // 4, 1):
                break
            scale = scale * 0.5                     # coarsen: twice as wide cells
        L = per_cell_limit(counts, target)
        order = np.lexsort((-self.priority, inv))   # by cell, then by decreasing priority
        start = np.concatenate([[0], np.cumsum(counts)[:-1]])
        rank = np.empty(len(order), np.int64)
        rank[order] = np.arange(len(order)) - start[inv[order]]
        keep = rank < L
        # the dropped rows' weight goes to the rows their cell keeps (every cell keeps >= 1 row)
        lost = np.bincount(inv, weights=np.where(keep, 0.0, self.weight), minlength=len(counts))
        kept = np.bincount(inv, weights=keep.astype(float), minlength=len(counts))
        w = self.weight + lost[inv] / np.maximum(kept[inv], 1.0)
        return replace(store, X=self.X[keep], Y=self.Y[keep], priority=self.priority[keep], weight=w[keep]), keep

    def sample(self, m: int, seed: int = 0) -> np.ndarray:
        """Indices ``(min(m, N),)`` of a random subset of the stored rows (sorted)."""
        n = len(self)
        return np.sort(np.random.default_rng(seed).choice(n, int(min(m, n)), replace=False))

    def nbytes(self) -> int:
        """Bytes held by the arrays."""
        return int(self.X.nbytes + self.Y.nbytes + self.priority.nbytes + self.weight.nbytes + self.cell_scale.nbytes)
