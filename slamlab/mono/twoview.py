"""Relative pose of two views and their points (003 §4.3.1): homography or 5-point essential matrix, DLT triangulation.

Used by the :class:`~slamlab.mono.Initialiser` of :mod:`slamlab.mono.initialise` (which re-exports these names);
OpenCV's RANSAC estimates, made machine-independent where they feed the map (:func:`polish_homography`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .._validate import as_finite_array, as_matrix
from ..geometry.homography import apply_homography

__all__ = ["TwoViewPose", "polish_homography", "relative_pose_essential", "relative_pose_homography", "triangulate_two_view"]


def _check_uv_pair(uv0, uv1):
    uv0 = as_finite_array(uv0, "uv0", ndim=2)
    uv1 = as_finite_array(uv1, "uv1", ndim=2)
    if uv0.shape[1] != 2 or uv1.shape != uv0.shape:
        raise ValueError(f"`uv0` and `uv1` must both have shape (N, 2); got {uv0.shape} and {uv1.shape}")
    return uv0, uv1


@dataclass(frozen=True)
class TwoViewPose:
    """Relative pose of view 1 in view 0: ``X_1 = R X_0 + t`` with ``|t| = 1`` (003 §4.3.1).

    ``inliers`` (N,) the RANSAC inliers; ``n_front`` points in front of both cameras for the
    chosen solution; ``normal`` the plane normal in view 0 (homography) or None; ``ok`` False
    when the input was degenerate (then ``R = I``, ``t = 0``); ``reason`` says why.

    Attributes
    ----------
    R : ndarray, shape (3, 3)
        Rotation of view 0 into view 1.
    t : ndarray, shape (3,)
        Unit translation (0 when not ``ok``).
    inliers : ndarray of bool, shape (N,)
        RANSAC inliers.
    n_front : int
        Points in front of both cameras for the chosen solution.
    normal : ndarray, shape (3,), or None
        Plane normal in view 0 (homography), else ``None``.
    ok : bool
        False when the input was degenerate.
    reason : str
        Why it failed (``""`` when ``ok``).
    n_ransac : int
        Pairs the RANSAC model explains, before any cheirality or distance test (the homography's: ``inliers``;
        the essential matrix's: more than ``inliers``, which keeps those ``cv2.recoverPose`` triangulates in
        front of both views and nearer than 50 baselines).
    """

    R: np.ndarray
    t: np.ndarray
    inliers: np.ndarray
    n_front: int
    normal: np.ndarray | None
    ok: bool
    reason: str = ""
    n_ransac: int = 0


def _fail(n, reason):
    return TwoViewPose(np.eye(3), np.zeros(3), np.zeros(n, bool), 0, None, False, reason)


def _norm3(x) -> float:
    """Length of a 3-vector in Python floats (``np.linalg.norm`` of a vector is a BLAS dot: its last bit varies)."""
    x = np.asarray(x, dtype=np.float64).ravel()
    return math.sqrt(float(x[0] * x[0] + x[1] * x[1] + x[2] * x[2]))


def triangulate_two_view(K, R, t, uv0, uv1):
    """Points in view 0 from pixel pairs (linear DLT, ``cv2.triangulatePoints``): ``(X0 (N, 3), in_front)``.

    Parameters
    ----------
    K : array_like, shape (3, 3)
        Intrinsic matrix.
    R : array_like, shape (3, 3)
        Rotation of view 0 into view 1.
    t : array_like, shape (3,)
        Translation of view 1 (``X_1 = R X_0 + t``).
    uv0, uv1 : array_like, shape (N, 2)
        Matched pixels in views 0 and 1.

    Returns
    -------
    X0 : ndarray, shape (N, 3)
        Points in the frame of view 0 (units of ``t``).
    in_front : ndarray of bool, shape (N,)
        Finite and in front of both cameras.
    """
    import cv2

    K = as_matrix(K, "K", (3, 3))
    P0 = np.einsum("ij,jk->ik", K, np.hstack([np.eye(3), np.zeros((3, 1))]))  # einsum: no BLAS, same bits anywhere
    P1 = np.einsum("ij,jk->ik", K, np.hstack([np.asarray(R, float), np.asarray(t, float).reshape(3, 1)]))
    if len(uv0) == 0:
        return np.zeros((0, 3)), np.zeros(0, bool)
    Xh = cv2.triangulatePoints(P0, P1, np.asarray(uv0, float).T, np.asarray(uv1, float).T)
    w = Xh[3]
    good = np.abs(w) > 1e-12
    X = np.where(good[:, None], (Xh[:3] / np.where(good, w, 1.0)).T, 0.0)
    z1 = np.einsum("nj,j->n", X, np.asarray(R, float)[2]) + float(np.asarray(t, float)[2])
    return X, good & (X[:, 2] > 0) & (z1 > 0)


def _hartley(uv):
    """Similarity ``T`` (3, 3) taking pixels to zero mean and RMS distance √2 (Hartley's normalisation)."""
    c = uv.mean(axis=0)
    d = uv - c
    rms = math.sqrt(float(np.mean(d[:, 0] * d[:, 0] + d[:, 1] * d[:, 1])))
    s = math.sqrt(2.0) / max(rms, 1e-12)
    return np.array([[s, 0.0, -s * c[0]], [0.0, s, -s * c[1]], [0.0, 0.0, 1.0]])


def _transfer(Hn, x):
    """``(u, v, w)`` of ``π(Hn x)`` for points ``x (N, 2)``; ``w`` the homogeneous scale (for the Jacobian)."""
    uv = apply_homography(Hn, x)
    return uv[:, 0], uv[:, 1], Hn[2, 0] * x[:, 0] + Hn[2, 1] * x[:, 1] + Hn[2, 2]


def polish_homography(H, uv0, uv1, *, mantissa_bits: int = 14, max_iter: int = 50) -> np.ndarray:
    """The homography of inlier pairs, the same bits on every machine: snap OpenCV's ``H``, then re-fit it (ours).

    ``cv2.findHomography`` refines its RANSAC model by Levenberg-Marquardt on OpenCV's bundled
    OpenBLAS, and stops at a tolerance: its ``H`` differs between machines in the 7th digit, and the
    monocular map built on it (a tracker amplifies such differences into different inlier sets) came
    out different. Here ``H`` (in Hartley-normalised coordinates, ``h33 = 1``) is rounded to
    ``mantissa_bits`` significant bits (relative 6e-5 for 14: far coarser than the machine
    differences, so both machines round to the same start unless a value lies within 1e-8 of a
    rounding boundary), then refined by Levenberg-Marquardt on the one-sided transfer error
    ``|π(H x0) − x1|²`` written without BLAS/LAPACK (see :func:`slamlab.mono.align.solve_spd`),
    to convergence: the result depends on the inliers, not on the machine.

    Parameters
    ----------
    H : array_like, shape (3, 3)
        OpenCV's homography from view 0 to view 1.
    uv0, uv1 : array_like, shape (N, 2)
        Inlier pixel pairs.
    mantissa_bits : int
        Significant bits kept when snapping ``H`` (default 14).
    max_iter : int
        Levenberg-Marquardt steps at most (default 50).

    Returns
    -------
    H : ndarray, shape (3, 3)
        The re-fitted homography.
    """
    from .align import solve_spd

    uv0 = np.asarray(uv0, dtype=np.float64)
    uv1 = np.asarray(uv1, dtype=np.float64)
    T0, T1 = _hartley(uv0), _hartley(uv1)
    x0 = uv0 * T0[0, 0] + T0[:2, 2]
    x1 = uv1 * T1[0, 0] + T1[:2, 2]
    T0_inv = np.array([[1 / T0[0, 0], 0.0, -T0[0, 2] / T0[0, 0]], [0.0, 1 / T0[1, 1], -T0[1, 2] / T0[1, 1]],
                       [0.0, 0.0, 1.0]])
    Hn = np.einsum("ij,jk,kl->il", T1, np.asarray(H, dtype=np.float64), T0_inv)
    if not abs(Hn[2, 2]) > 1e-8:
        return np.asarray(H, dtype=np.float64)
    Hn = Hn / Hn[2, 2]
    m, e = np.frexp(Hn)
    Hn = np.ldexp(np.round(m * 2.0**mantissa_bits), e - mantissa_bits)
    Hn[2, 2] = 1.0

    def cost_of(Hc):
        u, v, _ = _transfer(Hc, x0)
        ru, rv = u - x1[:, 0], v - x1[:, 1]
        return ru, rv, float(np.sum(ru * ru + rv * rv))

    ru, rv, cost = cost_of(Hn)
    lam = 1e-3
    x, y = x0[:, 0], x0[:, 1]
    for _ in range(max_iter):
        u, v, w = _transfer(Hn, x0)
        zero = np.zeros_like(x)
        Ju = np.column_stack([x / w, y / w, 1 / w, zero, zero, zero, -u * x / w, -u * y / w])
        Jv = np.column_stack([zero, zero, zero, x / w, y / w, 1 / w, -v * x / w, -v * y / w])
        A = np.einsum("ni,nj->ij", Ju, Ju) + np.einsum("ni,nj->ij", Jv, Jv)
        g = np.einsum("ni,n->i", Ju, ru) + np.einsum("ni,n->i", Jv, rv)
        done = False
        while True:
            step = -solve_spd(A + lam * np.diag(np.diag(A)), g)
            if not np.all(np.isfinite(step)):
                done = True
                break
            H_new = Hn.copy()
            H_new.flat[:8] += step
            ru_n, rv_n, cost_n = cost_of(H_new)
            if cost_n <= cost:
                small = cost - cost_n <= 1e-15 * cost or float(np.sum(step * step)) < 1e-30
                Hn, ru, rv, cost = H_new, ru_n, rv_n, cost_n
                lam = max(lam / 10.0, 1e-12)
                done = small
                break
            lam *= 10.0
            if lam > 1e10:
                done = True
                break
        if done:
            break
    T1_inv = np.array([[1 / T1[0, 0], 0.0, -T1[0, 2] / T1[0, 0]], [0.0, 1 / T1[1, 1], -T1[1, 2] / T1[1, 1]],
                       [0.0, 0.0, 1.0]])
    return np.einsum("ij,jk,kl->il", T1_inv, Hn, T0)


def relative_pose_homography(uv0, uv1, K, *, ransac_px: float = 2.0, min_points: int = 8) -> TwoViewPose:
    """Pose from a RANSAC homography and its decomposition (003 §4.3.1).

    ``cv2.findHomography(RANSAC)`` then ``cv2.decomposeHomographyMat`` (up to four
    solutions); we keep the one with most inliers triangulated in front of both views and,
    on a tie, the plane normal most facing view 0 (our choice). ``t`` is normalised.

    Parameters
    ----------
    uv0, uv1 : array_like, shape (N, 2)
        Tracked pixel pairs in views 0 and 1.
    K : array_like, shape (3, 3)
        Intrinsic matrix.
    ransac_px : float
        RANSAC reprojection threshold [px] (default 2).
    min_points : int
        Fewest pairs (at least 4) before failing with ``"too_few_points"`` (default 8).

    Returns
    -------
    TwoViewPose
        ``R``, ``t``, ``inliers``, ``normal``, ``ok``, ``reason``.
    """
    import cv2

    uv0, uv1 = _check_uv_pair(uv0, uv1)
    K = as_matrix(K, "K", (3, 3))
    n = uv0.shape[0]
    if n < max(4, min_points):
        return _fail(n, "too_few_points")
    cv2.setRNGSeed(0)  # OpenCV's RANSAC seeds itself today; this keeps it so if a release draws from the global RNG
    H, mask = cv2.findHomography(uv0, uv1, cv2.RANSAC, ransac_px)
    if H is None or not np.all(np.isfinite(H)) or abs(np.linalg.det(H)) < 1e-12:
        return _fail(n, "degenerate_homography")
    inl = mask.ravel().astype(bool)
    if inl.sum() < min_points:
        return _fail(n, "degenerate_homography")
    H = polish_homography(H, uv0[inl], uv1[inl])
    _, Rs, ts, normals = cv2.decomposeHomographyMat(H, K)
    best, best_key = None, None
    for R, tt, nn in zip(Rs, ts, normals, strict=True):
        tt = tt.ravel()
        tt_norm = _norm3(tt)
        if tt_norm < 1e-9:  # a pure rotation: no translation to recover
            continue
        tn = tt / tt_norm
        _, front = triangulate_two_view(K, R, tn, uv0[inl], uv1[inl])
        key = (int(front.sum()), float(-nn.ravel()[2]))
        if best_key is None or key > best_key:
            best, best_key = (R, tn, nn.ravel()), key
    if best is None:
        return _fail(n, "no_parallax")
    R, tn, nn = best
    return TwoViewPose(R, tn, inl, best_key[0], nn, best_key[0] >= min_points,
                       "" if best_key[0] >= min_points else "cheirality", int(inl.sum()))


def relative_pose_essential(uv0, uv1, K, *, ransac_px: float = 1.0, prob: float = 0.999,
                            min_points: int = 8) -> TwoViewPose:
    """Pose by the 5-point algorithm: ``cv2.findEssentialMat`` (RANSAC) + ``cv2.recoverPose`` (003 §4.3.1).

    Parameters
    ----------
    uv0, uv1 : array_like, shape (N, 2)
        Tracked pixel pairs in views 0 and 1.
    K : array_like, shape (3, 3)
        Intrinsic matrix.
    ransac_px : float
        RANSAC threshold [px] (default 1).
    prob : float
        RANSAC confidence (default 0.999).
    min_points : int
        Fewest pairs (at least 5) before failing with ``"too_few_points"`` (default 8).

    Returns
    -------
    TwoViewPose
        ``R``, ``t``, ``inliers``, ``n_front``, ``ok`` (``normal`` is ``None``).
    """
    import cv2

    uv0, uv1 = _check_uv_pair(uv0, uv1)
    K = as_matrix(K, "K", (3, 3))
    n = uv0.shape[0]
    if n < max(5, min_points):
        return _fail(n, "too_few_points")
    cv2.setRNGSeed(0)  # as in relative_pose_homography
    E, mask = cv2.findEssentialMat(uv0, uv1, K, method=cv2.RANSAC, prob=prob, threshold=ransac_px)
    if E is None or E.shape != (3, 3):
        return _fail(n, "degenerate_essential")
    n_front, R, t, mask2 = cv2.recoverPose(E, uv0, uv1, K, mask=mask.copy())
    inl = mask2.ravel().astype(bool)
    t = t.ravel()
    if n_front < min_points or not np.all(np.isfinite(t)):
        return _fail(n, "cheirality")
    return TwoViewPose(R, t / _norm3(t), inl, int(n_front), None, True, "", int(np.count_nonzero(mask)))
