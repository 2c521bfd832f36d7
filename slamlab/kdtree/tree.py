"""Teaching kd-tree: static, balanced, exact k-NN and Best-Bin-First search (000 §1.4.3).

000 §1.4.3 builds the tree recursively: pick the coordinate ``m`` with the "best
distribution" of the points, split at the median of that coordinate, recurse on
both halves -- a balanced tree that cannot be modified. Our reading of "best
distribution" (000 is silent on it): the coordinate of **largest spread**
(max - min); the median split is by *position* in the sorted order, so points
equal to the split value may sit on either side (ties handled explicitly: left
holds values ``<= split``, right ``>= split``; both lower bounds stay valid).

Search (Beis & Lowe's Best-Bin-First, which 000 cites): descend to the leaf of
the query, remember every branch not taken with its lower bound -- the squared
distance from the query to the splitting plane (our choice: the max of that and
the parent's bound) --, then keep expanding the pending branch with the smallest
bound. Exact search stops when the smallest pending bound is no better than the
current k-th neighbour; BBF also stops after ``max_leaves`` leaves (000: "about
200"). With ``max_leaves=None`` both are the same search, so BBF with unlimited
leaves equals exact search by construction (and the tests check it against
``scipy.spatial.cKDTree``).

Speed: all queries of a batch run in lock-step with numpy arrays -- in each round
every unfinished query pops its best pending branch, descends to a leaf and
evaluates that leaf's bucket. There is no Python loop over queries or points;
the Python loops are over rounds (≤ leaves visited) and tree depth. Where numba is enabled the same rounds run
compiled (``_kernels.py``, issue 25): the same neighbours, distances and counts, without the per-round cost.
:func:`slamlab.kdtree.bbf_trace` (in ``trace.py``) is the plain one-query version with ``heapq`` that
the notebook prints step by step.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .. import _validate as v
from .._compiled import numba_enabled
from ._bounds import BBF_BOUNDS, _cell_bounds, _far_bound

__all__ = ["BBF_BOUNDS", "KDTree", "SearchStats", "build_kdtree"]


@dataclass(frozen=True)
class SearchStats:
    """Work done by the last :meth:`KDTree.query` (per query arrays and totals).

    Attributes
    ----------
    nodes_visited : (Q,) int
        Internal nodes passed on the way down, per query.
    leaves_visited : (Q,) int
        Leaf buckets evaluated, per query.
    distance_evals : (Q,) int
        Point-to-query distances computed, per query.
    """

    nodes_visited: np.ndarray  # (Q,) internal nodes passed on the way down
    leaves_visited: np.ndarray  # (Q,) leaf buckets evaluated
    distance_evals: np.ndarray  # (Q,) point-to-query distances computed

    @property
    def mean_leaves(self) -> float:
        return float(self.leaves_visited.mean()) if self.leaves_visited.size else 0.0

    @property
    def mean_distance_evals(self) -> float:
        return float(self.distance_evals.mean()) if self.distance_evals.size else 0.0

    def __str__(self) -> str:
        n = self.leaves_visited.size
        return (f"{n} queries: mean {self.nodes_visited.mean() if n else 0:.1f} nodes, "
                f"{self.mean_leaves:.1f} leaves, {self.mean_distance_evals:.1f} distance evaluations per query")


def build_kdtree(points, ids=None, *, leaf_size: int = 1):
    """Median split on the coordinate of largest spread, level by level (000 §1.4.3).

    Parameters
    ----------
    points : (N, k) array
        The k-dimensional points (descriptors).
    ids : (N,) int array, optional
        Identifiers returned by queries; ``arange(N)`` by default.
    leaf_size : int
        A node with at most this many points is a leaf (bucket). 1 = one point per
        leaf, as in Beis & Lowe's BBF where "200 leaves" means 200 points examined.

    Returns
    -------
    dict of arrays
        ``perm`` (points in leaf order), ``split_dim``, ``split_val``, ``left``,
        ``right`` (-1 for leaves), ``start``, ``stop`` (leaf bucket ranges in
        ``perm``), ``depth``. Node 0 is the root; nodes are numbered level by level.

    Examples
    --------
    >>> t = build_kdtree(np.array([[0.0, 0], [1, 0], [2, 0], [3, 5]]))
    >>> int(t["split_dim"][0]), float(t["split_val"][0])
    (1, 0.0)
    """
    keep32 = isinstance(points, np.ndarray) and points.dtype == np.float32
    X = v.as_finite_array(points, "points", ndim=2, dtype=np.float32 if keep32 else np.float64)
    n, k = X.shape
    if n == 0 or k == 0:
        raise ValueError(f"`points` must hold at least one point of dimension >= 1; got shape {X.shape}")
    leaf_size = v.check_int(leaf_size, "leaf_size", minimum=1)
    if ids is None:
        ids = np.arange(n, dtype=np.int64)
    else:
        ids = np.asarray(ids)
        if not np.issubdtype(ids.dtype, np.integer):
            raise TypeError(f"`ids` must be an integer array; got dtype {ids.dtype}")
        if ids.shape != (n,):
            raise ValueError(f"`ids` must have shape ({n},) to match `points`; got shape {ids.shape}")
        ids = ids.astype(np.int64)

    perm = np.arange(n, dtype=np.int64)
    # current level: segments [s0, s1) of perm, with their node numbers
    seg_start = np.array([0], dtype=np.int64)
    seg_stop = np.array([n], dtype=np.int64)
    seg_node = np.array([0], dtype=np.int64)
    n_nodes, level = 1, 0
    node_rows = []  # (node ids, dims, vals, left, right, start, stop, depth) per level
    while seg_start.size:
        size = seg_stop - seg_start
        is_leaf = size <= leaf_size
        inner = ~is_leaf
        # leaves of this level
        lf = np.flatnonzero(is_leaf)
        node_rows.append((seg_node[lf], np.full(lf.size, -1), np.zeros(lf.size), np.full(lf.size, -1),
                          np.full(lf.size, -1), seg_start[lf], seg_stop[lf], np.full(lf.size, level)))
        if not inner.any():
            break
        s0, s1, nodes = seg_start[inner], seg_stop[inner], seg_node[inner]
        lens = s1 - s0
        dim = _widest_coordinate(X, perm, s0, lens)
        lmax = int(lens.max())
        # sort every segment by its split coordinate (rows padded with +inf; stable: ties keep order)
        cols = np.arange(lmax)
        valid = cols < lens[:, None]
        idx = np.where(valid, s0[:, None] + cols, s0[:, None])
        key = np.where(valid, X[perm[idx], dim[:, None]], np.inf)
        o = np.argsort(key, axis=1, kind="stable")
        key = np.take_along_axis(key, o, axis=1)
        perm[idx[valid]] = perm[np.take_along_axis(idx, o, axis=1)][valid]
        half = lens // 2  # left gets floor(n/2) points, right the rest
        mid = s0 + half
        # split value: the largest value on the left (left <= split <= right)
        val = key[np.arange(s0.size), half - 1].astype(np.float64)
        lnode = n_nodes + 2 * np.arange(s0.size)
        rnode = lnode + 1
        n_nodes += 2 * s0.size
        node_rows.append((nodes, dim, val, lnode, rnode, np.full(s0.size, -1), np.full(s0.size, -1),
                          np.full(s0.size, level)))
        seg_start = np.concatenate([s0, mid])
        seg_stop = np.concatenate([mid, s1])
        seg_node = np.concatenate([lnode, rnode])
        srt = np.argsort(seg_node)
        seg_start, seg_stop, seg_node = seg_start[srt], seg_stop[srt], seg_node[srt]
        level += 1

    split_dim = np.empty(n_nodes, dtype=np.int64)
    split_val = np.empty(n_nodes, dtype=np.float64)
    left = np.empty(n_nodes, dtype=np.int64)
    right = np.empty(n_nodes, dtype=np.int64)
    start = np.empty(n_nodes, dtype=np.int64)
    stop = np.empty(n_nodes, dtype=np.int64)
    depth = np.empty(n_nodes, dtype=np.int64)
    for nodes, d, val, lft, rgt, s0, s1, dep in node_rows:
        split_dim[nodes], split_val[nodes], left[nodes], right[nodes] = d, val, lft, rgt
        start[nodes], stop[nodes], depth[nodes] = s0, s1, dep
    return {"points": X, "ids": ids, "perm": perm, "split_dim": split_dim, "split_val": split_val,
            "left": left, "right": right, "start": start, "stop": stop, "depth": depth, "leaf_size": leaf_size}


def _widest_coordinate(X, perm, s0, lens):
    """Per segment ``perm[s0 : s0 + lens]`` of the points ``X``, the coordinate of largest spread (max − min;
    ties: the lowest index), our reading of 000 §1.4.3's "best distribution"."""
    # balanced halving keeps a level's lengths within {L, L+1}, so the first min(lens) points of every segment
    # form a regular (segments, L, k) block
    lmin, lmax = int(lens.min()), int(lens.max())
    block = X[perm[s0[:, None] + np.arange(lmin)]]
    hi, lo = block.max(axis=1), block.min(axis=1)
    for e in range(lmin, lmax):
        has = np.flatnonzero(lens > e)
        extra = X[perm[s0[has] + e]]
        hi[has] = np.maximum(hi[has], extra)
        lo[has] = np.minimum(lo[has], extra)
    return np.argmax(hi - lo, axis=1)


class KDTree:
    """Static balanced kd-tree with exact and Best-Bin-First k-NN queries (000 §1.4.3).

    Parameters
    ----------
    points : (N, k) array
        Points (e.g. 64-d SURF descriptors); float32 input is kept as float32.
    ids : (N,) int array, optional
        Identifiers returned by :meth:`query` (default ``arange(N)``).
    leaf_size : int
        Bucket size of a leaf (default 1: a leaf is a point, as in BBF's "200 leaves").

    Examples
    --------
    >>> rng = np.random.default_rng(0)
    >>> X = rng.random((100, 3))
    >>> tree = KDTree(X)
    >>> d, i = tree.query(X[:2], k=2)
    >>> i[:, 0].tolist(), d[:, 0].tolist()
    ([0, 1], [0.0, 0.0])
    >>> tree.last_stats.leaves_visited.shape
    (2,)
    """

    def __init__(self, points, ids=None, *, leaf_size: int = 1):
        t = build_kdtree(points, ids, leaf_size=leaf_size)
        self.points = t["points"]
        self.ids = t["ids"]
        self.leaf_size = t["leaf_size"]
        self._t = t
        # points and ids in leaf order: a leaf's bucket is a contiguous slice
        self._P = np.ascontiguousarray(self.points[t["perm"]])
        self._ids_leaf = self.ids[t["perm"]]
        self.last_stats: SearchStats | None = None

    @property
    def n(self) -> int:
        """Number of stored points."""
        return self.points.shape[0]

    @property
    def dim(self) -> int:
        """Dimension k of the points."""
        return self.points.shape[1]

    @property
    def n_nodes(self) -> int:
        return self._t["split_dim"].size

    @property
    def n_leaves(self) -> int:
        return int(np.count_nonzero(self._t["left"] < 0))

    @property
    def height(self) -> int:
        """Depth of the deepest leaf (root = 0)."""
        return int(self._t["depth"].max())

    @property
    def nodes(self) -> dict:
        """The node arrays (see :func:`build_kdtree`); read-only views for teaching and plots."""
        return self._t

    def __len__(self) -> int:
        return self.n

    def __repr__(self) -> str:
        return f"KDTree(n={self.n}, k={self.dim}, leaf_size={self.leaf_size}, height={self.height})"

    def query(self, Q, k: int = 2, *, max_leaves: int | None = None, bound: str = "max"):
        """k nearest neighbours of every row of ``Q``: exact, or BBF after ``max_leaves`` leaves (000 §1.4.3).

        Parameters
        ----------
        Q : (M, k_dim) or (k_dim,) array
            Query points.
        k : int
            Number of neighbours (2 for the matching rules).
        max_leaves : int or None
            None = exact search; otherwise stop each query after that many leaves
            (000: about 200).
        bound : {'max', 'incremental', 'sum'}
            Lower bound that orders the pending branches (:data:`BBF_BOUNDS`; default ``"max"``).

        Returns
        -------
        dist : (M, k) float array
            Euclidean distances, ascending; ``inf`` where fewer than k points exist.
        ids : (M, k) int array
            Ids of the neighbours (-1 where missing).
        """
        Q = v.as_finite_array(Q, "Q")
        single = Q.ndim == 1
        if single:
            Q = Q[None, :]
        if Q.ndim != 2 or Q.shape[1] != self.dim:
            raise ValueError(f"`Q` must have shape (M, {self.dim}) to match the tree; got shape {Q.shape}")
        k = v.check_int(k, "k", minimum=1)
        if max_leaves is not None:
            max_leaves = v.check_int(max_leaves, "max_leaves", minimum=1)
        if bound not in BBF_BOUNDS:
            raise ValueError(f"`bound` must be one of {BBF_BOUNDS}; got {bound!r}")
        if bound == "incremental" and "cell_lo" not in self._t:
            self._t["cell_lo"], self._t["cell_hi"] = _cell_bounds(self._t)
        Q = Q.astype(self._P.dtype, copy=False)
        if numba_enabled():  # the compiled search: the same results as the numpy one (issue 25)
            from ._kernels import bbf_search

            d2, idx, *counts = bbf_search(self._t, self._P, Q, k, max_leaves, bound)
            stats = SearchStats(*counts)
        else:
            d2, idx, stats = _lockstep_search(self._t, self._P, Q, k, max_leaves, bound)
        self.last_stats = stats
        dist = np.sqrt(np.maximum(d2, 0.0))
        ids = np.where(idx >= 0, self._ids_leaf[np.maximum(idx, 0)], -1)
        if single:
            return dist[0], ids[0]
        return dist, ids


def _leaf_distances(P, Qa, s0, s1, lane):
    """Squared distances from each query ``Qa[i]`` to the points ``s0[i]:s1[i]`` of its leaf (rows padded to the
    leaf size with inf) and the candidates' leaf-order indices."""
    cand = s0[:, None] + lane[None, :]
    valid = cand < s1[:, None]
    cand = np.where(valid, cand, s0[:, None])
    diffs = P[cand] - Qa[:, None, :]
    d2 = np.einsum("ijk,ijk->ij", diffs, diffs).astype(np.float64)
    d2[~valid] = np.inf
    return d2, cand


def _merge_k_best(bd, bi, d2, cand, k):
    """Merge a leaf's candidates (distances ``d2``, indices ``cand``: one row per query) into the sorted k best."""
    if d2.shape[1] == 1:  # insert one candidate into the sorted k best (ties: the earlier stays first)
        nd, ni = d2[:, 0], cand[:, 0]
        pos = (bd <= nd[:, None]).sum(axis=1)
        for col in range(k - 1, -1, -1):
            take_new = pos == col
            shift = pos < col
            bd[:, col] = np.where(take_new, nd, np.where(shift, bd[:, col - 1] if col else nd, bd[:, col]))
            bi[:, col] = np.where(take_new, ni, np.where(shift, bi[:, col - 1] if col else ni, bi[:, col]))
        return bd, bi
    all_d = np.concatenate([bd, d2], axis=1)
    all_i = np.concatenate([bi, cand], axis=1)
    o = np.argsort(all_d, axis=1, kind="stable")[:, :k]
    return np.take_along_axis(all_d, o, axis=1), np.take_along_axis(all_i, o, axis=1)


def _pop_best(pb, pn, width, a, kth, cur, cur_b, free):
    """Queries ``a`` take their best pending branch (its node into ``cur``, its bound into ``cur_b``; the slot is
    freed for the next push) when its bound beats their k-th distance ``kth``; returns the queries that stop."""
    sub = pb[a, :width]
    j = np.argmin(sub, axis=1)
    bnd = sub[np.arange(a.size), j]
    ok = bnd < kth
    stop_q = a[~ok]
    a, j, bnd = a[ok], j[ok], bnd[ok]
    cur[a] = pn[a, j]
    cur_b[a] = bnd
    pb[a, j] = np.inf
    free[a] = j
    return stop_q


def _push_pending(pb, pn, free, width, a, far, fb):
    """Push branch ``far`` with bound ``fb`` for queries ``a`` into the pending table (a freed slot, else a new
    column; the table doubles when full). Returns the table and its width."""
    slot = free[a]
    new = slot < 0
    if new.any():
        if width >= pb.shape[1]:
            M = pb.shape[0]
            pb = np.concatenate([pb, np.full((M, pb.shape[1]), np.inf)], axis=1)
            pn = np.concatenate([pn, np.zeros((M, pn.shape[1]), dtype=np.int64)], axis=1)
        slot[new] = width
        width += 1
    pb[a, slot] = fb
    pn[a, slot] = far
    free[a] = -1
    return pb, pn, width


def _compact_pending(pb, pn, free, width):
    """Sort the live pending branches to the front when the table is mostly holes; returns the new width."""
    sub = pb[:, :width]
    n_live = int(np.isfinite(sub).sum(axis=1).max())
    if n_live < width // 2:
        o = np.argsort(sub, axis=1, kind="stable")[:, :max(n_live, 1)]
        pb[:, :o.shape[1]] = np.take_along_axis(sub, o, axis=1)
        pn[:, :o.shape[1]] = np.take_along_axis(pn[:, :width], o, axis=1)
        pb[:, o.shape[1]:width] = np.inf
        width = o.shape[1]
        free[:] = -1
    return width


def _lockstep_search(t, P, Q, k, max_leaves, bound="max"):
    """All queries' BBF in lock-step, one step per query per iteration (numpy over the queries).

    Each iteration, every unfinished query does one of: evaluate the leaf it stands on,
    pop its best pending branch (or stop: nothing pending can beat its k-th
    neighbour, or ``max_leaves`` reached), descend one level pushing the far child.
    """
    split_dim, split_val, left, right = t["split_dim"], t["split_val"], t["left"], t["right"]
    start, stop = t["start"], t["stop"]
    leaf_size = t["leaf_size"]
    M = Q.shape[0]
    best_d = np.full((M, k), np.inf)
    best_i = np.full((M, k), -1, dtype=np.int64)
    nodes_v = np.zeros(M, dtype=np.int64)
    leaves_v = np.zeros(M, dtype=np.int64)
    dist_v = np.zeros(M, dtype=np.int64)
    # pending branches of every query: bounds and nodes in a growing (M, C) table, inf = empty slot
    cap = 64
    pb = np.full((M, cap), np.inf)
    pn = np.zeros((M, cap), dtype=np.int64)
    width = 0
    cur = np.zeros(M, dtype=np.int64)  # every query starts at the root with bound 0
    cur_b = np.zeros(M)
    free = np.full(M, -1, dtype=np.int64)  # a slot freed by the last pop, reused by the next push
    is_leaf = left < 0
    lane = np.arange(leaf_size)
    active = np.arange(M)
    it = 0
    while active.size:
        c = cur[active]
        # 1. queries standing on a leaf evaluate its bucket
        at_leaf = c >= 0
        at_leaf[at_leaf] = is_leaf[c[at_leaf]]
        if at_leaf.any():
            a = active[at_leaf]
            s0, s1 = start[c[at_leaf]], stop[c[at_leaf]]
            d2, cand = _leaf_distances(P, Q[a], s0, s1, lane)
            leaves_v[a] += 1
            dist_v[a] += s1 - s0
            best_d[a], best_i[a] = _merge_k_best(best_d[a], best_i[a], d2, cand, k)
            cur[a] = -1
            if max_leaves is not None:
                full = leaves_v[active] >= max_leaves
                if full.any():
                    active = active[~full]
                    if not active.size:
                        break
            c = cur[active]
        # 2. queries without a node pop their best pending branch, or stop
        need = c < 0
        if need.any():
            a = active[need]
            if width == 0:
                active = active[~need]
                c = cur[active]
            else:
                stop_q = _pop_best(pb, pn, width, a, best_d[a, k - 1], cur, cur_b, free)
                if stop_q.size:
                    active = np.setdiff1d(active, stop_q, assume_unique=True)
                c = cur[active]
        if not active.size:
            break
        # 3. queries on an inner node descend one level and push the far child
        inner = ~is_leaf[c]
        if inner.any():
            a = active[inner]
            cn = c[inner]
            diff = Q[a, split_dim[cn]] - split_val[cn]
            go_left = diff <= 0
            near = np.where(go_left, left[cn], right[cn])
            far = np.where(go_left, right[cn], left[cn])
            if bound == "incremental":
                fb = _far_bound(bound, cur_b[a], diff, Q[a, split_dim[cn]].astype(np.float64),
                                t["cell_lo"][cn], t["cell_hi"][cn])
            else:
                fb = _far_bound(bound, cur_b[a], diff, None, None, None)
            nodes_v[a] += 1
            cur[a] = near
            keep = fb < best_d[a, k - 1]
            if keep.any():
                pb, pn, width = _push_pending(pb, pn, free, width, a[keep], far[keep], fb[keep])
        # compact the pending table when it is mostly holes (popped or pruned slots)
        it += 1
        if width > 64 and it % 32 == 0:
            width = _compact_pending(pb, pn, free, width)
    best_i[~np.isfinite(best_d)] = -1
    return best_d, best_i, SearchStats(nodes_v, leaves_v, dist_v)
