"""The keypoint noise estimated online from the pose refinement's stereo reprojection residuals (ours; issue 25).

The stereo pipeline's noise model (``StereoParams.pixel_std``) sets every stereo point's covariance, hence the
landmark filter's weights and its innovation gate. When the images' keypoints are noisier than assumed, the gate
keeps landmarks from being updated. With ``pixel_std_estimate`` (:class:`~slamlab.stereo.StereoParams`), the
pipeline measures the noise from data it already has: after the pose refinement
(``pose_refine='reprojection'``), the residuals of the inliers' horizontal pixels ``u_l``, ``u_r`` (each a
keypoint coordinate, where the midpoint triangulation keeps it; ``v`` is the two images' mean) give one robust
standard deviation per frame, 1.4826 x the median absolute deviation (Hampel 1974; the normal distribution's
factor), smoothed over frames and never below ``pixel_std`` (the nominal noise is a floor: the data may raise
the model, not lower it). No knowledge of the scene is used.
"""

from __future__ import annotations

import numpy as np

from .. import _validate as v
from .params import StereoParams
from .pose_stages import _refine_body_pose, _stereo_project

__all__ = ["MAD_TO_STD", "robust_pixel_std", "stereo_residuals_px"]

#: 1 / Φ⁻¹(3/4): the median absolute deviation of a normal sample times this is its standard deviation
MAD_TO_STD = 1.4826
#: fewest residual pairs (matches) a frame needs to contribute an estimate
MIN_RESIDUALS = 20


def stereo_residuals_px(T_body, landmarks_map, points_left, rig, T_body_left=None) -> np.ndarray:
    """Stereo reprojection residuals ``(u_l, v_l, u_r, v_r)`` [px] of landmarks at a body pose (issue 25).

    Each row is the pixels of a stereo point of this frame (``points_left`` projected into both cameras: the
    keypoints it was triangulated from) minus the projection of its landmark seen from ``T_body``: what
    :func:`~slamlab.stereo.refine_pose_stereo` minimises.

    Parameters
    ----------
    T_body : array_like, shape (4, 4)
        Body-to-map pose.
    landmarks_map : array_like, shape (M, 3)
        Landmarks in the map frame [m].
    points_left : array_like, shape (M, 3)
        Their stereo points in the left-camera frame [m] (``z`` > 0).
    rig : StereoRig
        The calibrated pair.
    T_body_left : array_like, shape (4, 4), optional
        Left camera in the body frame (default identity).

    Returns
    -------
    numpy.ndarray, shape (M, 4)
        Residuals [px]; rows whose landmark lies behind the left camera are NaN.
    """
    Tb = v.as_matrix(T_body, "T_body", (4, 4))
    X = v.as_finite_array(landmarks_map, "landmarks_map", ndim=2)
    Pl = v.as_finite_array(points_left, "points_left", ndim=2)
    if X.shape[1:] != (3,) or Pl.shape != X.shape:
        raise ValueError(f"`landmarks_map` and `points_left` must both have shape (M, 3); got {X.shape} and {Pl.shape}")
    if np.any(Pl[:, 2] <= 0):
        raise ValueError("`points_left` must lie in front of the left camera (z > 0)")
    Tbl = np.eye(4) if T_body_left is None else v.as_matrix(T_body_left, "T_body_left", (4, 4))
    return _residuals(Tb, X, Pl, rig, Tbl)


def _residuals(T_body, X_map, pts_left, rig, T_body_left):
    T_cw = np.linalg.inv(T_body @ T_body_left)
    Xc = X_map @ T_cw[:3, :3].T + T_cw[:3, 3]
    r = np.full((len(X_map), 4), np.nan)
    ok = Xc[:, 2] > 0
    r[ok] = _stereo_project(rig, pts_left[ok])[0] - _stereo_project(rig, Xc[ok])[0]
    return r


def robust_pixel_std(residuals_px) -> float:
    """Robust standard deviation of pixel residuals: 1.4826 x their median absolute deviation from the median.

    Parameters
    ----------
    residuals_px : array_like
        Residuals [px], any shape; NaNs are left out.

    Returns
    -------
    float
        The estimate [px] (NaN when no finite residual is given).

    Examples
    --------
    >>> r = np.random.default_rng(0).normal(0.0, 0.8, 20000)
    >>> round(robust_pixel_std(r), 1)
    0.8
    """
    r = np.asarray(residuals_px, dtype=float).ravel()
    r = r[np.isfinite(r)]
    if r.size == 0:
        return float("nan")
    return float(MAD_TO_STD * np.median(np.abs(r - np.median(r))))


class _NoiseTracker:
    """The running keypoint-noise estimate of one :class:`~slamlab.stereo.StereoSLAM` (``pixel_std_estimate``).

    ``params`` is the user's settings with ``pixel_std`` replaced by the estimate; ``refine`` runs the pose
    refinement and feeds its residuals to the estimate. ``history`` holds each frame's raw estimate."""

    def __init__(self, params: StereoParams):
        self.nominal = params
        self.params = params
        self.sigma_px = params.pixel_std
        self.history: list[float] = []

    def refine(self, T_body, X_map, pts_left, rig, T_body_left):
        p = self.nominal
        T = _refine_body_pose(T_body, X_map, pts_left, rig, T_body_left, p.refine_iters, p.refine_huber_px,
                              p.min_depth_m)
        if p.pixel_std_estimate:
            self.observe(_residuals(T, X_map, pts_left, rig, T_body_left)[:, [0, 2]])
        return T

    def observe(self, residuals_px):
        """One frame's residuals of the inliers' ``u_l``, ``u_r`` [px]: update the smoothed estimate."""
        r = np.asarray(residuals_px, dtype=float)
        if np.isfinite(r).sum() < 2 * MIN_RESIDUALS:
            return
        s = robust_pixel_std(r)
        self.history.append(s)
        a = self.nominal.pixel_std_smoothing
        self.sigma_px = (1.0 - a) * self.sigma_px + a * s
        self.params = self.nominal.replace(pixel_std=max(self.nominal.pixel_std, self.sigma_px))
