"""The odometry motion model (PR Tables 5.5, 5.6; 003 §2.2) and the particle check shared by the filters.

Moved unchanged from :mod:`slamlab.localisation.models` (which re-exports every name). Lengths in cells, angles in
radians.
"""

from __future__ import annotations

import numpy as np

from .._validate import as_rng
from ..geometry import wrap_angle

__all__ = ["check_alpha", "check_particles", "motion_density_odometry", "motion_from_noise", "odometry_deltas",
           "sample_motion_odometry"]


def check_particles(poses, name: str = "particles") -> np.ndarray:
    """Particles as a finite ``(N, 3)`` float array with ``N >= 1`` (a NaN pose is a ValueError).

    Parameters
    ----------
    poses : array_like, shape (N, 3) or (3,)
        Poses ``(x, y, θ)``; one pose becomes ``(1, 3)``.
    name : str
        The argument's name in the error message.

    Returns
    -------
    ndarray, shape (N, 3)
        The poses as floats.
    """
    P = np.asarray(poses, dtype=float)
    if P.ndim == 1 and P.shape == (3,):
        P = P[None, :]
    if P.ndim != 2 or P.shape[1] != 3:
        raise ValueError(f"`{name}` must have shape (N, 3) = (x, y, heading) rows; got shape {P.shape}")
    if P.shape[0] == 0:
        raise ValueError(f"`{name}` must hold at least one pose; got 0")
    if not np.all(np.isfinite(P)):
        raise ValueError(f"`{name}` must be finite; got {int((~np.isfinite(P)).any(axis=1).sum())} pose(s) "
                         "with NaN or inf")
    return P


def check_alpha(alpha, name: str = "alpha") -> np.ndarray:
    """The odometry motion model's noise parameters α1…α4 as a checked ``(4,)`` float array (PR Tables 5.5-5.6).

    Parameters
    ----------
    alpha : sequence of 4 float
        α1 (rotation from rotation), α2 (rotation from translation), α3 (translation from translation),
        α4 (translation from rotation); finite and >= 0.
    name : str
        The argument's name in the error message.

    Returns
    -------
    ndarray, shape (4,)
        The four values as floats.

    Examples
    --------
    >>> check_alpha((0.1, 0, 0.1, 0)).tolist()
    [0.1, 0.0, 0.1, 0.0]
    """
    try:
        a = np.asarray(alpha, dtype=float)
    except (TypeError, ValueError):
        a = np.full(1, np.nan)
    if a.shape != (4,) or not np.all(np.isfinite(a)) or np.any(a < 0):
        raise ValueError(f"`{name}` must be four finite numbers >= 0 (α1…α4); got {alpha!r}")
    return a


def odometry_deltas(odom_prev, odom_now, *, min_trans: float = 1e-6):
    """Odometry reading ``(x̄_{t-1}, x̄_t)`` → ``(δrot1, δtrans, δrot2)`` (PR Table 5.5 lines 2-4).

    Below ``min_trans`` the first rotation is taken as 0 (the heading of a tiny
    translation is noise; ROS AMCL does the same with 0.01 m). Works on arrays of
    poses too (``(..., 3)``).

    Parameters
    ----------
    odom_prev, odom_now : array_like, shape (..., 3)
        Odometry poses before and after the motion.
    min_trans : float
        Below this translation the first rotation is 0.

    Returns
    -------
    tuple of (float or ndarray)
        ``(δrot1, δtrans, δrot2)``.

    Examples
    --------
    >>> [round(float(d), 6) for d in odometry_deltas([0, 0, 0], [1, 1, np.pi / 2])]
    [0.785398, 1.414214, 0.785398]
    """
    a = np.asarray(odom_prev, dtype=float)
    b = np.asarray(odom_now, dtype=float)
    if a.shape[-1:] != (3,) or b.shape[-1:] != (3,):
        raise ValueError(f"odometry poses must have shape (..., 3); got {a.shape} and {b.shape}")
    if not (np.all(np.isfinite(a)) and np.all(np.isfinite(b))):
        raise ValueError("odometry poses must be finite; got NaN or inf")
    dx, dy = b[..., 0] - a[..., 0], b[..., 1] - a[..., 1]
    trans = np.hypot(dx, dy)
    rot1 = np.where(trans < min_trans, 0.0, wrap_angle(np.arctan2(dy, dx) - a[..., 2]))
    rot2 = wrap_angle(b[..., 2] - a[..., 2] - rot1)
    return rot1, trans, rot2


def sample_motion_odometry(poses, odom_prev, odom_now, alpha, rng=None) -> np.ndarray:
    """Move every particle by a noisy copy of the odometry reading (PR Table 5.6, vectorised).

    ``δ̂rot1 = δrot1 − ε(α1·δrot1² + α2·δtrans²)``,
    ``δ̂trans = δtrans − ε(α3·δtrans² + α4·δrot1² + α4·δrot2²)``,
    ``δ̂rot2 = δrot2 − ε(α1·δrot2² + α2·δtrans²)``, with ``ε(b²)`` a zero-mean
    normal draw of variance ``b²``; then ``x' = x + δ̂trans·cos(θ + δ̂rot1)``,
    ``y' = y + δ̂trans·sin(θ + δ̂rot1)``, ``θ' = θ + δ̂rot1 + δ̂rot2``.

    Parameters
    ----------
    poses : array_like, shape (N, 3)
    odom_prev, odom_now : array_like, shape (3,)
        Two consecutive odometry poses (only their difference matters).
    alpha : sequence of 4 floats
        α1 (rot from rot), α2 (rot from trans), α3 (trans from trans), α4 (trans from rot).
    rng : Generator, int or None

    Examples
    --------
    >>> sample_motion_odometry([[0, 0, 0]], [0, 0, 0], [2, 0, 0], [0, 0, 0, 0]).tolist()
    [[2.0, 0.0, 0.0]]
    """
    P = check_particles(poses, "poses")
    a = check_alpha(alpha)
    rot1, trans, rot2 = (float(d) for d in odometry_deltas(odom_prev, odom_now))
    rng = as_rng(rng)
    return motion_from_noise(P, (rot1, trans, rot2), a, rng.standard_normal((3, P.shape[0])))


def motion_from_noise(P, deltas, a, e) -> np.ndarray:
    """PR Table 5.6 lines 5-10 with given standard-normal draws ``e`` (3, N): the deterministic core.

    Parameters
    ----------
    P : ndarray, shape (N, 3)
        Poses before the motion.
    deltas : tuple
        ``(δrot1, δtrans, δrot2)`` of the odometry reading (:func:`odometry_deltas`).
    a : sequence of 4 float
        α1…α4.
    e : ndarray, shape (3, N)
        Standard-normal draws for the three perturbed quantities.

    Returns
    -------
    ndarray, shape (N, 3)
        The moved poses.
    """
    rot1, trans, rot2 = deltas
    # PR Table 5.6 lines 5-7 (variances; errata form)
    r1 = rot1 - np.sqrt(a[0] * rot1**2 + a[1] * trans**2) * e[0]
    tr = trans - np.sqrt(a[2] * trans**2 + a[3] * (rot1**2 + rot2**2)) * e[1]
    r2 = rot2 - np.sqrt(a[0] * rot2**2 + a[1] * trans**2) * e[2]
    # lines 8-10
    h = P[:, 2] + r1
    return np.column_stack([P[:, 0] + tr * np.cos(h), P[:, 1] + tr * np.sin(h), wrap_angle(h + r2)])


def _normal_pdf(x, var):
    with np.errstate(divide="ignore", invalid="ignore"):
        out = np.exp(-0.5 * x * x / var) / np.sqrt(2 * np.pi * var)
    # a zero variance is a point mass: density 0 off it (and inf on it, which we cap at a large number)
    return np.where(var > 0, out, np.where(x == 0, 1e300, 0.0))


def motion_density_odometry(poses_now, poses_prev, odom_prev, odom_now, alpha) -> np.ndarray:
    """``p(x_t | u_t, x_{t-1})`` of the odometry model (PR Table 5.5), for arrays of pose pairs.

    Parameters
    ----------
    poses_now, poses_prev : array_like, shape (N, 3)
        Pose pairs ``x_t`` and ``x_{t-1}``.
    odom_prev, odom_now : array_like, shape (3,)
        The odometry reading.
    alpha : sequence of 4 float
        α1…α4.

    Returns
    -------
    ndarray, shape (N,)
        The density of each pair.

    Examples
    --------
    >>> p = motion_density_odometry([[1, 0, 0]], [[0, 0, 0]], [0, 0, 0], [1, 0, 0], [0.1, 0.1, 0.1, 0.1])
    >>> round(float(p[0]), 6)  # = N(0; 0.1)·N(0; 0.1)·N(0; 0.1)
    2.007845
    """
    X1 = check_particles(poses_now, "poses_now")
    X0 = check_particles(poses_prev, "poses_prev")
    if X1.shape != X0.shape:
        raise ValueError(f"`poses_now` and `poses_prev` must have the same shape; got {X1.shape} and {X0.shape}")
    a = check_alpha(alpha)
    rot1, trans, rot2 = odometry_deltas(odom_prev, odom_now)
    h1, ht, h2 = odometry_deltas(X0, X1)
    p1 = _normal_pdf(wrap_angle(rot1 - h1), a[0] * h1**2 + a[1] * ht**2)
    p2 = _normal_pdf(trans - ht, a[2] * ht**2 + a[3] * (h1**2 + h2**2))
    p3 = _normal_pdf(wrap_angle(rot2 - h2), a[0] * h2**2 + a[1] * ht**2)
    return p1 * p2 * p3


# --- the beams a filter uses ---------------------------------------------------------------------------
