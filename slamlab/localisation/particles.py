"""Particle-set tools: KLD sampling, the pose estimate with its covariance and the "localised" test (003 §2.2;
PR Table 8.4); normalising log weights, N_eff and low-variance resampling come from the shared particle toolbox.

API summary
-----------
- :func:`normalise_log_weights`, :func:`n_eff`, :func:`low_variance_resample` (PR Table 4.4):
  re-exported from :mod:`slamlab.filters.particles` (one place, shared with :mod:`slamlab.planes`).
- :func:`kld_bound` ``(k, epsilon, z_quantile)``: Fox 2003's sample count for ``k`` bins;
  :func:`kld_sample_count` the count for a drawn set (our addition, labelled: 003 has a fixed count).
- :func:`pose_estimate` ``(particles, w) -> (mean, cov)`` (circular mean of the heading);
  :func:`is_localised` from the covariance.
- :func:`cluster_labels` ``(particles, bin_size)``: ROS 1 amcl's clusters (connected occupied bins);
  :func:`best_cluster_estimate` the mean and covariance of the heaviest one (amcl's published pose).
- :func:`uniform_free_particles` ``(grid, n, rng)``: poses spread over the free cells (global start, injection).
"""

from __future__ import annotations

import numpy as np
from scipy.stats import norm

from .._validate import as_rng, check_int, check_positive, check_probability
from ..filters.particles import low_variance_resample, n_eff, normalise_log_weights
from ..geometry import wrap_angle
from ..scans import FREE, check_grid

__all__ = [
    "FAIL_DEG",
    "FAIL_POS_CELLS",
    "amcl_converged",
    "best_cluster_estimate",
    "cluster_labels",
    "free_cell_centres",
    "is_localised",
    "kld_bound",
    "kld_sample_count",
    "low_variance_resample",
    "n_eff",
    "normalise_log_weights",
    "pose_estimate",
    "uniform_free_particles",
]

#: Success of a localisation (the chapter's one criterion, simulated and real): final position error below this
#: (map cells) ...
FAIL_POS_CELLS = 3.0
#: ... and heading error below this (degrees) (ours).
FAIL_DEG = 5.0


def kld_bound(k, epsilon: float = 0.05, z_quantile: float = 0.99):
    """Fox's (2003) particle count for ``k`` occupied bins: ``(k−1)/(2ε)·(1 − 2/(9(k−1)) + √(2/(9(k−1)))·z)³``.

    ``z`` is the upper ``1 − δ`` quantile of the standard normal (``z_quantile = 1 − δ``);
    PR Table 8.4 line 17. One bin gives 1.

    Parameters
    ----------
    k : int or array_like of int
        Number of occupied bins.
    epsilon : float
        Bound ε on the Kullback-Leibler divergence (PR Table 8.4).
    z_quantile : float
        ``1 − δ``: the probability of staying within the bound.

    Returns
    -------
    float or ndarray
        The particle count (as floats, not rounded), shaped like ``k``.

    Examples
    --------
    >>> int(np.ceil(kld_bound(10, 0.05, 0.99)))
    217
    """
    eps = check_positive(epsilon, "epsilon")
    zq = float(norm.ppf(check_probability(z_quantile, "z_quantile")))
    k = np.asarray(k, dtype=float)
    km1 = np.maximum(k - 1, 1e-12)
    a = 2.0 / (9.0 * km1)
    out = km1 / (2 * eps) * (1 - a + np.sqrt(a) * zq) ** 3
    return np.where(k <= 1, 1.0, out)


def _bin_ids(particles, bin_size):
    b = np.floor(particles[:, :2] / bin_size[:2]).astype(np.int64)
    h = np.floor(np.mod(particles[:, 2], 2 * np.pi) / bin_size[2]).astype(np.int64)
    return b[:, 0] * 1_000_003 + b[:, 1] * 7919 + h  # distinct for any map below a million cells a side


def kld_sample_count(particles, *, bin_size=(2.0, 2.0, 0.174533), epsilon: float = 0.05,
                     z_quantile: float = 0.99, n_min: int = 100) -> int:
    """How many of ``particles`` (drawn in order) KLD sampling keeps: the first ``m`` with
    ``m ≥ max(n_min, kld_bound(k(m)))``, ``k(m)`` the bins occupied by the first ``m`` (PR Table 8.4;
    Fox 2003). All of them when the bound is never met. Vectorised: bins by first occurrence, a cumsum.

    Default bins: 2 cells, 2 cells, 10°. Our addition (003 uses a fixed number of particles), as ROS AMCL does.

    Parameters
    ----------
    particles : array_like, shape (N, 3)
        The drawn set, in the order it was drawn.
    bin_size : tuple of float
        Bin size in x, y (cells) and heading (rad).
    epsilon : float
        Fox's ε (PR Table 8.4).
    z_quantile : float
        ``1 − δ``.
    n_min : int
        Lower bound on the count.

    Returns
    -------
    int
        The number of leading particles to keep.
    """
    P = np.asarray(particles, dtype=float)
    bs = np.asarray(bin_size, dtype=float)
    ids = _bin_ids(P, bs)
    _, first = np.unique(ids, return_index=True)
    new = np.zeros(ids.size, bool)
    new[first] = True
    k = np.cumsum(new)
    m = np.arange(1, ids.size + 1)
    ok = m >= np.maximum(n_min, kld_bound(k, epsilon, z_quantile))
    return int(m[np.argmax(ok)]) if ok.any() else int(ids.size)


def pose_estimate(particles, weights=None) -> tuple[np.ndarray, np.ndarray]:
    """Weighted mean pose (circular mean of the heading) and the 3×3 covariance of the particles.

    The heading residuals are wrapped around the mean before the covariance.

    Parameters
    ----------
    particles : array_like, shape (N, 3)
        Poses ``(x, y, θ)``.
    weights : array_like, shape (N,), optional
        Non-negative weights with a positive sum (normalised here); None: equal weights.

    Returns
    -------
    mean : ndarray, shape (3,)
        Weighted mean position and circular mean heading.
    cov : ndarray, shape (3, 3)
        Weighted covariance, heading residuals wrapped about the mean.

    Examples
    --------
    >>> m, C = pose_estimate([[0, 0, np.pi - 0.1], [2, 0, -np.pi + 0.1]])
    >>> m.round(6).tolist(), round(float(C[0, 0]), 6), round(float(C[2, 2]), 6)
    ([1.0, 0.0, 3.141593], 1.0, 0.01)
    """
    P = np.asarray(particles, dtype=float)
    if P.ndim != 2 or P.shape[1] != 3 or P.shape[0] == 0:
        raise ValueError(f"`particles` must have shape (N, 3) with N >= 1; got {P.shape}")
    if weights is None:
        w = np.full(P.shape[0], 1.0 / P.shape[0])
    else:
        w = np.asarray(weights, dtype=float)
        if w.shape != (P.shape[0],) or not np.all(np.isfinite(w)) or w.sum() <= 0:
            raise ValueError("`weights` must be N finite numbers with a positive sum")
        w = w / w.sum()
    mean_xy = w @ P[:, :2]
    th = float(np.arctan2(w @ np.sin(P[:, 2]), w @ np.cos(P[:, 2])))
    d = np.column_stack([P[:, :2] - mean_xy, wrap_angle(P[:, 2] - th)])
    C = (d * w[:, None]).T @ d
    return np.array([mean_xy[0], mean_xy[1], th]), C


def cluster_labels(particles, bin_size) -> np.ndarray:
    """Cluster label of every particle: ROS 1 amcl's clustering (``pf_kdtree_cluster``), the connected
    components of the occupied histogram bins, two bins adjacent when their indices differ by at most 1 in x, y
    and heading (26 neighbours; the heading bins wrap around). Our addition to 003 (labelled), as amcl.

    Parameters
    ----------
    particles : array_like, shape (N, 3)
        Poses ``(x, y, θ)``.
    bin_size : sequence of 3 float
        Bin size in x, y (the particles' unit) and heading (rad); amcl: its KLD bins (0.5 m, 0.5 m, 10°).

    Returns
    -------
    ndarray of int, shape (N,)
        Labels ``0 … K−1``, one per cluster.

    Examples
    --------
    >>> cluster_labels([[0, 0, 0], [0.9, 0, 0], [5, 5, 0], [0.2, 0, 6.2]], (1.0, 1.0, 0.5)).tolist()
    [0, 0, 1, 0]
    """
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components

    P = np.asarray(particles, dtype=float)
    if P.ndim != 2 or P.shape[1] != 3 or P.shape[0] == 0:
        raise ValueError(f"`particles` must have shape (N, 3) with N >= 1; got {P.shape}")
    if not np.all(np.isfinite(P)):
        raise ValueError("`particles` must be finite")
    b = np.asarray(bin_size, dtype=float)
    if b.shape != (3,) or not np.all(b > 0):
        raise ValueError(f"`bin_size` must be three sizes > 0 (x, y, θ); got {bin_size!r}")
    n_h = max(1, int(np.ceil(2 * np.pi / b[2] - 1e-9)))
    idx = np.empty((P.shape[0], 3), np.int64)
    idx[:, :2] = np.floor(P[:, :2] / b[:2])
    idx[:, 2] = np.floor(np.mod(P[:, 2], 2 * np.pi) / b[2]).astype(np.int64) % n_h
    lo = idx[:, :2].min(axis=0) - 1
    span = idx[:, :2].max(axis=0) - lo + 2  # room for the -1/+1 neighbours

    def code(i):
        return ((i[:, 0] - lo[0]) * span[1] + (i[:, 1] - lo[1])) * n_h + i[:, 2]

    keys, inverse = np.unique(code(idx), return_inverse=True)
    cells = idx[np.unique(inverse, return_index=True)[1]]  # the bin of each key, in key order
    rows, cols = [], []
    for d in np.stack(np.meshgrid([-1, 0, 1], [-1, 0, 1], [-1, 0, 1], indexing="ij"), -1).reshape(-1, 3):
        if not d.any():
            continue
        nb = cells + d
        nb[:, 2] %= n_h
        c = code(nb)
        j = np.minimum(np.searchsorted(keys, c), keys.size - 1)
        hit = keys[j] == c
        rows.append(np.flatnonzero(hit))
        cols.append(j[hit])
    r, c = np.concatenate(rows), np.concatenate(cols)
    graph = coo_matrix((np.ones(r.size, np.int8), (r, c)), shape=(keys.size, keys.size))
    _, comp = connected_components(graph, directed=False)
    # number the clusters by first appearance, so labels do not depend on the bin codes' order
    first = np.unique(comp[inverse], return_index=True)[1]
    order = np.empty(first.size, np.int64)
    order[np.argsort(np.argsort(first))] = np.arange(first.size)
    return order[comp[inverse]]


def best_cluster_estimate(particles, weights, bin_size) -> tuple[np.ndarray, np.ndarray]:
    """The pose ROS 1 amcl publishes: the weighted mean and covariance (:func:`pose_estimate`) of the cluster
    (:func:`cluster_labels`) with the largest total weight. Our addition to 003 (labelled): with two or more
    hypotheses left, the mean of the whole set lies between them.

    Parameters
    ----------
    particles : array_like, shape (N, 3)
        Poses ``(x, y, θ)``.
    weights : array_like, shape (N,)
        Non-negative weights with a positive sum.
    bin_size : sequence of 3 float
        Bin size in x, y and heading (rad), as :func:`cluster_labels`.

    Returns
    -------
    mean : ndarray, shape (3,)
        Weighted mean pose of the heaviest cluster.
    cov : ndarray, shape (3, 3)
        Its weighted covariance.

    Examples
    --------
    >>> m, _ = best_cluster_estimate([[0, 0, 0], [0.5, 0, 0], [9, 9, 0]], [0.3, 0.3, 0.4], (1.0, 1.0, 0.5))
    >>> m.round(3).tolist()
    [0.25, 0.0, 0.0]
    """
    P = np.asarray(particles, dtype=float)
    w = np.asarray(weights, dtype=float)
    if w.ndim != 1 or w.shape[0] != len(P):
        raise ValueError(f"`weights` must have shape ({len(P)},); got {w.shape}")
    if not np.all(np.isfinite(w)) or np.any(w < 0) or not w.sum() > 0:
        raise ValueError("`weights` must be finite, non-negative, with a positive sum")
    lab = cluster_labels(P, bin_size)
    keep = lab == int(np.argmax(np.bincount(lab, weights=w)))
    return pose_estimate(P[keep], w[keep])


def is_localised(cov, *, pos_std: float = 2.0, heading_std_rad: float = 0.087266) -> bool:
    """The "localised" test (ours; default 2 cells and 5°): the position's largest standard deviation (√ of the largest eigenvalue
    of the x-y block) below ``pos_std`` and the heading's below ``heading_std_rad``.

    Parameters
    ----------
    cov : array_like, shape (3, 3)
        Covariance of the pose estimate (:func:`pose_estimate`).
    pos_std : float
        Largest position standard deviation allowed (cells).
    heading_std_rad : float
        Largest heading standard deviation allowed (rad).

    Returns
    -------
    bool
        Whether both standard deviations are below their bounds.

    Examples
    --------
    >>> is_localised(np.diag([1.0, 1.0, 0.001])), is_localised(np.diag([9.0, 1.0, 0.001]))
    (True, False)
    """
    C = np.asarray(cov, dtype=float)
    if C.shape != (3, 3) or not np.all(np.isfinite(C)):
        raise ValueError(f"`cov` must be a finite 3×3 matrix; got shape {C.shape}")
    lam = float(np.linalg.eigvalsh(C[:2, :2]).max())
    return bool(np.sqrt(max(lam, 0.0)) < pos_std and np.sqrt(max(C[2, 2], 0.0)) < heading_std_rad)


def amcl_converged(particles, dist: float) -> bool:
    """ROS 1 amcl's convergence test (``pf_update_converged``): every particle within ``dist`` of the
    particles' (unweighted) mean in x and in y (amcl: 0.5 m).

    Parameters
    ----------
    particles : array_like, shape (N, 3) or (N, 2)
        The (resampled) particle set.
    dist : float
        Largest distance from the mean in x and in y (cells).

    Returns
    -------
    bool
        Whether every particle is within ``dist`` of the mean in both coordinates.

    Examples
    --------
    >>> amcl_converged([[0, 0, 0], [1, 0, 3]], 0.6), amcl_converged([[0, 0, 0], [1, 0, 3]], 0.4)
    (True, False)
    """
    P = np.asarray(particles, dtype=float)
    if P.ndim != 2 or P.shape[1] < 2 or P.shape[0] == 0:
        raise ValueError(f"`particles` must have shape (N, 3) with N >= 1; got {P.shape}")
    d = check_positive(dist, "dist")
    return bool(np.all(np.abs(P[:, :2] - P[:, :2].mean(axis=0)) <= d))


def free_cell_centres(grid) -> np.ndarray:
    """``(x, y)`` centres of the FREE cells of ``grid``, shape ``(K, 2)``; ValueError when there is none.

    Parameters
    ----------
    grid : array_like of int, shape (H, W)
        Occupancy grid with FREE / OCCUPIED / UNKNOWN cells (:mod:`slamlab.scans`).

    Returns
    -------
    ndarray, shape (K, 2)
        Cell centres ``(x, y)`` of the FREE cells, in cells.
    """
    g = check_grid(grid)
    rc = np.argwhere(g == FREE)
    if rc.shape[0] == 0:
        raise ValueError("`grid` has no FREE cell: nowhere to put a particle")
    return rc[:, ::-1].astype(float)


def uniform_free_particles(grid, n: int, rng=None, *, centres=None) -> np.ndarray:
    """``n`` poses uniform over the FREE cells (uniform inside a cell, heading uniform in [−π, π)).

    Parameters
    ----------
    grid : array_like of int, shape (H, W)
        Occupancy grid.
    n : int
        Number of poses.
    rng : Generator, int or None
        Random source.
    centres : ndarray, shape (K, 2), optional
        The free cell centres, if already computed (:func:`free_cell_centres`).

    Returns
    -------
    ndarray, shape (n, 3)
        Poses ``(x, y, θ)`` in cells and radians.

    Examples
    --------
    >>> g = np.zeros((3, 3), np.int8); g[0] = 1
    >>> P = uniform_free_particles(g, 5, rng=0); bool(np.all(P[:, 1] >= 0.5))
    True
    """
    n = check_int(n, "n", minimum=1)
    xy = free_cell_centres(grid) if centres is None else centres
    rng = as_rng(rng)
    pick = xy[rng.integers(0, xy.shape[0], n)] + rng.uniform(-0.5, 0.5, (n, 2))
    return np.column_stack([pick, rng.uniform(-np.pi, np.pi, n)])
