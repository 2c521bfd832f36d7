"""Building the teaching kd-tree, level by level (000 §1.4.3), and its split rules (issue 25).

000 §1.4.3 splits at the median of the coordinate with the "best distribution" (our reading: the largest
spread, max − min): a balanced tree, the default. ``split=`` offers the other rules of the literature, for the
Best-Bin-First recall (issue 25): the coordinate of largest **variance** (FLANN's randomised kd-tree, Muja &
Lowe, without its random choice among the top five), cut at the **mean** (FLANN) or at the **midrange** of the
points (the midpoint rule of ANN and nanoflann, on the points' extent) -- unbalanced trees. ``gap=True`` keeps
both ends of the empty interval between the halves (nanoflann's ``divlow``/``divhigh``): the search takes the
side of the gap's middle and bounds the far half by its nearest value rather than by one plane.
"""

from __future__ import annotations

import numpy as np

from .._validate import as_finite_array, check_choice, check_int

__all__ = ["SPLIT_RULES", "build_kdtree"]

#: split rules of :func:`build_kdtree`, "coordinate-position": the coordinate of largest ``spread`` (max − min,
#: 000's "best distribution" as we read it) or ``variance``; cut at the ``median`` (balanced), the ``mean``
#: (FLANN's) or the ``midrange`` (max + min) / 2. ``"spread-median"`` is the default; ``"variance-mean"`` is FLANN's.
SPLIT_RULES = tuple(f"{c}-{p}" for c in ("spread", "variance") for p in ("median", "mean", "midrange"))


def build_kdtree(points, ids=None, *, leaf_size: int = 1, split: str = "spread-median", gap: bool = False):
    """Split on a coordinate, level by level, down to leaves of ``leaf_size`` points (000 §1.4.3).

    Parameters
    ----------
    points : (N, k) array
        The k-dimensional points (descriptors).
    ids : (N,) int array, optional
        Identifiers returned by queries; ``arange(N)`` by default.
    leaf_size : int
        A node with at most this many points is a leaf (bucket). 1 = one point per
        leaf, as in Beis & Lowe's BBF where "200 leaves" means 200 points examined.
    split : str
        One of :data:`SPLIT_RULES`. ``"spread-median"`` (default): median split on the coordinate of largest
        spread, a balanced tree (000 §1.4.3); ``"variance-mean"``: FLANN's split; the others: see the module doc.
        A cut off the median is moved to the nearest position that leaves both halves non-empty, among points
        equal to the cut as near the middle as they allow (FLANN's rule).
    gap : bool
        False (default): the plane ``split_val`` is the largest value on the left, and ``split_lo`` =
        ``split_hi`` = ``split_val``. True: ``split_lo`` is the largest value on the left, ``split_hi`` the
        smallest on the right (nanoflann's divlow/divhigh), ``split_val`` their middle (our addition, issue 25).

    Returns
    -------
    dict of arrays
        ``perm`` (points in leaf order), ``split_dim``, ``split_val``, ``split_lo``, ``split_hi``, ``left``,
        ``right`` (-1 for leaves), ``start``, ``stop`` (leaf bucket ranges in ``perm``), ``depth``, ``split``,
        ``gap``. Node 0 is the root; nodes are numbered level by level.

    Examples
    --------
    >>> t = build_kdtree(np.array([[0.0, 0], [1, 0], [2, 0], [3, 5]]))
    >>> int(t["split_dim"][0]), float(t["split_val"][0])
    (1, 0.0)
    >>> t = build_kdtree(np.array([[0.0], [1], [2], [6]]), split="variance-mean", gap=True)
    >>> float(t["split_lo"][0]), float(t["split_hi"][0]), float(t["split_val"][0])
    (2.0, 6.0, 4.0)
    """
    keep32 = isinstance(points, np.ndarray) and points.dtype == np.float32
    X = as_finite_array(points, "points", ndim=2, dtype=np.float32 if keep32 else np.float64)
    n, k = X.shape
    if n == 0 or k == 0:
        raise ValueError(f"`points` must hold at least one point of dimension >= 1; got shape {X.shape}")
    leaf_size = check_int(leaf_size, "leaf_size", minimum=1)
    split = check_choice(split, "split", SPLIT_RULES)
    if not isinstance(gap, (bool, np.bool_)):
        raise TypeError(f"`gap` must be a bool; got {type(gap).__name__}")
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
    XT = None if split == "spread-median" else np.ascontiguousarray(X.T)
    # current level: segments [s0, s1) of perm, with their node numbers
    seg_start = np.array([0], dtype=np.int64)
    seg_stop = np.array([n], dtype=np.int64)
    seg_node = np.array([0], dtype=np.int64)
    n_nodes, level = 1, 0
    node_rows = []  # (node ids, dims, vals, lo, hi, left, right, start, stop, depth) per level
    while seg_start.size:
        size = seg_stop - seg_start
        is_leaf = size <= leaf_size
        inner = ~is_leaf
        # leaves of this level
        lf = np.flatnonzero(is_leaf)
        zero = np.zeros(lf.size)
        node_rows.append((seg_node[lf], np.full(lf.size, -1), zero, zero, zero, np.full(lf.size, -1),
                          np.full(lf.size, -1), seg_start[lf], seg_stop[lf], np.full(lf.size, level)))
        if not inner.any():
            break
        s0, s1, nodes = seg_start[inner], seg_stop[inner], seg_node[inner]
        lens = s1 - s0
        if split == "spread-median":
            dim, half, lo, hi = _split_balanced(X, perm, s0, lens)
        else:
            dim, half, lo, hi = _split_unbalanced(XT, perm, s0, lens, *split.split("-"))
        mid = s0 + half
        val = 0.5 * (lo + hi) if gap else lo
        if not gap:
            hi = lo
        lnode = n_nodes + 2 * np.arange(s0.size)
        rnode = lnode + 1
        n_nodes += 2 * s0.size
        node_rows.append((nodes, dim, val, lo, hi, lnode, rnode, np.full(s0.size, -1), np.full(s0.size, -1),
                          np.full(s0.size, level)))
        seg_start = np.concatenate([s0, mid])
        seg_stop = np.concatenate([mid, s1])
        seg_node = np.concatenate([lnode, rnode])
        srt = np.argsort(seg_node)
        seg_start, seg_stop, seg_node = seg_start[srt], seg_stop[srt], seg_node[srt]
        level += 1

    cols = {name: np.empty(n_nodes, dtype=np.float64 if name in ("split_val", "split_lo", "split_hi") else np.int64)
            for name in ("split_dim", "split_val", "split_lo", "split_hi", "left", "right", "start", "stop",
                         "depth")}
    for nodes, *values in node_rows:
        for name, val in zip(cols, values, strict=True):
            cols[name][nodes] = val
    return {"points": X, "ids": ids, "perm": perm, **cols, "leaf_size": leaf_size, "split": split,
            "gap": bool(gap)}


def _split_balanced(X, perm, s0, lens):
    """Median split of every segment ``perm[s0 : s0 + lens]`` on its coordinate of largest spread (000 §1.4.3).

    Parameters
    ----------
    X : (N, k) array
        The points.
    perm : (N,) int array
        Leaf order being built; each segment is sorted by its split coordinate in place (stable).
    s0 : (S,) int array
        First position of each segment in ``perm``.
    lens : (S,) int array
        Segment lengths (>= 2; a level's lengths differ by at most one).

    Returns
    -------
    dim : (S,) int
        Split coordinates.
    half : (S,) int
        Points going left, floor(len / 2).
    lo, hi : (S,) float64
        Largest value on the left, smallest on the right.
    """
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
    rows = np.arange(s0.size)
    return dim, half, key[rows, half - 1].astype(np.float64), key[rows, half].astype(np.float64)


def _widest_coordinate(X, perm, s0, lens):
    """Per segment ``perm[s0 : s0 + lens]`` of the points ``X``, the coordinate of largest spread (max − min;
    ties: the lowest index), our reading of 000 §1.4.3's "best distribution".

    Parameters
    ----------
    X : (N, k) array
        The points.
    perm : (N,) int array
        Leaf order being built.
    s0 : (S,) int array
        First position of each segment in ``perm``.
    lens : (S,) int array
        Segment lengths (a level's lengths differ by at most one).

    Returns
    -------
    (S,) int
        The coordinate of largest spread per segment.
    """
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


def _split_unbalanced(XT, perm, s0, lens, coord, position):
    """Split every segment ``perm[s0 : s0 + lens]`` by a :data:`SPLIT_RULES` rule other than the default.

    The segments of a level have any lengths, so they are handled as one concatenated array reduced per
    segment (``np.*.reduceat``); the split coordinate is the largest spread (in the points' dtype, as the
    balanced build) or variance (float64, two passes); the cut is the median, the mean or the midrange of
    that coordinate, clipped to the segment's values; the left half takes the points below the cut and as many
    points equal to it as bring it nearest to half the segment (FLANN's ``planeSplit``).

    Parameters
    ----------
    XT : (k, N) array
        The points, transposed (C-contiguous).
    perm : (N,) int array
        Leaf order being built; each segment is reordered in place (left half first, stable).
    s0 : (S,) int array
        First position of each segment in ``perm``.
    lens : (S,) int array
        Segment lengths (>= 2).
    coord : {'spread', 'variance'}
        How the split coordinate is chosen (ties: the lowest index).
    position : {'median', 'mean', 'midrange'}
        Where the cut goes.

    Returns
    -------
    dim : (S,) int
        Split coordinates.
    m : (S,) int
        Points going left (1 <= m < len).
    lo, hi : (S,) float64
        Largest value on the left, smallest on the right.
    """
    ns = s0.size
    offs = np.concatenate([[0], np.cumsum(lens)[:-1]])  # segment starts in the concatenated array
    seg = np.repeat(np.arange(ns), lens)
    at = np.repeat(s0 - offs, lens) + np.arange(seg.size)  # positions in perm
    rows = perm[at]
    YT = XT[:, rows]  # (k, R): reduceat along contiguous rows is fast on many short segments
    if coord == "variance":
        YT = YT.astype(np.float64)
        mean = np.add.reduceat(YT, offs, axis=1) / lens
        YT -= mean[:, seg]
        dim = np.argmax(np.add.reduceat(np.square(YT, out=YT), offs, axis=1), axis=0)
        centre = mean[dim, np.arange(ns)]
    else:
        dim = np.argmax(np.maximum.reduceat(YT, offs, axis=1) - np.minimum.reduceat(YT, offs, axis=1), axis=0)
    key = XT[dim[seg], rows].astype(np.float64)
    if coord != "variance":
        centre = np.add.reduceat(key, offs) / lens
    kmin, kmax = np.minimum.reduceat(key, offs), np.maximum.reduceat(key, offs)
    half = lens // 2
    if position == "median":
        o = np.lexsort((key, seg))  # every segment sorted by its coordinate (stable)
        m = half
    else:
        cut = np.clip(centre if position == "mean" else 0.5 * (kmin + kmax), kmin, kmax)[seg]
        o = np.argsort(3 * seg + (key >= cut) + (key > cut), kind="stable")  # below, equal, above the cut
        lim1 = np.bincount(seg, weights=key < cut, minlength=ns).astype(np.int64)
        lim2 = np.bincount(seg, weights=key <= cut, minlength=ns).astype(np.int64)
        m = np.where(lim1 > half, lim1, np.where(lim2 < half, lim2, half))
    perm[at] = perm[at[o]]
    key = key[o]
    bounds = np.stack([offs, offs + m], axis=1).ravel()  # [left half, right half] of every segment
    lo = np.maximum.reduceat(key, bounds)[0::2]
    hi = np.minimum.reduceat(key, bounds)[1::2]
    return dim, m, lo, hi

