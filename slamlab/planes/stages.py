"""The stages of one cycle of the plane filter as functions (002 "MCL"): the motion model, the pairing of frame
and map planes, the intensity weights, the mean pose (used and re-exported by :mod:`slamlab.planes.filter`).
"""

from __future__ import annotations

import numpy as np

from ..geometry import so3_exp

__all__ = ["intensity_weights", "mean_pose", "pair_planes", "predict_particles"]


def predict_particles(X, U, V_xyz_m2: float, V_rpy_deg2: float, rng) -> np.ndarray:
    """Motion model: ``R ← R ΔR Exp(ε_r)``, ``t ← t + R Δt + ε_t``, ``ε ~ N(0, V)`` (002 "MCL"; composition ours).

    ``X (P, 4, 4)`` particles ``ᵐT_b``, ``U (4, 4)`` the odometry increment between the frames;
    ``V_xyz_m2`` [m²] and ``V_rpy_deg2`` [deg²] the *variances* of ε per axis (002: "with a variance
    equal to V"), so the draws have standard deviations ``√V``.

    Parameters
    ----------
    X : (P, 4, 4) float
        Particles (body → map).
    U : (4, 4) float
        Odometry increment between the frames.
    V_xyz_m2 : float
        Position noise variance per axis, m².
    V_rpy_deg2 : float
        Rotation noise variance per axis, deg².
    rng : numpy.random.Generator
        Randomness of ε.

    Returns
    -------
    (P, 4, 4) float
        The predicted particles.
    """
    P = X.shape[0]
    out = X @ U
    out[:, :3, :3] = out[:, :3, :3] @ so3_exp(rng.normal(0.0, np.deg2rad(np.sqrt(V_rpy_deg2)), (P, 3)))
    out[:, :3, 3] += rng.normal(0.0, np.sqrt(V_xyz_m2), (P, 3))
    return out


def pair_planes(X, n_b, p_b, n_map, p_map, *, angle_deg: float, dist_m: float) -> np.ndarray:
    """Map plane paired with each frame plane for each particle, ``(P, F)`` (-1: none) (002; rule ours).

    A frame plane moved by the particle pairs with the map plane of the smallest
    ``(1 − cos)/(1 − cos tol) + (Δp / dist_m)²`` among those within both tolerances.

    Parameters
    ----------
    X : (P, 4, 4) float
        Particles (body → map).
    n_b : (F, 3) float
        Frame planes' normals in the body frame.
    p_b : (F,) float
        Their offsets in metres.
    n_map : (M, 3) float
        Map planes' normals.
    p_map : (M,) float
        Their offsets in metres.
    angle_deg : float
        Largest angle between paired normals, degrees.
    dist_m : float
        Largest offset difference, metres.

    Returns
    -------
    (P, F) int
        Map plane index per particle and frame plane, -1 for none.
    """
    if len(n_map) == 0 or len(n_b) == 0:
        return np.full((X.shape[0], len(n_b)), -1, dtype=int)
    n_w = np.einsum("pij,fj->pfi", X[:, :3, :3], n_b)                     # (P, F, 3)
    p_w = p_b[None] + np.einsum("pfi,pi->pf", n_w, X[:, :3, 3])
    cos = np.einsum("pfi,mi->pfm", n_w, n_map)
    dp = np.abs(p_w[..., None] - p_map)
    c_tol = np.cos(np.deg2rad(angle_deg))
    ok = (cos > c_tol) & (dp < dist_m)
    cost = np.where(ok, (1 - cos) / (1 - c_tol) + (dp / dist_m) ** 2, np.inf)
    k = np.argmin(cost, axis=2)
    return np.where(np.isfinite(np.take_along_axis(cost, k[..., None], 2)[..., 0]), k, -1)


def intensity_weights(sad) -> np.ndarray:
    """``SAD*_i = max SAD − SAD_i``, ``w_i = SAD*_i / Σ SAD*`` (002); NaN SAD (no overlap) counts as the max;
    all equal → uniform.

    Parameters
    ----------
    sad : (P,) float
        Intensity SAD per particle (NaN: no overlap).

    Returns
    -------
    (P,) float
        Weights summing to 1.

    Examples
    --------
    >>> intensity_weights([1.0, 3.0, 2.0]).tolist()
    [0.6666666666666666, 0.0, 0.3333333333333333]
    """
    s = np.asarray(sad, dtype=float)
    if not np.isfinite(s).any():
        return np.full(s.shape, 1.0 / s.size)
    top = np.nanmax(s)
    star = top - np.where(np.isfinite(s), s, top)
    tot = star.sum()
    return star / tot if tot > 0 else np.full(s.shape, 1.0 / s.size)


def mean_pose(X, w=None) -> np.ndarray:
    """Weighted mean pose of particles ``(P, 4, 4)``: mean position; chordal mean rotation (SVD projection).

    Parameters
    ----------
    X : (P, 4, 4) float
        Particles.
    w : (P,) float, optional
        Weights (normalised here); uniform when None.

    Returns
    -------
    (4, 4) float
        The mean pose.
    """
    w = np.full(X.shape[0], 1.0 / X.shape[0]) if w is None else np.asarray(w) / np.sum(w)
    M = np.einsum("p,pij->ij", w, X[:, :3, :3])
    U, _, Vt = np.linalg.svd(M)
    D = np.diag([1.0, 1.0, np.sign(np.linalg.det(U @ Vt))])
    T = np.eye(4)
    T[:3, :3] = U @ D @ Vt
    T[:3, 3] = w @ X[:, :3, 3]
    return T
