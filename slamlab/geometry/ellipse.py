"""Covariance ellipses (compute only; drawing lives in the plot modules)."""

from __future__ import annotations

import numpy as np

from .._validate import as_covariance, as_vector, check_int, check_positive

__all__ = ["covariance_ellipse"]


def covariance_ellipse(P, center=(0.0, 0.0), n_std: float = 2.0, n_points: int = 64) -> np.ndarray:
    """Points ``(n_points, 2)`` of the ``n_std``-sigma ellipse of a 2x2 covariance around ``center``.

    Parameters
    ----------
    P : array_like, shape (2, 2)
        Covariance matrix (symmetric positive semi-definite).
    center : array_like, shape (2,)
        Centre of the ellipse (default the origin).
    n_std : float
        Size of the ellipse in standard deviations (default 2).
    n_points : int
        Number of points on the outline, at least 3 (default 64).

    Returns
    -------
    points : ndarray, shape (n_points, 2)
        Outline points (not closed: the first point is not repeated).

    Examples
    --------
    >>> pts = covariance_ellipse(np.diag([4.0, 1.0]), n_std=1.0, n_points=8)
    >>> np.abs(pts).max(axis=0).round(6)  # semi-axes: 1 sigma = 2 in x, 1 in y
    array([2., 1.])
    """
    P = as_covariance(P, "P", 2)
    c = as_vector(center, "center", 2)
    n_std = check_positive(n_std, "n_std")
    n_points = check_int(n_points, "n_points", minimum=3)
    w, U = np.linalg.eigh(P)
    t = np.linspace(0.0, 2.0 * np.pi, n_points, endpoint=False)
    circle = np.stack([np.cos(t), np.sin(t)], axis=1)
    return c + n_std * (circle * np.sqrt(np.maximum(w, 0.0))) @ U.T
