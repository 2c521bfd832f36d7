"""000's second method: kd-trees of maximum sizes ``n1, q n1, q² n1, ...`` behind a buffer of non-base points (000 §4).

:func:`multi_tree_sizes` (the size schedule), :class:`MultiKDTree` and :class:`NonBaseBuffer`; re-exported by
:mod:`slamlab.kdtree.stores` with the other stores.
"""

from __future__ import annotations

from dataclasses import fields

import numpy as np

from .._validate import check_int
from ._store_parts import PointSet, StaticTree
from .knn import merge_knn
from .store_base import LandmarkStore, SightingBook, StoreCounters
from .store_params import StoreParams, resolve_store_params

__all__ = ["MultiKDTree", "NonBaseBuffer", "multi_tree_sizes"]


def _max_size(n1, q, i):
    """``MAX_SIZE[i] = floor(n1 q^i)`` (tree index from 0; the 1e-9 absorbs the rounding of ``q^i``)."""
    return int(np.floor(n1 * q ** i + 1e-9))


def multi_tree_sizes(n1: int, q: float, batches) -> list[list[int]]:
    """Tree sizes of a multi kd-tree after each batch (000 §4.1's insertion rule, sizes only).

    A batch goes into tree 1; while tree ``i`` holds more than ``floor(n1 q^i)``
    points it is merged into tree ``i + 1``; trees are appended so that the last
    one can hold the total.

    Parameters
    ----------
    n1 : int
        Maximum size of the first tree.
    q : float
        Size ratio between consecutive trees (> 1).
    batches : sequence of int
        Points inserted per batch.

    Returns
    -------
    list of list of int
        The tree sizes after each batch.

    Examples
    --------
    >>> multi_tree_sizes(4, 2.0, [3, 3, 3])
    [[3], [0, 6], [3, 6, 0]]
    """
    p = StoreParams(n1=n1, q=q)  # checks n1 >= 1 and q > 1
    n1, q = int(p.n1), float(p.q)
    cap = lambda i: _max_size(n1, q, i)
    sizes: list[int] = []
    out = []
    for b in batches:
        b = check_int(b, "batches", minimum=0)
        if not sizes:
            sizes.append(0)
        sizes[0] += b
        i = 0
        while sizes[i] > cap(i):
            if len(sizes) == i + 1:
                sizes.append(0)
            sizes[i + 1] += sizes[i]
            sizes[i] = 0
            i += 1
        while cap(len(sizes) - 1) < sum(sizes):
            sizes.append(0)
        out.append(list(sizes))
    return out


class MultiKDTree(LandmarkStore):
    """000's multi kd-tree: static trees of maximum sizes ``n1, q n1, q^2 n1, ...`` (000 §4.1).

    A batch goes into tree 1; then, while tree ``i`` holds more than ``MAX_SIZE[i]``
    points, tree ``i`` is merged into tree ``i + 1`` (both rebuilt as one). Trees are
    appended as needed, so the last tree's maximum always exceeds the total. Only
    the trees whose contents changed are rebuilt. A query searches every non-empty
    tree and merges the k-NN lists (exact when the per-tree search is exact).

    The store reads ``n1``, ``q``, ``tree``, ``leaf_size`` and ``checks`` of its :class:`StoreParams`
    (an insert-only store: the base rule is the buffer's, :class:`NonBaseBuffer`).

    Parameters
    ----------
    n1 : int, optional
        Maximum size of the first tree (default from ``params``: 3500, 000 §4.1.2).
    q : float, optional
        Size ratio between consecutive trees, > 1 (default from ``params``: 5.5, 000 §4.1.2).
    params : StoreParams, optional
        The settings (default :class:`StoreParams`); the arguments that are not None change its fields.
    tree : {'bbf', 'exact', 'ckdtree', 'brute'}, optional
        Search in each tree (:data:`~slamlab.kdtree.store_params.TREE_KINDS`).
    leaf_size : int, optional
        Points per leaf of our trees.
    checks : int, optional
        Points examined per tree by the BBF search.

    Examples
    --------
    >>> rng = np.random.default_rng(0)
    >>> mt = MultiKDTree(4, 2.0, tree="ckdtree")
    >>> for b in range(5):
    ...     mt.add(rng.random((3, 2)), np.arange(3 * b, 3 * b + 3))
    >>> mt.sizes, mt.max_sizes
    ([3, 0, 12], [4, 8, 16])
    >>> mt.check_invariant()
    True
    """

    name = "multi kd-tree"

    def __init__(self, n1: int | None = None, q: float | None = None, *, params: StoreParams | None = None,
                 tree: str | None = None, leaf_size: int | None = None, checks: int | None = None):
        super().__init__()
        self.params = p = resolve_store_params(params, n1=n1, q=q, tree=tree, leaf_size=leaf_size, checks=checks)
        self.n1, self.q = int(p.n1), float(p.q)
        self.tree_kind, self.leaf_size, self.checks = p.tree, p.leaf_size, p.checks
        self._X: list[np.ndarray] = []
        self._ids: list[np.ndarray] = []
        self._trees: list[StaticTree | None] = []

    def max_size(self, i: int) -> int:
        """``MAX_SIZE[i] = floor(n1 q^i)`` (tree index from 0).

        Parameters
        ----------
        i : int
            Tree index, 0 for the first tree.

        Returns
        -------
        int
        """
        return _max_size(self.n1, self.q, i)

    @property
    def max_sizes(self) -> list[int]:
        return [self.max_size(i) for i in range(len(self._X))]

    @property
    def sizes(self) -> list[int]:
        return [x.shape[0] for x in self._X]

    @property
    def n_trees(self) -> int:
        """Number of non-empty trees (000's ``p``)."""
        return sum(1 for x in self._X if x.shape[0])

    def _ensure(self, i):
        while len(self._X) <= i:
            self._X.append(np.empty((0, self.dim), dtype=np.float32))
            self._ids.append(np.empty(0, dtype=np.int64))
            self._trees.append(None)

    def _add(self, X, ids):
        self._ensure(0)
        changed = {0}
        self._X[0] = np.concatenate([self._X[0], X])
        self._ids[0] = np.concatenate([self._ids[0], ids])
        i = 0
        while self._X[i].shape[0] > self.max_size(i):  # merge tree i into tree i+1
            self._ensure(i + 1)
            self._X[i + 1] = np.concatenate([self._X[i + 1], self._X[i]])
            self._ids[i + 1] = np.concatenate([self._ids[i + 1], self._ids[i]])
            self._X[i] = self._X[i][:0]
            self._ids[i] = self._ids[i][:0]
            changed.add(i + 1)
            i += 1
        while self.max_size(len(self._X) - 1) < len(self):  # the last tree can hold any total
            self._ensure(len(self._X))
        for j in changed:  # rebuild only the trees whose contents changed
            if self._X[j].shape[0]:
                self._trees[j] = StaticTree(self._X[j], self._ids[j], self.params)
                self.counters.points_rebuilt += self._X[j].shape[0]
                self.counters.trees_built += 1
            else:
                self._trees[j] = None

    def check_invariant(self) -> bool:
        """000's invariant: tree i empty or > MAX_SIZE[i-1], never > MAX_SIZE[i]; last max > total.

        Returns
        -------
        bool
            True when the invariant holds.
        """
        for i, n in enumerate(self.sizes):
            if n > self.max_size(i):
                return False
            if i > 0 and n and n <= self.max_size(i - 1):
                return False
        return not self._X or self.max_size(len(self._X) - 1) >= len(self)

    def _query(self, Q, k):
        res = [t.query(Q, k, self.counters) for t in self._trees if t is not None]
        return merge_knn([r[0] for r in res], [r[1] for r in res], k)

    def _stored(self):
        if not self._X:
            return np.empty((0, self.dim or 0), np.float32), np.empty(0, np.int64)
        return np.concatenate(self._X), np.concatenate(self._ids)

    def __len__(self):
        return sum(self.sizes)

    def __repr__(self):
        return f"MultiKDTree(n1={self.n1}, q={self.q}, sizes={self.sizes})"


class NonBaseBuffer(LandmarkStore):
    """Buffer of non-base points in front of an insert-only base store (000 §3.4, §4.1).

    A point is *non-base* while it has been seen fewer than ``base_seen_times``
    times and its first sighting is at most ``max_non_base_time`` iterations old.
    The buffer tree is rebuilt every iteration; at the end of an iteration the
    points that became base move to ``base`` (a :class:`MultiKDTree` by default)
    and the ones that timed out are dropped. ``base_seen_times = 1`` makes every
    point base at once (Table 2). Queries search buffer and base and merge the
    k-NN lists (our choice: 000 does not say how the 2-NN rule is merged).

    The buffer reads ``base_seen_times``, ``max_non_base_time``, ``tree``, ``leaf_size`` and ``checks`` of
    its :class:`StoreParams`; the default base is a :class:`MultiKDTree` of the same settings.

    Parameters
    ----------
    base : LandmarkStore, optional
        Insert-only store for the base points (default a :class:`MultiKDTree` with the same settings).
    params : StoreParams, optional
        The settings (default :class:`StoreParams`); the arguments that are not None change its fields.
    base_seen_times : int, optional
        Sightings that make a point base (default from ``params``: 3, 000 §3.4).
    max_non_base_time : int, optional
        Iterations after its first sighting at which a non-base point is dropped (default: 7, 000 §3.4).
    tree : {'bbf', 'exact', 'ckdtree', 'brute'}, optional
        Search in the buffer tree (and the default base).
    leaf_size : int, optional
        Points per leaf of our trees.
    checks : int, optional
        Points examined per tree by the BBF search.

    Examples
    --------
    >>> rng = np.random.default_rng(0)
    >>> buf = NonBaseBuffer(MultiKDTree(10, 2.0, tree="ckdtree"), tree="ckdtree")
    >>> buf.add(rng.random((5, 3)), np.arange(5)); buf.end_iteration()
    >>> for _ in range(2):
    ...     buf.observe([0, 1]); buf.end_iteration()
    >>> len(buf.base), len(buf.buffer_ids)
    (2, 3)
    """

    name = "buffer + multi kd-tree"
    insert_only = False

    def __init__(self, base: LandmarkStore | None = None, *, params: StoreParams | None = None,
                 base_seen_times: int | None = None, max_non_base_time: int | None = None, tree: str | None = None,
                 leaf_size: int | None = None, checks: int | None = None):
        super().__init__()
        self.params = p = resolve_store_params(params, base_seen_times=base_seen_times,
                                               max_non_base_time=max_non_base_time, tree=tree, leaf_size=leaf_size,
                                               checks=checks)
        if base is None:
            base = MultiKDTree(params=p)
        if not isinstance(base, LandmarkStore):
            raise TypeError(f"`base` must be a LandmarkStore; got {type(base).__name__}")
        self.base = base
        self.tree_kind, self.leaf_size, self.checks = p.tree, p.leaf_size, p.checks
        self._book = SightingBook(p.base_seen_times, p.max_non_base_time)
        self._pts = PointSet()
        self._tree: StaticTree | None = None
        self.n_promoted = 0
        self.n_dropped = 0

    def _add(self, X, ids):
        if self._book.base_seen_times == 1:  # every point base at once
            self.base.add(X, ids)
            self.n_promoted += X.shape[0]
            return
        self._pts.append(X, ids)
        self._book.add(ids)

    def _observe(self, ids):
        self._book.observe(ids)  # re-sightings of buffered ids count towards base_seen_times

    def end_iteration(self):
        promoted, dropped = self._book.step()
        if promoted.size or dropped.size:
            ids = self._pts.point_ids
            up = np.isin(ids, promoted)
            if up.any():
                self.base.add(self._pts.points[up], ids[up])
            self.n_promoted += int(up.sum())
            self.n_dropped += int(np.isin(ids, dropped).sum())
            self._pts.keep(~(up | np.isin(ids, dropped)))
        self.base.end_iteration()
        # the buffer tree is rebuilt every iteration
        if self._pts.n:
            self._tree = StaticTree(self._pts.points.copy(), self._pts.point_ids.copy(), self.params)
            self.counters.points_rebuilt += self._pts.n
            self.counters.trees_built += 1
        else:
            self._tree = None

    @property
    def buffer_ids(self):
        return self._pts.point_ids

    def _query(self, Q, k):
        parts = []
        if self._pts.n:
            if self._tree is None or self._tree.n != self._pts.n:
                self._tree = StaticTree(self._pts.points.copy(), self._pts.point_ids.copy(), self.params)
            parts.append(self._tree.query(Q, k, self.counters))
        if len(self.base):
            parts.append(self.base.query(Q, k))
        return merge_knn([p[0] for p in parts], [p[1] for p in parts], k)

    def _stored(self):
        X, ids = self.base.stored()
        if not self._pts.n:
            return X, ids
        if not len(self.base):  # an empty base does not know the points' width yet: (0, 0)
            return self._pts.points, self._pts.point_ids
        return np.concatenate([self._pts.points, X.astype(self._pts.points.dtype)]), np.concatenate([self._pts.point_ids, ids])

    @property
    def all_counters(self) -> StoreCounters:
        """Buffer and base counters summed."""
        out = StoreCounters()
        for f in fields(out):
            setattr(out, f.name, getattr(self.counters, f.name) + getattr(self.base.counters, f.name))
        out.queries = self.counters.queries
        out.points_added = self.counters.points_added
        return out

    def __len__(self):
        return self._pts.n + len(self.base)
