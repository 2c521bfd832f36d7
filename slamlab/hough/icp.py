"""Scan-matching baseline: plain point-to-point ICP on ``scipy.spatial.cKDTree`` (our addition).

004 compares its line SLAM with particle-filter SLAM only in words; the issue asks for a
scan-matching baseline. :func:`icp` registers a scan on the previous one (Besl-McKay:
nearest neighbours from a kd-tree, closed-form SVD rigid fit, repeat), and
:func:`icp_odometry` chains it along a sequence of scans.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.spatial import cKDTree

from .._validate import as_finite_array, as_vector, check_int, check_positive
from ..geometry.se2 import se2_compose, se2_transform

__all__ = ["IcpResult", "icp", "icp_odometry", "rigid_fit_2d"]


@dataclass(frozen=True)
class IcpResult:
    """``pose`` = ``(Δx, Δy, Δφ)`` of the source scan in the target's frame.

    Attributes
    ----------
    pose : numpy.ndarray, shape (3,)
        ``(Δx, Δy, Δφ)`` (point unit, rad).
    converged : bool
        The update fell below ``tol`` before ``max_iter``.
    n_iter : int
        Iterations run.
    rmse : float
        RMS distance of the last inlier pairs.
    n_inliers : int
        Pairs within ``max_dist`` in the last iteration.
    """

    pose: np.ndarray
    converged: bool
    n_iter: int
    rmse: float
    n_inliers: int


def _points(value, name):
    arr = as_finite_array(value, name)
    if arr.ndim != 2 or arr.shape[1] != 2:
        raise ValueError(f"`{name}` must have shape (N, 2); got shape {arr.shape}")
    if arr.shape[0] < 3:
        raise ValueError(f"`{name}` must hold at least 3 points; got {arr.shape[0]}")
    return arr


def rigid_fit_2d(src, dst) -> np.ndarray:
    """Least-squares rotation + translation with ``dst ≈ R(φ)·src + t`` (SVD); returns ``(tx, ty, φ)``.

    Parameters
    ----------
    src, dst : array_like, shape (N, 2)
        Corresponding points.

    Returns
    -------
    numpy.ndarray, shape (3,)
        ``(tx, ty, φ)``.

    Examples
    --------
    >>> a = np.array([[0.0, 0.0], [1.0, 0.0], [0.0, 2.0]])
    >>> R = np.array([[0.0, -1.0], [1.0, 0.0]])
    >>> rigid_fit_2d(a, a @ R.T + [1.0, 2.0]).round(12).tolist()
    [1.0, 2.0, 1.570796326795]
    """
    src, dst = _points(src, "src"), _points(dst, "dst")
    if src.shape != dst.shape:
        raise ValueError(f"`src` and `dst` must have the same shape; got {src.shape} and {dst.shape}")
    cs, cd = src.mean(axis=0), dst.mean(axis=0)
    S = (src - cs).T @ (dst - cd)
    phi = math.atan2(S[0, 1] - S[1, 0], S[0, 0] + S[1, 1])
    t = cd - se2_transform([0.0, 0.0, phi], cs)
    return np.array([t[0], t[1], phi])


def icp(source, target, init=(0.0, 0.0, 0.0), *, max_iter: int = 50, tol: float = 1e-6,
        max_dist: float | None = None, tree: cKDTree | None = None) -> IcpResult:
    """Point-to-point ICP of ``source`` onto ``target`` (Besl & McKay 1992; baseline, our addition).

    Parameters
    ----------
    source, target : (N, 2), (M, 2) array_like
        Points in their own sensor frames.
    init : (3,) array_like
        Initial ``(Δx, Δy, Δφ)`` (e.g. from odometry).
    max_iter, tol : int, float
        Stop after ``max_iter`` iterations or when the update is below ``tol``.
    max_dist : float, optional
        Pairs farther apart are rejected (default: keep all).
    tree : cKDTree, optional
        A kd-tree of ``target`` to reuse.

    Returns
    -------
    IcpResult
        ``pose`` of ``source`` in ``target``'s frame, ``converged``, ``n_iter``, ``rmse``, ``n_inliers``.

    Examples
    --------
    >>> g = np.linspace(0, 10, 41)
    >>> target = np.concatenate([np.column_stack([g, 0 * g]), np.column_stack([0 * g, g])])
    >>> c, s = np.cos(0.02), np.sin(0.02)
    >>> source = (target - [0.1, -0.05]) @ np.array([[c, -s], [s, c]])   # seen from (0.1, -0.05, 0.02)
    >>> res = icp(source, target)
    >>> res.converged, res.pose.round(6).tolist()
    (True, [0.1, -0.05, 0.02])
    """
    src = _points(source, "source")
    dst = _points(target, "target")
    pose = as_vector(init, "init", 3).copy()
    max_iter = check_int(max_iter, "max_iter", minimum=1)
    tol = check_positive(tol, "tol")
    max_dist = np.inf if max_dist is None else check_positive(max_dist, "max_dist")
    kd = cKDTree(dst) if tree is None else tree
    converged, it, rmse, n_in = False, 0, float("nan"), 0
    for it in range(1, max_iter + 1):  # noqa: B007 - the count is returned
        moved = se2_transform(pose, src)
        dist, idx = kd.query(moved, distance_upper_bound=max_dist)
        ok = np.isfinite(dist)
        n_in = int(ok.sum())
        if n_in < 3:
            break
        rmse = float(np.sqrt(np.mean(dist[ok] ** 2)))
        new = rigid_fit_2d(src[ok], dst[idx[ok]])
        step = np.abs(new - pose)
        pose = new
        if step[:2].max() < tol and step[2] < tol:
            converged = True
            break
    return IcpResult(pose, converged, it, rmse, n_in)


def icp_odometry(points, start_pose=(0.0, 0.0, 0.0), init_increments=None, *, max_dist: float | None = None,
                 max_iter: int = 50) -> tuple[np.ndarray, np.ndarray]:
    """Chain scan-to-scan ICP along a sequence of scans (baseline, our addition).

    Parameters
    ----------
    points : sequence of (N_k, 2) arrays
        Each scan's returns in its sensor frame.
    start_pose : (3,) array_like
        Pose of the first scan ``(x, y, φ)``.
    init_increments : (n-1, 3) array_like, optional
        Initial guesses (odometry increments); zeros by default.
    max_dist : float, optional
        Pairs farther apart are rejected (default: keep all).
    max_iter : int, default 50
        Iterations per scan pair.

    Returns
    -------
    poses : (n, 3) array
    converged : (n-1,) bool array
    """
    pts = list(points)
    if len(pts) < 1:
        raise ValueError("`points` must hold at least one scan; got 0")
    U = np.zeros((len(pts) - 1, 3)) if init_increments is None else as_finite_array(init_increments,
                                                                                       "init_increments", ndim=2)
    if U.shape != (len(pts) - 1, 3):
        raise ValueError(f"`init_increments` must have shape ({len(pts) - 1}, 3); got {U.shape}")
    poses = [as_vector(start_pose, "start_pose", 3).copy()]
    conv = np.zeros(len(pts) - 1, dtype=bool)
    tree = None
    for k in range(1, len(pts)):
        tree = cKDTree(_points(pts[k - 1], f"points[{k - 1}]"))
        res = icp(pts[k], pts[k - 1], U[k - 1], max_dist=max_dist, max_iter=max_iter, tree=tree)
        conv[k - 1] = res.converged
        poses.append(se2_compose(poses[-1], res.pose))
    return np.array(poses), conv
