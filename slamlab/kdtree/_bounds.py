"""Lower bounds of a pending Best-Bin-First branch (package-private; our addition, issue 25): the rule of
:meth:`KDTree.query`'s ``bound`` option, shared by the numpy search (``tree.py``) and the teaching trace
(``trace.py``); the compiled search (``_kernels.py``) writes the same three lines.
"""

from __future__ import annotations

import numpy as np

__all__ = ["BBF_BOUNDS", "cell_bounds", "far_bound"]

#: lower bound of a pending branch (issue 25): ``"max"`` max(parent bound, (q[d] - split)²), ours, the default;
#: ``"incremental"`` Arya & Mount's incremental distance from the query to the branch's cell (ANN's priority
#: search): the parent's bound with coordinate d's offset replaced, a tighter bound that keeps exact search exact;
#: ``"sum"`` parent bound + (q[d] - split)², FLANN's randomised kd-tree (not a lower bound when a coordinate is
#: split twice on the path: unlimited search is then not guaranteed exact)
BBF_BOUNDS = ("max", "incremental", "sum")


def cell_bounds(t):
    """Per inner node, its cell's interval ``[lo, hi]`` along its own split coordinate (±inf where no ancestor
    splits on it): the nearest ancestor on each side that splits on the same coordinate bounds it (at its
    ``split_hi`` for a right descendant, ``split_lo`` for a left one).

    Parameters
    ----------
    t : dict of arrays
        The node arrays of :func:`build_kdtree`.

    Returns
    -------
    lo, hi : (n_nodes,) float64
        The interval per node (leaves: ±inf).
    """
    left, right, dim = t["left"], t["right"], t["split_dim"]
    split_lo, split_hi = t["split_lo"], t["split_hi"]  # the halves' nearest values (both split_val without gaps)
    n = left.size
    inner = np.flatnonzero(left >= 0)
    parent = np.full(n, -1, dtype=np.int64)
    parent[left[inner]] = inner
    parent[right[inner]] = inner
    is_right = np.zeros(n, dtype=bool)
    is_right[right[inner]] = True
    lo, hi = np.full(n, -np.inf), np.full(n, np.inf)
    cur = np.arange(n)
    for _ in range(int(t["depth"].max())):  # walk every node's path up to the root
        up = np.flatnonzero(parent[cur] >= 0)
        p = parent[cur[up]]
        same = dim[p] == dim[up]
        r = up[same & is_right[cur[up]]]  # a right child holds values >= split_hi: a lower end
        lo[r] = np.maximum(lo[r], split_hi[parent[cur[r]]])
        lf = up[same & ~is_right[cur[up]]]
        hi[lf] = np.minimum(hi[lf], split_lo[parent[cur[lf]]])
        cur[up] = p
    return lo, hi


def far_bound(bound, cur_b, diff, qd, lo, hi):
    """Lower bound of the far child (see :data:`BBF_BOUNDS`; our addition, issue 25).

    Parameters
    ----------
    bound : {'max', 'incremental', 'sum'}
        The rule.
    cur_b : (A,) float64
        Bounds of the nodes being descended.
    diff : (A,) float
        The queries' distances to the far halves along the split coordinate (to the splitting planes when the
        tree keeps no gaps; the sign does not matter).
    qd : (A,) float64 or None
        The queries' split coordinates (``"incremental"`` only).
    lo, hi : (A,) float64 or None
        The nodes' cell intervals along the split coordinate (``"incremental"`` only).

    Returns
    -------
    (A,) float64
        The far children's bounds.
    """
    d2 = diff.astype(np.float64) ** 2
    if bound == "max":
        return np.maximum(cur_b, d2)
    if bound == "sum":
        return cur_b + d2
    off = np.maximum(np.maximum(lo - qd, qd - hi), 0.0)  # the query's offset from the node's cell along d
    return np.maximum(cur_b, cur_b - off * off + d2)
