"""Compiled Best-Bin-First search (our addition, speed; issue 25): the kernel behind :meth:`KDTree.query`.

The teaching version is the numpy lock-step search in ``tree.py`` (``_lockstep_search``) and the one-query
``heapq`` trace in ``trace.py``; this kernel returns **the same neighbours, distances and counts** as the
numpy version, bit for bit. That needs three things reproduced exactly:

- *the leaf order* -- which pending branch is expanded next. numpy keeps every query's pending branches in
  the slots of an (M, width) table and takes the smallest bound, ties going to the lowest slot; a push
  reuses the slot freed by the query's last pop, else opens a new column; every 32 rounds, when the table
  is mostly holes, the live entries are sorted by (bound, slot) to the front (``_compact_pending``). Here
  each query holds a binary heap ordered by the same key (bound, slot), with the slot numbers numpy would
  give, and the kernel runs the queries in the same rounds so that the compaction happens in the same
  round as in numpy (its timing depends on the whole batch);
- *the distances* -- numpy's ``einsum("ijk,ijk->ij")`` sums a leaf point's squared differences in 128-bit
  SIMD lanes (4 float32 or 2 float64 accumulators, blocks of four vectors, then a pairwise horizontal sum);
  :func:`_sq_dist` adds in that order, in the points' dtype (no fast-math, so no fused multiply-add);
- *the k best* -- a leaf's candidates are inserted in leaf order after any equal distance (numpy's stable
  sort).

The kernel is taken when :func:`slamlab._compiled.numba_enabled`; ``tests/kdtree/test_bbf_kernel.py``
checks it against the numpy version.
"""

from __future__ import annotations

import numpy as np
from numba.extending import register_jitable  # this module is imported only when numba is enabled

from .._compiled import kernel

__all__ = ["bbf_search"]


def bbf_search(t, P, Q, k, max_leaves, bound="max"):
    """All queries' BBF, compiled; the same results as ``tree._lockstep_search`` (000 §1.4.3).

    Parameters
    ----------
    t : dict of arrays
        The tree's node arrays (:func:`slamlab.kdtree.build_kdtree`).
    P : (N, dim) float32 or float64 array
        The points in leaf order.
    Q : (M, dim) array of ``P``'s dtype
        Queries.
    k : int
        Neighbours per query.
    max_leaves : int or None
        Leaf budget per query; None = exact search.
    bound : {'max', 'incremental', 'sum'}
        Lower bound of a pending branch (``tree.BBF_BOUNDS``); ``t`` holds ``cell_lo``/``cell_hi`` for
        ``"incremental"``.

    Returns
    -------
    best_d : (M, k) float64
        Squared distances, ascending (inf where missing).
    best_i : (M, k) int64
        Leaf-order indices of the neighbours (-1 where missing).
    nodes_v, leaves_v, dist_v : (M,) int64
        Internal nodes passed, leaves evaluated, distances computed per query.
    """
    lanes = np.zeros(16 // P.dtype.itemsize, dtype=P.dtype)  # one 128-bit register of accumulators
    mode = ("max", "incremental", "sum").index(bound)
    lo, hi = (t["cell_lo"], t["cell_hi"]) if mode == 1 else (t["split_val"], t["split_val"])
    return _bbf_lockstep(t["split_dim"], t["split_val"], t["split_lo"], t["split_hi"], t["left"], t["right"],
                         t["start"], t["stop"], np.ascontiguousarray(P), np.ascontiguousarray(Q), int(k),
                         0 if max_leaves is None else int(max_leaves), lanes, mode, lo, hi)


def _sq_dist(P, i, Q, q, acc):
    """Squared distance from point ``P[i]`` to query ``Q[q]`` summed as numpy's einsum does (see module doc).

    Parameters
    ----------
    P : (N, dim) float array
        Points in leaf order.
    i : int
        Row of ``P``.
    Q : (M, dim) array of ``P``'s dtype
        Queries.
    q : int
        Row of ``Q``.
    acc : (L,) array of ``P``'s dtype
        Scratch accumulators, L = 16 / itemsize lanes (one 128-bit register).

    Returns
    -------
    float
        The squared distance, summed in ``P``'s dtype, as float64.
    """
    L = acc.size
    dim = P.shape[1]
    for l in range(L):
        acc[l] = 0
    j = 0
    while dim - j >= 4 * L:  # blocks of four vectors: acc = d0² + (d1² + (d2² + (d3² + acc)))
        for l in range(L):
            d3 = P[i, j + 3 * L + l] - Q[q, j + 3 * L + l]
            d2 = P[i, j + 2 * L + l] - Q[q, j + 2 * L + l]
            d1 = P[i, j + L + l] - Q[q, j + L + l]
            d0 = P[i, j + l] - Q[q, j + l]
            acc[l] = d0 * d0 + (d1 * d1 + (d2 * d2 + (d3 * d3 + acc[l])))
        j += 4 * L
    while j < dim:  # the rest one vector at a time (missing lanes add 0)
        for l in range(L):
            if j + l < dim:
                d = P[i, j + l] - Q[q, j + l]
                acc[l] = d * d + acc[l]
        j += L
    if L == 4:  # horizontal sum of the register: (a0 + a1) + (a2 + a3)
        return np.float64((acc[0] + acc[1]) + (acc[2] + acc[3]))
    return np.float64(acc[0] + acc[1])


def _key_less(b1, s1, b2, s2):
    """Heap order: smaller bound first, ties to the lower slot (numpy's argmin over the slots).

    Parameters
    ----------
    b1, s1 : float, int
        Bound and slot of the first entry.
    b2, s2 : float, int
        Bound and slot of the second entry.

    Returns
    -------
    bool
        True when the first entry is popped before the second.
    """
    return b1 < b2 or (b1 == b2 and s1 < s2)


def _heap_push(hb, hs, hn, q, n, b, s, node):
    """Push (bound ``b``, slot ``s``, ``node``) onto query ``q``'s heap of ``n`` entries (sift up).

    Parameters
    ----------
    hb, hs, hn : (M, C) arrays
        Bounds, slots and nodes of every query's heap (row ``q``, first ``n`` entries), changed in place.
    q : int
        The query.
    n : int
        Entries in its heap before the push (< C).
    b : float
        Bound of the new entry.
    s : int
        Its slot (numpy's pending-table column).
    node : int
        The branch's node.
    """
    i = n
    while i > 0:
        p = (i - 1) // 2
        if not _key_less(b, s, hb[q, p], hs[q, p]):
            break
        hb[q, i], hs[q, i], hn[q, i] = hb[q, p], hs[q, p], hn[q, p]
        i = p
    hb[q, i], hs[q, i], hn[q, i] = b, s, node


def _heap_pop(hb, hs, hn, q, n):
    """Remove the root of query ``q``'s heap of ``n`` entries (sift the last entry down).

    Parameters
    ----------
    hb, hs, hn : (M, C) arrays
        Bounds, slots and nodes of every query's heap, changed in place.
    q : int
        The query.
    n : int
        Entries in its heap before the pop (>= 1).
    """
    n -= 1
    b, s, node = hb[q, n], hs[q, n], hn[q, n]
    i = 0
    while True:
        c = 2 * i + 1
        if c >= n:
            break
        if c + 1 < n and _key_less(hb[q, c + 1], hs[q, c + 1], hb[q, c], hs[q, c]):
            c += 1
        if not _key_less(hb[q, c], hs[q, c], b, s):
            break
        hb[q, i], hs[q, i], hn[q, i] = hb[q, c], hs[q, c], hn[q, c]
        i = c
    hb[q, i], hs[q, i], hn[q, i] = b, s, node


def _compact(hb, hs, hn, hsize, tb, ts, tn):
    """numpy's ``_compact_pending``: every query's live entries sorted by (bound, slot), slots renumbered
    0, 1, ... (a sorted array is a heap, so the heaps stay valid).

    Parameters
    ----------
    hb, hs, hn : (M, C) arrays
        Bounds, slots and nodes of every query's heap, changed in place.
    hsize : (M,) int array
        Entries per heap.
    tb, ts, tn : (>= max(hsize),) arrays
        Scratch rows.
    """
    for q in range(hsize.size):
        n = hsize[q]
        for r in range(n):  # heap sort into the scratch row
            tb[r], ts[r], tn[r] = hb[q, 0], hs[q, 0], hn[q, 0]
            _heap_pop(hb, hs, hn, q, n - r)
        for r in range(n):
            hb[q, r], hs[q, r], hn[q, r] = tb[r], r, tn[r]


def _eval_leaf(P, Q, q, s0, s1, best_d, best_i, acc):
    """Query ``q`` evaluates the leaf bucket ``P[s0:s1]``: each point goes into the sorted k best after any
    equal distance (numpy's stable merge).

    Parameters
    ----------
    P : (N, dim) float array
        Points in leaf order.
    Q : (M, dim) array of ``P``'s dtype
        Queries.
    q : int
        The query.
    s0, s1 : int
        The leaf's bucket ``P[s0:s1]``.
    best_d, best_i : (M, k) arrays
        Sorted squared distances and leaf-order indices of every query's k best, changed in place.
    acc : (L,) array of ``P``'s dtype
        Scratch accumulators for :func:`_sq_dist`.
    """
    k = best_d.shape[1]
    for i in range(s0, s1):
        d2 = _sq_dist(P, i, Q, q, acc)
        pos = k
        while pos > 0 and best_d[q, pos - 1] > d2:
            pos -= 1
        if pos < k:
            for j in range(k - 1, pos, -1):
                best_d[q, j], best_i[q, j] = best_d[q, j - 1], best_i[q, j - 1]
            best_d[q, pos], best_i[q, pos] = d2, i


def _grow(hb, hs, hn):
    """The heaps' arrays with twice the columns (the first ones copied).

    Parameters
    ----------
    hb, hs, hn : (M, C) arrays
        Bounds, slots and nodes of every query's heap.

    Returns
    -------
    hb, hs, hn : (M, 2 C) arrays
        The same heaps with room for C more entries each.
    """
    M, cap = hb.shape
    nb, ns, nn = np.empty((M, 2 * cap)), np.empty((M, 2 * cap), np.int64), np.empty((M, 2 * cap), np.int64)
    for q in range(M):
        for j in range(cap):
            nb[q, j], ns[q, j], nn[q, j] = hb[q, j], hs[q, j], hn[q, j]
    return nb, ns, nn


def _bbf_lockstep(split_dim, split_val, split_lo, split_hi, left, right, start, stop, P, Q, k, max_leaves, acc,
                  mode, lo, hi):
    """The rounds of ``tree._lockstep_search``, one query after the other inside a round (see the module doc).

    In each round every unfinished query: evaluates the leaf it stands on (and stops at ``max_leaves``);
    without a node, pops its best pending branch, or stops when that bound is no better than its k-th
    distance; on an inner node, descends one level (the side of ``split_val``) and pushes the far child with
    the bound max(parent bound, e²), e = the distance from q[d] to the far half's nearest value ``split_hi`` /
    ``split_lo`` (the plane unless the tree keeps gaps; 000 §1.4.3, our bound; ``mode`` 0), Arya & Mount's
    incremental
    distance to the far cell (1: the parent bound with coordinate d's offset from ``[lo, hi]`` replaced) or
    FLANN's sum (2), when it beats the k-th distance.

    Parameters
    ----------
    split_dim, split_val, split_lo, split_hi, left, right, start, stop : (n_nodes,) arrays
        The tree's node arrays (:func:`slamlab.kdtree.build_kdtree`).
    P : (N, dim) float array
        Points in leaf order.
    Q : (M, dim) array of ``P``'s dtype
        Queries.
    k : int
        Neighbours per query.
    max_leaves : int
        Leaf budget per query; 0 = none (exact search).
    acc : (L,) array of ``P``'s dtype
        Scratch accumulators for :func:`_sq_dist`.
    mode : int
        0 max bound, 1 incremental, 2 sum.
    lo, hi : (n_nodes,) float64
        Each node's cell interval along its split coordinate (used by mode 1).

    Returns
    -------
    best_d, best_i, nodes_v, leaves_v, dist_v
        As :func:`bbf_search`.
    """
    M = Q.shape[0]
    best_d = np.full((M, k), np.inf)
    best_i = np.full((M, k), -1, dtype=np.int64)
    nodes_v = np.zeros(M, dtype=np.int64)
    leaves_v = np.zeros(M, dtype=np.int64)
    dist_v = np.zeros(M, dtype=np.int64)
    cap = 64
    hb = np.empty((M, cap))  # per query: a heap of pending branches (bound, slot, node)
    hs = np.empty((M, cap), dtype=np.int64)
    hn = np.empty((M, cap), dtype=np.int64)
    hsize = np.zeros(M, dtype=np.int64)
    cur = np.zeros(M, dtype=np.int64)  # every query starts at the root with bound 0
    cur_b = np.zeros(M)
    free = np.full(M, -1, dtype=np.int64)  # the slot freed by the last pop, reused by the next push
    active = np.arange(M)
    n_act = M
    width = 0  # numpy's table width: a push without a freed slot opens column `width`
    it = 0
    while n_act > 0:
        w0 = width
        opened = False
        n_next = 0
        for a in range(n_act):
            q = active[a]
            kth = best_d[q, k - 1]
            # 1. on a leaf: evaluate its bucket, insert each point after any equal distance
            c = cur[q]
            if left[c] < 0:
                _eval_leaf(P, Q, q, start[c], stop[c], best_d, best_i, acc)
                leaves_v[q] += 1
                dist_v[q] += stop[c] - start[c]
                kth = best_d[q, k - 1]
                cur[q] = -1
                if max_leaves > 0 and leaves_v[q] >= max_leaves:
                    continue
            # 2. without a node: pop the best pending branch, or stop
            if cur[q] < 0:
                if w0 == 0 or hsize[q] == 0 or not hb[q, 0] < kth:
                    continue
                cur[q], cur_b[q], free[q] = hn[q, 0], hb[q, 0], hs[q, 0]
                _heap_pop(hb, hs, hn, q, hsize[q])
                hsize[q] -= 1
            # 3. on an inner node: descend one level, push the far child
            c = cur[q]
            if left[c] >= 0:
                qd = np.float64(Q[q, split_dim[c]])  # float64, as numpy promotes it
                if qd - split_val[c] <= 0:  # e to the far half's nearest value (the plane without gaps)
                    near, far, diff = left[c], right[c], split_hi[c] - qd
                else:
                    near, far, diff = right[c], left[c], qd - split_lo[c]
                if mode == 0:
                    fb = max(cur_b[q], diff * diff)
                elif mode == 2:
                    fb = cur_b[q] + diff * diff
                else:
                    off = max(max(lo[c] - qd, qd - hi[c]), 0.0)
                    fb = max(cur_b[q], cur_b[q] - off * off + diff * diff)
                nodes_v[q] += 1
                cur[q] = near
                if fb < kth:
                    s = free[q]
                    if s < 0:
                        s = w0
                        opened = True
                    if hsize[q] == hb.shape[1]:  # grow every row's heap (numpy doubles its table)
                        hb, hs, hn = _grow(hb, hs, hn)
                    _heap_push(hb, hs, hn, q, hsize[q], fb, s, far)
                    hsize[q] += 1
                    free[q] = -1
            active[n_next] = q
            n_next += 1
        n_act = n_next
        if n_act == 0:
            break
        if opened:
            width = w0 + 1
        it += 1
        if width > 64 and it % 32 == 0:  # numpy's compaction, in the same round
            n_live = hsize.max()
            if n_live < width // 2:
                m = max(n_live, 1)
                _compact(hb, hs, hn, hsize, np.empty(m), np.empty(m, np.int64), np.empty(m, np.int64))
                width = m
                free[:] = -1
    for q in range(M):
        for j in range(k):
            if not np.isfinite(best_d[q, j]):
                best_i[q, j] = -1
    return best_d, best_i, nodes_v, leaves_v, dist_v


# the helpers are compiled into the kernel that calls them; the kernel is compiled lazily on its first call
_sq_dist = register_jitable(_sq_dist)
_key_less = register_jitable(_key_less)
_heap_push = register_jitable(_heap_push)
_heap_pop = register_jitable(_heap_pop)
_compact = register_jitable(_compact)
_eval_leaf = register_jitable(_eval_leaf)
_grow = register_jitable(_grow)
_bbf_lockstep = kernel(_bbf_lockstep)
