"""Teaching kd-tree: static, balanced, exact k-NN and Best-Bin-First search (000 §1.4.3).

000 §1.4.3 builds the tree recursively: pick the coordinate ``m`` with the "best
distribution" of the points, split at the median of that coordinate, recurse on
both halves -- a balanced tree that cannot be modified. Our reading of "best
distribution" (000 is silent on it): the coordinate of **largest spread**
(max - min); the median split is by *position* in the sorted order, so points
equal to the split value may sit on either side (ties handled explicitly: left
holds values ``<= split``, right ``>= split``; both lower bounds stay valid).
Other split rules (FLANN's variance and mean, the midrange; unbalanced trees) and the
split gaps: ``KDTree(..., split=, gap=)``, built in ``build.py`` (issue 25).

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

from .._compiled import numba_enabled
from .._validate import as_finite_array, check_int
from ._bounds import BBF_BOUNDS, cell_bounds, far_bound
from .build import SPLIT_RULES, build_kdtree

__all__ = ["BBF_BOUNDS", "SPLIT_RULES", "KDTree", "SearchStats", "build_kdtree"]


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
    split : str
        Split rule (:data:`SPLIT_RULES`): ``"spread-median"`` (default, balanced, 000 §1.4.3) or e.g.
        ``"variance-mean"`` (FLANN's) -- see :func:`build_kdtree`.
    gap : bool
        Keep both ends of every split's gap (nanoflann's divlow/divhigh; default False) -- see
        :func:`build_kdtree`.

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

    def __init__(self, points, ids=None, *, leaf_size: int = 1, split: str = "spread-median", gap: bool = False):
        t = build_kdtree(points, ids, leaf_size=leaf_size, split=split, gap=gap)
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

    @property
    def leaf_points(self) -> np.ndarray:
        """(N, k) the points in leaf order: leaf node ``i``'s bucket is rows ``nodes["start"][i]:nodes["stop"][i]``."""
        return self._P

    @property
    def leaf_ids(self) -> np.ndarray:
        """(N,) the ids of :attr:`leaf_points`, row for row."""
        return self._ids_leaf

    def __len__(self) -> int:
        return self.n

    def __repr__(self) -> str:
        opts = "" if self._t["split"] == "spread-median" and not self._t["gap"] else \
            f", split={self._t['split']!r}, gap={self._t['gap']}"
        return f"KDTree(n={self.n}, k={self.dim}, leaf_size={self.leaf_size}{opts}, height={self.height})"

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
        Q = as_finite_array(Q, "Q")
        single = Q.ndim == 1
        if single:
            Q = Q[None, :]
        if Q.ndim != 2 or Q.shape[1] != self.dim:
            raise ValueError(f"`Q` must have shape (M, {self.dim}) to match the tree; got shape {Q.shape}")
        k = check_int(k, "k", minimum=1)
        if max_leaves is not None:
            max_leaves = check_int(max_leaves, "max_leaves", minimum=1)
        if bound not in BBF_BOUNDS:
            raise ValueError(f"`bound` must be one of {BBF_BOUNDS}; got {bound!r}")
        if bound == "incremental" and "cell_lo" not in self._t:
            self._t["cell_lo"], self._t["cell_hi"] = cell_bounds(self._t)
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
    split_lo, split_hi = t["split_lo"], t["split_hi"]
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
            qd = Q[a, split_dim[cn]].astype(np.float64)
            go_left = qd - split_val[cn] <= 0
            near = np.where(go_left, left[cn], right[cn])
            far = np.where(go_left, right[cn], left[cn])
            # distance to the far half: its nearest value (= split_val unless the tree keeps the gaps)
            diff = np.where(go_left, split_hi[cn] - qd, qd - split_lo[cn])
            if bound == "incremental":
                fb = far_bound(bound, cur_b[a], diff, qd, t["cell_lo"][cn], t["cell_hi"][cn])
            else:
                fb = far_bound(bound, cur_b[a], diff, None, None, None)
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
