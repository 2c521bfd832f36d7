"""Rigid and similarity registration of point sets: Umeyama / SVD (000 §3.5; 003 §5.2).

``umeyama(src, dst)`` finds ``R, t`` (and scale ``c`` with ``with_scale=True``)
minimising ``sum ||dst_i - (c R src_i + t)||^2`` — the absolute-orientation
problem that 000 §3.5 solves to map the local landmark cloud onto the global
one, and the alignment used by ATE (SE(3) or Sim(3)).
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from .._validate import as_finite_array, as_vector

__all__ = ["RigidTransform", "apply_transform", "umeyama"]


class RigidTransform(NamedTuple):
    """``x' = c R x + t``: rotation ``R`` (d, d), translation ``t`` (d,), scale ``c`` (1 for rigid).

    Attributes
    ----------
    R : ndarray, shape (d, d)
        Rotation.
    t : ndarray, shape (d,)
        Translation.
    c : float
        Scale (1 for a rigid transform).
    """

    R: np.ndarray
    t: np.ndarray
    c: float = 1.0


def umeyama(src, dst, *, with_scale: bool = False, weights=None, check: bool = True) -> RigidTransform:
    """Least-squares rotation, translation (and scale) mapping ``src`` onto ``dst`` (Umeyama 1991).

    Parameters
    ----------
    src, dst : array_like, shape (N, d)
        Corresponding points, ``d`` = 2 or 3, ``N >= d``.
    with_scale : bool, default False
        Also estimate a scale ``c`` (Sim(d)); otherwise ``c = 1`` (SE(d)).
    weights : array_like, shape (N,), optional
        Non-negative weights with a positive sum (default equal); normalised to sum 1.
    check : bool, default True
        Check the arguments. ``False`` skips the checks, for inner loops on rows checked once (a
        RANSAC's hypotheses, 000 §3.5): the points must then be finite float arrays of a valid shape and
        the weights positive.

    Returns
    -------
    RigidTransform
        ``R`` is a proper rotation (det +1) even for reflected or degenerate input.

    Examples
    --------
    >>> th = 0.3
    >>> R = np.array([[np.cos(th), -np.sin(th)], [np.sin(th), np.cos(th)]])
    >>> src = np.array([[0.0, 0.0], [1.0, 0.0], [0.0, 2.0]])
    >>> T = umeyama(src, src @ R.T + [1.0, -2.0])
    >>> np.allclose(T.R, R), np.round(T.t, 12)
    (True, array([ 1., -2.]))
    """
    if not check:
        src, dst = np.asarray(src, dtype=float), np.asarray(dst, dtype=float)
        w = np.full(len(src), 1.0 / len(src)) if weights is None else weights / weights.sum()
        return _umeyama(src, dst, w, with_scale)
    src = as_finite_array(src, "src", ndim=2)
    dst = as_finite_array(dst, "dst", ndim=2)
    if src.shape != dst.shape:
        raise ValueError(f"`src` and `dst` must have the same shape; got {src.shape} and {dst.shape}")
    n, d = src.shape
    if d not in (2, 3):
        raise ValueError(f"`src` must have 2 or 3 columns; got {d}")
    if n < d:
        raise ValueError(f"`src` must have at least {d} points for a {d}-D registration; got {n}")
    if weights is None:
        w = np.full(n, 1.0 / n)
    else:
        w = as_vector(weights, "weights", n)
        if np.any(w < 0) or w.sum() <= 0:
            raise ValueError("`weights` must be non-negative with a positive sum")
        w = w / w.sum()
    return _umeyama(src, dst, w, with_scale)


def _umeyama(src, dst, w, with_scale: bool = False) -> RigidTransform:
    """:func:`umeyama`'s arithmetic on checked float arrays and weights ``w`` summing to 1."""
    d = src.shape[1]
    mu_s, mu_d = w @ src, w @ dst
    xs, xd = src - mu_s, dst - mu_d
    # cross-covariance Sigma = sum w (dst - mu_d)(src - mu_s)^T
    Sigma = (xd * w[:, None]).T @ xs
    U, D, Vt = np.linalg.svd(Sigma)
    S = np.eye(d)
    if np.linalg.det(U) * np.linalg.det(Vt) < 0:
        S[-1, -1] = -1.0  # keep a proper rotation
    R = U @ S @ Vt
    c = 1.0
    if with_scale:
        var_s = float(np.sum(w * np.sum(xs**2, axis=1)))
        if var_s <= 0:
            raise ValueError("`src` points must not all coincide when estimating a scale")
        c = float(np.sum(D * np.diag(S)) / var_s)
    t = mu_d - c * R @ mu_s
    return RigidTransform(R, t, c)


def apply_transform(T: RigidTransform, points) -> np.ndarray:
    """``c R x + t`` for each row of ``points`` (N, d).

    Parameters
    ----------
    T : RigidTransform
        The transform ``(R, t, c)``.
    points : array_like, shape (N, d)
        Points to map.

    Returns
    -------
    mapped : ndarray, shape (N, d)
        ``c R x + t`` for each row.

    Examples
    --------
    >>> apply_transform(RigidTransform(np.eye(2), np.array([1.0, 2.0]), 2.0), [[1.0, 1.0]])
    array([[3., 4.]])
    """
    pts = as_finite_array(points, "points", ndim=2)
    return T.c * pts @ np.asarray(T.R).T + T.t
