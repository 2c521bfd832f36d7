"""SO(3) and SE(3) exponential and logarithm maps, and the hat operator (Lie algebra; ModernRobotics ch. 3).

One place for every chapter that moves a rotation or a pose by a small increment: the
monocular tracker (003 §4.4, a twist ``ξ = (v, ω)``), the plane particle filter (002, the
motion noise ``Exp(ε_r)``) and its Levenberg-Marquardt (``R ← R Exp(δ)``). All functions are
batched over leading axes and written without BLAS (element-wise sums and ``np.einsum``
without ``optimize``): a tracker turns a last-bit difference into a different inlier set a few
frames later, and BLAS rounds differently by kernel and thread count. The trigonometric
coefficients are taken in Python floats (``math.sin``), the same operations in the same order
for one twist or many.

Conventions: ``hat(ω) x = ω × x``; a twist is ``ξ = (v, ω)`` (translation part first, as
Sophus), ``se3_exp(ξ) = [[Exp(ω), V v], [0, 1]]`` with ``V = I + B [ω]× + C [ω]×²``,
``A = sin θ / θ``, ``B = (1 − cos θ) / θ²``, ``C = (1 − A) / θ²``, ``θ = |ω|`` (Rodrigues).
"""

from __future__ import annotations

import math

import numpy as np

__all__ = ["hat", "rotation_angle", "se3_exp", "se3_log", "so3_exp", "so3_log", "vee"]

#: below this angle [rad] the exponential is taken to first order, ``I + [ω]×`` (the error is below 1e-20)
_SMALL_RAD = 1e-10


def _last_axis(value, name: str, n: int) -> np.ndarray:
    a = np.asarray(value, dtype=np.float64)
    if a.ndim < 1 or a.shape[-1] != n:
        raise ValueError(f"`{name}` must have shape ({n},) or (..., {n}); got {a.shape}")
    return a


def _last_two_axes(value, name: str, n: int) -> np.ndarray:
    a = np.asarray(value, dtype=np.float64)
    if a.ndim < 2 or a.shape[-2:] != (n, n):
        raise ValueError(f"`{name}` must have shape ({n}, {n}) or (..., {n}, {n}); got {a.shape}")
    return a


def hat(w) -> np.ndarray:
    """Skew-symmetric matrix ``[w]×`` with ``[w]× x = w × x`` (ModernRobotics §3.2.3).

    Parameters
    ----------
    w : array_like, shape (3,) or (..., 3)
        Vectors (an angular velocity, a rotation vector, a translation).

    Returns
    -------
    ndarray, shape (3, 3) or (..., 3, 3)
        ``[[0, -w3, w2], [w3, 0, -w1], [-w2, w1, 0]]`` for each vector.

    Examples
    --------
    >>> hat([1.0, 2.0, 3.0])
    array([[ 0., -3.,  2.],
           [ 3.,  0., -1.],
           [-2.,  1.,  0.]])
    """
    w = _last_axis(w, "w", 3)
    S = np.zeros((*w.shape[:-1], 3, 3))
    S[..., 0, 1], S[..., 0, 2] = -w[..., 2], w[..., 1]
    S[..., 1, 0], S[..., 1, 2] = w[..., 2], -w[..., 0]
    S[..., 2, 0], S[..., 2, 1] = -w[..., 1], w[..., 0]
    return S


def vee(S) -> np.ndarray:
    """The vector ``w`` of a skew-symmetric matrix ``S = [w]×`` (the inverse of :func:`hat`).

    Parameters
    ----------
    S : array_like, shape (3, 3) or (..., 3, 3)
        Skew-symmetric matrices (only the lower triangle is read).

    Returns
    -------
    ndarray, shape (3,) or (..., 3)
        ``(S[2, 1], S[0, 2], S[1, 0])``.

    Examples
    --------
    >>> vee(hat([1.0, 2.0, 3.0]))
    array([1., 2., 3.])
    """
    S = _last_two_axes(S, "S", 3)
    return np.stack([S[..., 2, 1], S[..., 0, 2], S[..., 1, 0]], axis=-1)


def _norm3(w) -> np.ndarray:
    return np.sqrt(w[..., 0] * w[..., 0] + w[..., 1] * w[..., 1] + w[..., 2] * w[..., 2])


def _exp_coefficients(theta) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``A = sin θ/θ``, ``B = (1 − cos θ)/θ²``, ``C = (1 − A)/θ²`` per angle, in Python floats (0 below ``_SMALL_RAD``)."""
    flat = np.asarray(theta, dtype=np.float64).ravel().tolist()
    A, B, C = [0.0] * len(flat), [0.0] * len(flat), [0.0] * len(flat)
    for i, th in enumerate(flat):
        if th >= _SMALL_RAD:
            A[i] = math.sin(th) / th
            B[i] = (1 - math.cos(th)) / th**2
            C[i] = (1 - A[i]) / th**2
    shape = np.shape(theta)
    return tuple(np.array(c).reshape(shape)[..., None, None] for c in (A, B, C))


def _rodrigues(w) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """``(R, V, W, small)`` of rotation vectors ``w (..., 3)``: ``R = Exp(w)``, ``V`` the SE(3) left Jacobian."""
    theta = _norm3(w)
    W = hat(w)
    WW = np.einsum("...ij,...jk->...ik", W, W)
    A, B, C = _exp_coefficients(theta)
    eye = np.eye(3)
    small = (theta < _SMALL_RAD)[..., None, None]
    R = np.where(small, eye + W, eye + A * W + B * WW)
    V = np.where(small, eye + 0.5 * W, eye + B * W + C * WW)
    return R, V, W, small


def so3_exp(w) -> np.ndarray:
    """Rotation matrix ``Exp(w) = I + sin θ/θ [w]× + (1 − cos θ)/θ² [w]×²`` of a rotation vector (Rodrigues; ModernRobotics §3.2.3).

    Parameters
    ----------
    w : array_like, shape (3,) or (..., 3)
        Rotation vectors ``θ n`` [rad] (axis ``n``, angle ``θ``).

    Returns
    -------
    ndarray, shape (3, 3) or (..., 3, 3)
        Rotation matrices; ``I + [w]×`` below an angle of 1e-10 rad.

    Examples
    --------
    >>> so3_exp([0.0, 0.0, np.pi / 2]).round(12)
    array([[ 0., -1.,  0.],
           [ 1.,  0.,  0.],
           [ 0.,  0.,  1.]])
    """
    w = _last_axis(w, "w", 3)
    return _rodrigues(w)[0]


def _angle_parts(R) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """``(d, c, s, θ)`` of rotations ``R (..., 3, 3)``: ``d = vee(R − Rᵀ)``, ``c = cos θ``, ``s = sin θ``, ``θ = atan2(s, c)``."""
    d = np.stack([R[..., 2, 1] - R[..., 1, 2], R[..., 0, 2] - R[..., 2, 0], R[..., 1, 0] - R[..., 0, 1]], axis=-1)
    c = 0.5 * (R[..., 0, 0] + R[..., 1, 1] + R[..., 2, 2] - 1.0)
    s = 0.5 * _norm3(d)
    return d, c, s, np.arctan2(s, np.clip(c, -1.0, 1.0))


def rotation_angle(R) -> np.ndarray:
    """Angle ``θ = |Log(R)|`` of rotation matrices, in ``[0, π]`` (ModernRobotics §3.2.3.3).

    ``θ = atan2(|vee(R − Rᵀ)| / 2, (tr R − 1) / 2)`` (the angle of :func:`so3_log`): accurate at every angle,
    where ``arccos((tr R − 1) / 2)`` loses half the digits near 0 and π (ours: the careful form). ``R`` must
    be a rotation to working precision; project a matrix that is not (one read from a file with 9 digits,
    say) onto SO(3) first.

    Parameters
    ----------
    R : array_like, shape (3, 3) or (..., 3, 3)
        Rotation matrices (orthonormal, determinant +1; not checked).

    Returns
    -------
    float or ndarray, shape (...)
        Rotation angles [rad]; a NumPy scalar for one matrix.

    Examples
    --------
    >>> float(rotation_angle(so3_exp([0.0, 0.3, 0.4])).round(12))
    0.5
    >>> rotation_angle(np.stack([np.eye(3), so3_exp([0.0, 0.0, np.pi / 2])])).round(12)
    array([0.        , 1.57079633])
    """
    return _angle_parts(_last_two_axes(R, "R", 3))[3]


def so3_log(R) -> np.ndarray:
    """Rotation vector ``w`` with ``Exp(w) = R``, angle in ``[0, π]`` (ModernRobotics §3.2.3.3).

    ``θ = atan2(|vee(R − Rᵀ)| / 2, (tr R − 1) / 2)``; ``w = θ / (2 sin θ) vee(R − Rᵀ)``, with the
    series ``(1 + θ²/6) / 2`` for the factor at small angles and, near ``θ = π`` (``cos θ < −0.9``),
    the axis from the largest column of ``(R + Rᵀ)/2 − cos θ I = (1 − cos θ) n nᵀ``, signed by
    ``vee(R − Rᵀ)`` (ours: accurate where ``sin θ`` vanishes).

    Parameters
    ----------
    R : array_like, shape (3, 3) or (..., 3, 3)
        Rotation matrices (orthonormal, determinant +1; not checked).

    Returns
    -------
    ndarray, shape (3,) or (..., 3)
        Rotation vectors [rad].

    Examples
    --------
    >>> so3_log(so3_exp([0.1, -0.2, 0.3])).round(12)
    array([ 0.1, -0.2,  0.3])
    """
    R = _last_two_axes(R, "R", 3)
    d, c, s, theta = _angle_parts(R)
    t2 = theta * theta
    factor = np.where(theta < 1e-4, 0.5 * (1.0 + t2 / 6.0), theta / (2.0 * np.where(s > 0, s, 1.0)))
    w = factor[..., None] * d
    near_pi = c < -0.9
    if np.any(near_pi):
        S = 0.5 * (R + np.swapaxes(R, -1, -2)) - c[..., None, None] * np.eye(3)
        k = np.argmax(np.stack([S[..., 0, 0], S[..., 1, 1], S[..., 2, 2]], axis=-1), axis=-1)
        col = np.take_along_axis(S, k[..., None, None], axis=-1)[..., 0]
        n = col / np.maximum(_norm3(col), 1e-300)[..., None]
        sign = np.where(np.einsum("...i,...i->...", n, d) < 0, -1.0, 1.0)
        w = np.where(near_pi[..., None], (sign * theta)[..., None] * n, w)
    return w


def se3_exp(xi) -> np.ndarray:
    """4×4 transform ``exp([v, ω]^) = [[Exp(ω), V v], [0, 1]]`` of a twist ``ξ = (v, ω)`` (closed form; ModernRobotics §3.3.3).

    Parameters
    ----------
    xi : array_like, shape (6,) or (..., 6)
        Twists: translation part ``v`` [m] first, rotation vector ``ω`` [rad] last.

    Returns
    -------
    ndarray, shape (4, 4) or (..., 4, 4)
        Homogeneous transforms.

    Examples
    --------
    >>> np.allclose(se3_exp(np.zeros(6)), np.eye(4))
    True
    >>> se3_exp([1.0, 0.0, 0.0, 0.0, 0.0, np.pi / 2])[:3, 3].round(12)
    array([0.63661977, 0.63661977, 0.        ])
    """
    xi = _last_axis(xi, "xi", 6)
    R, V, _, _ = _rodrigues(xi[..., 3:])
    T = np.zeros((*xi.shape[:-1], 4, 4))
    T[..., :3, :3] = R
    T[..., :3, 3] = np.einsum("...ij,...j->...i", V, xi[..., :3])
    T[..., 3, 3] = 1.0
    return T


def se3_log(T) -> np.ndarray:
    """Twist ``ξ = (v, ω)`` with ``se3_exp(ξ) = T`` (ModernRobotics §3.3.3.2).

    ``ω = Log(R)``, ``v = V⁻¹ t`` with ``V⁻¹ = I − ½[ω]× + (1 − A / (2B)) / θ² [ω]×²``
    (the coefficient tends to 1/12 at small angles).

    Parameters
    ----------
    T : array_like, shape (4, 4) or (..., 4, 4)
        Rigid transforms (the last row is not read).

    Returns
    -------
    ndarray, shape (6,) or (..., 6)
        Twists, translation part first.

    Examples
    --------
    >>> xi = np.array([0.3, -0.1, 0.2, 0.1, 0.2, -0.3])
    >>> np.allclose(se3_log(se3_exp(xi)), xi)
    True
    """
    T = _last_two_axes(T, "T", 4)
    w = so3_log(T[..., :3, :3])
    theta = _norm3(w)
    W = hat(w)
    WW = np.einsum("...ij,...jk->...ik", W, W)
    A, B, _ = _exp_coefficients(theta)
    t2 = (theta * theta)[..., None, None]
    big = (theta >= 1e-4)[..., None, None]
    D = np.where(big, (1.0 - A / (2.0 * np.where(big, B, 1.0))) / np.where(big, t2, 1.0), 1.0 / 12.0 + t2 / 720.0)
    V_inv = np.eye(3) - 0.5 * W + D * WW
    v = np.einsum("...ij,...j->...i", V_inv, T[..., :3, 3])
    return np.concatenate([v, w], axis=-1)
