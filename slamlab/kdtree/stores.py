"""Landmark descriptor stores: the one store interface and every store (000 §3.4, §4).

Every store derives from :class:`LandmarkStore` (an abstract base class) and keeps a
growing set of descriptors with integer ids:

- ``add(X, ids)`` -- new points of this iteration (their first sighting);
- ``observe(ids)`` -- ids re-sighted this iteration (used by the base rule);
- ``end_iteration()`` -- apply the base rule / rebuild (part of the "add" time);
- ``query(Q, k=2) -> (dist, ids)`` -- the k nearest stored points of every query
  (``inf`` / ``-1`` where the store holds fewer than k: :func:`~slamlab.kdtree.knn.pad_knn`);
- ``query_among(Q, among, k=2)`` -- the k nearest among the stored points whose ids are
  in ``among``, exactly (the stereo pipeline's view gate);
- ``len(store)`` and ``store.counters`` -- points rebuilt, trees searched, nodes
  visited, distance evaluations (the operation counts the analysis needs).

The base rule of 000 §3.4 is written once, in :func:`base_rule` (a point becomes *base*
after ``BaseSeenTimes = 3`` sightings; a non-base point first seen
``MaxNonBaseTime = 7`` iterations ago is dropped), kept per point by
:class:`SightingBook`; every store and the stereo pipeline use them.

Stores of 000: :class:`RebuildStore` (first method: one static tree rebuilt every
iteration from kept + new points) and :class:`MultiKDTree` (second method: trees
of maximum sizes ``n1, q n1, q^2 n1, ...``) behind a :class:`NonBaseBuffer`.
Exact references (our addition): :class:`ExactStore` (brute force, Hamming for binary
``uint8`` descriptors, Euclidean for float ones, with the base rule; the stereo
pipeline's store for ORB), :class:`BruteForceStore` (the same without the base rule)
and :class:`FlannStore` (OpenCV's randomised kd-trees, ``checks = 200``).

The tree inside a store is chosen with ``tree``: ``"bbf"`` -- the teaching
:class:`~slamlab.kdtree.tree.KDTree` searched by Best-Bin-First with ``checks``
points examined per tree (000 §1.4.3: "about 200"), ``"exact"`` -- the same tree
searched exactly, ``"ckdtree"`` -- scipy's exact ``cKDTree``, ``"brute"`` --
:func:`~slamlab.kdtree.knn.exact_knn` (exact; used for the buffer in front of brute
force). In 64 dimensions an exact tree search visits almost every leaf, so only
``"bbf"`` is fast.
"""

from __future__ import annotations

from abc import ABC, abstractmethod
from dataclasses import dataclass, fields

import numpy as np
from scipy.spatial import cKDTree

from .. import _validate as v
from .knn import augment_rows, exact_knn, flann_index, merge_knn, pad_knn
from .tree import KDTree

__all__ = [
    "STORE_NAMES",
    "TREE_KINDS",
    "BruteForceStore",
    "ExactStore",
    "FlannStore",
    "LandmarkStore",
    "MultiKDTree",
    "NonBaseBuffer",
    "RebuildStore",
    "SightingBook",
    "StoreCounters",
    "base_rule",
    "make_store",
    "merge_knn",
    "multi_tree_sizes",
]

TREE_KINDS = ("bbf", "exact", "ckdtree", "brute")


@dataclass
class StoreCounters:
    """Operation counts accumulated by a store (the quantities of 000's cost model)."""

    points_added: int = 0
    points_rebuilt: int = 0  # points put into a newly built tree (build work)
    trees_built: int = 0
    queries: int = 0
    trees_searched: int = 0  # non-empty trees searched, summed over query batches
    nodes_visited: int = 0  # internal tree nodes passed (teaching tree only)
    distance_evals: int = 0  # query-to-point distances computed (0 where the backend does not say)

    def as_dict(self) -> dict:
        return {f.name: getattr(self, f.name) for f in fields(self)}

    def reset(self) -> None:
        for f in fields(self):
            setattr(self, f.name, 0)


def base_rule(seen, age, base_seen_times: int, max_non_base_time: int):
    """000 §3.4's base rule: ``(is_base, timed_out)`` per point from its sightings and age.

    A point is *base* once seen ``base_seen_times`` times (000: ``BaseSeenTimes = 3``); a
    non-base point whose first sighting is ``max_non_base_time`` iterations old (000:
    ``MaxNonBaseTime = 7``) times out and is dropped. ``age`` = iterations since the first
    sighting (0 in the iteration it was first seen).

    >>> b, late = base_rule(np.array([3, 1, 2]), np.array([2, 7, 6]), 3, 7)
    >>> b.tolist(), late.tolist()
    ([True, False, False], [False, True, False])
    """
    seen = np.asarray(seen)
    is_base = seen >= base_seen_times
    return is_base, ~is_base & (np.asarray(age) >= max_non_base_time)


class SightingBook:
    """Seen counts and first-sighting iterations of non-base points; :meth:`step` applies :func:`base_rule`.

    >>> book = SightingBook(3, 7)
    >>> book.add(np.array([1, 2])); book.step()[0].tolist()
    []
    >>> for _ in range(2):
    ...     book.observe(np.array([1])); promoted, dropped = book.step()
    >>> promoted.tolist(), book.ids.tolist()
    ([1], [2])
    """

    def __init__(self, base_seen_times: int, max_non_base_time: int):
        self.base_seen_times = base_seen_times
        self.max_non_base_time = max_non_base_time
        self.ids = np.empty(0, dtype=np.int64)  # sorted
        self.seen = np.empty(0, dtype=np.int64)
        self.first = np.empty(0, dtype=np.int64)
        self.iteration = 0

    def add(self, ids):
        allid = np.concatenate([self.ids, ids])
        o = np.argsort(allid, kind="stable")
        self.ids = allid[o]
        self.seen = np.concatenate([self.seen, np.ones(ids.size, dtype=np.int64)])[o]
        self.first = np.concatenate([self.first, np.full(ids.size, self.iteration, dtype=np.int64)])[o]

    def observe(self, ids):
        if not self.ids.size or not ids.size:
            return
        pos = np.searchsorted(self.ids, ids)
        pos = np.minimum(pos, self.ids.size - 1)
        hit = self.ids[pos] == ids
        self.seen += np.bincount(pos[hit], minlength=self.ids.size)

    def step(self):
        """End the iteration: return (ids that became base, ids that timed out); forget both."""
        base, late = base_rule(self.seen, self.iteration - self.first, self.base_seen_times,
                               self.max_non_base_time)
        promoted, dropped = self.ids[base], self.ids[late]
        keep = ~(base | late)
        self.ids, self.seen, self.first = self.ids[keep], self.seen[keep], self.first[keep]
        self.iteration += 1
        return promoted, dropped


def _as_points(X, name, dim=None, dtype=None, binary_ok=False):
    """Descriptors as float32 (or uint8 where the store compares binary descriptors)."""
    X = np.asarray(X)
    if X.dtype.kind not in "fiu":
        raise TypeError(f"`{name}` must be a numeric array; got dtype {X.dtype}")
    if X.dtype == np.uint8 and binary_ok and dtype != np.float32:
        if X.ndim != 2:
            raise ValueError(f"`{name}` must be a 2-D (N, d) descriptor array; got shape {X.shape}")
    else:
        if dtype == np.uint8:
            raise TypeError(f"`{name}` must be uint8 (binary) like the stored descriptors; got {X.dtype}")
        if X.dtype == np.uint8 and X.ndim == 2 and not binary_ok:
            raise TypeError(f"`{name}`: binary (uint8) descriptors need an exact store (ExactStore, "
                            "BruteForceStore); a kd-tree compares float descriptors")
        X = v.as_finite_array(X, name, ndim=2, dtype=np.float32)
    if dim is not None and X.shape[1] != dim:
        raise ValueError(f"`{name}` must have shape (N, {dim}) to match the store; got shape {X.shape}")
    return X


def _as_ids(ids, name, n=None):
    ids = np.asarray(ids)
    if ids.size == 0:
        ids = ids.astype(np.int64)
    if not np.issubdtype(ids.dtype, np.integer):
        raise TypeError(f"`{name}` must be an integer array; got dtype {ids.dtype}")
    if ids.ndim != 1 or (n is not None and ids.shape[0] != n):
        want = f"({n},)" if n is not None else "(N,)"
        raise ValueError(f"`{name}` must have shape {want}; got shape {ids.shape}")
    return ids.astype(np.int64)


def multi_tree_sizes(n1: int, q: float, batches) -> list[list[int]]:
    """Tree sizes of a multi kd-tree after each batch (000 §4.1's insertion rule, sizes only).

    A batch goes into tree 1; while tree ``i`` holds more than ``floor(n1 q^i)``
    points it is merged into tree ``i + 1``; trees are appended so that the last
    one can hold the total.

    >>> multi_tree_sizes(4, 2.0, [3, 3, 3])
    [[3], [0, 6], [3, 6, 0]]
    """
    n1 = v.check_int(n1, "n1", minimum=1)
    q = v.check_positive(q, "q")
    if q <= 1:
        raise ValueError(f"`q` must be > 1; got {q}")
    cap = lambda i: int(np.floor(n1 * q ** i + 1e-9))
    sizes: list[int] = []
    out = []
    for b in batches:
        b = v.check_int(b, "batches", minimum=0)
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


class _Tree:
    """Thin adapter: one static tree of the chosen kind with a uniform ``query`` (our addition)."""

    def __init__(self, X, ids, kind, leaf_size, checks):
        self.n = X.shape[0]
        self.kind = kind
        self.ids = ids
        if kind == "ckdtree":
            self._t = cKDTree(X, leafsize=leaf_size, balanced_tree=True, compact_nodes=False)
        elif kind == "brute":
            self._t = X
        else:
            self._t = KDTree(X, ids, leaf_size=leaf_size)
        self.max_leaves = None if kind != "bbf" else max(1, -(-checks // leaf_size))

    def query(self, Q, k, counters):
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


class LandmarkStore(ABC):
    """The landmark-store interface (000 §3.4): every store, and the stereo pipeline's, derives from it.

    Subclasses implement ``_add(X, ids)`` (checked batch), ``_query(Q, k)`` (checked, non-empty),
    ``_stored() -> (X, ids)`` (every stored point) and ``__len__``; ``observe`` and
    ``end_iteration`` do nothing unless the store applies the base rule or rebuilds.
    ``query_among`` is exact (brute force over the selected points) for every store.
    """

    name = "store"
    insert_only = True
    #: True for the stores that compare binary uint8 descriptors by Hamming distance (exact stores)
    binary_ok = False

    def __init__(self):
        self.counters = StoreCounters()
        self.dim: int | None = None
        self.dtype = None

    # -- interface ---------------------------------------------------------------------------------
    def add(self, X, ids) -> None:
        """Add a batch of new points (first sighting) with their ids."""
        X, ids = self._check_batch(X, ids)
        if X.shape[0]:
            self.counters.points_added += X.shape[0]
            self._add(X, ids)

    def observe(self, ids) -> None:
        """Record re-sightings of stored ids this iteration (only the base rule uses them)."""
        _as_ids(ids, "ids")

    def end_iteration(self) -> None:  # noqa: B027 (a no-op unless the store rebuilds or applies the base rule)
        """Close an iteration (apply the base rule, rebuild what the store rebuilds)."""

    def query(self, Q, k: int = 2):
        """The ``k`` nearest stored points of every row of ``Q``: ``(dist (M, k), ids (M, k))``."""
        Q, k = self._check_query(Q, k)
        if len(self) == 0 or Q.shape[0] == 0:
            return pad_knn(np.empty((Q.shape[0], 0)), np.empty((Q.shape[0], 0), dtype=np.int64), k)
        return self._query(Q, k)

    def query_among(self, Q, among, k: int = 2):
        """Like :meth:`query`, searching only (and exactly) the stored points whose ids are in ``among``."""
        Q, k = self._check_query(Q, k)
        among = _as_ids(np.asarray(among).ravel(), "among")
        X, ids = self._stored()
        rows = np.isin(ids, among)
        self.counters.distance_evals += Q.shape[0] * int(rows.sum())
        return exact_knn(Q, X[rows], k, ids[rows])

    @abstractmethod
    def __len__(self) -> int:
        """Number of stored points."""

    def __repr__(self) -> str:
        return f"{type(self).__name__}(n={len(self)})"

    # -- what a store implements --------------------------------------------------------------------
    @abstractmethod
    def _add(self, X, ids) -> None:
        """Store a checked, non-empty batch."""

    @abstractmethod
    def _query(self, Q, k):
        """k-NN of a checked, non-empty query batch in a non-empty store."""

    @abstractmethod
    def _stored(self):
        """``(X (n, d), ids (n,))``: every stored point."""

    # -- helpers -----------------------------------------------------------------------------------
    def _check_batch(self, X, ids):
        X = _as_points(X, "X", self.dim, self.dtype, self.binary_ok)
        ids = _as_ids(ids, "ids", X.shape[0])
        if self.dim is None and X.shape[0]:
            self.dim, self.dtype = X.shape[1], X.dtype
        return X, ids

    def _check_query(self, Q, k):
        Q = _as_points(Q, "Q", self.dim, self.dtype, self.binary_ok)
        k = v.check_int(k, "k", minimum=1)
        self.counters.queries += Q.shape[0]
        return Q, k


def _check_tree_args(tree, leaf_size, checks):
    tree = v.check_choice(tree, "tree", TREE_KINDS)
    leaf_size = v.check_int(leaf_size, "leaf_size", minimum=1)
    checks = v.check_int(checks, "checks", minimum=1)
    return tree, leaf_size, checks


class _PointSet:
    """Points + ids in a growing buffer (capacity doubling; no per-add copy of everything)."""

    def __init__(self):
        self.X = np.empty((0, 0), dtype=np.float32)
        self.ids = np.empty(0, dtype=np.int64)
        self.n = 0
        self._aug = None  # float rows [x, |x|²/2] for the exact search, rows [0, _aug_n) valid
        self._aug_n = 0

    def append(self, X, ids):
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
        return self.X[:self.n]

    @property
    def point_ids(self):
        return self.ids[:self.n]


class _BaseRuleStore(LandmarkStore):
    """Points in one buffer; with ``base_seen_times > 1`` non-base points that time out are dropped."""

    insert_only = False

    def __init__(self, base_seen_times: int, max_non_base_time: int):
        super().__init__()
        bst = v.check_int(base_seen_times, "base_seen_times", minimum=1)
        mnt = v.check_int(max_non_base_time, "max_non_base_time", minimum=1)
        self._pts = _PointSet()
        self._book = SightingBook(bst, mnt) if bst > 1 else None
        self._dirty = False
        self.dropped_ids = np.empty(0, dtype=np.int64)  # ids that timed out at the last end_iteration

    def _add(self, X, ids):
        self._pts.append(X, ids)
        if self._book is not None:
            self._book.add(ids)
        self._dirty = True

    def observe(self, ids):
        ids = _as_ids(ids, "ids")
        if self._book is not None:
            self._book.observe(ids)

    def end_iteration(self):
        if self._book is not None:
            _, self.dropped_ids = self._book.step()
            if self.dropped_ids.size:
                self._pts.keep(~np.isin(self._pts.point_ids, self.dropped_ids))
                self._dirty = True

    def _stored(self):
        return self._pts.points, self._pts.point_ids

    @property
    def points(self):
        return self._pts.points

    @property
    def ids(self):
        return self._pts.point_ids

    def __len__(self):
        return self._pts.n


class RebuildStore(_BaseRuleStore):
    """000's first method: one static tree rebuilt every iteration from kept + new points (000 §3.4).

    With ``base_seen_times > 1`` the store applies the base rule itself and drops
    non-base points that time out (Table 1 scenario), so it holds the same points
    as :class:`NonBaseBuffer` + :class:`MultiKDTree`.

    >>> rng = np.random.default_rng(0)
    >>> s = RebuildStore(tree="ckdtree")
    >>> s.add(rng.random((50, 4)), np.arange(50)); s.end_iteration()
    >>> d, i = s.query(s.points[:3]); i[:, 0].tolist()
    [0, 1, 2]
    """

    name = "kd-tree (rebuild)"

    def __init__(self, *, tree: str = "bbf", leaf_size: int = 8, checks: int = 200, base_seen_times: int = 1,
                 max_non_base_time: int = 7):
        super().__init__(base_seen_times, max_non_base_time)
        self.tree_kind, self.leaf_size, self.checks = _check_tree_args(tree, leaf_size, checks)
        self._tree: _Tree | None = None

    def end_iteration(self):
        super().end_iteration()
        if self._dirty:
            self._rebuild()

    def _rebuild(self):
        self._dirty = False
        if self._pts.n == 0:
            self._tree = None
            return
        self._tree = _Tree(self._pts.points.copy(), self._pts.point_ids.copy(), self.tree_kind, self.leaf_size,
                           self.checks)
        self.counters.points_rebuilt += self._pts.n
        self.counters.trees_built += 1

    def _query(self, Q, k):
        if self._dirty or self._tree is None:
            self._rebuild()
        return self._tree.query(Q, k, self.counters)


class ExactStore(_BaseRuleStore):
    """Exact brute-force store with 000's base rule (000 §3.4; our exact reference).

    Hamming distance for binary ``uint8`` descriptors (ORB: a kd-tree does not apply),
    Euclidean for float ones, by :func:`~slamlab.kdtree.knn.exact_knn`. Non-base points
    first seen ``max_non_base_time`` iterations ago are dropped (``dropped_ids``);
    ``base_seen_times = 1`` keeps every point (:class:`BruteForceStore`).

    Examples
    --------
    >>> s = ExactStore()
    >>> s.add(np.array([[0, 0], [3, 0]], np.float32), [10, 11]); s.end_iteration()
    >>> s.query(np.array([[1, 0]], np.float32))
    (array([[1., 2.]]), array([[10, 11]]))
    """

    name = "exact (brute force)"
    binary_ok = True

    def __init__(self, base_seen_times: int = 3, max_non_base_time: int = 7):
        super().__init__(base_seen_times, max_non_base_time)

    @property
    def is_base(self) -> np.ndarray:
        """(n,) True for stored points that reached ``base_seen_times`` sightings."""
        if self._book is None:
            return np.ones(self._pts.n, dtype=bool)
        return ~np.isin(self._pts.point_ids, self._book.ids)

    def _query(self, Q, k):
        self.counters.trees_searched += 1
        self.counters.distance_evals += Q.shape[0] * self._pts.n
        return exact_knn(Q, self._pts.points, k, self._pts.point_ids, augmented=self._pts.augmented)


class BruteForceStore(ExactStore):
    """Exact search by brute force, every point kept (no base rule; the reference of Tables 1-2).

    >>> rng = np.random.default_rng(0)
    >>> s = BruteForceStore()
    >>> X = rng.random((100, 8)); s.add(X, np.arange(100))
    >>> d, i = s.query(X[[5, 50]]); i[:, 0].tolist()
    [5, 50]
    """

    name = "brute force"
    insert_only = True

    def __init__(self):
        super().__init__(base_seen_times=1)


class MultiKDTree(LandmarkStore):
    """000's multi kd-tree: static trees of maximum sizes ``n1, q n1, q^2 n1, ...`` (000 §4.1).

    A batch goes into tree 1; then, while tree ``i`` holds more than ``MAX_SIZE[i]``
    points, tree ``i`` is merged into tree ``i + 1`` (both rebuilt as one). Trees are
    appended as needed, so the last tree's maximum always exceeds the total. Only
    the trees whose contents changed are rebuilt. A query searches every non-empty
    tree and merges the k-NN lists (exact when the per-tree search is exact).

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

    def __init__(self, n1: int = 3500, q: float = 5.5, *, tree: str = "bbf", leaf_size: int = 8,
                 checks: int = 200):
        super().__init__()
        self.n1 = v.check_int(n1, "n1", minimum=1)
        self.q = v.check_positive(q, "q")
        if self.q <= 1:
            raise ValueError(f"`q` must be > 1; got {q}")
        self.tree_kind, self.leaf_size, self.checks = _check_tree_args(tree, leaf_size, checks)
        self._X: list[np.ndarray] = []
        self._ids: list[np.ndarray] = []
        self._trees: list[_Tree | None] = []

    def max_size(self, i: int) -> int:
        """``MAX_SIZE[i] = floor(n1 q^i)`` (tree index from 0)."""
        return int(np.floor(self.n1 * self.q ** i + 1e-9))

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
                self._trees[j] = _Tree(self._X[j], self._ids[j], self.tree_kind, self.leaf_size, self.checks)
                self.counters.points_rebuilt += self._X[j].shape[0]
                self.counters.trees_built += 1
            else:
                self._trees[j] = None

    def check_invariant(self) -> bool:
        """000's invariant: tree i empty or > MAX_SIZE[i-1], never > MAX_SIZE[i]; last max > total."""
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


class FlannStore(LandmarkStore):
    """OpenCV FLANN randomised kd-trees searched with ``checks`` leaves (outside reference).

    OpenCV's Python ``cv2.flann_Index`` exposes no ``add``/``addPoints``, so this
    adapter rebuilds the index on every add (the C++ ``addPoints`` is not
    reachable from Python). FLANN draws its random split dimensions from OpenCV's
    global RNG; ``seed`` (not None) reseeds it with ``cv2.setRNGSeed`` before each
    build so that runs repeat (a side effect on OpenCV's global RNG).
    """

    name = "FLANN (OpenCV)"

    def __init__(self, *, trees: int = 4, checks: int = 200, seed: int | None = 0):
        super().__init__()
        self.seed = None if seed is None else v.check_int(seed, "seed", minimum=0)
        self.trees = v.check_int(trees, "trees", minimum=1)
        self.checks = v.check_int(checks, "checks", minimum=1)
        self._pts = _PointSet()
        self._index = None
        self._dirty = False

    def _add(self, X, ids):
        self._pts.append(X, ids)
        self._dirty = True

    def end_iteration(self):
        if self._dirty:
            self._build()

    def _build(self):
        self._data = np.ascontiguousarray(self._pts.points)
        self._index = flann_index(self._data, trees=self.trees, seed=self.seed)
        self._id_map = self._pts.point_ids.copy()
        self.counters.points_rebuilt += self._pts.n
        self.counters.trees_built += self.trees
        self._dirty = False

    def _query(self, Q, k):
        if self._dirty or self._index is None:
            self._build()
        kk = min(k, self._pts.n)
        idx, d2 = self._index.knnSearch(np.ascontiguousarray(Q), kk, params={"checks": self.checks})
        self.counters.trees_searched += self.trees
        idx = idx.reshape(Q.shape[0], kk).astype(np.int64)
        d = np.sqrt(np.maximum(d2.reshape(Q.shape[0], kk).astype(np.float64), 0.0))
        out_i = np.where(idx >= 0, self._id_map[np.maximum(idx, 0)], -1)
        return pad_knn(d, out_i, k)

    def _stored(self):
        return self._pts.points, self._pts.point_ids

    def __len__(self):
        return self._pts.n


class NonBaseBuffer(LandmarkStore):
    """Buffer of non-base points in front of an insert-only base store (000 §3.4, §4.1).

    A point is *non-base* while it has been seen fewer than ``base_seen_times``
    times and its first sighting is at most ``max_non_base_time`` iterations old.
    The buffer tree is rebuilt every iteration; at the end of an iteration the
    points that became base move to ``base`` (a :class:`MultiKDTree` by default)
    and the ones that timed out are dropped. ``base_seen_times = 1`` makes every
    point base at once (Table 2). Queries search buffer and base and merge the
    k-NN lists (our choice: 000 does not say how the 2-NN rule is merged).

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

    def __init__(self, base: LandmarkStore | None = None, *, base_seen_times: int = 3, max_non_base_time: int = 7,
                 tree: str = "bbf", leaf_size: int = 8, checks: int = 200):
        super().__init__()
        if base is None:
            base = MultiKDTree(tree=tree, leaf_size=leaf_size, checks=checks)
        if not isinstance(base, LandmarkStore):
            raise TypeError(f"`base` must be a LandmarkStore; got {type(base).__name__}")
        self.base = base
        self.tree_kind, self.leaf_size, self.checks = _check_tree_args(tree, leaf_size, checks)
        bst = v.check_int(base_seen_times, "base_seen_times", minimum=1)
        mnt = v.check_int(max_non_base_time, "max_non_base_time", minimum=1)
        self._book = SightingBook(bst, mnt)
        self._pts = _PointSet()
        self._tree: _Tree | None = None
        self.n_promoted = 0
        self.n_dropped = 0

    def _add(self, X, ids):
        if self._book.base_seen_times == 1:  # every point base at once
            self.base.add(X, ids)
            self.n_promoted += X.shape[0]
            return
        self._pts.append(X, ids)
        self._book.add(ids)

    def observe(self, ids):
        self._book.observe(_as_ids(ids, "ids"))

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
            self._tree = _Tree(self._pts.points.copy(), self._pts.point_ids.copy(), self.tree_kind, self.leaf_size,
                               self.checks)
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
                self._tree = _Tree(self._pts.points.copy(), self._pts.point_ids.copy(), self.tree_kind,
                                   self.leaf_size, self.checks)
            parts.append(self._tree.query(Q, k, self.counters))
        if len(self.base):
            parts.append(self.base.query(Q, k))
        return merge_knn([p[0] for p in parts], [p[1] for p in parts], k)

    def _stored(self):
        X, ids = self.base._stored()
        if not self._pts.n:
            return X, ids
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


STORE_NAMES = ("rebuild", "multi", "flann", "brute")


def make_store(name: str, *, n1: int = 3500, q: float = 5.5, base_seen_times: int = 1, max_non_base_time: int = 7,
               tree: str = "bbf", leaf_size: int = 8, checks: int = 200) -> LandmarkStore:
    """A store by short name, with the base rule applied the same way for all (000 §3.4).

    ``"rebuild"`` -- :class:`RebuildStore` (it applies the base rule itself);
    ``"multi"``, ``"flann"``, ``"brute"`` -- :class:`MultiKDTree`,
    :class:`FlannStore`, :class:`BruteForceStore` behind a :class:`NonBaseBuffer`.

    >>> make_store("multi", n1=1000, q=4).base
    MultiKDTree(n1=1000, q=4.0, sizes=[])
    """
    name = v.check_choice(name, "name", STORE_NAMES)
    if name == "rebuild":
        return RebuildStore(tree=tree, leaf_size=leaf_size, checks=checks, base_seen_times=base_seen_times,
                            max_non_base_time=max_non_base_time)
    if name == "multi":
        base = MultiKDTree(n1, q, tree=tree, leaf_size=leaf_size, checks=checks)
    elif name == "flann":
        base = FlannStore(checks=checks)
    else:
        base = BruteForceStore()
    buf = NonBaseBuffer(base, base_seen_times=base_seen_times, max_non_base_time=max_non_base_time,
                        tree="brute" if name == "brute" else tree,
                        leaf_size=leaf_size, checks=checks)
    buf.name = {"multi": "buffer + multi kd-tree", "flann": "buffer + FLANN", "brute": "buffer + brute force"}[name]
    return buf
