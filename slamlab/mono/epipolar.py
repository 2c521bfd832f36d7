"""Epipolar search of a seed in a new frame (003 §4.2).

For a seed of reference keyframe ``r`` (bearing ``f``, inverse depth ``ρ ± σ``) the search
covers only the depths ``[1/(ρ + 2σ), 1/max(ρ − 2σ, 1e-10)]`` (003 §4.2): their projections
into the current frame bound a segment of the epipolar line. The candidates are the FAST
corners of the current frame within ``tol_px`` of that segment (003 Fig. 4.3b), and the score
is the zero-mean normalised cross-correlation (ZNCC) of ``patch_px × patch_px`` patches,
unwarped (our choice; SVO warps the patch affinely and scores by zero-mean SSD). The best
candidate above ``zncc_min`` is triangulated along ``f``; a failed search is an outlier
for the Beta part (SVO: ``b += 1``).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..geometry.triangulation import triangulate_midpoint
from .align import bilinear
from .depth_filter import depth_interval

__all__ = ["EpipolarMatch", "epipolar_segments", "extract_patches", "search_epipolar", "zncc"]

_FAR_DEPTH = 1e6  # depths beyond this are drawn at their vanishing point


def extract_patches(img, uv, patch_px: int) -> np.ndarray:
    """``(N, patch_px²)`` bilinear patches centred at ``uv`` (N, 2)."""
    o = np.arange(patch_px) - (patch_px - 1) / 2.0
    ou, ov = np.meshgrid(o, o)
    uv = np.asarray(uv, dtype=np.float64).reshape(-1, 2)
    return bilinear(np.asarray(img, np.float32), uv[:, 0:1] + ou.ravel(), uv[:, 1:2] + ov.ravel())


def zncc(A, B) -> np.ndarray:
    """ZNCC matrix ``(N, M)`` between rows of ``A`` (N, P) and ``B`` (M, P); flat patches score 0."""
    A = np.asarray(A, dtype=np.float64)
    B = np.asarray(B, dtype=np.float64)
    A = A - A.mean(axis=1, keepdims=True)
    B = B - B.mean(axis=1, keepdims=True)
    na = np.linalg.norm(A, axis=1)
    nb = np.linalg.norm(B, axis=1)
    den = np.outer(na, nb)
    return np.where(den > 1e-6, (A @ B.T) / np.maximum(den, 1e-12), 0.0)


def epipolar_segments(K, T_cur_ref, f, mu, sigma, n_sigma: float = 2.0):
    """End points ``(a, b)`` (N, 2) of the searched epipolar segment, ``ok`` (N,) (003 §4.2).

    ``a`` is the projection of the nearest depth ``1/(ρ + nσ)``, ``b`` of the farthest
    ``1/max(ρ − nσ, 1e-10)`` (drawn at the vanishing point beyond ``1e6`` m). ``ok`` False
    when the near end is behind the current camera.
    """
    K = np.asarray(K, dtype=np.float64)
    R, t = T_cur_ref[:3, :3], T_cur_ref[:3, 3]
    z_near, z_far = depth_interval(mu, sigma, n_sigma)
    fc = np.asarray(f, dtype=np.float64) @ R.T
    Xa = fc * z_near[:, None] + t
    far_inf = z_far > _FAR_DEPTH
    Xb = np.where(far_inf[:, None], fc, fc * np.minimum(z_far, _FAR_DEPTH)[:, None] + t)
    ok = (Xa[:, 2] > 1e-6) & (Xb[:, 2] > 1e-6)
    Xa = np.where(ok[:, None], Xa, [0.0, 0.0, 1.0])
    Xb = np.where(ok[:, None], Xb, [0.0, 0.0, 1.0])
    a = np.column_stack([K[0, 0] * Xa[:, 0] / Xa[:, 2] + K[0, 2], K[1, 1] * Xa[:, 1] / Xa[:, 2] + K[1, 2]])
    b = np.column_stack([K[0, 0] * Xb[:, 0] / Xb[:, 2] + K[0, 2], K[1, 1] * Xb[:, 1] / Xb[:, 2] + K[1, 2]])
    return a, b, ok


@dataclass(frozen=True)
class EpipolarMatch:
    """Result of :func:`search_epipolar` for N seeds.

    ``found`` (N,), ``uv`` (N, 2) matched pixel (NaN-free: zeros when not found), ``depth_m``
    (N,) triangulated depth along ``f`` in the reference frame, ``score`` (N,) best ZNCC,
    ``n_candidates`` (N,) corners tested, ``a``/``b`` segment end points.
    """

    found: np.ndarray
    uv: np.ndarray
    depth_m: np.ndarray
    score: np.ndarray
    n_candidates: np.ndarray
    a: np.ndarray
    b: np.ndarray


def search_epipolar(K, T_cur_ref, f, mu, sigma, ref_patches, img_cur, corners_uv, *, n_sigma: float = 2.0,
                    tol_px: float = 2.0, patch_px: int = 8, zncc_min: float = 0.8, min_parallax_rad: float = 1e-3,
                    chunk: int = 512) -> EpipolarMatch:
    """Find each seed in the current frame among FAST corners near its epipolar segment (003 §4.2).

    ``ref_patches`` (N, patch_px²) the seeds' patches in their reference keyframe;
    ``corners_uv`` (C, 2) the current frame's FAST corners. Vectorised over seeds × corners
    in chunks of ``chunk`` seeds.
    """
    K = np.asarray(K, dtype=np.float64)
    f = np.asarray(f, dtype=np.float64).reshape(-1, 3)
    n = f.shape[0]
    a, b, ok = epipolar_segments(K, T_cur_ref, f, mu, sigma, n_sigma)
    corners = np.asarray(corners_uv, dtype=np.float64).reshape(-1, 2)
    h, w = img_cur.shape[:2]
    m = (patch_px + 1) / 2.0 + 1
    corners = corners[(corners[:, 0] >= m) & (corners[:, 0] < w - m) & (corners[:, 1] >= m) & (corners[:, 1] < h - m)]
    found = np.zeros(n, bool)
    uv = np.zeros((n, 2))
    score = np.full(n, -1.0)
    ncand = np.zeros(n, np.int64)
    if n == 0 or corners.shape[0] == 0:
        return EpipolarMatch(found, uv, np.zeros(n), score, ncand, a, b)
    cur_patches = extract_patches(img_cur, corners, patch_px)
    for s0 in range(0, n, chunk):
        sl = slice(s0, min(n, s0 + chunk))
        A, B = a[sl], b[sl]
        d = B - A
        L2 = np.maximum(np.sum(d * d, axis=1), 1e-12)
        rel = corners[None, :, :] - A[:, None, :]  # (S, C, 2)
        tpar = np.einsum("scj,sj->sc", rel, d) / L2[:, None]
        tcl = np.clip(tpar, 0.0, 1.0)
        closest = A[:, None, :] + tcl[..., None] * d[:, None, :]
        dist = np.linalg.norm(corners[None, :, :] - closest, axis=2)
        near = (dist <= tol_px) & ok[sl, None]
        ncand[sl] = near.sum(axis=1)
        S = zncc(ref_patches[sl], cur_patches)
        S = np.where(near, S, -2.0)
        j = np.argmax(S, axis=1)
        best = S[np.arange(S.shape[0]), j]
        hit = best >= zncc_min
        score[sl] = np.maximum(best, -1.0)
        found[sl] = hit
        uv[sl] = np.where(hit[:, None], corners[j], 0.0)
    # triangulate along f: ray f from the reference centre, ray through uv from the current centre
    R, t = T_cur_ref[:3, :3], T_cur_ref[:3, 3]
    c_cur = -R.T @ t  # current centre in the reference frame
    rays = np.column_stack([(uv[:, 0] - K[0, 2]) / K[0, 0], (uv[:, 1] - K[1, 2]) / K[1, 1], np.ones(n)]) @ R  # R^T r
    tri = triangulate_midpoint(np.zeros(3), f, c_cur, rays, parallel_tol=min_parallax_rad**2)
    depth = tri.s  # f is unit: the ray parameter is the depth along f
    found &= tri.valid
    return EpipolarMatch(found, uv, np.where(found, depth, 0.0), score, ncand, a, b)
