"""Planar rigid motions SE(2) on pose arrays ``(x, y, heading_rad)``: one batched implementation.

API summary
-----------
- :func:`se2_compose` ``(a, b) -> a ⊕ b``: pose ``b`` given in ``a``'s frame, seen in the world.
- :func:`se2_inverse` ``(a) -> a⁻¹``.
- :func:`se2_relative` ``(a, b) -> a⁻¹ ⊕ b``: ``b`` in ``a``'s frame (odometry increments).
- :func:`se2_transform` ``(pose, points) -> (…, 2)``: body-frame points to the world.
- :func:`se2_integrate` ``(start, increments) -> (n + 1, 3)``: cumulative composition
  ``p_{k+1} = p_k ⊕ u_k``, vectorised (no Python loop).
- :func:`check_pose`, :func:`check_poses`: argument checks for ``(3,)`` and ``(n, 3)`` arrays.

Every function broadcasts over leading axes: a pose is ``(3,)`` or ``(..., 3)``.
Headings come back wrapped to ``[-π, π)`` by :func:`slamlab.geometry.wrap_angle`,
except in :func:`se2_integrate` with ``wrap=False`` (an unwrapped heading track).
The maths (pose ``a = (t_a, θ_a)``, ``R(θ)`` the rotation)::

    a ⊕ b  = (t_a + R(θ_a)·t_b,  θ_a + θ_b)
    a⁻¹    = (-R(θ_a)ᵀ·t_a,      -θ_a)
    a⁻¹ ⊕ b = (R(θ_a)ᵀ·(t_b - t_a),  θ_b - θ_a)

These functions are the strict core: they convert with ``numpy.asarray`` and
check only the last axis; public functions of the chapters call
:func:`check_pose` / :func:`check_poses` once on entry.
"""

from __future__ import annotations

import numpy as np

from .._validate import as_finite_array, as_vector
from .angles import wrap_angle

__all__ = ["check_pose", "check_poses", "se2_compose", "se2_integrate", "se2_inverse", "se2_relative",
           "se2_transform"]


def check_pose(pose, name: str = "pose") -> np.ndarray:
    """A finite pose ``(x, y, heading_rad)`` as a float vector of length 3.

    Parameters
    ----------
    pose : array_like, shape (3,)
        ``(x, y, heading_rad)``.
    name : str
        Argument name used in the error message (default ``"pose"``).

    Returns
    -------
    pose : ndarray, shape (3,)
        The pose as floats; ``ValueError`` when not finite or not of length 3.

    Examples
    --------
    >>> check_pose([1, 2, 0.5])
    array([1. , 2. , 0.5])
    """
    return as_vector(pose, name, 3)


def check_poses(poses, name: str = "poses", *, n: int | None = None) -> np.ndarray:
    """Finite poses as a float ``(n, 3)`` array of ``(x, y, heading_rad)`` rows (at least one).

    Parameters
    ----------
    poses : array_like, shape (n, 3)
        ``(x, y, heading_rad)`` rows.
    name : str
        Argument name used in the error messages (default ``"poses"``).
    n : int, optional
        Required number of rows; ``None`` = any number of at least one.

    Returns
    -------
    poses : ndarray, shape (n, 3)
        The poses as floats.

    Examples
    --------
    >>> check_poses([[0, 0, 0], [1, 2, 3]]).shape
    (2, 3)
    >>> check_poses([0, 0, 0])
    Traceback (most recent call last):
    ...
    ValueError: `poses` must have shape (n, 3) = (x, y, heading_rad) rows; got shape (3,)
    """
    arr = as_finite_array(poses, name)
    if arr.ndim != 2 or arr.shape[1] != 3:
        raise ValueError(f"`{name}` must have shape (n, 3) = (x, y, heading_rad) rows; got shape {arr.shape}")
    if arr.shape[0] == 0:
        raise ValueError(f"`{name}` must hold at least one pose; got shape {arr.shape}")
    if n is not None and arr.shape[0] != n:
        raise ValueError(f"`{name}` must have {n} rows (one per scan/step); got {arr.shape[0]}")
    return arr


def _poses(a, name):
    arr = np.asarray(a, dtype=float)
    if arr.ndim == 0 or arr.shape[-1] != 3:
        raise ValueError(f"`{name}` must have shape (3,) or (..., 3) = (x, y, heading_rad); got shape {arr.shape}")
    return arr


def se2_compose(a, b) -> np.ndarray:
    """``a ⊕ b``: the pose ``b``, given in the frame of pose ``a``, in the world frame.

    Parameters
    ----------
    a, b : array_like, shape (..., 3)
        Poses ``(x, y, heading_rad)``; leading axes broadcast.

    Returns
    -------
    numpy.ndarray, shape (..., 3)
        Heading wrapped to ``[-π, π)``.

    Examples
    --------
    >>> se2_compose([1.0, 2.0, np.pi / 2], [3.0, 0.0, 0.1]).round(12).tolist()
    [1.0, 5.0, 1.670796326795]
    >>> se2_compose([[0, 0, 0], [1, 0, np.pi]], [1, 0, 0]).round(12).tolist()
    [[1.0, 0.0, 0.0], [0.0, 0.0, -3.14159265359]]
    """
    A, B = _poses(a, "a"), _poses(b, "b")
    c, s = np.cos(A[..., 2]), np.sin(A[..., 2])
    x = A[..., 0] + c * B[..., 0] - s * B[..., 1]
    y = A[..., 1] + s * B[..., 0] + c * B[..., 1]
    return np.stack(np.broadcast_arrays(x, y, wrap_angle(A[..., 2] + B[..., 2])), axis=-1)


def se2_inverse(a) -> np.ndarray:
    """``a⁻¹``: the world origin seen from pose ``a``, so that ``a ⊕ a⁻¹ = 0``.

    Parameters
    ----------
    a : array_like, shape (..., 3)
        Pose(s) ``(x, y, heading_rad)``.

    Returns
    -------
    inverse : ndarray, shape (..., 3)
        Heading wrapped to ``[-pi, pi)``.

    Examples
    --------
    >>> se2_inverse([1.0, 0.0, np.pi / 2]).round(12).tolist()
    [-0.0, 1.0, -1.570796326795]
    """
    A = _poses(a, "a")
    c, s = np.cos(A[..., 2]), np.sin(A[..., 2])
    x = -(c * A[..., 0] + s * A[..., 1])
    y = s * A[..., 0] - c * A[..., 1]
    return np.stack([x, y, wrap_angle(-A[..., 2])], axis=-1)


def se2_relative(a, b) -> np.ndarray:
    """``a⁻¹ ⊕ b``: pose ``b`` in the frame of pose ``a`` (the body-frame increment from ``a`` to ``b``).

    Parameters
    ----------
    a, b : array_like, shape (..., 3)
        Poses ``(x, y, heading_rad)``; leading axes broadcast.

    Returns
    -------
    relative : ndarray, shape (..., 3)
        ``b`` in the frame of ``a``; heading wrapped to ``[-pi, pi)``.

    Examples
    --------
    >>> se2_relative([0.0, 0.0, np.pi / 2], [0.0, 2.0, np.pi]).round(12).tolist()
    [2.0, 0.0, 1.570796326795]
    """
    A, B = _poses(a, "a"), _poses(b, "b")
    c, s = np.cos(A[..., 2]), np.sin(A[..., 2])
    dx, dy = B[..., 0] - A[..., 0], B[..., 1] - A[..., 1]
    return np.stack(np.broadcast_arrays(c * dx + s * dy, -s * dx + c * dy, wrap_angle(B[..., 2] - A[..., 2])),
                    axis=-1)


def se2_transform(pose, points) -> np.ndarray:
    """Body-frame points ``(x, y)`` seen from ``pose`` → world points: ``t + R(θ)·p``.

    Parameters
    ----------
    pose : array_like, shape (3,) or (..., 3)
    points : array_like, shape (..., 2)
        With a single pose, any number of leading axes; with a batch of poses, the
        leading axes of ``points`` broadcast against ``pose[..., None, :]`` when
        given as ``(..., k, 2)``.

    Examples
    --------
    >>> se2_transform([1.0, 1.0, np.pi / 2], [[2.0, 0.0], [0.0, 1.0]]).round(12).tolist()
    [[1.0, 3.0], [0.0, 1.0]]
    """
    P = _poses(pose, "pose")
    X = np.asarray(points, dtype=float)
    if X.ndim == 0 or X.shape[-1] != 2:
        raise ValueError(f"`points` must have shape (..., 2); got shape {X.shape}")
    if P.ndim > 1:
        P = P[..., None, :]
    c, s = np.cos(P[..., 2]), np.sin(P[..., 2])
    return np.stack([P[..., 0] + c * X[..., 0] - s * X[..., 1], P[..., 1] + s * X[..., 0] + c * X[..., 1]], axis=-1)


def se2_integrate(start, increments, *, wrap: bool = True) -> np.ndarray:
    """Cumulative composition ``p_0 = start``, ``p_{k+1} = p_k ⊕ u_k``, vectorised.

    Headings are cumulative sums; each increment's translation is rotated by the
    heading before it and the translations summed (no per-step loop).

    Parameters
    ----------
    start : array_like, shape (3,)
    increments : array_like, shape (n, 3)
        Body-frame ``(dx, dy, dθ)``.
    wrap : bool
        Wrap the headings to ``[-π, π)`` (default) or keep the unwrapped sum.

    Returns
    -------
    numpy.ndarray, shape (n + 1, 3)

    Examples
    --------
    >>> se2_integrate([0, 0, np.pi / 2], [[2, 0, np.pi / 4]]).round(12).tolist()
    [[0.0, 0.0, 1.570796326795], [0.0, 2.0, 2.356194490192]]
    """
    p0 = _poses(start, "start")
    U = np.asarray(increments, dtype=float)
    if p0.shape != (3,):
        raise ValueError(f"`start` must have shape (3,); got shape {p0.shape}")
    if U.ndim != 2 or U.shape[1] != 3:
        raise ValueError(f"`increments` must have shape (n, 3) = (dx, dy, dθ) rows; got shape {U.shape}")
    th = p0[2] + np.concatenate([[0.0], np.cumsum(U[:, 2])])
    steps = se2_transform(np.column_stack([np.zeros((U.shape[0], 2)), th[:-1]]), U[:, None, :2])[:, 0]
    xy = p0[:2] + np.concatenate([np.zeros((1, 2)), np.cumsum(steps, axis=0)])
    return np.column_stack([xy, wrap_angle(th) if wrap else th])
