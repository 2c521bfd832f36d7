"""Frame building and plane extraction by RANSAC (002 "Forming the range frame", "Plane extraction").

Frame (002, reconstructed; the source's formula is garbled): the N lines of a buffer,
each in the body frame at its own time, are moved into the body pose of the *last*
line with the odometry, ``T_j = (ᵒT_N)⁻¹ ᵒT_j`` (``ᵒT_j``: body pose of line ``j`` in
the odom frame).

Planes ``n·x = p`` (002's normal form ``n·x − p = 0``) by RANSAC; 002 used PCL's, ours
is numpy and batched (:func:`~slamlab.geometry.ransac` with ``batch_size``): each round draws
``iterations`` minimal samples (3 points) at once from a random subset of ``sample_points``
points, scores all hypotheses on that subset at once (ours: preemptive scoring on a subset),
takes the best (the first of the most inliers), collects its
inliers (``|n·x − p| <= tolerance_m``) among all remaining points, refits by least
squares (SVD) on them and recounts (:func:`~slamlab.geometry.ransac_refit`); a plane needs ``min_support`` inliers. Planes
are taken greedily until none has enough support or ``max_planes`` were found.
Sign convention (ours): ``p >= 0``, i.e. the normal points away from the sensor.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .._validate import as_finite_array, as_rng, as_vector, check_int, check_positive
from ..geometry.ransac import ransac, ransac_refit

__all__ = ["Frame", "build_frame", "extract_planes", "fit_plane_lsq", "frame_transforms", "plane_distances"]


def frame_transforms(odometry) -> np.ndarray:
    """``T_j = (ᵒT_N)⁻¹ ᵒT_j`` for every line ``j`` of a buffer (002, reconstructed): ``(N, 4, 4)``.

    Parameters
    ----------
    odometry : (N, 4, 4) float
        Body poses of the lines in the odometry frame.

    Returns
    -------
    (N, 4, 4) float
        Each line's pose in the last line's body frame (the last is the identity).

    Examples
    --------
    >>> T = np.tile(np.eye(4), (2, 1, 1)); T[0, 0, 3] = 1.0
    >>> frame_transforms(T)[0, :3, 3].tolist()
    [1.0, 0.0, 0.0]
    """
    T = as_finite_array(odometry, "odometry", ndim=3)
    if T.shape[1:] != (4, 4) or T.shape[0] < 1:
        raise ValueError(f"`odometry` must have shape (N >= 1, 4, 4); got {T.shape}")
    RN, tN = T[-1, :3, :3], T[-1, :3, 3]
    out = np.zeros_like(T)
    out[:, :3, :3] = RN.T @ T[:, :3, :3]
    out[:, :3, 3] = (T[:, :3, 3] - tN) @ RN
    out[:, 3, 3] = 1.0
    return out


@dataclass(frozen=True)
class Frame:
    """A 3-D range frame in the body pose of its last line (002): ``points (K, 3)``, ``intensities (K,)``,
    ``rays (K, 3)`` unit beam directions (for the incidence-angle correction), ``n_dropped`` points without
    a return (NaN) left out.

    Attributes
    ----------
    points : (K, 3) float
        Points in the last line's body frame, metres.
    intensities : (K,) float
        Their return intensities.
    rays : (K, 3) float
        Unit beam directions in the same frame.
    n_dropped : int
        Beams without a return that were left out.
    """

    points: np.ndarray
    intensities: np.ndarray
    rays: np.ndarray
    n_dropped: int

    def __len__(self) -> int:
        return self.points.shape[0]


def build_frame(points, intensities, odometry, *, origin_m=(0.0, 0.0, 0.0)) -> Frame:
    """Move N lines of body-frame points into the last line's body pose (002 "Forming the range frame").

    Parameters
    ----------
    points : (N, B, 3) points of N lines (NaN: no return) in the body frame at each line's time.
    intensities : (N, B) intensities.
    odometry : (N, 4, 4) body poses ``ᵒT_j`` of the lines in the odom frame.
    origin_m : (3,) scanner origin in the body frame (for the beam directions).

    Returns
    -------
    Frame
        The frame's finite points, intensities and ray directions in the last line's body frame.
    """
    P = np.asarray(points, dtype=float)
    if P.ndim != 3 or P.shape[2] != 3:
        raise ValueError(f"`points` must have shape (N, B, 3); got {P.shape}")
    I = np.asarray(intensities, dtype=float)
    if I.shape != P.shape[:2]:
        raise ValueError(f"`intensities` must have shape {P.shape[:2]}; got {I.shape}")
    T = frame_transforms(odometry)
    if T.shape[0] != P.shape[0]:
        raise ValueError(f"`odometry` must hold one pose per line ({P.shape[0]}); got {T.shape[0]}")
    o = as_vector(origin_m, "origin_m", 3)
    ok = np.isfinite(P).all(axis=2) & np.isfinite(I)
    line = np.nonzero(ok)[0]
    pb = P[ok]
    R = T[line, :3, :3]
    pts = np.einsum("kij,kj->ki", R, pb) + T[line, :3, 3]
    d = pb - o
    d /= np.maximum(np.linalg.norm(d, axis=1, keepdims=True), 1e-12)
    rays = np.einsum("kij,kj->ki", R, d)
    return Frame(pts, I[ok], rays, int((~ok).sum()))


def fit_plane_lsq(points) -> tuple[np.ndarray, float]:
    """Least-squares plane through ``points (K >= 3, 3)``: ``(n, p)`` with ``n·x = p``, ``p >= 0`` (SVD; ours).

    Parameters
    ----------
    points : (K, 3) float
        At least three non-collinear points, metres.

    Returns
    -------
    n : (3,) float
        Unit normal.
    p : float
        Distance of the plane from the origin in metres (>= 0).

    Examples
    --------
    >>> n, p = fit_plane_lsq([[0, 0, 2.0], [1, 0, 2], [0, 1, 2], [1, 1, 2]])
    >>> np.round(n, 12).tolist(), round(p, 12)
    ([0.0, 0.0, 1.0], 2.0)
    """
    X = as_finite_array(points, "points", ndim=2)
    if X.shape[1] != 3 or X.shape[0] < 3:
        raise ValueError(f"`points` must have shape (K >= 3, 3); got {X.shape}")
    c = X.mean(axis=0)
    _, s, Vt = np.linalg.svd(X - c, full_matrices=False)
    if s[1] <= 1e-12 * max(s[0], 1e-300):
        raise ValueError("`points` are collinear: no unique plane")
    n = Vt[2]
    p = float(n @ c)
    if p < 0:
        n, p = -n, -p
    return n, p


def plane_distances(points, n, p) -> np.ndarray:
    """Signed distances ``n·x − p`` of ``points (K, 3)`` to the plane ``(n, p)``.

    Parameters
    ----------
    points : (K, 3) float
        Points, metres.
    n : (3,) float
        Unit normal.
    p : float
        Distance term in metres.

    Returns
    -------
    (K,) float
        Signed distances in metres.
    """
    return np.asarray(points) @ np.asarray(n) - p


def _fit_planes(rows):
    """Planes through 3-point samples ``rows (b, 3, 3)``: ``(n (b', 3), p (b',))`` of the non-degenerate ones."""
    a, b, c = rows[:, 0], rows[:, 1], rows[:, 2]
    nrm = np.cross(b - a, c - a)
    norm = np.linalg.norm(nrm, axis=1)
    good = norm > 1e-9
    nrm = nrm[good] / norm[good, None]
    return nrm, np.einsum("ij,ij->i", nrm, a[good])


def _plane_residuals(plane, points):
    """``|n·x − p|`` of ``points (K, 3)``: ``(K,)`` for one plane ``(n (3,), p)``, ``(b, K)`` for ``(n (b, 3), p (b,))``."""
    n, p = plane
    return np.abs(points @ np.transpose(n) - p).T


def extract_planes(points, *, tolerance_m: float = 0.03, iterations: int = 100, min_support: int = 400,
                   max_planes: int = 12, sample_points: int = 1000, refit_rounds: int = 2,
                   min_width_m: float = 0.0, rng=None):
    """Greedy batched RANSAC plane extraction (002 "Plane extraction"; our numpy version of PCL's).

    Parameters
    ----------
    points : (K, 3) frame points (finite).
    tolerance_m : inlier distance.
    iterations : minimal samples (hypotheses) per plane.
    min_support : inliers a plane needs.
    max_planes : planes at most.
    sample_points : hypotheses are drawn and scored on this many random remaining points.
    refit_rounds : least-squares refits on the inliers, each followed by a recount.
    min_width_m : a plane whose inliers span less than this between their 10th and 90th percentiles along
        either in-plane principal axis is dropped (its points go to the leftover): a narrow band (a few
        scan lines) fixes its normal badly about its axis (ours).
    rng : Generator, int or None.

    Returns
    -------
    planes : list of ``(n (3,), p, inlier_indices)``; leftover (K,) bool mask of points on no plane.

    Examples
    --------
    >>> g = np.random.default_rng(0); xy = g.uniform(-2, 2, (2000, 2))
    >>> pts = np.c_[xy, np.full(2000, 1.5)]
    >>> planes, rest = extract_planes(pts, rng=0)
    >>> len(planes), np.round(planes[0][0], 9).tolist(), round(planes[0][1], 9), int(rest.sum())
    (1, [0.0, 0.0, 1.0], 1.5, 0)
    """
    X = as_finite_array(points, "points", ndim=2)
    if X.shape[1] != 3:
        raise ValueError(f"`points` must have shape (K, 3); got {X.shape}")
    tol = check_positive(tolerance_m, "tolerance_m")
    iters = check_int(iterations, "iterations", minimum=1)
    min_support = check_int(min_support, "min_support", minimum=3)
    max_planes = check_int(max_planes, "max_planes", minimum=0)
    sample_points = check_int(sample_points, "sample_points", minimum=3)
    refit_rounds = check_int(refit_rounds, "refit_rounds", minimum=0)
    min_width_m = check_positive(min_width_m, "min_width_m", allow_zero=True)
    rng = as_rng(rng)
    remaining = np.arange(X.shape[0])
    planes, rejected = [], []
    while len(planes) + len(rejected) < 2 * max_planes and len(planes) < max_planes and remaining.size >= max(min_support, 3):
        sub = remaining if remaining.size <= sample_points else remaining[rng.integers(0, remaining.size,
                                                                                        sample_points)]
        S = X[sub]
        best = ransac(S, _fit_planes, _plane_residuals, 3, tol, max_iters=iters, batch_size=iters, refit_rounds=0,
                      rng=rng)
        if best.model is None:
            break
        # the subset's best count predicts the full count; stop early when even that is too small
        if int(best.inliers.sum()) * remaining.size / S.shape[0] < 0.5 * min_support:
            break
        n, p = best.model[0], float(best.model[1])
        Y = X[remaining]
        mask = _plane_residuals((n, p), Y) <= tol
        (n, p), mask = ransac_refit(Y, fit_plane_lsq, _plane_residuals, (n, p), mask, tol, rounds=refit_rounds,
                                    min_rows=3)
        if mask.sum() < min_support:
            break
        if p < 0:
            n, p = -n, -p
        if min_width_m > 0:
            Z = Y[mask] - Y[mask].mean(axis=0)
            ab = Z @ np.linalg.eigh(Z.T @ Z)[1][:, 1:]              # in-plane principal coordinates
            width = np.diff(np.percentile(ab, [10, 90], axis=0), axis=0).min()
            if width < min_width_m:
                rejected.append(remaining[mask])           # on no plane: back into the leftover at the end
                remaining = remaining[~mask]
                continue
        planes.append((n, p, remaining[mask]))
        remaining = remaining[~mask]
    leftover = np.zeros(X.shape[0], dtype=bool)
    leftover[remaining] = True
    for idx in rejected:
        leftover[idx] = True
    return planes, leftover
