"""Tracking steps of 003 §4.4: sparse direct alignment and motion-only refinement.

* :func:`sparse_align` - 003 §4.4.1 (SVO's sparse image alignment): the pose of the
  current frame relative to the previous one minimising the photometric residual of small
  patches (003: 4×4) around points of known depth, by inverse compositional Gauss-Newton
  (Baker & Matthews 2004) on SE(3), coarse to fine over an image pyramid.
* :func:`refine_pose` - 003 §4.4 step 4: the reprojection error of matched map points,
  minimised over the 6 pose parameters by ``scipy.optimize.least_squares`` (Huber loss).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .. import _validate as v

__all__ = [
    "AlignResult",
    "bilinear",
    "build_pyramid",
    "project",
    "refine_pose",
    "se3_exp",
    "sparse_align",
]


def _hat(w):
    return np.array([[0.0, -w[2], w[1]], [w[2], 0.0, -w[0]], [-w[1], w[0], 0.0]])


def se3_exp(xi) -> np.ndarray:
    """4×4 transform ``exp([v, ω]^)`` of a twist ``xi = (v, ω)`` (closed form).

    >>> np.allclose(se3_exp(np.zeros(6)), np.eye(4))
    True
    """
    xi = np.asarray(xi, dtype=np.float64)
    vv, w = xi[:3], xi[3:]
    th = float(np.linalg.norm(w))
    W = _hat(w)
    if th < 1e-10:
        R = np.eye(3) + W
        V = np.eye(3) + 0.5 * W
    else:
        A = np.sin(th) / th
        B = (1 - np.cos(th)) / th**2
        C = (1 - A) / th**2
        R = np.eye(3) + A * W + B * W @ W
        V = np.eye(3) + B * W + C * W @ W
    T = np.eye(4)
    T[:3, :3] = R
    T[:3, 3] = V @ vv
    return T


def build_pyramid(image, levels: int) -> list[np.ndarray]:
    """Float32 image pyramid, level ``l`` halved ``l`` times (``cv2.pyrDown``)."""
    import cv2

    img = v.as_image(image, "image").astype(np.float32)
    pyr = [img]
    for _ in range(levels):
        if min(pyr[-1].shape) < 16:
            break
        pyr.append(cv2.pyrDown(pyr[-1]))
    return pyr


def bilinear(img, u, v_):
    """Bilinear samples of ``img`` at ``(u, v)`` (any shapes, clamped to the border)."""
    h, w = img.shape
    u = np.clip(u, 0.0, w - 1.001)
    v_ = np.clip(v_, 0.0, h - 1.001)
    u0 = np.floor(u).astype(np.intp)
    v0 = np.floor(v_).astype(np.intp)
    du = u - u0
    dv = v_ - v0
    a = img[v0, u0]
    b = img[v0, u0 + 1]
    c = img[v0 + 1, u0]
    d = img[v0 + 1, u0 + 1]
    return (a * (1 - du) + b * du) * (1 - dv) + (c * (1 - du) + d * du) * dv


def project(K, X):
    """Pixels ``(N, 2)`` of camera-frame points ``(N, 3)`` (no checks: hot path)."""
    z = X[:, 2]
    return np.column_stack([K[0, 0] * X[:, 0] / z + K[0, 2], K[1, 1] * X[:, 1] / z + K[1, 2]])


def _d_proj(K, X, scale):
    """∂π/∂ξ (N, 2, 6) at camera points X for a left perturbation ``exp(ξ) X`` (ξ = v, ω)."""
    x, y, z = X[:, 0], X[:, 1], X[:, 2]
    fx, fy = K[0, 0] * scale, K[1, 1] * scale
    zi = 1.0 / z
    zi2 = zi * zi
    J = np.zeros((X.shape[0], 2, 6))
    J[:, 0, 0] = fx * zi
    J[:, 0, 2] = -fx * x * zi2
    J[:, 0, 3] = -fx * x * y * zi2
    J[:, 0, 4] = fx * (1 + x * x * zi2)
    J[:, 0, 5] = -fx * y * zi
    J[:, 1, 1] = fy * zi
    J[:, 1, 2] = -fy * y * zi2
    J[:, 1, 3] = -fy * (1 + y * y * zi2)
    J[:, 1, 4] = fy * x * y * zi2
    J[:, 1, 5] = fy * x * zi
    return J


@dataclass(frozen=True)
class AlignResult:
    """``T_cur_ref`` 4×4, ``ok`` converged with enough points, ``n_points``, ``rms`` final photometric residual."""

    T_cur_ref: np.ndarray
    ok: bool
    n_points: int
    rms: float
    iterations: int


def sparse_align(pyr_ref, pyr_cur, K, X_ref, T_init, *, patch_px: int = 4, max_level: int = 3,
                 min_level: int = 1, max_iter: int = 30, eps: float = 1e-6, min_points: int = 10) -> AlignResult:
    """Inverse compositional Gauss-Newton on SE(3) over patches (003 §4.4.1; SVO).

    Residual per patch pixel ``r = I_cur(π(T X) + o) − I_ref(π(X) + o)``; the Jacobian is
    taken on the reference image once per level: ``J = ∇I_ref · ∂π/∂ξ``; step
    ``δ = (JᵀJ)⁻¹ Jᵀ r`` and update ``T ← T · exp(δ)⁻¹``. A step that raises the error is
    undone and the level ends (as SVO). ``X_ref`` (N, 3) points in the reference camera frame.
    """
    K = np.asarray(K, dtype=np.float64)
    X_ref = np.asarray(X_ref, dtype=np.float64).reshape(-1, 3)
    T = np.array(T_init, dtype=np.float64)
    half = patch_px // 2
    o = np.arange(patch_px) - half
    ou, ov = np.meshgrid(o, o)
    ou, ov = ou.ravel().astype(np.float64), ov.ravel().astype(np.float64)
    front = np.all(np.isfinite(X_ref), axis=1) & (X_ref[:, 2] > 1e-6)
    X_ref = X_ref[front]
    n_it = 0
    rms = np.inf
    if X_ref.shape[0] < min_points:
        return AlignResult(T, False, int(X_ref.shape[0]), float("inf"), 0)
    top = min(max_level, len(pyr_ref) - 1, len(pyr_cur) - 1)
    for level in range(top, min(min_level, top) - 1, -1):
        s = 0.5**level
        Iref, Icur = pyr_ref[level], pyr_cur[level]
        h, w = Iref.shape
        uv = project(K, X_ref) * s  # cv2.pyrDown keeps pixel 2u of level l at u of level l + 1
        inside = (uv[:, 0] >= half + 1) & (uv[:, 0] < w - half - 2) & (uv[:, 1] >= half + 1) & (uv[:, 1] < h - half - 2)
        if inside.sum() < min_points:
            continue
        Xl, uvl = X_ref[inside], uv[inside]
        pu = uvl[:, 0:1] + ou  # (M, P)
        pv = uvl[:, 1:2] + ov
        ref_patch = bilinear(Iref, pu, pv)
        gx = 0.5 * (bilinear(Iref, pu + 1, pv) - bilinear(Iref, pu - 1, pv))
        gy = 0.5 * (bilinear(Iref, pu, pv + 1) - bilinear(Iref, pu, pv - 1))
        Jp = _d_proj(K, Xl, s)  # (M, 2, 6)
        J = gx[..., None] * Jp[:, None, 0, :] + gy[..., None] * Jp[:, None, 1, :]  # (M, P, 6)
        J = J.reshape(-1, 6)
        H = J.T @ J + 1e-9 * np.eye(6)
        chi_prev = np.inf
        T_prev = T
        for _ in range(max_iter):
            n_it += 1
            Xc = Xl @ T[:3, :3].T + T[:3, 3]
            ok_z = Xc[:, 2] > 1e-6
            uvc = project(K, np.where(ok_z[:, None], Xc, 1.0)) * s
            vis = ok_z & (uvc[:, 0] >= half + 1) & (uvc[:, 0] < w - half - 2) & (uvc[:, 1] >= half + 1) & (uvc[:, 1] < h - half - 2)
            if vis.sum() < min_points:
                break
            cur = bilinear(Icur, uvc[:, 0:1] + ou, uvc[:, 1:2] + ov)
            r = cur - ref_patch
            r[~vis] = 0.0
            Jm = J.reshape(r.shape[0], -1, 6) * vis[:, None, None]
            chi = float(np.sum(r * r) / max(vis.sum() * r.shape[1], 1))
            if chi > chi_prev:  # undo the last step
                T = T_prev
                break
            rms = np.sqrt(chi)
            g = Jm.reshape(-1, 6).T @ r.ravel()
            Hm = Jm.reshape(-1, 6).T @ Jm.reshape(-1, 6) + 1e-9 * np.eye(6) if not vis.all() else H
            delta = np.linalg.solve(Hm, g)
            if not np.all(np.isfinite(delta)):
                break
            T_prev = T
            T = T @ np.linalg.inv(se3_exp(delta))
            chi_prev = chi
            if np.linalg.norm(delta) < eps:
                break
    ok = bool(np.isfinite(rms)) and np.all(np.isfinite(T))
    if not np.all(np.isfinite(T)):
        T = np.array(T_init, dtype=np.float64)
    return AlignResult(T, ok, int(X_ref.shape[0]), float(rms), n_it)


def refine_pose(K, X_world, uv, T_cam_world_init, *, huber_px: float = 1.0, reject_px: float | None = 3.0,
                max_nfev: int = 50):
    """Motion-only refinement: ``min Σ ρ(|π(T X) − uv|²)`` over the pose (003 §4.4, step 4).

    ``scipy.optimize.least_squares`` with a Huber loss of scale ``huber_px``, twist
    parametrisation ``T = exp(ξ) T_init``; then (ours) once more on the points whose error is
    below ``reject_px`` (the Huber loss still leans on gross outliers). Returns
    ``(T_cam_world, residual_px (N,), ok)`` with the residuals of every point.
    """
    from scipy.optimize import least_squares

    K = np.asarray(K, dtype=np.float64)
    X = np.asarray(X_world, dtype=np.float64).reshape(-1, 3)
    uv = np.asarray(uv, dtype=np.float64).reshape(-1, 2)
    T0 = np.asarray(T_cam_world_init, dtype=np.float64)
    if X.shape[0] < 3:
        return T0, np.full(X.shape[0], np.inf), False
    Xc0 = X @ T0[:3, :3].T + T0[:3, 3]

    def resid(xi):
        Tx = se3_exp(xi)
        Xc = Xc0 @ Tx[:3, :3].T + Tx[:3, 3]
        z = np.maximum(Xc[:, 2], 1e-6)
        return np.concatenate([(K[0, 0] * Xc[:, 0] / z + K[0, 2]) - uv[:, 0], (K[1, 1] * Xc[:, 1] / z + K[1, 2]) - uv[:, 1]])

    sol = least_squares(resid, np.zeros(6), jac="2-point", loss="huber", f_scale=huber_px, max_nfev=max_nfev,
                        method="trf", x_scale="jac")
    r = sol.fun.reshape(2, -1)
    err = np.hypot(r[0], r[1])
    ok = sol.status > 0
    if ok and reject_px is not None:
        keep = err < reject_px
        if 6 <= keep.sum() < err.size:
            sub = np.concatenate([keep, keep])
            sol = least_squares(lambda xi: resid(xi)[sub], sol.x, jac="2-point", loss="huber", f_scale=huber_px,
                                max_nfev=max_nfev, method="trf", x_scale="jac")
            r = resid(sol.x).reshape(2, -1)
            err = np.hypot(r[0], r[1])
            ok = sol.status > 0
    T = se3_exp(sol.x) @ T0
    ok = ok and bool(np.all(np.isfinite(T)))
    if not ok:
        return T0, np.full(X.shape[0], np.inf), False
    return T, err, ok
