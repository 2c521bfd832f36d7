"""Tracking steps of 003 §4.4: sparse direct alignment and motion-only refinement.

* :func:`sparse_align` - 003 §4.4.1 (SVO's sparse image alignment): the pose of the
  current frame relative to the previous one minimising the photometric residual of small
  patches (003: 4×4) around points of known depth, by inverse compositional Gauss-Newton
  (Baker & Matthews 2004) on SE(3), coarse to fine over an image pyramid.
* :func:`refine_pose` - 003 §4.4 step 4: the reprojection error of matched map points,
  minimised over the 6 pose parameters by Levenberg-Marquardt with Huber weights.

Every product, norm and solve here is written without BLAS/LAPACK (``np.einsum``, element-wise
sums, a 6×6 Cholesky in Python floats): a tracker turns a last-bit difference into a different
inlier set a few frames later, and BLAS rounds differently by kernel, machine and thread count,
so with BLAS the same notebook printed different results on different machines (our choice).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .._validate import as_image
from ..geometry.camera import project_points as project
from ..geometry.se3 import se3_compose, se3_inverse, transform_points
from ..geometry.so3 import se3_exp

__all__ = [
    "AlignResult",
    "bilinear",
    "build_pyramid",
    "project",
    "refine_pose",
    "se3_exp",
    "solve_spd",
    "sparse_align",
]


def solve_spd(H, g) -> np.ndarray:
    """``H⁻¹ g`` for a small symmetric positive definite ``H`` by Cholesky in Python floats (ours).

    The same bits on every machine (LAPACK's solvers call BLAS kernels that round by CPU).
    Returns NaNs when ``H`` is not positive definite.

    Parameters
    ----------
    H : array_like, shape (n, n)
        Symmetric positive definite matrix (``n`` small: the Gauss-Newton 6×6).
    g : array_like, shape (n,)
        Right-hand side.

    Returns
    -------
    x : ndarray, shape (n,)
        The solution of ``H x = g`` (NaNs when ``H`` is not positive definite).

    Examples
    --------
    >>> solve_spd(np.array([[4.0, 2.0], [2.0, 3.0]]), np.array([2.0, 1.0])).tolist()
    [0.5, 0.0]
    """
    A = np.asarray(H, dtype=np.float64).tolist()
    b = np.asarray(g, dtype=np.float64).tolist()
    n = len(b)
    L = [[0.0] * n for _ in range(n)]
    for i in range(n):
        for j in range(i + 1):
            acc = A[i][j]
            for k in range(j):
                acc -= L[i][k] * L[j][k]
            if i == j:
                if not acc > 0.0:
                    return np.full(n, np.nan)
                L[i][i] = math.sqrt(acc)
            else:
                L[i][j] = acc / L[j][j]
    y = [0.0] * n
    for i in range(n):
        acc = b[i]
        for k in range(i):
            acc -= L[i][k] * y[k]
        y[i] = acc / L[i][i]
    x = [0.0] * n
    for i in range(n - 1, -1, -1):
        acc = y[i]
        for k in range(i + 1, n):
            acc -= L[k][i] * x[k]
        x[i] = acc / L[i][i]
    return np.array(x)


def build_pyramid(image, levels: int) -> list[np.ndarray]:
    """Float32 image pyramid, level ``l`` halved ``l`` times (``cv2.pyrDown``).

    Parameters
    ----------
    image : array_like, shape (H, W)
        Grey image.
    levels : int
        Number of halvings; fewer when a level's smaller side drops below 16 px.

    Returns
    -------
    list of ndarray
        Float32 images, ``[0]`` the full-size one.
    """
    import cv2

    img = as_image(image, "image").astype(np.float32)
    pyr = [img]
    for _ in range(levels):
        if min(pyr[-1].shape) < 16:
            break
        pyr.append(cv2.pyrDown(pyr[-1]))
    return pyr


def bilinear(img, u, v_):
    """Bilinear samples of ``img`` at ``(u, v)`` (any shapes, clamped to the border).

    Parameters
    ----------
    img : ndarray, shape (H, W)
        Image to sample.
    u, v_ : ndarray
        Column and row coordinates [px], arrays of one shape.

    Returns
    -------
    values : ndarray
        Interpolated intensities, shape of ``u``.
    """
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
    """``T_cur_ref`` 4×4, ``ok`` converged with enough points, ``n_points``, ``rms`` final photometric residual.

    Attributes
    ----------
    T_cur_ref : ndarray, shape (4, 4)
        Pose of the reference camera in the current camera's frame.
    ok : bool
        Finite result from at least ``min_points`` points.
    n_points : int
        Points in front of the reference camera that were used.
    rms : float
        Final photometric RMS residual (grey levels).
    iterations : int
        Gauss-Newton steps taken over all levels.
    """

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

    Parameters
    ----------
    pyr_ref, pyr_cur : list of ndarray
        Image pyramids (:func:`build_pyramid`) of the reference and current frames.
    K : array_like, shape (3, 3)
        Intrinsic matrix of level 0.
    X_ref : array_like, shape (N, 3)
        Points in the reference camera frame [m].
    T_init : array_like, shape (4, 4)
        Initial ``T_cur_ref`` (e.g. from a motion prior).
    patch_px : int
        Side of the square patch around each point [px] (default 4).
    max_level, min_level : int
        Coarsest and finest pyramid levels used (defaults 3 and 1).
    max_iter : int
        Gauss-Newton steps per level at most (default 30).
    eps : float
        A step with norm below ``eps`` ends the level (default 1e-6).
    min_points : int
        Fewest usable points; fewer returns ``ok`` False at once (default 10).

    Returns
    -------
    AlignResult
        ``T_cur_ref``, ``ok``, ``n_points``, ``rms``, ``iterations``.
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
        H = np.einsum("ni,nj->ij", J, J) + 1e-9 * np.eye(6)
        chi_prev = np.inf
        T_prev = T
        for _ in range(max_iter):
            n_it += 1
            Xc = transform_points(T, Xl)
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
            Jf = Jm.reshape(-1, 6)
            g = np.einsum("ni,n->i", Jf, r.ravel())
            Hm = np.einsum("ni,nj->ij", Jf, Jf) + 1e-9 * np.eye(6) if not vis.all() else H
            delta = solve_spd(Hm, g)
            if not np.all(np.isfinite(delta)):
                break
            T_prev = T
            T = se3_compose(T, se3_inverse(se3_exp(delta)))
            chi_prev = chi
            if math.sqrt(float(np.sum(delta * delta))) < eps:
                break
    ok = bool(np.isfinite(rms)) and np.all(np.isfinite(T))
    if not np.all(np.isfinite(T)):
        T = np.array(T_init, dtype=np.float64)
    return AlignResult(T, ok, int(X_ref.shape[0]), float(rms), n_it)


def refine_pose(K, X_world, uv, T_cam_world_init, *, huber_px: float = 1.0, reject_px: float | None = 3.0,
                max_iter: int = 50, tol: float = 1e-8):
    """Motion-only refinement: ``min Σ ρ(r)`` over the pose, ``r`` = π(T X) − uv per coordinate (003 §4.4, step 4).

    Levenberg-Marquardt on the twist of a left update ``T ← exp(ξ) T`` with the analytic
    Jacobian of :func:`_d_proj` and Huber weights of scale ``huber_px`` (iteratively reweighted),
    until the step's norm or the cost's relative decrease is below ``tol`` (scipy's ``xtol`` and
    ``ftol`` defaults), or ``max_iter`` steps; then (ours) once more on the points
    whose error is below ``reject_px`` (the Huber loss still leans on gross outliers). Returns
    ``(T_cam_world, residual_px (N,), ok)`` with the residuals of every point; ``ok`` is False
    (and the initial pose returned) when a run does not converge in ``max_iter`` steps or ends
    non-finite. Written without BLAS (see the module docstring): the same bits on any machine.

    Parameters
    ----------
    K : array_like, shape (3, 3)
        Intrinsic matrix.
    X_world : array_like, shape (N, 3)
        Map points in the world frame [m].
    uv : array_like, shape (N, 2)
        Their measured pixels.
    T_cam_world_init : array_like, shape (4, 4)
        Initial camera pose (world to camera).
    huber_px : float
        Huber scale [px] (default 1).
    reject_px : float or None
        Error [px] above which a point is left out of the second run; ``None`` = one run only (default 3).
    max_iter : int
        Levenberg-Marquardt steps per run at most (default 50).
    tol : float
        Step-norm and relative-cost tolerance (default 1e-8).

    Returns
    -------
    T_cam_world : ndarray, shape (4, 4)
        Refined pose (the initial one when ``ok`` is False).
    residual_px : ndarray, shape (N,)
        Reprojection error of every point [px].
    ok : bool
        Both runs converged to a finite pose.
    """
    K = np.asarray(K, dtype=np.float64)
    X = np.asarray(X_world, dtype=np.float64).reshape(-1, 3)
    uv = np.asarray(uv, dtype=np.float64).reshape(-1, 2)
    T0 = np.asarray(T_cam_world_init, dtype=np.float64)
    if X.shape[0] < 3:
        return T0, np.full(X.shape[0], np.inf), False
    T, ok = _lm_huber(K, X, uv, T0, huber_px, max_iter, tol)
    err = _reproj_err(K, X, uv, T)
    if ok and reject_px is not None:
        keep = err < reject_px
        if 6 <= keep.sum() < err.size:
            T, ok = _lm_huber(K, X[keep], uv[keep], T, huber_px, max_iter, tol)
            err = _reproj_err(K, X, uv, T)
    ok = ok and bool(np.all(np.isfinite(T)))
    if not ok:
        return T0, np.full(X.shape[0], np.inf), False
    return T, err, ok


def _residuals(K, Xc, uv):
    return project(K, Xc, min_depth=1e-6) - uv


def _reproj_err(K, X, uv, T):
    r = _residuals(K, transform_points(T, X), uv)
    return np.hypot(r[:, 0], r[:, 1])


def _huber_cost(r, delta):
    a = np.abs(r)
    return float(np.sum(np.where(a <= delta, 0.5 * r * r, delta * (a - 0.5 * delta))))


def _lm_huber(K, X, uv, T, huber_px, max_iter, tol):
    """Levenberg-Marquardt with Huber (IRLS) weights on ``T ← exp(ξ) T``; ``(T, converged)``."""
    lam = 1e-4
    Xc = transform_points(T, X)
    r = _residuals(K, Xc, uv)
    cost = _huber_cost(r, huber_px)
    for _ in range(max_iter):
        a = np.abs(r)
        w = np.where(a <= huber_px, 1.0, huber_px / np.maximum(a, 1e-300))  # (N, 2)
        J = _d_proj(K, Xc, 1.0)  # (N, 2, 6)
        H = np.einsum("nk,nki,nkj->ij", w, J, J)
        g = np.einsum("nk,nki,nk->i", w, J, r)
        while True:
            Hd = H + lam * np.diag(np.diag(H))
            step = -solve_spd(Hd, g)
            if not np.all(np.isfinite(step)):
                return T, False
            T_new = se3_compose(se3_exp(step), T)
            Xc_new = transform_points(T_new, X)
            r_new = _residuals(K, Xc_new, uv)
            cost_new = _huber_cost(r_new, huber_px)
            if cost_new <= cost:
                decrease = cost - cost_new
                T, Xc, r, cost = T_new, Xc_new, r_new, cost_new
                lam = max(lam / 10.0, 1e-12)
                break
            lam *= 10.0
            if lam > 1e8:  # no step lowers the cost: at a minimum
                return T, True
        if math.sqrt(float(np.sum(step * step))) < tol or decrease <= tol * cost:
            return T, True
    return T, False
