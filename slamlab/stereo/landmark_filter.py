"""Stereo SLAM stage 5: the landmarks' static Kalman filter (000 §3.6) and our options on it (issue 25): the
observation covariance, the gated update in the map frame or in the stereo pixels, the landmarks in view.

The maths of :class:`slamlab.stereo.StereoSLAM`'s map update, as functions on arrays (the class keeps the state).
They run on every frame and check only what the loop does not (shapes of their own making): give them
finite arrays of the documented shapes.
"""

from __future__ import annotations

import numpy as np

from ..filters.landmark import landmark_predict, landmark_update
from ..geometry.camera import PinholeCamera, StereoRig
from .local_stages import stereo_point_cov
from .params import StereoParams

__all__ = ["duplicate_mask", "gated_update", "in_view", "landmark_observations", "pixel_update"]


def landmark_observations(points_body, cov_body, T_body, T_body_left, rig: StereoRig, *, true_cam=None,
                          landmarks_map=None, params: StereoParams | None = None, **overrides):
    """Map-frame observations of landmarks by this frame's stereo points, with their covariances (000 §3.6; issue 25).

    ``Z = R p + t`` for the points ``p`` at body pose ``T_body``; the pose's own uncertainty adds
    ``pose_var = pose_std_m² + (pose_std_rad |p|)²`` per axis. The covariance's depth comes from
    ``update_cov_depth``: 'measured' the points' own covariances ``cov_body``; 'map' the stereo covariance at the
    landmark (``landmarks_map``) seen from the pose, not at the measured point, so that a measurement's weight
    does not depend on its own error; 'true' at the point's true left-camera position ``true_cam`` (an ablation
    oracle).

    Parameters
    ----------
    points_body : numpy.ndarray, shape (K, 3)
        The frame's stereo points in the body frame [m].
    cov_body : numpy.ndarray, shape (K, 3, 3)
        Their covariances [m²].
    T_body : numpy.ndarray, shape (4, 4)
        Body pose in the map.
    T_body_left : numpy.ndarray, shape (4, 4)
        Left camera in the body frame.
    rig : StereoRig
        The calibrated pair (focal length and baseline of the stereo covariance).
    true_cam : numpy.ndarray, shape (K, 3), optional
        True left-camera positions of the points (``update_cov_depth='true'`` only).
    landmarks_map : numpy.ndarray, shape (K, 3), optional
        The matched landmarks in the map frame (``update_cov_depth='map'`` only).
    params : StereoParams, optional
        Pipeline settings (``update_cov_depth``, ``pose_std_m``, ``pose_std_rad``, ``pixel_std``, ``min_depth_m``).
    **overrides
        :class:`StereoParams` fields to change.

    Returns
    -------
    Z : numpy.ndarray, shape (K, 3)
        Observations in the map frame [m].
    pose_var : numpy.ndarray, shape (K,)
        The pose's variance per point and axis [m²].
    Rz : numpy.ndarray, shape (K, 3, 3)
        Their covariances [m²], ``pose_var`` included.

    Examples
    --------
    >>> Z, pose_var, Rz = landmark_observations(np.array([[0.0, 0.0, 2.0]]), np.eye(3)[None] * 1e-4, np.eye(4),
    ...                                         np.eye(4), StereoRig.parallel(), pose_std_m=0.0, pose_std_rad=0.0)
    >>> Z.tolist(), pose_var.tolist(), float(Rz[0, 0, 0])
    ([[0.0, 0.0, 2.0]], [0.0], 0.0001)
    """
    p = StereoParams.resolve(params, **overrides)
    R, t = T_body[:3, :3], T_body[:3, 3]
    Z = points_body @ R.T + t
    pose_var = p.pose_std_m**2 + (p.pose_std_rad * np.linalg.norm(points_body, axis=1)) ** 2
    if p.update_cov_depth == "true":  # the ablation oracle: the covariance at the point's true position
        if true_cam is None:
            raise ValueError("`true_cam` is needed with update_cov_depth='true'")
        Rwc = (T_body @ T_body_left)[:3, :3]
        Rz = Rwc @ stereo_point_cov(true_cam, rig.left.fx, rig.baseline_m, p.pixel_std) @ Rwc.T
        Rz += pose_var[:, None, None] * np.eye(3)
    elif p.update_cov_depth == "map":
        # the observation's covariance at the landmark's position seen from the new pose, not at the
        # measured one: a measurement's weight then does not depend on its own error (issue 25)
        if landmarks_map is None:
            raise ValueError("`landmarks_map` is needed with update_cov_depth='map'")
        T_wc = T_body @ T_body_left
        Xc = (landmarks_map - T_wc[:3, 3]) @ T_wc[:3, :3]
        Xc[:, 2] = np.maximum(Xc[:, 2], p.min_depth_m)
        Rwc = T_wc[:3, :3]
        Rz = Rwc @ stereo_point_cov(Xc, rig.left.fx, rig.baseline_m, p.pixel_std) @ Rwc.T
        Rz += pose_var[:, None, None] * np.eye(3)
    else:
        Rz = R @ cov_body @ R.T + pose_var[:, None, None] * np.eye(3)
    return Z, pose_var, Rz


def duplicate_mask(points_body, nearest, landmarks_map, T_body, gap_m: float) -> np.ndarray:
    """Mask of the points whose nearest landmark by descriptor lies within ``gap_m`` of them (ours, ``duplicate_gap_m``).

    Such a point is that landmark seen again (its match was missed), not a new landmark.

    Parameters
    ----------
    points_body : numpy.ndarray, shape (K, 3)
        Unmatched points of the frame in the body frame [m].
    nearest : numpy.ndarray of int, shape (K,)
        Each point's nearest landmark id by descriptor (-1: none).
    landmarks_map : numpy.ndarray, shape (n, 3)
        Landmark positions by id in the map frame [m].
    T_body : numpy.ndarray, shape (4, 4)
        Body pose in the map.
    gap_m : float
        Largest distance of a duplicate [m].

    Returns
    -------
    numpy.ndarray of bool, shape (K,)

    Examples
    --------
    >>> duplicate_mask(np.array([[0.0, 0, 1], [5.0, 0, 1]]), np.array([0, -1]), np.array([[0.01, 0, 1]]),
    ...                np.eye(4), 0.05).tolist()
    [True, False]
    """
    R, t = T_body[:3, :3], T_body[:3, 3]
    has = nearest >= 0
    gap = np.full(len(nearest), np.inf)
    gap[has] = np.linalg.norm(points_body[has] @ R.T + t - landmarks_map[nearest[has]], axis=1)
    return gap <= gap_m


def gated_update(X, P, Z, Rz, state_var: float, gate: float | None):
    """The static-landmark Kalman update of 000 §3.6, with an innovation gate (ours, ``update_gate``).

    Each landmark ``X`` (covariance ``P``) is predicted with process variance ``state_var`` and updated by its
    map-frame observation ``Z`` (covariance ``Rz``); observations whose innovation's Mahalanobis² exceeds
    ``gate`` are left out (their landmark unchanged).

    Parameters
    ----------
    X : numpy.ndarray, shape (M, 3)
        Landmark positions [m].
    P : numpy.ndarray, shape (M, 3, 3)
        Their covariances [m²].
    Z : numpy.ndarray, shape (M, 3)
        Observations [m].
    Rz : numpy.ndarray, shape (M, 3, 3)
        Their covariances [m²].
    state_var : float
        Process variance per axis [m²].
    gate : float or None
        Largest Mahalanobis² of an innovation (None: no gate).

    Returns
    -------
    ok : numpy.ndarray of bool, shape (M,)
        The updated landmarks.
    X_new : numpy.ndarray, shape (M_ok, 3)
        Their new positions.
    P_new : numpy.ndarray, shape (M_ok, 3, 3)
        Their new covariances.

    Examples
    --------
    >>> ok, X_new, P_new = gated_update(np.zeros((1, 3)), np.eye(3)[None], np.ones((1, 3)), np.eye(3)[None], 0.0, None)
    >>> ok.tolist(), X_new.tolist()
    ([True], [[0.5, 0.5, 0.5]])
    """
    P_pred = landmark_predict(P, state_var)
    ok = np.ones(len(X), dtype=bool)
    if gate is not None and len(X):
        innov = Z - X
        ok = np.einsum("ni,ni->n", innov, np.linalg.solve(P_pred + Rz, innov[:, :, None])[:, :, 0]) <= gate
    X_new, P_new = landmark_update(X[ok], P_pred[ok], Z[ok], Rz[ok])
    return ok, X_new, P_new


def pixel_update(X, P, points_left, T_wc, pose_var, rig: StereoRig, state_var: float, pixel_std: float,
                 min_depth_m: float, gate: float | None):
    """The static-landmark Kalman update of 000 §3.6 in the stereo pixels ``(u_l, v_l, u_r)`` (ours, issue 25).

    ``filter_space='pixels'``: every observation has the same noise ``pixel_std`` there (plus the pose's,
    ``pose_var`` m² per point); the landmark's mean ``X`` (map frame) is projected exactly into the left camera
    at ``T_wc``, its covariance ``P`` through the projection's Jacobian, and the fused pixels are triangulated
    back. Weights then do not depend on a noisy depth and the disparities are averaged (unbiased for Gaussian
    pixel noise, where depths are not). Rectified rigs only.

    Parameters
    ----------
    X : numpy.ndarray, shape (M, 3)
        Landmark positions in the map frame [m].
    P : numpy.ndarray, shape (M, 3, 3)
        Their covariances [m²].
    points_left : numpy.ndarray, shape (M, 3)
        This frame's stereo points of those landmarks in the left camera frame [m].
    T_wc : numpy.ndarray, shape (4, 4)
        Left camera in the map.
    pose_var : numpy.ndarray, shape (M,)
        The pose's variance per point and axis [m²].
    rig : StereoRig
        The rectified pair.
    state_var : float
        Process variance per axis [m²].
    pixel_std : float
        Keypoint noise [px].
    min_depth_m : float
        Landmarks nearer than this to the camera (or behind it) are not updated [m].
    gate : float or None
        Largest Mahalanobis² of an innovation (None: no gate).

    Returns
    -------
    ok : numpy.ndarray of bool, shape (M,)
        The updated landmarks.
    X_new : numpy.ndarray, shape (M_ok, 3)
        Their new positions in the map frame.
    P_new : numpy.ndarray, shape (M_ok, 3, 3)
        Their new covariances.
    """
    cam = rig.left
    R, t = T_wc[:3, :3], T_wc[:3, 3]
    P_pred = landmark_predict(P, state_var)
    Xc = (X - t) @ R
    ok = Xc[:, 2] > min_depth_m
    h, J = rig.stereo_pixels(np.where(ok[:, None], Xc, [0.0, 0.0, 1.0]), jacobian=True)
    h, J = h[:, :3], J[:, :3]
    z = rig.stereo_pixels(points_left)[:, :3]
    C_lm = J @ (R.T @ P_pred @ R) @ np.swapaxes(J, 1, 2)
    C_z = pixel_std**2 * np.eye(3) + pose_var[:, None, None] * (J @ np.swapaxes(J, 1, 2))
    if gate is not None and len(X):
        innov = z - h
        ok &= np.einsum("ni,ni->n", innov, np.linalg.solve(C_lm + C_z, innov[:, :, None])[:, :, 0]) <= gate
    m, C = landmark_update(h[ok], C_lm[ok], z[ok], C_z[ok])
    disp = (m[:, 0] - cam.cx) - (m[:, 2] - rig.right.cx)
    good = disp > 0
    ok[np.flatnonzero(ok)[~good]] = False
    m, C = m[good], C[good]
    zc = cam.fx * rig.baseline_m / disp[good]
    Xn = np.column_stack([(m[:, 0] - cam.cx) * zc / cam.fx, (m[:, 1] - cam.cy) * zc / cam.fy, zc])
    Ji = np.linalg.inv(rig.stereo_pixels(Xn, jacobian=True)[1][:, :3])
    return ok, Xn @ R.T + t, R @ (Ji @ C @ np.swapaxes(Ji, 1, 2)) @ R.T


def in_view(X, T_wc, camera: PinholeCamera, margin_deg: float, max_range_m: float) -> np.ndarray:
    """Mask of the points in front of a camera, within its horizontal field of view and range (ours, ``view_margin_deg``).

    Parameters
    ----------
    X : numpy.ndarray, shape (N, 3)
        Points in the map frame [m].
    T_wc : numpy.ndarray, shape (4, 4)
        The camera in the map.
    camera : PinholeCamera
        Its intrinsics (the horizontal field of view from ``cx``, ``width_px`` and ``fx``).
    margin_deg : float
        Widening of the field of view per side [deg].
    max_range_m : float
        Largest distance from the camera [m].

    Returns
    -------
    numpy.ndarray of bool, shape (N,)

    Examples
    --------
    >>> cam = PinholeCamera(100, 80, 50.0, 50.0, 50.0, 40.0)  # 90 deg wide
    >>> in_view(np.array([[0.0, 0, 5], [6.0, 0, 5], [0.0, 0, -5], [0.0, 0, 50]]), np.eye(4), cam, 0.0, 20.0).tolist()
    [True, False, False, False]
    """
    Xc = (X - T_wc[:3, 3]) @ T_wc[:3, :3]
    half = np.arctan2(max(camera.cx, camera.width_px - camera.cx), camera.fx) + np.deg2rad(margin_deg)
    z = Xc[:, 2]
    keep = (z > 0) & (np.abs(np.arctan2(Xc[:, 0], z)) <= half)
    keep &= np.einsum("ij,ij->i", Xc, Xc) <= max_range_m**2
    return keep
