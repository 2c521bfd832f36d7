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

Every store takes its settings from one :class:`~slamlab.kdtree.store_params.StoreParams` (``params=``; the
keyword arguments a store names change its fields): the base rule, the multi kd-tree's ``n1, q`` and the
trees' ``tree``, ``leaf_size``, ``checks``, each with one default and its source.

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

import numpy as np

from .._validate import check_choice, check_int
from ._store_parts import PointSet, StaticTree
from .knn import exact_knn, flann_index, merge_knn, pad_knn
from .multi import MultiKDTree, NonBaseBuffer, multi_tree_sizes
from .store_base import LandmarkStore, SightingBook, StoreCounters, base_rule
from .store_params import TREE_KINDS, StoreParams, resolve_store_params

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
    "StoreParams",
    "base_rule",
    "make_store",
    "merge_knn",
    "multi_tree_sizes",
]


class _BaseRuleStore(LandmarkStore):
    """Points in one buffer; with ``base_seen_times > 1`` non-base points that time out are dropped."""

    insert_only = False

    def __init__(self, params: StoreParams):
        super().__init__()
        self.params = params
        self._pts = PointSet()
        self._book = (SightingBook(params.base_seen_times, params.max_non_base_time)
                      if params.base_seen_times > 1 else None)
        self._dirty = False
        self.dropped_ids = np.empty(0, dtype=np.int64)  # ids that timed out at the last end_iteration

    def _add(self, X, ids):
        self._pts.append(X, ids)
        if self._book is not None:
            self._book.add(ids)
        self._dirty = True

    def _observe(self, ids):
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

    With ``base_seen_times > 1`` (the default, 000 §3.4) the store applies the base rule itself and
    drops non-base points that time out (Table 1 scenario), so it holds the same points as
    :class:`NonBaseBuffer` + :class:`MultiKDTree`; ``base_seen_times=1`` keeps every point (Table 2).
    The store reads ``tree``, ``leaf_size``, ``checks`` and the base rule of its :class:`StoreParams`.

    Parameters
    ----------
    params : StoreParams, optional
        The settings (default :class:`StoreParams`); the arguments that are not None change its fields.
    tree : {'bbf', 'exact', 'ckdtree', 'brute'}, optional
        Search in the tree (:data:`TREE_KINDS`).
    leaf_size : int, optional
        Points per leaf of our trees.
    checks : int, optional
        Points examined by the BBF search.
    base_seen_times : int, optional
        Sightings that make a point base; 1 keeps every point.
    max_non_base_time : int, optional
        Age in iterations at which a non-base point is dropped.

    Examples
    --------
    >>> rng = np.random.default_rng(0)
    >>> s = RebuildStore(tree="ckdtree")
    >>> s.add(rng.random((50, 4)), np.arange(50)); s.end_iteration()
    >>> d, i = s.query(s.points[:3]); i[:, 0].tolist()
    [0, 1, 2]
    """

    name = "kd-tree (rebuild)"

    def __init__(self, *, params: StoreParams | None = None, tree: str | None = None, leaf_size: int | None = None,
                 checks: int | None = None, base_seen_times: int | None = None,
                 max_non_base_time: int | None = None):
        super().__init__(resolve_store_params(params, tree=tree, leaf_size=leaf_size, checks=checks,
                                              base_seen_times=base_seen_times, max_non_base_time=max_non_base_time))
        self.tree_kind, self.leaf_size, self.checks = self.params.tree, self.params.leaf_size, self.params.checks
        self._tree: StaticTree | None = None

    def end_iteration(self):
        super().end_iteration()
        if self._dirty:
            self._rebuild()

    def _rebuild(self):
        self._dirty = False
        if self._pts.n == 0:
            self._tree = None
            return
        self._tree = StaticTree(self._pts.points.copy(), self._pts.point_ids.copy(), self.params)
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
    ``base_seen_times = 1`` keeps every point (:class:`BruteForceStore`). The store reads the base
    rule of its :class:`StoreParams`.

    Parameters
    ----------
    base_seen_times : int, optional
        Sightings that make a point base (default from ``params``: 3, 000 §3.4).
    max_non_base_time : int, optional
        Age in iterations at which a non-base point is dropped (default from ``params``: 7, 000 §3.4).
    params : StoreParams, optional
        The settings (default :class:`StoreParams`); the arguments that are not None change its fields.

    Examples
    --------
    >>> s = ExactStore()
    >>> s.add(np.array([[0, 0], [3, 0]], np.float32), [10, 11]); s.end_iteration()
    >>> s.query(np.array([[1, 0]], np.float32))
    (array([[1., 2.]]), array([[10, 11]]))
    """

    name = "exact (brute force)"
    binary_ok = True

    def __init__(self, base_seen_times: int | None = None, max_non_base_time: int | None = None, *,
                 params: StoreParams | None = None):
        super().__init__(resolve_store_params(params, base_seen_times=base_seen_times,
                                              max_non_base_time=max_non_base_time))

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
    """Exact search by brute force, every point kept (no base rule; the reference of Tables 1-2; ours).

    An :class:`ExactStore` with ``base_seen_times=1``, said here rather than by a default.

    Examples
    --------
    >>> rng = np.random.default_rng(0)
    >>> s = BruteForceStore()
    >>> X = rng.random((100, 8)); s.add(X, np.arange(100))
    >>> d, i = s.query(X[[5, 50]]); i[:, 0].tolist()
    [5, 50]
    """

    name = "brute force"
    insert_only = True

    def __init__(self):
        super().__init__(base_seen_times=1)  # every point kept: the exact reference


class FlannStore(LandmarkStore):
    """OpenCV FLANN randomised kd-trees searched with ``checks`` leaves (outside reference).

    OpenCV's Python ``cv2.flann_Index`` exposes no ``add``/``addPoints``, so this
    adapter rebuilds the index on every add (the C++ ``addPoints`` is not
    reachable from Python). FLANN draws its random split dimensions from OpenCV's
    global RNG; ``opencv_seed`` (not None) reseeds it with ``cv2.setRNGSeed`` before each
    build so that runs repeat (a side effect on OpenCV's global RNG).

    The store reads ``checks`` of its :class:`StoreParams` (an insert-only store: the base rule is the
    buffer's, :class:`NonBaseBuffer`).

    Parameters
    ----------
    params : StoreParams, optional
        The settings (default :class:`StoreParams`); ``checks`` changes its field.
    checks : int, optional
        Leaves checked per query (default from ``params``: 200).
    trees : int
        Randomised kd-trees in the index (ours: OpenCV's default 4).
    opencv_seed : int or None
        Seed of OpenCV's global RNG (``cv2.setRNGSeed``, not a numpy stream) before each build
        (None: not reseeded).
    """

    name = "FLANN (OpenCV)"

    def __init__(self, *, params: StoreParams | None = None, checks: int | None = None, trees: int = 4,
                 opencv_seed: int | None = 0):
        super().__init__()
        self.params = resolve_store_params(params, checks=checks)
        self.opencv_seed = None if opencv_seed is None else check_int(opencv_seed, "opencv_seed", minimum=0)
        self.trees = check_int(trees, "trees", minimum=1)
        self.checks = self.params.checks
        self._pts = PointSet()
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
        self._index = flann_index(self._data, trees=self.trees, opencv_seed=self.opencv_seed)
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


STORE_NAMES = ("rebuild", "multi", "flann", "brute")


def make_store(name: str, *, params: StoreParams | None = None, **overrides) -> LandmarkStore:
    """A store by short name, with the base rule applied the same way for all (000 §3.4).

    ``"rebuild"`` -- :class:`RebuildStore` (it applies the base rule itself);
    ``"multi"``, ``"flann"``, ``"brute"`` -- :class:`MultiKDTree`,
    :class:`FlannStore`, :class:`BruteForceStore` behind a :class:`NonBaseBuffer`. The settings are
    resolved once, ``StoreParams.resolve(params, **overrides)``, and given to every part (the buffer in
    front of ``"brute"`` is searched by brute force whatever ``tree`` says).

    Parameters
    ----------
    name : {'rebuild', 'multi', 'flann', 'brute'}
        The store (:data:`STORE_NAMES`).
    params : StoreParams, optional
        The settings (default :class:`StoreParams`: 000's base rule 3 / 7, ``n1 = 3500``, ``q = 5.5``).
    **overrides
        :class:`StoreParams` fields to change (``base_seen_times``, ``max_non_base_time``, ``n1``, ``q``,
        ``tree``, ``leaf_size``, ``checks``).

    Returns
    -------
    LandmarkStore
        A :class:`RebuildStore` or a :class:`NonBaseBuffer` in front of the named base.

    Examples
    --------
    >>> make_store("multi", n1=1000, q=4).base
    MultiKDTree(n1=1000, q=4.0, sizes=[])
    >>> make_store("brute", base_seen_times=1).params.base_seen_times
    1
    """
    name = check_choice(name, "name", STORE_NAMES)
    p = StoreParams.resolve(params, **overrides)
    if name == "rebuild":
        return RebuildStore(params=p)
    if name == "multi":
        base = MultiKDTree(params=p)
    elif name == "flann":
        base = FlannStore(params=p)
    else:
        base = BruteForceStore()
    buf = NonBaseBuffer(base, params=p.replace(tree="brute") if name == "brute" else p)
    buf.name = {"multi": "buffer + multi kd-tree", "flann": "buffer + FLANN", "brute": "buffer + brute force"}[name]
    return buf
