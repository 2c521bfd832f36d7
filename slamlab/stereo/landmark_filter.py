"""Stereo SLAM stage 5: the landmarks' static Kalman filter (000 §3.6) and our options on it (issue 25): the
observation covariance, the gated update in the map frame or in the stereo pixels, the landmarks in view.

The maths of :class:`slamlab.stereo.StereoSLAM`'s map update, as functions on arrays (the class keeps the state).
"""

from __future__ import annotations

import numpy as np

from ..filters.landmark import landmark_predict, landmark_update
from .local_stages import stereo_point_cov
from .pose_stages import _stereo_project

__all__: list[str] = []


def _observations(pts_body, cov_body, T_body, T_body_left, rig, p, true_cam=None, X_map=None):
    """The map-frame observations ``Z`` of landmarks ``X_map`` by this frame's points ``pts_body`` (covariances
    ``cov_body``, body frame) at body pose ``T_body``: ``(Z, pose_var, Rz)``, ``pose_var`` the pose's variance per
    point [m²] (``params.pose_std_m``, ``pose_std_rad``), ``Rz`` the ``(K, 3, 3)`` covariances
    (``params.update_cov_depth``): 'measured' the points' own, 'map' the stereo covariance at the landmark seen
    from the pose, 'true' at the point's true left-camera position ``true_cam`` (the ablation oracle); each plus
    ``pose_var`` per axis."""
    R, t = T_body[:3, :3], T_body[:3, 3]
    Z = pts_body @ R.T + t
    pose_var = p.pose_std_m**2 + (p.pose_std_rad * np.linalg.norm(pts_body, axis=1)) ** 2
    depth_source, pixel_std, min_depth_m = p.update_cov_depth, p.pixel_std, p.min_depth_m
    if depth_source == "true":  # the ablation oracle: the covariance at the point's true position
        Rwc = (T_body @ T_body_left)[:3, :3]
        Rz = Rwc @ stereo_point_cov(true_cam, rig.left.fx, rig.baseline_m, pixel_std) @ Rwc.T
        Rz += pose_var[:, None, None] * np.eye(3)
    elif depth_source == "map":
        # the observation's covariance at the landmark's position seen from the new pose, not at the
        # measured one: a measurement's weight then does not depend on its own error (issue 25)
        T_wc = T_body @ T_body_left
        Xc = (X_map - T_wc[:3, 3]) @ T_wc[:3, :3]
        Xc[:, 2] = np.maximum(Xc[:, 2], min_depth_m)
        Rwc = T_wc[:3, :3]
        Rz = Rwc @ stereo_point_cov(Xc, rig.left.fx, rig.baseline_m, pixel_std) @ Rwc.T
        Rz += pose_var[:, None, None] * np.eye(3)
    else:
        Rz = R @ cov_body @ R.T + pose_var[:, None, None] * np.eye(3)
    return Z, pose_var, Rz


def _duplicates(pts_body, nearest, X, T_body, gap_m):
    """Mask of the body-frame points ``pts_body`` whose nearest landmark by descriptor (``nearest``, -1: none)
    lies within ``gap_m`` of them in the map at body pose ``T_body``: that landmark again (``duplicate_gap_m``)."""
    R, t = T_body[:3, :3], T_body[:3, 3]
    has = nearest >= 0
    gap = np.full(len(nearest), np.inf)
    gap[has] = np.linalg.norm(pts_body[has] @ R.T + t - X[nearest[has]], axis=1)
    return gap <= gap_m


def _gated_update(X, P, Z, Rz, state_var, gate):
    """The static-landmark Kalman update of landmarks ``X`` (covariances ``P``) by map-frame observations ``Z``
    (``Rz``) (000 §3.6), observations whose innovation's Mahalanobis² exceeds ``gate`` (None: none) left out.
    ``(ok, X_new, P_new)``: the mask of the updated landmarks and their new means and covariances."""
    P_pred = landmark_predict(P, state_var)
    ok = np.ones(len(X), dtype=bool)
    if gate is not None and len(X):
        innov = Z - X
        ok = np.einsum("ni,ni->n", innov, np.linalg.solve(P_pred + Rz, innov[:, :, None])[:, :, 0]) <= gate
    X_new, P_new = landmark_update(X[ok], P_pred[ok], Z[ok], Rz[ok])
    return ok, X_new, P_new


def _pixel_update(X, P, pts_left, T_wc, pose_var, rig, state_var, pixel_std, min_depth_m, gate):
    """``filter_space='pixels'`` (our option; issue 25): the static-landmark Kalman update of 000 §3.6 in the
    stereo pixels ``(u_l, v_l, u_r)`` of the left camera at ``T_wc``, where every observation has the same
    noise ``pixel_std`` (plus the pose's, ``pose_var`` m² per point): the landmark's mean (``X``, map frame) is
    projected there exactly, its covariance ``P`` through the projection's Jacobian, the fused pixels are
    triangulated back. Weights then do not depend on a noisy depth and the disparities are averaged (unbiased
    for Gaussian pixel noise, where depths are not). Rectified rigs only. ``pts_left``: this frame's points in
    the left camera. ``(ok, X_new, P_new)`` as :func:`_gated_update` (innovation gate ``gate``)."""
    cam = rig.left
    R, t = T_wc[:3, :3], T_wc[:3, 3]
    P_pred = landmark_predict(P, state_var)
    Xc = (X - t) @ R
    ok = Xc[:, 2] > min_depth_m
    h, J = _stereo_project(rig, np.where(ok[:, None], Xc, [0.0, 0.0, 1.0]))
    h, J = h[:, :3], J[:, :3]
    z = _stereo_project(rig, pts_left)[0][:, :3]
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
    Ji = np.linalg.inv(_stereo_project(rig, Xn)[1][:, :3])
    return ok, Xn @ R.T + t, R @ (Ji @ C @ np.swapaxes(Ji, 1, 2)) @ R.T


def _in_view(X, T_wc, cam, margin_deg, max_range_m):
    """Mask of the points ``X`` (map frame) in front of ``cam`` at ``T_wc``, within its horizontal field of view
    widened by ``margin_deg`` per side and at most ``max_range_m`` away."""
    Xc = (X - T_wc[:3, 3]) @ T_wc[:3, :3]
    half = np.arctan2(max(cam.cx, cam.width_px - cam.cx), cam.fx) + np.deg2rad(margin_deg)
    z = Xc[:, 2]
    keep = (z > 0) & (np.abs(np.arctan2(Xc[:, 0], z)) <= half)
    keep &= np.einsum("ij,ij->i", Xc, Xc) <= max_range_m**2
    return keep
