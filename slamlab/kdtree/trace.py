"""Best-Bin-First for one query, step by step (000 §1.4.3): the teaching version of :meth:`KDTree.query`."""

from __future__ import annotations

import heapq

import numpy as np

from .._validate import as_vector, check_int
from ._bounds import BBF_BOUNDS, cell_bounds
from .tree import KDTree

__all__ = ["bbf_trace"]


def bbf_trace(tree: KDTree, q, *, k: int = 2, max_leaves: int | None = None, bound: str = "max"):
    """One query, step by step, with a ``heapq`` priority queue (000 §1.4.3) -- the teaching version.

    Returns the neighbours and a list of events ``(kind, node, bound)`` where kind
    is ``"pop"``, ``"push"`` or ``"leaf"``; the same search as :meth:`KDTree.query`.

    Parameters
    ----------
    tree : KDTree
        The tree searched.
    q : (dim,) float
        The query point.
    k : int
        Neighbours wanted.
    max_leaves : int, optional
        BBF leaf budget; None searches exactly.
    bound : {'max', 'incremental', 'sum'}
        Lower bound of a pending branch (:data:`slamlab.kdtree.tree.BBF_BOUNDS`).

    Returns
    -------
    dist : (k,) float
        Distances of the neighbours, ascending.
    ids : (k,) int
        Their ids.
    events : list of (str, int, float)
        ``(kind, node, bound)`` in search order.

    Examples
    --------
    >>> tree = KDTree(np.array([[0.0], [1.0], [2.0], [3.0]]))
    >>> d, ids, events = bbf_trace(tree, [2.2], k=1)
    >>> int(ids[0]), round(float(d[0]), 6)
    (2, 0.2)
    """
    if not isinstance(tree, KDTree):
        raise TypeError(f"`tree` must be a KDTree; got {type(tree).__name__}")
    q = as_vector(q, "q", tree.dim)
    k = check_int(k, "k", minimum=1)
    if max_leaves is not None:
        max_leaves = check_int(max_leaves, "max_leaves", minimum=1)
    if bound not in BBF_BOUNDS:
        raise ValueError(f"`bound` must be one of {BBF_BOUNDS}; got {bound!r}")
    bound_rule = bound  # `bound` below is the popped branch's bound
    t = tree.nodes
    if bound == "incremental" and "cell_lo" not in t:
        t["cell_lo"], t["cell_hi"] = cell_bounds(t)
    best: list[tuple[float, int]] = []  # (d2, leaf-order index), sorted
    heap = [(0.0, 0)]
    events = []
    leaves = 0
    while heap:
        bound, node = heapq.heappop(heap)
        kth = best[k - 1][0] if len(best) >= k else np.inf
        if bound >= kth:
            break
        events.append(("pop", int(node), float(bound)))
        while t["left"][node] >= 0:
            d, s = t["split_dim"][node], t["split_val"][node]
            if q[d] - s <= 0:  # the far half's nearest value: split_hi / split_lo (= s unless the tree keeps gaps)
                near, far, diff = t["left"][node], t["right"][node], t["split_hi"][node] - q[d]
            else:
                near, far, diff = t["right"][node], t["left"][node], q[d] - t["split_lo"][node]
            if bound_rule == "max":  # our bound: the farthest single plane so far
                fb = max(bound, diff * diff)
            elif bound_rule == "sum":  # FLANN's: the planes' squared distances added up
                fb = bound + diff * diff
            else:  # Arya & Mount: coordinate d's old offset from the cell replaced by the plane's distance
                off = max(t["cell_lo"][node] - q[d], q[d] - t["cell_hi"][node], 0.0)
                fb = max(bound, bound - off * off + diff * diff)
            kth = best[k - 1][0] if len(best) >= k else np.inf
            if fb < kth:
                heapq.heappush(heap, (fb, int(far)))
                events.append(("push", int(far), float(fb)))
            node = near
        pts = np.arange(t["start"][node], t["stop"][node])
        d2 = ((tree.leaf_points[pts].astype(np.float64) - q) ** 2).sum(axis=1)
        best = sorted(best + list(zip(d2.tolist(), pts.tolist(), strict=True)))[:k]
        leaves += 1
        events.append(("leaf", int(node), float(min(d2))))
        if max_leaves is not None and leaves >= max_leaves:
            break
    dist = np.array([np.sqrt(b[0]) for b in best] + [np.inf] * (k - len(best)))
    ids = np.array([tree.leaf_ids[b[1]] for b in best] + [-1] * (k - len(best)), dtype=np.int64)
    return dist, ids, events
