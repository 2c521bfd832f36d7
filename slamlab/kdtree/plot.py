"""Drawing a 2-D kd-tree and a BBF trace (000 §1.4.3)."""

from __future__ import annotations

import numpy as np

from ..plotting import new_axes

__all__ = ["plot_kdtree_2d"]


def plot_kdtree_2d(tree, *, query=None, events=None, ax=None, max_depth: int | None = None):
    """The splitting lines of a 2-D tree (darker = closer to the root) and, optionally, a BBF trace.

    ``events`` is the list from :func:`slamlab.kdtree.bbf_trace`; visited leaves are
    numbered in the order BBF examined them.

    Parameters
    ----------
    tree : KDTree
        A tree over 2-D points.
    query : (2,) float, optional
        Query point to mark.
    events : list, optional
        BBF trace of ``query`` (:func:`slamlab.kdtree.bbf_trace`).
    ax : matplotlib.axes.Axes, optional
        Axes to draw into.
    max_depth : int, optional
        Draw splits only down to this depth.

    Returns
    -------
    matplotlib.axes.Axes
    """
    if tree.dim != 2:
        raise ValueError(f"`tree` must hold 2-D points to be drawn; got dimension {tree.dim}")
    t = tree.nodes
    P = tree.points
    ax = new_axes(ax, title="kd-tree: median splits on the coordinate of largest spread", xlabel="x", ylabel="y")
    ax.set_aspect("equal", adjustable="box")
    pad = 0.05 * (P.max(axis=0) - P.min(axis=0) + 1e-9)
    lo0, hi0 = P.min(axis=0) - pad, P.max(axis=0) + pad
    stack = [(0, lo0.copy(), hi0.copy())]
    height = max(tree.height, 1)
    while stack:
        node, lo, hi = stack.pop()
        if t["left"][node] < 0 or (max_depth is not None and t["depth"][node] >= max_depth):
            continue
        d, s = int(t["split_dim"][node]), float(t["split_val"][node])
        shade = 0.15 + 0.6 * t["depth"][node] / height
        if d == 0:
            ax.plot([s, s], [lo[1], hi[1]], color=str(shade), linewidth=1.6 - t["depth"][node] / height)
        else:
            ax.plot([lo[0], hi[0]], [s, s], color=str(shade), linewidth=1.6 - t["depth"][node] / height)
        lhi, rlo = hi.copy(), lo.copy()
        lhi[d], rlo[d] = s, s
        stack += [(int(t["left"][node]), lo, lhi), (int(t["right"][node]), rlo, hi)]
    ax.plot(P[:, 0], P[:, 1], ".", color="tab:blue", markersize=5, label="points")
    if query is not None:
        q = np.asarray(query, dtype=float)
        ax.plot(q[0], q[1], "*", color="tab:red", markersize=12, label="query")
        if events:
            order = 0
            for kind, node, _ in events:
                if kind != "leaf":
                    continue
                order += 1
                for i in range(t["start"][node], t["stop"][node]):
                    p = tree.leaf_points[i]
                    ax.annotate(str(order), (p[0], p[1]), textcoords="offset points", xytext=(3, 3), fontsize=8,
                                color="tab:red")
    ax.set_xlim(lo0[0], hi0[0])
    ax.set_ylim(lo0[1], hi0[1])
    ax.legend(loc="upper right")
    return ax
