"""The parts the landmark stores are built from (package-private): a growing point buffer and a static tree.

:class:`PointSet` (points and ids in a buffer that grows by doubling, with the rows the exact search needs) and
:class:`StaticTree` (one tree of a :data:`~slamlab.kdtree.store_params.TREE_KINDS` kind behind one ``query``),
used by the stores of :mod:`slamlab.kdtree.stores` and :mod:`slamlab.kdtree.multi`.
"""

from __future__ import annotations

import numpy as np
from scipy.spatial import cKDTree

from .knn import augment_rows, exact_knn, pad_knn
from .store_params import StoreParams
from .tree import KDTree

__all__ = ["PointSet", "StaticTree"]


class PointSet:
    """Points + ids in a growing buffer (capacity doubling; no per-add copy of everything)."""

    def __init__(self):
        self.X = np.empty((0, 0), dtype=np.float32)
        self.ids = np.empty(0, dtype=np.int64)
        self.n = 0
        self._aug = None  # float rows [x, |x|²/2] for the exact search, rows [0, _aug_n) valid
        self._aug_n = 0

    def append(self, X, ids):
        """Add the rows ``X`` with their ``ids`` at the end."""
        need = self.n + X.shape[0]
        if self.X.shape[0] < need or self.X.shape[1] != X.shape[1] or self.X.dtype != X.dtype:
            cap = max(need, 2 * self.X.shape[0], 1024)
            Xn = np.empty((cap, X.shape[1]), dtype=X.dtype)
            In = np.empty(cap, dtype=np.int64)
            if self.n:
                Xn[:self.n], In[:self.n] = self.X[:self.n], self.ids[:self.n]
            self.X, self.ids = Xn, In
        self.X[self.n:need], self.ids[self.n:need] = X, ids
        self.n = need

    def keep(self, mask):
        """Keep the points where ``mask`` (over the stored points) is True, in order."""
        k = int(mask.sum())
        if self._aug is not None and self._aug_n == self.n:
            self._aug[:k] = self._aug[:self.n][mask]
            self._aug_n = k
        else:
            self._aug_n = 0
        self.X[:k], self.ids[:k] = self.X[:self.n][mask], self.ids[:self.n][mask]
        self.n = k

    @property
    def augmented(self):
        """``augment_rows(points)`` (float points only), extended by the rows added since the last call.

        Kept between queries (issue 17): rebuilding it for every query of 65000 points cost a
        quarter of the GEMM it feeds.
        """
        if self.X.dtype == np.uint8:
            return None
        if self._aug is None or self._aug.shape != (self.X.shape[0], self.X.shape[1] + 1):
            old, old_n = self._aug, self._aug_n
            self._aug = np.empty((self.X.shape[0], self.X.shape[1] + 1), dtype=np.float32)
            self._aug_n = 0
            if old is not None and old.shape[1] == self._aug.shape[1] and old_n:
                self._aug[:old_n] = old[:old_n]
                self._aug_n = old_n
        if self._aug_n < self.n:
            augment_rows(self.X[self._aug_n:self.n], out=self._aug[self._aug_n:self.n])
            self._aug_n = self.n
        return self._aug[:self.n]

    @property
    def points(self):
        """The stored points, ``(n, d)``."""
        return self.X[:self.n]

    @property
    def point_ids(self):
        """Their ids, ``(n,)``."""
        return self.ids[:self.n]


class StaticTree:
    """One static tree of the chosen kind (:data:`~slamlab.kdtree.store_params.TREE_KINDS`) with a uniform
    ``query(Q, k, counters)`` that adds its work to a store's counters (our addition)."""

    def __init__(self, X, ids, params: StoreParams):
        """A tree over the points ``X`` with ids ``ids``, of ``params``' ``tree``, ``leaf_size`` and ``checks``."""
        self.n = X.shape[0]
        self.kind = kind = params.tree
        self.ids = ids
        if kind == "ckdtree":
            self._t = cKDTree(X, leafsize=params.leaf_size, balanced_tree=True, compact_nodes=False)
        elif kind == "brute":
            self._t = X
        else:
            self._t = KDTree(X, ids, leaf_size=params.leaf_size)
        self.max_leaves = None if kind != "bbf" else max(1, -(-params.checks // params.leaf_size))

    def query(self, Q, k, counters):
        """``(dist (M, k), ids (M, k))`` of the queries ``Q``; the work is added to ``counters``."""
        counters.trees_searched += 1
        if self.kind == "ckdtree":
            kk = min(k, self.n)
            d, i = self._t.query(Q, kk)
            d, i = d.reshape(Q.shape[0], kk), i.reshape(Q.shape[0], kk)
            out_i = np.where(np.isfinite(d), self.ids[np.minimum(i, self.n - 1)], -1)
            return pad_knn(d, out_i, k)
        if self.kind == "brute":
            counters.distance_evals += Q.shape[0] * self.n
            return exact_knn(Q, self._t, k, self.ids)
        d, i = self._t.query(Q, k, max_leaves=self.max_leaves)
        st = self._t.last_stats
        counters.nodes_visited += int(st.nodes_visited.sum())
        counters.distance_evals += int(st.distance_evals.sum())
        return d, i
