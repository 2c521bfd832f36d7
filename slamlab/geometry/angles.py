"""Angles: the one ``wrap_angle`` of slamlab and a circular mean."""

from __future__ import annotations

import numpy as np

__all__ = ["angle_mean", "wrap_angle"]


def wrap_angle(angle_rad):
    """Wrap angles to ``[-pi, pi)``; works element-wise on arrays.

    Parameters
    ----------
    angle_rad : float or array_like
        Angle(s) [rad], any shape.

    Returns
    -------
    wrapped : float or ndarray
        Same shape as ``angle_rad``, each value in ``[-pi, pi)``.

    Examples
    --------
    >>> float(wrap_angle(3 * np.pi / 2))
    -1.5707963267948966
    """
    return np.mod(np.asarray(angle_rad, dtype=float) + np.pi, 2.0 * np.pi) - np.pi


def angle_mean(angles_rad, weights=None, axis: int = 0, ref=None):
    """Weighted mean of angles.

    Without ``ref``: the circular mean ``atan2(sum w sin a, sum w cos a)``.
    With ``ref``: the mean taken in the chart around ``ref``,
    ``ref + sum w wrap(a - ref)`` (weights summing to 1). The unscented
    transform needs the second: with a small ``alpha`` its weights reach
    ``-10^6`` and the sin/cos sums approximate ``E[cos a] ~ 1 - sigma^2/2``,
    which turns negative (the mean flips by 180 deg) once ``sigma > sqrt(2)`` rad.

    Parameters
    ----------
    angles_rad : array_like
        Angles [rad]; the mean is taken along ``axis``.
    weights : array_like, shape (n,), optional
        One weight per angle along ``axis``; ``None`` = equal weights. With ``ref`` they should sum to 1
        (they may be negative, as unscented-transform weights are).
    axis : int
        Axis of ``angles_rad`` to average over (default 0).
    ref : float or array_like, optional
        Reference angle [rad] for the chart mean; ``None`` = circular mean. An array holds one reference
        per mean (the shape of ``angles_rad`` without ``axis``).

    Returns
    -------
    mean : ndarray or float
        Mean angle(s) [rad] in ``[-pi, pi]``.

    Examples
    --------
    >>> float(angle_mean(np.array([np.pi - 0.1, -np.pi + 0.1])))
    3.141592653589793
    >>> float(angle_mean(np.array([np.pi - 0.1, -np.pi + 0.3]), np.array([0.5, 0.5]), ref=np.pi))
    -3.041592653589793
    """
    a = np.asarray(angles_rad, dtype=float)
    if ref is not None:
        d = wrap_angle(a - np.expand_dims(ref, axis) if np.ndim(ref) else a - ref)
        m = d.mean(axis=axis) if weights is None else np.tensordot(np.asarray(weights, float), d, axes=(0, axis))
        return wrap_angle(np.asarray(ref, dtype=float) + m)
    if weights is None:
        s, c = np.sin(a).sum(axis=axis), np.cos(a).sum(axis=axis)
    else:
        w = np.asarray(weights, dtype=float)
        s = np.tensordot(w, np.sin(a), axes=(0, axis))
        c = np.tensordot(w, np.cos(a), axes=(0, axis))
    return np.arctan2(s, c)
