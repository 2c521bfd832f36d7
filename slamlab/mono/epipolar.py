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

from ..geometry.camera import backproject_points, project_points
from ..geometry.se3 import rotate_points
from ..geometry.triangulation import triangulate_midpoint
from .align import bilinear
from .depth_filter import depth_interval

__all__ = ["EpipolarCandidates", "EpipolarMatch", "affine_warp", "epipolar_candidates", "epipolar_segments",
           "extract_patches", "search_epipolar", "warped_patches", "zncc"]

_FAR_DEPTH = 1e6  # depths beyond this are drawn at their vanishing point


def extract_patches(img, uv, patch_px: int) -> np.ndarray:
    """``(N, patch_px²)`` bilinear patches centred at ``uv`` (N, 2).

    Parameters
    ----------
    img : ndarray, shape (H, W)
        Grey image.
    uv : array_like, shape (N, 2)
        Patch centres [px].
    patch_px : int
        Patch side [px].

    Returns
    -------
    patches : ndarray of float32, shape (N, patch_px²)
        Row-major patches (border pixels clamped).
    """
    uv = np.asarray(uv, dtype=np.float64).reshape(-1, 2)
    if patch_px % 2 and np.all(uv == np.rint(uv)):  # odd patch on whole pixels: plain indexing
        o = np.arange(patch_px) - patch_px // 2
        ou, ov = np.meshgrid(o, o)
        h, w = img.shape[:2]
        r = np.clip(uv[:, 1:2].astype(np.intp) + ov.ravel(), 0, h - 1)
        c = np.clip(uv[:, 0:1].astype(np.intp) + ou.ravel(), 0, w - 1)
        return np.asarray(img, np.float32)[r, c]
    o = np.arange(patch_px) - (patch_px - 1) / 2.0
    ou, ov = np.meshgrid(o, o)
    return bilinear(np.asarray(img, np.float32), uv[:, 0:1] + ou.ravel(), uv[:, 1:2] + ov.ravel())


def _normalise(P):
    """Rows made zero-mean and unit-norm (flat rows stay zero), so that a dot product is the ZNCC."""
    P = np.asarray(P, dtype=np.float64)
    P = P - P.mean(axis=1, keepdims=True)
    nrm = np.linalg.norm(P, axis=1, keepdims=True)
    return np.where(nrm > 1e-6, P / np.maximum(nrm, 1e-12), 0.0)


def zncc(A, B) -> np.ndarray:
    """ZNCC matrix ``(N, M)`` between rows of ``A`` (N, P) and ``B`` (M, P); flat patches score 0.

    Parameters
    ----------
    A : array_like, shape (N, P)
        Patches, one per row.
    B : array_like, shape (M, P)
        Patches, one per row.

    Returns
    -------
    scores : ndarray, shape (N, M)
        Zero-mean normalised cross-correlations in ``[-1, 1]``.
    """
    A = np.asarray(A, dtype=np.float64)
    B = np.asarray(B, dtype=np.float64)
    A = A - A.mean(axis=1, keepdims=True)
    B = B - B.mean(axis=1, keepdims=True)
    na = np.linalg.norm(A, axis=1)
    nb = np.linalg.norm(B, axis=1)
    den = np.outer(na, nb)
    return np.where(den > 1e-6, np.einsum("ip,jp->ij", A, B) / np.maximum(den, 1e-12), 0.0)  # no BLAS: same bits anywhere


def epipolar_segments(K, T_cur_ref, f, mu, sigma, n_sigma: float = 2.0):
    """End points ``(a, b)`` (N, 2) of the searched epipolar segment, ``ok`` (N,) (003 §4.2).

    ``a`` is the projection of the nearest depth ``1/(ρ + nσ)``, ``b`` of the farthest
    ``1/max(ρ − nσ, 1e-10)`` (drawn at the vanishing point beyond ``1e6`` m). ``ok`` False
    when the near end is behind the current camera.

    Parameters
    ----------
    K : array_like, shape (3, 3)
        Intrinsic matrix.
    T_cur_ref : ndarray, shape (4, 4)
        Reference camera pose in the current camera's frame.
    f : array_like, shape (N, 3)
        Unit bearings of the seeds in the reference frame.
    mu, sigma : array_like, shape (N,)
        Inverse-depth mean and standard deviation [1/m].
    n_sigma : float
        Half-width of the depth band in standard deviations (default 2).

    Returns
    -------
    a, b : ndarray, shape (N, 2)
        Near and far end points [px] in the current image.
    ok : ndarray of bool, shape (N,)
        Both ends in front of the current camera.
    """
    K = np.asarray(K, dtype=np.float64)
    R, t = T_cur_ref[:3, :3], T_cur_ref[:3, 3]
    z_near, z_far = depth_interval(mu, sigma, n_sigma)
    fc = rotate_points(R, np.asarray(f, dtype=np.float64))
    Xa = fc * z_near[:, None] + t
    far_inf = z_far > _FAR_DEPTH
    Xb = np.where(far_inf[:, None], fc, fc * np.minimum(z_far, _FAR_DEPTH)[:, None] + t)
    ok = (Xa[:, 2] > 1e-6) & (Xb[:, 2] > 1e-6)
    Xa = np.where(ok[:, None], Xa, [0.0, 0.0, 1.0])
    Xb = np.where(ok[:, None], Xb, [0.0, 0.0, 1.0])
    return project_points(K, Xa), project_points(K, Xb), ok


def _segment_frames(A, B):
    """Per segment ``A → B`` (S, 2): the unit normal and direction in float32 with their offsets, and the length.

    Returns ``(n_u, n_v, off_n, e_u, e_v, off_e, L)``: a pixel ``(u, v)`` lies ``|u n_u + v n_v − off_n|`` from
    the line and ``u e_u + v e_v − off_e`` along it from ``A``.
    """
    A = np.asarray(A, dtype=np.float64)
    d = np.asarray(B, dtype=np.float64) - A
    L = np.maximum(np.linalg.norm(d, axis=1), 1e-9)
    e = d / L[:, None]  # unit direction; normal (-e_v, e_u)
    nrm = np.column_stack([-e[:, 1], e[:, 0]])
    n32, e32 = nrm.astype(np.float32), e.astype(np.float32)
    return (n32[:, 0], n32[:, 1], np.sum(A * nrm, axis=1).astype(np.float32),
            e32[:, 0], e32[:, 1], np.sum(A * e, axis=1).astype(np.float32), L)


def _in_band(cu, cv, n_u, n_v, off_n, e_u, e_v, off_e, L, tol_px):
    """True where the pixel ``(cu, cv)`` (float32) is within ``tol_px`` of the segment (:func:`_segment_frames`).

    Element-wise float32 products that broadcast (a (C, 1) column against (S,) rows, or pairs of equal
    length): each pair gives the same bits whichever form is used, and no BLAS product decides, by its
    machine-dependent rounding, which corner is within ``tol_px``.
    """
    dist = np.abs(cu * n_u + cv * n_v - off_n)
    along = cu * e_u + cv * e_v - off_e
    return (dist <= tol_px) & (along >= -tol_px) & (along <= L + tol_px)


@dataclass(frozen=True)
class EpipolarCandidates:
    """The FAST corners each seed's search looks at (:func:`epipolar_candidates`, 003 §4.2).

    Attributes
    ----------
    seed_idx, corner_idx : ndarray of int, shape (P,)
        The candidate pairs: seed index and index into ``corners_uv`` of each corner within ``tol_px`` of that
        seed's segment, by seed then by corner row.
    n_rows : ndarray of int, shape (N,)
        Corners in the rows the segment spans (found by binary search in the row-sorted corners).
    n_box : ndarray of int, shape (N,)
        Those also in the columns the segment spans: 003's subset, the corners whose position is checked.
    n_band : ndarray of int, shape (N,)
        Those within ``tol_px`` of the segment: the candidates that are scored.
    """

    seed_idx: np.ndarray
    corner_idx: np.ndarray
    n_rows: np.ndarray
    n_box: np.ndarray
    n_band: np.ndarray


def epipolar_candidates(corners_uv, a, b, ok=None, *, tol_px: float = 2.0) -> EpipolarCandidates:
    """FAST corners within ``tol_px`` of each epipolar segment, found from the corners' row order (003 §4.2).

    003 §4.2: the search looks only at the FAST corners, and "since the points obtained by FAST are sorted
    by rows and columns, not every detected point needs checking, a subset is enough": only those that
    share rows and columns with the epipolar line (its Fig. 6.6b, orange). Here the corners are sorted by
    row once; each segment's rows (``± tol_px·√2``, ours: so that the subset holds the whole band) are found by
    binary search, then its columns filter them (the subset, ``n_box``), and only those are tested against
    the band (``n_band``). The band test is :func:`search_epipolar`'s, so the pairs are exactly the
    candidates it scores. Vectorised over seeds (no Python loop).

    Parameters
    ----------
    corners_uv : array_like, shape (C, 2)
        Corners of the current image [px].
    a, b : array_like, shape (N, 2)
        End points of the seeds' segments [px] (:func:`epipolar_segments`).
    ok : array_like of bool, shape (N,), optional
        Segments to search (default all); a segment not ok has no candidates.
    tol_px : float
        Largest distance of a candidate from its segment [px] (default 2).

    Returns
    -------
    EpipolarCandidates
        The candidate pairs and, per seed, the corners in its rows, in its rows and columns, and in its band.

    Examples
    --------
    >>> c = epipolar_candidates([[10, 10], [20, 11], [20, 40], [90, 10]], [[0, 10]], [[50, 10]])
    >>> c.n_rows.tolist(), c.n_box.tolist(), c.n_band.tolist(), c.corner_idx.tolist()
    ([3], [2], [2], [0, 1])
    """
    from .._validate import as_finite_array, check_positive

    corners = as_finite_array(corners_uv, "corners_uv", ndim=2)
    if corners.shape[1] != 2:
        raise ValueError(f"`corners_uv` must have shape (C, 2); got {corners.shape}")
    a = as_finite_array(a, "a", ndim=2)
    b = as_finite_array(b, "b", ndim=2)
    if a.shape[1] != 2 or a.shape != b.shape:
        raise ValueError(f"`a` and `b` must have one shape (N, 2); got {a.shape} and {b.shape}")
    n = a.shape[0]
    ok = np.ones(n, bool) if ok is None else np.asarray(ok, dtype=bool).reshape(-1)
    if ok.shape != (n,):
        raise ValueError(f"`ok` must have shape ({n},), one flag per segment; got {ok.shape}")
    tol_px = check_positive(tol_px, "tol_px")
    pad = tol_px * np.sqrt(2.0)  # a band corner lies at most tol·√2 beyond the segment's end, in u and in v
    order = np.argsort(corners[:, 1], kind="stable")
    v_sorted = corners[order, 1]
    lo = np.searchsorted(v_sorted, np.minimum(a[:, 1], b[:, 1]) - pad, side="left")
    hi = np.searchsorted(v_sorted, np.maximum(a[:, 1], b[:, 1]) + pad, side="right")
    n_rows = np.where(ok, hi - lo, 0)
    # the row ranges, concatenated: pair k of seed s is sorted corner lo[s] + (k - start of s's block)
    seed = np.repeat(np.arange(n), n_rows)
    start = np.cumsum(n_rows) - n_rows
    corner = order[np.arange(seed.size) - start[seed] + lo[seed]]
    u = corners[corner, 0]
    in_cols = (u >= np.minimum(a[seed, 0], b[seed, 0]) - pad) & (u <= np.maximum(a[seed, 0], b[seed, 0]) + pad)
    seed, corner = seed[in_cols], corner[in_cols]
    n_box = np.bincount(seed, minlength=n)
    nu, nv, offn, eu, ev, offe, L = _segment_frames(a, b)
    cu, cv = (corners[corner, k].astype(np.float32) for k in (0, 1))
    band = _in_band(cu, cv, nu[seed], nv[seed], offn[seed], eu[seed], ev[seed], offe[seed], L[seed], tol_px)
    seed, corner = seed[band], corner[band]
    return EpipolarCandidates(seed, corner, n_rows, n_box, np.bincount(seed, minlength=n))


@dataclass(frozen=True)
class EpipolarMatch:
    """Result of :func:`search_epipolar` for N seeds.

    ``found`` (N,), ``uv`` (N, 2) matched pixel (NaN-free: zeros when not found), ``depth_m``
    (N,) triangulated depth along ``f`` in the reference frame, ``score`` (N,) best ZNCC,
    ``n_candidates`` (N,) corners tested, ``a``/``b`` segment end points.

    Attributes
    ----------
    found : ndarray of bool, shape (N,)
        A corner with ZNCC at least ``zncc_min`` was found and triangulated.
    uv : ndarray, shape (N, 2)
        Matched pixel (zeros when not found).
    depth_m : ndarray, shape (N,)
        Triangulated depth along ``f`` in the reference frame [m] (0 when not found).
    score : ndarray, shape (N,)
        Best ZNCC (-1 when no candidate).
    n_candidates : ndarray of int, shape (N,)
        Corners tested.
    a, b : ndarray, shape (N, 2)
        End points of the searched segment [px].
    """

    found: np.ndarray
    uv: np.ndarray
    depth_m: np.ndarray
    score: np.ndarray
    n_candidates: np.ndarray
    a: np.ndarray
    b: np.ndarray


def affine_warp(K, T_cur_ref, f, depth_m, uv_ref, *, h_px: float = 5.0) -> np.ndarray:
    """``(N, 2, 2)`` affine warp ``∂uv_cur / ∂uv_ref`` of each point at ``depth_m`` along ``f`` (SVO's
    ``getWarpMatrixAffine``): the pixel ``uv_ref`` shifted by ``h_px`` in u and in v, back-projected to the
    same depth and projected into the current camera. Written without BLAS (einsum).

    Parameters
    ----------
    K : array_like, shape (3, 3)
        Intrinsic matrix.
    T_cur_ref : ndarray, shape (4, 4)
        Reference camera pose in the current camera's frame.
    f : array_like, shape (N, 3)
        Unit bearings in the reference frame (not used by the warp itself; one row per point).
    depth_m : array_like, shape (N,)
        Depth of each point along its ray [m].
    uv_ref : array_like, shape (N, 2)
        Pixels in the reference image.
    h_px : float
        Finite-difference step [px] (default 5).

    Returns
    -------
    A : ndarray, shape (N, 2, 2)
        ``∂uv_cur / ∂uv_ref`` per point.
    """
    K = np.asarray(K, dtype=np.float64)
    R, t = T_cur_ref[:3, :3], T_cur_ref[:3, 3]
    uv_ref = np.asarray(uv_ref, dtype=np.float64).reshape(-1, 2)
    z = np.asarray(depth_m, dtype=np.float64).reshape(-1)

    def cur_px(uv):
        r = backproject_points(K, uv)
        r /= np.sqrt(np.einsum("ni,ni->n", r, r))[:, None]
        X = np.einsum("ij,nj->ni", R, r * z[:, None]) + t
        return project_points(K, X, min_depth=1e-6)

    del f  # the ray of uv_ref is f; the shifted rays are rebuilt from the pixels
    c = cur_px(uv_ref)
    du = (cur_px(uv_ref + np.array([h_px, 0.0])) - c) / h_px
    dv = (cur_px(uv_ref + np.array([0.0, h_px])) - c) / h_px
    return np.stack([du, dv], axis=2)  # columns: d/du, d/dv


def warped_patches(img_ref, uv_ref, A, patch_px: int) -> np.ndarray:
    """``(N, patch_px²)`` reference patches resampled as the current camera sees them: pixel ``o`` of the
    current patch is ``uv_ref + A⁻¹ o`` in the reference image (SVO's ``warpAffine``).

    Parameters
    ----------
    img_ref : ndarray, shape (H, W)
        Reference image.
    uv_ref : ndarray, shape (N, 2)
        Patch centres in the reference image [px].
    A : array_like, shape (N, 2, 2)
        Affine warps (:func:`affine_warp`).
    patch_px : int
        Patch side [px].

    Returns
    -------
    patches : ndarray of float32, shape (N, patch_px²)
        Resampled patches.
    """
    A = np.asarray(A, dtype=np.float64)
    det = A[:, 0, 0] * A[:, 1, 1] - A[:, 0, 1] * A[:, 1, 0]
    det = np.where(np.abs(det) > 1e-9, det, 1.0)
    Ai = np.stack([np.stack([A[:, 1, 1], -A[:, 0, 1]], 1), np.stack([-A[:, 1, 0], A[:, 0, 0]], 1)], 1) / det[:, None, None]
    o = np.arange(patch_px) - (patch_px - 1) / 2.0
    ou, ov = (g.ravel() for g in np.meshgrid(o, o))
    uu = uv_ref[:, 0:1] + Ai[:, 0, 0:1] * ou + Ai[:, 0, 1:2] * ov
    vv = uv_ref[:, 1:2] + Ai[:, 1, 0:1] * ou + Ai[:, 1, 1:2] * ov
    h, w = img_ref.shape[:2]
    uu, vv = np.clip(uu, 0, w - 2), np.clip(vv, 0, h - 2)
    return bilinear(np.asarray(img_ref, np.float32), uu, vv)


def search_epipolar(K, T_cur_ref, f, mu, sigma, ref_patches, img_cur, corners_uv, *, n_sigma: float = 2.0,
                    tol_px: float = 2.0, patch_px: int = 9, zncc_min: float = 0.8, min_parallax_rad: float = 1e-3,
                    chunk: int = 512, cur_patches=None, img_ref=None, uv_ref=None) -> EpipolarMatch:
    """Find each seed in the current frame among FAST corners near its epipolar segment (003 §4.2).

    ``ref_patches`` (N, patch_px²) the seeds' patches in their reference keyframe;
    ``corners_uv`` (C, 2) the current frame's FAST corners. Vectorised over seeds × corners
    in chunks of ``chunk`` seeds. ``cur_patches`` (C, patch_px²): the corners' patches, if
    already cut (then ``corners_uv`` must be the same corners, all inside the margin).
    ``img_ref`` and ``uv_ref`` (N, 2) given: the reference patches are warped affinely to the
    current view at the seed's mean depth (SVO's remedy for scale change, e.g. forward motion)
    instead of ``ref_patches``.

    Parameters
    ----------
    K : array_like, shape (3, 3)
        Intrinsic matrix.
    T_cur_ref : ndarray, shape (4, 4)
        Reference camera pose in the current camera's frame.
    f : array_like, shape (N, 3)
        Unit bearings of the seeds in the reference frame.
    mu, sigma : array_like, shape (N,)
        Inverse-depth mean and standard deviation [1/m].
    ref_patches : ndarray, shape (N, patch_px²)
        The seeds' patches in their reference keyframe.
    img_cur : ndarray, shape (H, W)
        Current image.
    corners_uv : array_like, shape (C, 2)
        FAST corners of the current image [px].
    n_sigma : float
        Half-width of the depth band in standard deviations (default 2).
    tol_px : float
        Largest distance of a candidate corner from the segment [px] (default 2).
    patch_px : int
        Patch side [px] (default 9).
    zncc_min : float
        Smallest ZNCC of a match (default 0.8).
    min_parallax_rad : float
        Rays closer to parallel than this give no depth [rad] (default 1e-3).
    chunk : int
        Seeds per vectorised block (default 512).
    cur_patches : ndarray, shape (C, patch_px²), optional
        The corners' patches when already cut.
    img_ref : ndarray, optional
        Reference image; with ``uv_ref``, the reference patches are warped affinely.
    uv_ref : array_like, shape (N, 2), optional
        The seeds' pixels in ``img_ref``.

    Returns
    -------
    EpipolarMatch
        ``found``, ``uv``, ``depth_m``, ``score`` per seed.
    """
    K = np.asarray(K, dtype=np.float64)
    f = np.asarray(f, dtype=np.float64).reshape(-1, 3)
    n = f.shape[0]
    if img_ref is not None and uv_ref is not None and n:
        A = affine_warp(K, T_cur_ref, f, 1.0 / np.maximum(np.asarray(mu, dtype=np.float64), 1e-6), uv_ref)
        ref_patches = warped_patches(img_ref, np.asarray(uv_ref, dtype=np.float64).reshape(-1, 2), A, patch_px)
    a, b, ok = epipolar_segments(K, T_cur_ref, f, mu, sigma, n_sigma)
    corners = np.asarray(corners_uv, dtype=np.float64).reshape(-1, 2)
    h, w = img_cur.shape[:2]
    m = (patch_px + 1) / 2.0 + 1
    if cur_patches is None:
        inside = (corners[:, 0] >= m) & (corners[:, 0] < w - m) & (corners[:, 1] >= m) & (corners[:, 1] < h - m)
        corners = corners[inside]
    found = np.zeros(n, bool)
    uv = np.zeros((n, 2))
    score = np.full(n, -1.0)
    ncand = np.zeros(n, np.int64)
    if n == 0 or corners.shape[0] == 0:
        return EpipolarMatch(found, uv, np.zeros(n), score, ncand, a, b)
    cur_n = _normalise(extract_patches(img_cur, corners, patch_px) if cur_patches is None else cur_patches)
    ref_n = _normalise(ref_patches)
    for s0 in range(0, n, chunk):
        sl = slice(s0, min(n, s0 + chunk))
        seg = _segment_frames(a[sl], b[sl])
        # every (corner, seed) pair as a (C, S) array: element-wise, not a BLAS matrix product (_in_band)
        cu, cv = (corners[:, k:k + 1].astype(np.float32) for k in (0, 1))
        near = _in_band(cu, cv, *seg, tol_px) & ok[sl]
        ci, si = np.nonzero(near)
        ncand[sl] = np.bincount(si, minlength=seg[-1].size)
        if ci.size == 0:
            continue
        sc = np.einsum("ij,ij->i", ref_n[s0 + si], cur_n[ci])  # ZNCC of each candidate pair
        order = np.lexsort((-sc, si))  # per seed, best score first
        first = order[np.r_[True, si[order][1:] != si[order][:-1]]]
        bs, bc, bv = si[first] + s0, ci[first], sc[first]
        score[bs] = bv
        hit = bv >= zncc_min
        found[bs[hit]] = True
        uv[bs[hit]] = corners[bc[hit]]
    # triangulate along f: ray f from the reference centre, ray through uv from the current centre
    R, t = T_cur_ref[:3, :3], T_cur_ref[:3, 3]
    c_cur = -np.einsum("ji,j->i", R, t)  # current centre in the reference frame
    rays = rotate_points(R.T, backproject_points(K, uv))  # R^T r
    tri = triangulate_midpoint(np.zeros(3), f, c_cur, rays, parallel_tol=min_parallax_rad**2)
    depth = tri.s  # f is unit: the ray parameter is the depth along f
    found &= tri.valid
    return EpipolarMatch(found, uv, np.where(found, depth, 0.0), score, ncand, a, b)
