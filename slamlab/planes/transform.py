"""The plane transform and its Levenberg-Marquardt solution per particle (002 Fig. 1, eq. system; reconstructed).

002's system is garbled in the text; we reconstruct it (ours). A plane ``ᵐn·x = ᵐp`` of the
map seen from the body pose ``x_m = ᵐ_bR x_b + ᵐt_b`` is, in the body frame,

    ᵇn_i = (ᵐ_bR)ᵀ ᵐn_i,        ᵇp_i = ᵐp_i − ᵐn_i · ᵐt_b                  (002, reconstructed)

For M pairs (frame plane i ↔ map plane) the residual of pair i is the 4-vector
``r_i = [(ᵐ_bR)ᵀ ᵐn_i − ᵇn_i ; ᵐp_i − ᵐn_i·ᵐt_b − ᵇp_i]``, solved for ``(R, t)`` by
Levenberg-Marquardt. Ours: the rotation is updated on the right, ``R ← R Exp(δ)``, so
``∂r_n/∂δ = [a]_×`` with ``a = Rᵀ ᵐn`` and ``∂r_p/∂t = −ᵐnᵀ``; the damping is ``λ I``
(Levenberg), so every step lies in the row space of the Jacobian and a particle moves
only along the directions its pairs constrain: one pair pins it to a plane (of
positions), two non-parallel pairs to a line, three to a point (002 Fig. 2) — the
free coordinates keep their predicted values. Batched over particles, pairs padded
with a mask.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from ..geometry.so3 import hat, so3_exp, so3_log

__all__ = ["LMResult", "lm_pose", "plane_pair_jacobian", "plane_pair_residuals", "planes_to_body", "planes_to_map"]


def planes_to_body(n_m, p_m, R, t):
    """Map planes seen from body pose ``(R, t)``: ``ᵇn = Rᵀ ᵐn``, ``ᵇp = ᵐp − ᵐn·t`` (002, reconstructed).

    Batched: ``n_m (..., 3)``, ``p_m (...)``, ``R (..., 3, 3)``, ``t (..., 3)`` broadcast together.

    Parameters
    ----------
    n_m : (..., 3) float
        Map planes' unit normals.
    p_m : (...) float
        Their offsets in metres.
    R : (..., 3, 3) float
        Body → map rotation.
    t : (..., 3) float
        Body position in the map, metres.

    Returns
    -------
    n_b : (..., 3) float
        Normals in the body frame.
    p_b : (...) float
        Offsets in the body frame, metres.

    Examples
    --------
    >>> n, p = planes_to_body([1.0, 0, 0], 5.0, np.eye(3), [2.0, 0, 0])
    >>> n.tolist(), float(p)
    ([1.0, 0.0, 0.0], 3.0)
    """
    n_m, p_m, R, t = (np.asarray(a, dtype=float) for a in (n_m, p_m, R, t))
    n_b = np.einsum("...ji,...j->...i", R, n_m)
    p_b = p_m - np.einsum("...i,...i->...", n_m, t)
    return n_b, p_b


def planes_to_map(n_b, p_b, R, t):
    """Body planes in the map: ``ᵐn = R ᵇn``, ``ᵐp = ᵇp + ᵐn·t`` (the inverse of :func:`planes_to_body`).

    Parameters
    ----------
    n_b : (..., 3) float
        Body planes' unit normals.
    p_b : (...) float
        Their offsets in metres.
    R : (..., 3, 3) float
        Body → map rotation.
    t : (..., 3) float
        Body position in the map, metres.

    Returns
    -------
    n_m : (..., 3) float
    p_m : (...) float
        The planes in the map frame.
    """
    n_b, p_b, R, t = (np.asarray(a, dtype=float) for a in (n_b, p_b, R, t))
    n_m = np.einsum("...ij,...j->...i", R, n_b)
    return n_m, p_b + np.einsum("...i,...i->...", n_m, t)


def plane_pair_residuals(R, t, n_m, p_m, n_b, p_b, mask=None) -> np.ndarray:
    """Residuals ``(P, F, 4)`` of the plane pairs at poses ``R (P, 3, 3)``, ``t (P, 3)`` (zero where masked).

    Parameters
    ----------
    R : (P, 3, 3) float
        Body → map rotations.
    t : (P, 3) float
        Body positions, metres.
    n_m : (P, F, 3) float
        Paired map planes' normals.
    p_m : (P, F) float
        Their offsets, metres.
    n_b : (P, F, 3) or (F, 3) float
        Frame planes' normals (body frame).
    p_b : (P, F) or (F,) float
        Their offsets, metres.
    mask : (P, F) bool, optional
        Which pairs exist (default all).

    Returns
    -------
    (P, F, 4) float
        Normal residual (3) and offset residual in metres (1) per pair.
    """
    nb_pred = n_m @ R                                          # rows: (R^T n)^T = n^T R
    pb_pred = p_m - (n_m @ t[..., None])[..., 0]
    r = np.concatenate([nb_pred - n_b, (pb_pred - p_b)[..., None]], axis=-1)
    return r if mask is None else r * mask[..., None]


def plane_pair_jacobian(R, n_m, mask=None) -> np.ndarray:
    """Jacobian ``(P, F, 4, 6)`` of the residuals w.r.t. ``(δ, t)`` with ``R ← R Exp(δ)`` (ours).

    Parameters
    ----------
    R : (P, 3, 3) float
        Body → map rotations.
    n_m : (P, F, 3) float
        Paired map planes' normals.
    mask : (P, F) bool, optional
        Which pairs exist (default all).

    Returns
    -------
    (P, F, 4, 6) float
    """
    a = n_m @ R                                                # (P, F, 3): a_f = R^T n_f
    J = np.zeros((*a.shape[:2], 4, 6))
    J[..., :3, :3] = hat(a)
    J[..., 3, 3:] = -n_m
    return J if mask is None else J * mask[..., None, None]


class LMResult(NamedTuple):
    """``R (P, 3, 3)``, ``t (P, 3)``, final ``cost (P,)`` (½Σr²), ``n_iters``, ``converged (P,)``.

    Attributes
    ----------
    R : (P, 3, 3) float
        Solved rotations.
    t : (P, 3) float
        Solved positions, metres.
    cost : (P,) float
        Final cost ½Σr² (scaled residuals, plus the prior).
    n_iters : int
        Iterations run.
    converged : (P,) bool
        Particles that met the stopping rule.
    """

    R: np.ndarray
    t: np.ndarray
    cost: np.ndarray
    n_iters: int
    converged: np.ndarray


def lm_pose(R0, t0, n_m, p_m, n_b, p_b, mask=None, *, sigma_n: float = 1.0, sigma_p_m: float = 1.0,
            prior_sigma=None, lambda0: float = 1e-3, max_iters: int = 20, tol: float = 1e-12) -> LMResult:
    """Batched Levenberg-Marquardt on the plane-pair system, one pose per particle (002; ours).

    Parameters
    ----------
    R0 : (P, 3, 3) float
        Start rotations (the predicted particles).
    t0 : (P, 3) float
        Start positions, metres.
    n_m : (P, F, 3) float
        The paired map planes' normals.
    p_m : (P, F) float
        Their offsets, metres.
    n_b : (P, F, 3) or (F, 3) float
        The frame planes' normals.
    p_b : (P, F) or (F,) float
        Their offsets, metres.
    mask : (P, F) bool, optional
        Which pairs exist (default all).
    sigma_n, sigma_p_m : float
        Scales of the normal and offset residuals (each residual row is divided by its sigma;
        ours: the two have different units).
    prior_sigma : None or (6,) float
        Standard deviations ``(rotation [rad] ×3, translation [m] ×3)`` of a prior pulling the pose
        towards ``(R0, t0)`` (ours: keeps nearly unconstrained directions — two nearly parallel walls — at the
        prediction; its Jacobian is taken as the identity, exact at the start).
    lambda0 : float
        Initial damping; ×10 on a rejected step, ÷10 on an accepted one.
    max_iters, tol : int, float
        Stop after ``max_iters`` or when every step is shorter than ``tol`` (or cost < tol²).

    Returns
    -------
    LMResult
        Solved ``R``, ``t``, final ``cost``, ``n_iters`` and ``converged`` per particle.
    """
    R = np.array(R0, dtype=float)
    t = np.array(t0, dtype=float)
    if R.ndim != 3 or R.shape[1:] != (3, 3):
        raise ValueError(f"`R0` must have shape (P, 3, 3); got {R.shape}")
    P = R.shape[0]
    if t.shape != (P, 3):
        raise ValueError(f"`t0` must have shape ({P}, 3); got {t.shape}")
    n_m = np.asarray(n_m, dtype=float)
    if n_m.ndim != 3 or n_m.shape[0] != P or n_m.shape[2] != 3:
        raise ValueError(f"`n_m` must have shape ({P}, F, 3); got {n_m.shape}")
    F = n_m.shape[1]
    p_m = np.broadcast_to(np.asarray(p_m, dtype=float), (P, F))
    n_b = np.broadcast_to(np.asarray(n_b, dtype=float), (P, F, 3))
    p_b = np.broadcast_to(np.asarray(p_b, dtype=float), (P, F))
    m = np.ones((P, F)) if mask is None else np.asarray(mask, dtype=float)
    if m.shape != (P, F):
        raise ValueError(f"`mask` must have shape ({P}, {F}); got {m.shape}")
    lam = np.full(P, float(lambda0))
    scale = np.array([1 / sigma_n] * 3 + [1 / sigma_p_m])
    prior = None if prior_sigma is None else 1.0 / np.asarray(prior_sigma, dtype=float)
    R0c, t0c = R.copy(), t.copy()

    def cost_of(R_, t_):
        r_ = plane_pair_residuals(R_, t_, n_m, p_m, n_b, p_b, m) * scale
        c = 0.5 * np.sum(r_.reshape(P, -1) ** 2, axis=1)
        if prior is not None:
            e = np.c_[so3_log(np.swapaxes(R0c, 1, 2) @ R_), t_ - t0c] * prior
            c = c + 0.5 * np.sum(e**2, axis=1)
            return r_, c, e
        return r_, c, None

    r, cost, e = cost_of(R, t)
    done = cost < tol**2
    it = 0
    eye = np.eye(6)
    for it in range(1, max_iters + 1):
        if done.all():
            it -= 1
            break
        J = (plane_pair_jacobian(R, n_m, m) * scale[:, None]).reshape(P, 4 * F, 6)
        Jt = np.swapaxes(J, 1, 2)
        H = Jt @ J
        g = (Jt @ r.reshape(P, 4 * F, 1))[..., 0]
        if prior is not None:
            H = H + np.diag(prior**2)
            g = g + prior * e
        step = -np.linalg.solve(H + lam[:, None, None] * eye, g[..., None])[..., 0]
        step[done] = 0.0
        R_new = R @ so3_exp(step[:, :3])
        t_new = t + step[:, 3:]
        r_new, cost_new, e_new = cost_of(R_new, t_new)
        accept = (cost_new < cost) & ~done
        R[accept], t[accept], r[accept], cost[accept] = R_new[accept], t_new[accept], r_new[accept], cost_new[accept]
        if prior is not None:
            e[accept] = e_new[accept]
        lam = np.where(accept, lam / 10.0, lam * 10.0)
        small = np.linalg.norm(step, axis=1) < tol
        done = done | (accept & small) | (cost < tol**2) | (~accept & (lam > 1e12))
    return LMResult(R, t, cost, it, done)
