"""Landmark descriptor stores: one rebuilt tree, the multi kd-tree, the non-base buffer (000 §3.4, §4).

Every store keeps a growing set of k-dimensional descriptors with integer ids and
has the same interface:

- ``add(X, ids)`` -- new points of this iteration (their first sighting);
- ``observe(ids)`` -- ids re-sighted this iteration (used by the base rule);
- ``end_iteration()`` -- apply the base rule / rebuild (part of the "add" time);
- ``query(Q, k=2) -> (dist, ids)`` -- the k nearest stored points of every query;
- ``len(store)`` and ``store.counters`` -- points rebuilt, trees searched, nodes
  visited, distance evaluations (the operation counts the analysis needs).

Stores of 000: :class:`RebuildStore` (first method: one static tree rebuilt every
iteration from kept + new points) and :class:`MultiKDTree` (second method: trees
of maximum sizes ``n1, q n1, q^2 n1, ...``) behind a :class:`NonBaseBuffer`
(points seen fewer than ``BaseSeenTimes = 3`` times and first seen at most
``MaxNonBaseTime = 7`` iterations ago). References (our addition):
:class:`BruteForceStore` (exact, BLAS, running top-2 over cache-sized blocks) and
:class:`FlannStore` (OpenCV's randomised kd-trees, ``checks = 200``).

The tree inside a store is chosen with ``tree``: ``"bbf"`` -- the teaching
:class:`~slamlab.kdtree.tree.KDTree` searched by Best-Bin-First with ``checks``
points examined per tree (000 §1.4.3: "about 200"), ``"exact"`` -- the same tree
searched exactly, ``"ckdtree"`` -- scipy's exact ``cKDTree``, ``"brute"`` --
:class:`BruteForceStore` (exact; used for the buffer in front of brute force). In 64 dimensions
an exact tree search visits almost every leaf, so only ``"bbf"`` is fast.
"""

from __future__ import annotations

from dataclasses import dataclass, fields

import numpy as np
from scipy.spatial import cKDTree

from .. import _validate as v
from .tree import KDTree

__all__ = [
    "STORE_NAMES",
    "TREE_KINDS",
    "BruteForceStore",
    "FlannStore",
    "LandmarkStore",
    "MultiKDTree",
    "NonBaseBuffer",
    "RebuildStore",
    "StoreCounters",
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


def merge_knn(dists, ids, k: int = 2):
    """Merge per-tree k-NN lists into the k nearest overall (000 §4: a query searches every tree).

    Parameters
    ----------
    dists, ids : lists of (M, k_i) arrays
        Distances (``inf`` for missing) and ids (-1 for missing) from each tree.

    >>> d, i = merge_knn([np.array([[1.0, 3.0]]), np.array([[2.0, np.inf]])],
    ...                  [np.array([[10, 11]]), np.array([[20, -1]])])
    >>> d.tolist(), i.tolist()
    ([[1.0, 2.0]], [[10, 20]])
    """
    D = np.concatenate(dists, axis=1)
    idx = np.concatenate(ids, axis=1)
    o = np.argsort(D, axis=1, kind="stable")[:, :k]
    D, idx = np.take_along_axis(D, o, axis=1), np.take_along_axis(idx, o, axis=1)
    if D.shape[1] < k:  # fewer candidates than k: pad
        pad = k - D.shape[1]
        D = np.concatenate([D, np.full((D.shape[0], pad), np.inf)], axis=1)
        idx = np.concatenate([idx, np.full((idx.shape[0], pad), -1, dtype=idx.dtype)], axis=1)
    return D, idx


def _as_points(X, name, dim=None):
    X = np.asarray(X)
    if X.dtype.kind not in "fiu":
        raise TypeError(f"`{name}` must be a numeric array; got dtype {X.dtype}")
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
            self._t = BruteForceStore()
            self._t.add(X, ids)
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
            return d, out_i
        if self.kind == "brute":
            counters.distance_evals += Q.shape[0] * self.n
            return self._t.query(Q, k)
        d, i = self._t.query(Q, k, max_leaves=self.max_leaves)
        st = self._t.last_stats
        counters.nodes_visited += int(st.nodes_visited.sum())
        counters.distance_evals += int(st.distance_evals.sum())
        return d, i


class LandmarkStore:
    """Interface of a growing descriptor store (000 §3.4); see the module docstring."""

    name = "store"
    insert_only = True

    def __init__(self):
        self.counters = StoreCounters()
        self.dim: int | None = None

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

    def end_iteration(self) -> None:
        """Close an iteration (apply the base rule, rebuild what the store rebuilds)."""

    def query(self, Q, k: int = 2):
        """The ``k`` nearest stored points of every row of ``Q``: ``(dist (M, k), ids (M, k))``."""
        Q = _as_points(Q, "Q", self.dim)
        k = v.check_int(k, "k", minimum=1)
        self.counters.queries += Q.shape[0]
        if len(self) == 0 or Q.shape[0] == 0:
            return np.full((Q.shape[0], k), np.inf), np.full((Q.shape[0], k), -1, dtype=np.int64)
        return self._query(Q, k)

    def __len__(self) -> int:
        raise NotImplementedError

    def __repr__(self) -> str:
        return f"{type(self).__name__}(n={len(self)})"

    # -- helpers -----------------------------------------------------------------------------------
    def _check_batch(self, X, ids):
        X = _as_points(X, "X", self.dim)
        ids = _as_ids(ids, "ids", X.shape[0])
        if self.dim is None and X.shape[0]:
            self.dim = X.shape[1]
        return X, ids


def _check_tree_args(tree, leaf_size, checks):
    tree = v.check_choice(tree, "tree", TREE_KINDS)
    leaf_size = v.check_int(leaf_size, "leaf_size", minimum=1)
    checks = v.check_int(checks, "checks", minimum=1)
    return tree, leaf_size, checks


class _PointSet:
    """Points + ids in a growing float32 buffer (capacity doubling; no per-add copy of everything)."""

    def __init__(self):
        self.X = np.empty((0, 0), dtype=np.float32)
        self.ids = np.empty(0, dtype=np.int64)
        self.n = 0

    def append(self, X, ids):
        need = self.n + X.shape[0]
        if self.X.shape[0] < need or self.X.shape[1] != X.shape[1]:
            cap = max(need, 2 * self.X.shape[0], 1024)
            Xn = np.empty((cap, X.shape[1]), dtype=np.float32)
            In = np.empty(cap, dtype=np.int64)
            if self.n:
                Xn[:self.n], In[:self.n] = self.X[:self.n], self.ids[:self.n]
            self.X, self.ids = Xn, In
        self.X[self.n:need], self.ids[self.n:need] = X, ids
        self.n = need

    def keep(self, mask):
        k = int(mask.sum())
        self.X[:k], self.ids[:k] = self.X[:self.n][mask], self.ids[:self.n][mask]
        self.n = k

    @property
    def points(self):
        return self.X[:self.n]

    @property
    def point_ids(self):
        return self.ids[:self.n]


class _SightingBook:
    """The base rule of 000 §3.4: seen counts and first-sighting iterations of non-base points."""

    def __init__(self, base_seen_times, max_non_base_time):
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
        base = self.seen >= self.base_seen_times
        late = ~base & (self.iteration - self.first >= self.max_non_base_time)
        promoted, dropped = self.ids[base], self.ids[late]
        keep = ~(base | late)
        self.ids, self.seen, self.first = self.ids[keep], self.seen[keep], self.first[keep]
        self.iteration += 1
        return promoted, dropped


class RebuildStore(LandmarkStore):
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
    insert_only = False

    def __init__(self, *, tree: str = "bbf", leaf_size: int = 8, checks: int = 200, base_seen_times: int = 1,
                 max_non_base_time: int = 7):
        super().__init__()
        self.tree_kind, self.leaf_size, self.checks = _check_tree_args(tree, leaf_size, checks)
        bst = v.check_int(base_seen_times, "base_seen_times", minimum=1)
        mnt = v.check_int(max_non_base_time, "max_non_base_time", minimum=1)
        self._pts = _PointSet()
        self._book = _SightingBook(bst, mnt) if bst > 1 else None
        self._tree: _Tree | None = None
        self._dirty = False

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
            _, dropped = self._book.step()
            if dropped.size:
                self._pts.keep(~np.isin(self._pts.point_ids, dropped))
                self._dirty = True
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

    @property
    def points(self):
        return self._pts.points

    @property
    def ids(self):
        return self._pts.point_ids

    def __len__(self):
        return self._pts.n


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

    def __len__(self):
        return sum(self.sizes)

    def __repr__(self):
        return f"MultiKDTree(n1={self.n1}, q={self.q}, sizes={self.sizes})"


class BruteForceStore(LandmarkStore):
    """Exact search on BLAS with a running top-2 over cache-sized blocks (our addition).

    The squared distance is ``|q|^2 + |x|^2 - 2 q.x``; one GEMM per block of
    ``block`` database rows computes ``|x|^2/2 - q.x`` (the database is kept as
    ``[x, |x|^2/2]`` and queries as ``[-q, 1]``, so the GEMM writes the ranking key
    directly) and the best two per query are kept; the full distance matrix is
    never written. The winners' distances are then recomputed directly in float64.

    >>> rng = np.random.default_rng(0)
    >>> s = BruteForceStore(block=16)
    >>> X = rng.random((100, 8)); s.add(X, np.arange(100))
    >>> d, i = s.query(X[[5, 50]]); i[:, 0].tolist()
    [5, 50]
    """

    name = "brute force (BLAS)"

    def __init__(self, *, block: int = 8192):
        super().__init__()
        self.block = v.check_int(block, "block", minimum=1)
        self._A = np.empty((0, 0), dtype=np.float32)  # (cap, k+1): [x, |x|^2/2]
        self._ids = np.empty(0, dtype=np.int64)
        self._n = 0
        self._buf: np.ndarray | None = None

    def _add(self, X, ids):
        need = self._n + X.shape[0]
        if self._A.shape[0] < need:
            cap = max(need, 2 * self._A.shape[0], 1024)
            A = np.empty((cap, X.shape[1] + 1), dtype=np.float32)
            In = np.empty(cap, dtype=np.int64)
            if self._n:
                A[:self._n] = self._A[:self._n]
                In[:self._n] = self._ids[:self._n]
            self._A, self._ids = A, In
        self._A[self._n:need, :-1] = X
        self._A[self._n:need, -1] = 0.5 * np.einsum("ij,ij->i", X, X)
        self._ids[self._n:need] = ids
        self._n = need

    def _query(self, Q, k):
        M, n, B = Q.shape[0], self._n, self.block
        Qa = np.empty((M, Q.shape[1] + 1), dtype=np.float32)
        Qa[:, :-1] = -Q
        Qa[:, -1] = 1.0
        if self._buf is None or self._buf.shape[0] != M or self._buf.shape[1] < min(B, n):
            self._buf = np.empty((M, min(B, n)), dtype=np.float32)  # reused while the shapes allow
        rows = np.arange(M)
        kk = min(k, n)
        best_v = np.full((M, kk), np.inf, dtype=np.float32)
        best_i = np.zeros((M, kk), dtype=np.int64)
        for s0 in range(0, n, B):
            s1 = min(s0 + B, n)
            G = self._buf[:, :s1 - s0]
            np.matmul(Qa, self._A[s0:s1].T, out=G)  # |x|^2/2 - q.x for the block
            if kk <= 2 and s1 - s0 >= kk:
                i1 = np.argmin(G, axis=1)
                v1 = G[rows, i1]
                if kk == 2:
                    G[rows, i1] = np.inf
                    i2 = np.argmin(G, axis=1)
                    v2 = G[rows, i2]
                    cv = np.concatenate([best_v, v1[:, None], v2[:, None]], axis=1)
                    ci = np.concatenate([best_i, (i1 + s0)[:, None], (i2 + s0)[:, None]], axis=1)
                else:
                    cv = np.concatenate([best_v, v1[:, None]], axis=1)
                    ci = np.concatenate([best_i, (i1 + s0)[:, None]], axis=1)
            else:
                cv = np.concatenate([best_v, G], axis=1)
                ci = np.concatenate([best_i, np.broadcast_to(np.arange(s0, s1), G.shape)], axis=1)
            o = np.argsort(cv, axis=1, kind="stable")[:, :kk]
            best_v, best_i = np.take_along_axis(cv, o, axis=1), np.take_along_axis(ci, o, axis=1)
        self.counters.trees_searched += 1
        self.counters.distance_evals += M * n
        # distances of the winners recomputed directly (the GEMM form loses digits to cancellation)
        diff = self._A[best_i, :-1].astype(np.float64) - Q[:, None, :].astype(np.float64)
        d = np.sqrt(np.einsum("ijk,ijk->ij", diff, diff))
        o = np.argsort(d, axis=1, kind="stable")
        d, best_i = np.take_along_axis(d, o, axis=1), np.take_along_axis(best_i, o, axis=1)
        out_i = self._ids[best_i]
        if kk < k:
            d = np.concatenate([d, np.full((M, k - kk), np.inf)], axis=1)
            out_i = np.concatenate([out_i, np.full((M, k - kk), -1, dtype=np.int64)], axis=1)
        return d, out_i

    def __len__(self):
        return self._n


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
        import cv2

        self._data = np.ascontiguousarray(self._pts.points)
        if self.seed is not None:
            cv2.setRNGSeed(self.seed)
        self._index = cv2.flann_Index(self._data, {"algorithm": 1, "trees": self.trees})
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
        if kk < k:
            d = np.concatenate([d, np.full((Q.shape[0], k - kk), np.inf)], axis=1)
            out_i = np.concatenate([out_i, np.full((Q.shape[0], k - kk), -1, dtype=np.int64)], axis=1)
        return d, out_i

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
        self._book = _SightingBook(bst, mnt)
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
