"""The keypoint noise estimated online from the pose refinement's stereo reprojection residuals (ours; issue 25).

The stereo pipeline's noise model (``StereoParams.pixel_std``) sets every stereo point's covariance, hence the
landmark filter's weights and its innovation gate. When the keypoints are noisier than assumed, the gate keeps
landmarks from being updated. With ``pixel_std_estimate`` (:class:`~slamlab.stereo.StereoParams`), the pipeline
measures the noise from data it already has: after the pose refinement (``pose_refine='reprojection'``), each
inlier's **disparity residual** ``(u_l - u_r)`` of the frame's keypoints minus that of its landmark seen from the
refined pose. Its variance is ``2 σ² + q``: the two keypoints' noise ``σ`` and the landmark's own error ``q``
(its filter covariance projected on the disparity). The frame's estimate is the ``σ`` for which the residuals
normalised by that variance have the median of a χ²₁ variable, 0.4549 (a robust, median-based moment
condition, as 1.4826 x MAD is for a plain normal sample); it is smoothed over frames and never below ``pixel_std``
(the nominal noise is a floor: the data may raise the model, not lower it). The disparity is used, not the
single coordinates: a landmark's error in ``u_l``, ``u_r`` also holds its depth error seen from a moved camera and
the pose inflation of the filter (``pose_std_m``, ``pose_std_rad``), both of which the difference nearly cancels.
No knowledge of the scene is used.
"""

from __future__ import annotations

import numpy as np

from .._validate import as_finite_array, as_matrix
from ..geometry.camera import StereoRig
from .params import StereoParams

__all__ = ["CHI2_1_MEDIAN", "MAD_TO_STD", "KeypointNoiseTracker", "disparity_noise_px", "disparity_residuals_px",
           "robust_pixel_std", "stereo_residuals_px"]

#: 1 / Φ⁻¹(3/4): the median absolute deviation of a normal sample times this is its standard deviation
MAD_TO_STD = 1.4826
#: the median of a χ² variable with one degree of freedom, (Φ⁻¹(3/4))² = 1 / 1.4826²
CHI2_1_MEDIAN = 0.45493642311957283
#: fewest residuals (matches) a frame needs to contribute an estimate
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
    X, Pl, _, Xc = _landmarks_in_left_camera(T_body, landmarks_map, points_left, rig, T_body_left)
    r = np.full((len(X), 4), np.nan)
    ok = Xc[:, 2] > 0
    r[ok] = rig.stereo_pixels(Pl[ok]) - rig.stereo_pixels(Xc[ok])
    return r


def _landmarks_in_left_camera(T_body, landmarks_map, points_left, rig, T_body_left):
    """The checked landmarks ``X`` and points ``Pl``, the map-to-left-camera rotation ``R`` and the landmarks in the left
    camera ``Xc``: ``(X, Pl, R, Xc)``."""
    Tb = as_matrix(T_body, "T_body", (4, 4))
    X = as_finite_array(landmarks_map, "landmarks_map", ndim=2)
    Pl = as_finite_array(points_left, "points_left", ndim=2)
    if X.shape[1:] != (3,) or Pl.shape != X.shape:
        raise ValueError(f"`landmarks_map` and `points_left` must both have shape (M, 3); got {X.shape} and {Pl.shape}")
    if np.any(Pl[:, 2] <= 0):
        raise ValueError("`points_left` must lie in front of the left camera (z > 0)")
    if not isinstance(rig, StereoRig):
        raise TypeError(f"`rig` must be a StereoRig; got {type(rig).__name__}")
    Tbl = np.eye(4) if T_body_left is None else as_matrix(T_body_left, "T_body_left", (4, 4))
    T_cw = np.linalg.inv(Tb @ Tbl)
    R = T_cw[:3, :3]
    return X, Pl, R, X @ R.T + T_cw[:3, 3]


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


def disparity_noise_px(disparity_residuals_px, landmark_var_px2=None) -> float:
    """Keypoint noise ``σ`` [px] behind disparity residuals whose variance is ``2 σ² + q`` (ours; issue 25).

    ``σ`` solves ``median(r² / (2 σ² + q)) = 0.4549`` (the median of χ²₁): the residuals ``r`` of the disparity
    ``u_l - u_r`` of two keypoints with independent noise ``σ`` each, against a prediction whose own variance
    is ``q`` (a landmark's, from its covariance). With ``q = 0`` this is ``1.4826 x median|r| / √2``. The
    left side falls as ``σ`` grows, so bisection finds it; 0 when ``q`` alone explains the residuals.

    Parameters
    ----------
    disparity_residuals_px : array_like, shape (K,)
        Disparity residuals [px]; NaNs are left out.
    landmark_var_px2 : array_like, shape (K,), optional
        The predictions' variances ``q`` [px²] (default 0).

    Returns
    -------
    float
        ``σ`` [px] (NaN when no finite residual is given).

    Examples
    --------
    >>> g = np.random.default_rng(0)
    >>> r = g.normal(0.0, 0.8, 20000) - g.normal(0.0, 0.8, 20000) + g.normal(0.0, 0.5, 20000)
    >>> round(disparity_noise_px(r, np.full(20000, 0.25)), 1)
    0.8
    """
    r = np.asarray(disparity_residuals_px, dtype=float).ravel()
    q = np.zeros_like(r) if landmark_var_px2 is None else np.asarray(landmark_var_px2, dtype=float).ravel()
    if q.shape != r.shape:
        raise ValueError(f"`landmark_var_px2` must have the shape of `disparity_residuals_px`; got {q.shape} and {r.shape}")
    if np.any(q < 0):
        raise ValueError("`landmark_var_px2` must be non-negative")
    ok = np.isfinite(r) & np.isfinite(q)
    r2, q = r[ok] ** 2, q[ok]
    if r2.size == 0:
        return float("nan")

    def excess(sigma):  # median normalised square minus its target: falls as sigma grows
        return np.median(r2 / np.maximum(2.0 * sigma**2 + q, 1e-300)) - CHI2_1_MEDIAN

    if excess(0.0) <= 0.0:
        return 0.0
    lo, hi = 0.0, max(float(np.sqrt(np.median(r2) / (2 * CHI2_1_MEDIAN))), 1e-12)
    while excess(hi) > 0.0:
        hi *= 2.0
    for _ in range(60):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if excess(mid) > 0.0 else (lo, mid)
    return float(0.5 * (lo + hi))


class KeypointNoiseTracker:
    """The running keypoint-noise estimate of one :class:`~slamlab.stereo.StereoSLAM` (``pixel_std_estimate``; ours, issue 25).

    Each frame's disparity residuals (:func:`disparity_residuals_px`) give an estimate
    (:func:`disparity_noise_px`), smoothed into :attr:`sigma_px`; :meth:`current` is the settings with
    ``pixel_std`` raised to it.

    Parameters
    ----------
    params : StereoParams
        The pipeline's settings (``pixel_std``: the start and the floor of the estimate).

    Attributes
    ----------
    sigma_px : float
        The running estimate [px].
    history : list of float
        Each frame's raw estimate [px].
    """

    def __init__(self, params: StereoParams):
        if not isinstance(params, StereoParams):
            raise TypeError(f"`params` must be a StereoParams; got {type(params).__name__}")
        self.sigma_px = params.pixel_std
        self.history: list[float] = []
        self._cache: tuple = (None, None, None)

    def current(self, params: StereoParams) -> StereoParams:
        """``params`` with ``pixel_std`` raised to the estimate (``params`` itself when ``pixel_std_estimate`` is off).

        Parameters
        ----------
        params : StereoParams
            The nominal settings.

        Returns
        -------
        StereoParams
        """
        if not params.pixel_std_estimate:
            return params
        sigma = max(params.pixel_std, self.sigma_px)
        if self._cache[0] is not params or self._cache[1] != sigma:
            self._cache = (params, sigma, params.replace(pixel_std=sigma))
        return self._cache[2]

    def observe(self, disparity_residuals_px, landmark_var_px2=None, smoothing: float = 0.2) -> None:
        """Update the estimate with one frame's disparity residuals (frames with fewer than 20 are skipped).

        Parameters
        ----------
        disparity_residuals_px : array_like, shape (K,)
            Disparity residuals [px] (NaNs are left out).
        landmark_var_px2 : array_like, shape (K,), optional
            Their landmarks' predicted disparity variances [px²] (default 0).
        smoothing : float, default 0.2
            Weight of this frame's estimate in the running one (``pixel_std_smoothing``).
        """
        r = np.asarray(disparity_residuals_px, dtype=float)
        if np.isfinite(r).sum() < MIN_RESIDUALS:
            return
        s = disparity_noise_px(r, landmark_var_px2)
        self.history.append(s)
        self.sigma_px = (1.0 - smoothing) * self.sigma_px + smoothing * s


def disparity_residuals_px(T_body, landmarks_map, landmark_cov, points_left, rig: StereoRig, T_body_left=None):
    """Disparity residuals ``u_l - u_r`` [px] of stereo points against their landmarks, and the landmarks' variances (issue 25).

    Each residual is the disparity of a stereo point of this frame (``points_left``) minus that of its landmark
    seen from ``T_body``; beside it, the variance [px²] of the landmark's predicted disparity from its covariance
    (``J P Jᵀ``, ``J`` the disparity's derivative): the input of :func:`disparity_noise_px`.

    Parameters
    ----------
    T_body : array_like, shape (4, 4)
        Body-to-map pose.
    landmarks_map : array_like, shape (M, 3)
        Landmarks in the map frame [m].
    landmark_cov : array_like, shape (M, 3, 3)
        Their covariances [m²].
    points_left : array_like, shape (M, 3)
        Their stereo points in the left-camera frame [m] (``z`` > 0).
    rig : StereoRig
        The calibrated pair.
    T_body_left : array_like, shape (4, 4), optional
        Left camera in the body frame (default identity).

    Returns
    -------
    r : numpy.ndarray, shape (M,)
        Disparity residuals [px]; NaN where the landmark lies behind the left camera.
    q : numpy.ndarray, shape (M,)
        The landmarks' predicted disparity variances [px²] (NaN there too).

    Examples
    --------
    >>> rig = StereoRig.parallel(baseline_m=0.5)
    >>> X = np.array([[0.0, 0.0, 10.0]])
    >>> r, q = disparity_residuals_px(np.eye(4), X, np.zeros((1, 3, 3)), X, rig)
    >>> r.tolist(), q.tolist()
    ([0.0], [0.0])
    """
    X, Pl, R, Xc = _landmarks_in_left_camera(T_body, landmarks_map, points_left, rig, T_body_left)
    P = as_finite_array(landmark_cov, "landmark_cov", ndim=3)
    if P.shape != (len(X), 3, 3):
        raise ValueError(f"`landmark_cov` must have shape ({len(X)}, 3, 3); got {P.shape}")
    ok = Xc[:, 2] > 0
    r, q = np.full(len(X), np.nan), np.full(len(X), np.nan)
    h, J = rig.stereo_pixels(Xc[ok], jacobian=True)
    z = rig.stereo_pixels(Pl[ok])
    r[ok] = (z[:, 0] - z[:, 2]) - (h[:, 0] - h[:, 2])
    Jd = (J[:, 0] - J[:, 2]) @ R  # d(disparity) / d(X_map)
    q[ok] = np.einsum("ki,kij,kj->k", Jd, P[ok], Jd)
    return r, q
