"""Midpoint triangulation of two viewing rays (000 §3.3).

000 §3.3: for a point seen by both cameras, build the viewing ray of each
camera, then "a vector orthogonal to both rays; the middle of it is taken as
their intersection". With rays ``c1 + s d1`` and ``c2 + t d2`` the closest
points satisfy (``w = c1 - c2``, ``a = d1·d1``, ``b = d1·d2``, ``c = d2·d2``,
``d = d1·w``, ``e = d2·w``)::

    s = (b e - c d) / (a c - b²),   t = (a e - b d) / (a c - b²)

and the landmark is ``((c1 + s d1) + (c2 + t d2)) / 2``.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from .._validate import as_finite_array

__all__ = ["Triangulation", "triangulate_midpoint", "triangulate_stereo"]


class Triangulation(NamedTuple):
    """Result of :func:`triangulate_midpoint`.

    ``points`` (N, 3) midpoints; ``gap_m`` (N,) length of the common perpendicular;
    ``s, t`` (N,) ray parameters; ``valid`` (N,) both parameters positive and the
    rays not parallel.

    Attributes
    ----------
    points : ndarray, shape (N, 3)
        Midpoints of the common perpendiculars [m].
    gap_m : ndarray, shape (N,)
        Length of the common perpendicular [m].
    s, t : ndarray, shape (N,)
        Ray parameters of the closest points on ray 1 and ray 2.
    valid : ndarray of bool, shape (N,)
        Both parameters positive and the rays not parallel.
    """

    points: np.ndarray
    gap_m: np.ndarray
    s: np.ndarray
    t: np.ndarray
    valid: np.ndarray


def _rays(x, name, n=None):
    x = as_finite_array(x, name)
    if x.ndim == 1:
        if x.shape != (3,):
            raise ValueError(f"`{name}` must have shape (3,) or (N, 3); got {x.shape}")
        x = np.broadcast_to(x, (1 if n is None else n, 3))
    elif x.ndim != 2 or x.shape[1] != 3:
        raise ValueError(f"`{name}` must have shape (3,) or (N, 3); got {x.shape}")
    return x


def triangulate_midpoint(c1, d1, c2, d2, *, parallel_tol: float = 1e-12) -> Triangulation:
    """Midpoint of the common perpendicular of rays ``c1 + s d1`` and ``c2 + t d2`` (000 §3.3).

    Parameters
    ----------
    c1, c2 : (3,) or (N, 3) ray origins (optical centres).
    d1, d2 : (N, 3) ray directions (any length, not zero).
    parallel_tol : rays with ``1 - cos²(angle) <= parallel_tol`` count as parallel (``valid`` False,
        the point is then the midpoint of ``c1`` and ``c2``).

    Examples
    --------
    >>> r = triangulate_midpoint([0, 0, 0], [[0, 0, 1.0]], [1.0, 0, 0], [[-1.0, 0, 1.0]])
    >>> r.points, r.valid
    (array([[0., 0., 1.]]), array([ True]))
    """
    d1 = _rays(d1, "d1")
    n = d1.shape[0]
    d2 = _rays(d2, "d2", n)
    if d2.shape[0] != n:
        raise ValueError(f"`d1` and `d2` must have the same number of rows; got {n} and {d2.shape[0]}")
    c1 = _rays(c1, "c1", n)
    c2 = _rays(c2, "c2", n)
    if c1.shape[0] != n or c2.shape[0] != n:
        raise ValueError(f"`c1` and `c2` must have shape (3,) or ({n}, 3)")
    w = c1 - c2
    a = np.einsum("ij,ij->i", d1, d1)
    b = np.einsum("ij,ij->i", d1, d2)
    c = np.einsum("ij,ij->i", d2, d2)
    if np.any(a == 0) or np.any(c == 0):
        raise ValueError("`d1` and `d2` must not contain zero-length directions")
    d = np.einsum("ij,ij->i", d1, w)
    e = np.einsum("ij,ij->i", d2, w)
    denom = a * c - b * b
    ok = denom > parallel_tol * a * c
    safe = np.where(ok, denom, 1.0)
    # closest-point parameters on each ray
    s = np.where(ok, (b * e - c * d) / safe, 0.0)
    t = np.where(ok, (a * e - b * d) / safe, 0.0)
    p1 = c1 + s[:, None] * d1
    p2 = c2 + t[:, None] * d2
    gap = np.linalg.norm(p1 - p2, axis=1)
    return Triangulation(0.5 * (p1 + p2), gap, s, t, ok & (s > 0) & (t > 0))


def triangulate_stereo(rig, uv_left, uv_right) -> Triangulation:
    """Landmarks in the left camera frame from matched pixels of a :class:`StereoRig` (000 §3.3).

    Parameters
    ----------
    rig : StereoRig
        The calibrated rig.
    uv_left, uv_right : array_like, shape (N, 2)
        Matched pixel coordinates in the left and right images.

    Returns
    -------
    Triangulation
        ``points`` (N, 3) in the left camera frame [m], ``gap_m``, ``valid``.

    Examples
    --------
    >>> from slamlab.geometry.camera import StereoRig
    >>> rig = StereoRig.parallel(0.2)
    >>> uvl, uvr = rig.project([[0.3, -0.1, 2.5]])
    >>> np.round(triangulate_stereo(rig, uvl, uvr).points, 9)
    array([[ 0.3, -0.1,  2.5]])
    """
    c1, d1, c2, d2 = rig.rays(uv_left, uv_right)
    return triangulate_midpoint(c1, d1, c2, d2)
