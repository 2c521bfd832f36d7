"""Stereo SLAM stage 4: the pose by absolute orientation inside RANSAC, oldest landmarks first (000 §3.5), and
its optional refinement on the stereo reprojection error (our option, issue 25).

Part of :mod:`slamlab.stereo.stages` (which re-exports every name; its docstring gives the pipeline's order).
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from .._validate import as_finite_array, as_matrix, as_rng, as_vector, check_int, check_positive
from ..geometry.camera import StereoRig
from ..geometry.ransac import ransac
from ..geometry.registration import RigidTransform, umeyama
from ..geometry.so3 import hat, rotation_angle, se3_exp
from .params import StereoParams

__all__ = [
    "PoseEstimate",
    "estimate_pose",
    "pose_std",
    "refine_pose_stereo",
    "select_oldest",
]


# --- pose: absolute orientation inside RANSAC, oldest landmarks first (000 §3.5) -----------------


def select_oldest(first_seen, n_min: int) -> np.ndarray:
    """Indices of the matches whose landmarks were first seen longest ago (000 §3.5).

    Sort by the frame of the first sighting and take the earliest ones until at
    least ``n_min`` are gathered, with every landmark of the last frame included
    ("seen as long ago as possible and at about the same time").

    Parameters
    ----------
    first_seen : array_like of int, shape (M,)
        Frame of each match's first sighting.
    n_min : int
        Fewest matches to take.

    Returns
    -------
    numpy.ndarray of int
        Indices of the selected matches.

    Examples
    --------
    >>> select_oldest([5, 0, 3, 0, 9, 3], 3).tolist()
    [1, 2, 3, 5]
    """
    fs = np.asarray(first_seen)
    if fs.ndim != 1:
        raise ValueError(f"`first_seen` must be 1-D; got shape {fs.shape}")
    n_min = check_int(n_min, "n_min", minimum=1)
    if fs.size <= n_min:
        return np.arange(fs.size)
    cut = np.sort(fs)[n_min - 1]
    return np.flatnonzero(fs <= cut)


def pose_std(points_map, cov_map, center=None) -> np.ndarray:
    """Standard deviations of the 6 pose parameters (3 rotations, rad; 3 translations, m)
    determined by matched points with covariances ``cov_map`` (Gauss-Newton information
    ``Σ Jᵢᵀ Σᵢ⁻¹ Jᵢ``, ``Jᵢ = [-[pᵢ - c]ₓ, I]``; translations about ``center``, default the
    points' mean). Our addition: it tells whether a set of landmarks is "sufficiently large
    for computing the position" (000 §3.5). A wall of points straight ahead, with stereo depth
    error much larger than the lateral error, leaves yaw and sideways translation nearly
    interchangeable; this shows as large standard deviations.

    Parameters
    ----------
    points_map : array_like, shape (M, 3)
        Matched points in the map frame [m].
    cov_map : array_like, shape (M, 3, 3)
        Their covariances [m²].
    center : array_like, shape (3,), optional
        Centre of the rotations (default the points' mean).

    Returns
    -------
    numpy.ndarray, shape (6,)
        Std of 3 rotations [rad] and 3 translations [m]; inf when undetermined.

    Examples
    --------
    >>> P = np.array([[1.0, 0, 0], [0, 1, 0], [0, 0, 1], [1, 1, 1]])
    >>> bool(np.all(np.isfinite(pose_std(P, np.tile(np.eye(3) * 1e-4, (4, 1, 1))))))
    True
    """
    P = as_finite_array(points_map, "points_map", ndim=2)
    C = np.asarray(cov_map, dtype=float)
    if C.shape != (len(P), 3, 3):
        raise ValueError(f"`cov_map` must have shape ({len(P)}, 3, 3); got {C.shape}")
    c = P.mean(axis=0) if center is None else np.asarray(center, dtype=float)
    return _std_from_information(_point_information(P, C, c).sum(axis=0))


def _point_information(P, C, center) -> np.ndarray:
    """(N, 6, 6) Gauss-Newton information ``Jᵢᵀ Cᵢ⁻¹ Jᵢ`` of each point about ``center``."""
    q = P - center
    J = np.zeros((len(P), 3, 6))
    J[:, :, :3] = hat(-q)  # d(R p)/d(rotation vector) = -[p]x = [-p]x
    J[:, :, 3:] = np.eye(3)
    CiJ = np.linalg.solve(C, J)
    return np.einsum("nki,nkj->nij", J, CiJ)


def _std_from_information(info) -> np.ndarray:
    """Standard deviations from (..., 6, 6) information matrices; inf where one is singular."""
    info = np.asarray(info)
    out = np.full(info.shape[:-1], np.inf)
    ok = np.linalg.cond(info) < 1e12
    if ok.any():
        out[ok] = np.sqrt(np.diagonal(np.linalg.inv(info[ok]), axis1=-2, axis2=-1))
    return out


class PoseEstimate(NamedTuple):
    """Pose ``T`` (4, 4) mapping local points to the map, ``inliers (M,)`` over all matches,
    ``converged``, ``n_used`` matches the final fit used, ``n_iters`` hypotheses.

    Attributes
    ----------
    T : numpy.ndarray, shape (4, 4)
        Body-to-map transform.
    inliers : numpy.ndarray of bool, shape (M,)
        Inlier mask over all matches.
    converged : bool
        A valid pose was found.
    n_used : int
        Matches in the final fit.
    n_iters : int
        RANSAC hypotheses drawn.
    """

    T: np.ndarray
    inliers: np.ndarray
    converged: bool
    n_used: int
    n_iters: int


def _fit(src, dst, w):
    # a RANSAC hypothesis or refit: the rows were checked once, by estimate_pose
    return umeyama(src, dst, weights=w, check=False)


def _residuals(T: RigidTransform, src, dst, w):
    # residual in units of the per-point scale: sqrt(w) = 1 / scale
    return np.linalg.norm(src @ T.R.T + T.t - dst, axis=1) * np.sqrt(w)


def estimate_pose(local_points, map_points, first_seen=None, *, depth_m=None, cov=None,
                  params: StereoParams | None = None, rng=None, **overrides) -> PoseEstimate:
    """Rotation + translation mapping the local cloud onto the map landmarks, by RANSAC + Umeyama (000 §3.5).

    Parameters
    ----------
    local_points, map_points : (M, 3) matched points in the body frame and in the map frame.
    first_seen : (M,) frame at which each matched landmark was first seen (for ``policy="oldest"``).
    params, overrides : :class:`StereoParams` (``policy``, ``ransac_iters``, ``threshold_m``,
        ``depth_ref_m``, ``min_inliers``, ``n_oldest``, ``oldest_fraction``, ``keep_fraction``,
        ``loose_factor``, ``still_fraction``, ``max_std_factor``, ``max_correction_*``).
    depth_m : (M,) depths of the local points: the inlier threshold grows as
        ``threshold_m · max(1, (depth / depth_ref_m)²)`` (stereo depth error ∝ depth²; our choice),
        and the final fit weights points by the inverse square of that scale.
    policy : ``"oldest"`` — RANSAC on all matches gives a consensus pose; the matches within
        ``loose_factor`` thresholds of it are candidates; the landmarks among them first seen
        longest ago (:func:`select_oldest`: at least ``n_oldest`` and ``oldest_fraction`` of the
        candidates — fewer, all from one edge of the view, leave yaw and sideways translation
        nearly ambiguous) — extended by the next-oldest until, with ``cov`` given, no pose parameter is
        more than ``max_std_factor`` times as uncertain as with all candidates (:func:`pose_std`;
        "sufficiently large for computing the position") — get a RANSAC of their own, whose pose wins when at least
        ``keep_fraction`` of them agree, it keeps ``still_fraction`` (80 %) of the candidates within the loose band and
        it differs from the consensus pose by at most ``max_correction_rad`` / ``max_correction_m``
        (None = unbounded; a bound of 5° / 0.3 m also blocks the loop-closing correction)
        (our reading of 000 §3.5: old landmarks correct the drift of the recent ones when a place
        is revisited);
        ``"all"`` — the pose is the least-squares fit on all RANSAC inliers.
    cov : (M, 3, 3) covariances of the local points (body frame), for the conditioning test of
        ``policy="oldest"``; None skips the test.
    rng : int or numpy.random.Generator, optional
        Seed or generator of the RANSAC samples.
    ransac_iters : RANSAC hypotheses (000: about 200), minimal samples of 3, early exit at 99.9 % confidence.
    min_inliers : inliers needed for a valid pose.

    Returns
    -------
    PoseEstimate
        ``T`` (4, 4) body-to-map, the inlier mask, ``converged``, ``n_used``, ``n_iters``.

    Raises
    ------
    ValueError if fewer than 3 matches are given.

    Examples
    --------
    >>> rng = np.random.default_rng(0); P = rng.uniform(-2, 2, (30, 3))
    >>> from slamlab.geometry import se3_from_planar
    >>> T = se3_from_planar(0.5, -0.2, 0.3)
    >>> est = estimate_pose(P, P @ T[:3, :3].T + T[:3, 3], rng=0)
    >>> bool(np.allclose(est.T, T)), int(est.inliers.sum())
    (True, 30)
    """
    p = StereoParams.resolve(params, **overrides)
    src = as_finite_array(local_points, "local_points", ndim=2)
    dst = as_finite_array(map_points, "map_points", ndim=2)
    if src.shape != dst.shape or src.shape[1:] != (3,):
        raise ValueError(f"`local_points` and `map_points` must both have shape (M, 3); got {src.shape} and {dst.shape}")
    m = src.shape[0]
    if m < 3:
        raise ValueError(f"`local_points` must hold at least 3 matches for a 3-D pose; got {m}")
    if cov is not None:
        cov = np.asarray(cov, dtype=float)
        if cov.shape != (m, 3, 3) or not np.all(np.isfinite(cov)):
            raise ValueError(f"`cov` must be a finite ({m}, 3, 3) array; got shape {cov.shape}")
    depth = np.linalg.norm(src, axis=1) if depth_m is None else as_vector(depth_m, "depth_m", m)
    first_seen = np.zeros(m, dtype=np.int64) if first_seen is None else np.asarray(first_seen)
    if first_seen.shape != (m,):
        raise ValueError(f"`first_seen` must have shape ({m},); got {first_seen.shape}")
    rng = as_rng(rng)
    threshold_m, min_inliers, max_iters = p.threshold_m, p.min_inliers, p.ransac_iters
    loose_factor, max_std_factor = p.loose_factor, p.max_std_factor
    scale = np.maximum(1.0, (depth / p.depth_ref_m) ** 2)
    w = 1.0 / scale**2

    r = ransac((src, dst, w), _fit, _residuals, 3, threshold_m, max_iters=max_iters, min_inliers=min_inliers, rng=rng)
    if not r.converged:
        return PoseEstimate(np.eye(4), np.zeros(m, dtype=bool), False, 0, r.n_iters)
    Tm = r.model
    used = np.flatnonzero(r.inliers)
    if p.policy == "oldest":
        # 000 §3.5: the pose from the landmarks first seen longest ago and at about the same time.
        # Candidates: matches within `loose_factor` thresholds of the consensus pose (true matches to
        # old landmarks that drifted apart from the recent map stay, random false matches go);
        # then RANSAC again on the oldest of them, kept if most of them agree.
        loose = np.flatnonzero(_residuals(Tm, src, dst, w) <= loose_factor * threshold_m)
        n_min = max(p.n_oldest, int(np.ceil(p.oldest_fraction * loose.size)))
        old = loose[select_oldest(first_seen[loose], n_min)]
        if cov is not None and max_std_factor is not None and old.size < loose.size:
            # grow the set by first-sighting time until it determines the pose nearly as well as all candidates
            # (cumulative information over the loose candidates sorted by first sighting)
            pts_map = dst[loose]
            info = _point_information(pts_map, Tm.R @ cov[loose] @ Tm.R.T, pts_map.mean(axis=0))
            order = np.argsort(first_seen[loose], kind="stable")
            fs = first_seen[loose][order]
            cum = np.cumsum(info[order], axis=0)
            ends = np.flatnonzero(np.r_[fs[1:] != fs[:-1], True])  # last candidate of each sighting time
            ends = ends[fs[ends] >= first_seen[old].max()]
            bound, cut = max_std_factor * _std_from_information(cum[-1]), len(order) - 1
            for e in np.array_split(ends, np.arange(16, ends.size, 16)):  # 16 at a time: the first good one is enough
                good = np.all(_std_from_information(cum[e]) <= bound, axis=1)
                if good.any():
                    cut = e[np.argmax(good)]
                    break
            old = loose[np.sort(order[: cut + 1])]
        if old.size >= 3:
            r_old = ransac((src[old], dst[old], w[old]), _fit, _residuals, 3, threshold_m, max_iters=max_iters, rng=rng)
            n_old = int(r_old.inliers.sum())
            if r_old.converged and n_old >= max(min(min_inliers, old.size), p.keep_fraction * old.size):
                # and it must still explain the candidates loosely: a wedge of old landmarks at one
                # edge of the view can otherwise trade yaw for sideways translation
                T_old = r_old.model
                still = _residuals(T_old, src[loose], dst[loose], w[loose]) <= loose_factor * threshold_m
                # the old landmarks may correct the consensus pose by a bounded amount only
                d_rot = rotation_angle(T_old.R @ Tm.R.T)
                d_pos = np.linalg.norm(T_old.t - Tm.t)
                bounded = (p.max_correction_rad is None or d_rot <= p.max_correction_rad) and (
                    p.max_correction_m is None or d_pos <= p.max_correction_m
                )
                if still.mean() >= p.still_fraction and bounded:
                    Tm, used = T_old, old[r_old.inliers]
    inl = _residuals(Tm, src, dst, w) <= threshold_m
    T = np.eye(4)
    T[:3, :3], T[:3, 3] = Tm.R, Tm.t
    return PoseEstimate(T, inl, bool(inl.sum() >= min_inliers), int(used.size), r.n_iters)


# --- pose refinement on the stereo reprojection error (our option; issue 25) -------------------------


def _refine_pose_stereo(T_cw, X_map, z_px, rig, iters, huber_px, min_depth_m):
    """Gauss-Newton on ``T_cw`` (map to left camera): the stereo pixels ``z_px`` (K, 4) of landmarks ``X_map``;
    left-multiplied twist updates ``T ← exp(δ) T``; Huber weights on each point's pixel residual norm."""
    T = T_cw.copy()
    for _ in range(iters):
        Xc = X_map @ T[:3, :3].T + T[:3, 3]
        ok = Xc[:, 2] > min_depth_m
        if ok.sum() < 3:
            break
        h, J3 = rig.stereo_pixels(Xc[ok], jacobian=True)
        r = z_px[ok] - h
        # d(Xc)/d(δ) for δ = (v, ω): [I, -[Xc]x]
        D = np.zeros((ok.sum(), 3, 6))
        D[:, :, :3] = np.eye(3)
        D[:, :, 3:] = hat(-Xc[ok])
        J = J3 @ D  # (K, 4, 6)
        norm = np.linalg.norm(r, axis=1)
        w = np.where(norm <= huber_px, 1.0, huber_px / np.maximum(norm, 1e-300))
        H = np.einsum("k,kai,kaj->ij", w, J, J)
        g = np.einsum("k,kai,ka->i", w, J, r)
        try:
            delta = np.linalg.solve(H, g)
        except np.linalg.LinAlgError:
            break
        T = se3_exp(delta) @ T
        if np.linalg.norm(delta) < 1e-10:
            break
    return T


def refine_pose_stereo(T_body, landmarks_map, points_left, rig: StereoRig, T_body_left=None, *, iters: int = 5,
                       huber_px: float = 2.0, min_depth_m: float = 0.1) -> np.ndarray:
    """Refine a body pose by minimising the stereo reprojection error of matched landmarks (our option; issue 25).

    Motion-only bundle adjustment as in ORB-SLAM2's tracking (Mur-Artal & Tardós 2017, its bundle adjustment with
    monocular and stereo constraints, where a stereo keypoint is ``(u_l, v_l, u_r)``): the landmarks stay fixed, the
    pose moves; each match's measurement here is the pair of pixels ``(u_l, v_l, u_r, v_r)`` of its stereo point (``points_left`` projected into both cameras: the keypoints it was triangulated
    from), with one pixel noise for all (a Huber loss of ``huber_px`` on each point's residual norm). Unlike the
    weighted 3-D fit of :func:`estimate_pose`, no weight depends on a noisy depth, and the error is modelled
    where it arises (along the ray the pixels say little, across it much). Gauss-Newton on SE(3) with updates
    ``T_cw ← exp(δ) T_cw`` (:func:`slamlab.geometry.se3_exp`), ``iters`` steps at most.

    Parameters
    ----------
    T_body : array_like, shape (4, 4)
        Starting body-to-map pose (the 3-D fit's).
    landmarks_map : array_like, shape (M, 3)
        Matched landmarks in the map frame [m], M ≥ 3.
    points_left : array_like, shape (M, 3)
        Their stereo points of this frame in the left-camera frame [m] (``z`` > 0).
    rig : StereoRig
        The calibrated pair.
    T_body_left : array_like, shape (4, 4), optional
        Left camera in the body frame (default identity).
    iters : int, default 5
        Most Gauss-Newton steps.
    huber_px : float, default 2.0
        Residual norm [px] beyond which a point's weight falls as ``huber_px / norm``.
    min_depth_m : float, default 0.1
        Landmarks nearer than this to the left camera (or behind it) are left out.

    Returns
    -------
    numpy.ndarray, shape (4, 4)
        The refined body-to-map pose.

    Examples
    --------
    >>> from slamlab.geometry import se3_from_planar
    >>> rig = StereoRig.parallel(baseline_m=0.5)
    >>> P = np.random.default_rng(0).uniform([-5, -2, 5], [5, 2, 30], (40, 3))  # left camera = body
    >>> T = se3_from_planar(0.3, -0.1, 0.05)
    >>> T_est = refine_pose_stereo(se3_from_planar(0.2, 0.0, 0.0), P @ T[:3, :3].T + T[:3, 3], P, rig)
    >>> bool(np.allclose(T_est, T, atol=1e-9))
    True
    """
    Tb = as_matrix(T_body, "T_body", (4, 4))
    X = as_finite_array(landmarks_map, "landmarks_map", ndim=2)
    Pl = as_finite_array(points_left, "points_left", ndim=2)
    if X.shape[1:] != (3,) or Pl.shape != X.shape:
        raise ValueError(f"`landmarks_map` and `points_left` must both have shape (M, 3); got {X.shape} and {Pl.shape}")
    if len(X) < 3:
        raise ValueError(f"`landmarks_map` must hold at least 3 matches; got {len(X)}")
    if np.any(Pl[:, 2] <= 0):
        raise ValueError("`points_left` must lie in front of the left camera (z > 0)")
    if not isinstance(rig, StereoRig):
        raise TypeError(f"`rig` must be a StereoRig; got {type(rig).__name__}")
    Tbl = np.eye(4) if T_body_left is None else as_matrix(T_body_left, "T_body_left", (4, 4))
    iters = check_int(iters, "iters", minimum=1)
    huber_px = check_positive(huber_px, "huber_px")
    min_depth_m = check_positive(min_depth_m, "min_depth_m")
    T_cw = _refine_pose_stereo(np.linalg.inv(Tb @ Tbl), X, rig.stereo_pixels(Pl), rig, iters, huber_px, min_depth_m)
    return np.linalg.inv(T_cw) @ np.linalg.inv(Tbl)
