"""SE(3) pose helpers as 4×4 homogeneous matrices (000 §3.5; our helpers).

000 estimates a rotation and a translation (6 degrees of freedom is our
reading); the robot drives on a floor, so the pose is reported as planar
``(x, y, yaw)`` — :func:`yaw_from_R` and :func:`planar_from_se3`.
"""

from __future__ import annotations

import numpy as np

from .._validate import as_finite_array, as_matrix, as_vector

__all__ = ["planar_from_se3", "rotate_points", "se3", "se3_compose", "se3_from_planar", "se3_inverse", "transform_points",
           "yaw_from_R"]


def se3(R, t) -> np.ndarray:
    """4×4 matrix from rotation ``R`` (3, 3) and translation ``t`` (3,).

    Parameters
    ----------
    R : array_like, shape (3, 3)
        Rotation.
    t : array_like, shape (3,)
        Translation [m].

    Returns
    -------
    T : ndarray, shape (4, 4)
        Homogeneous transform.

    Examples
    --------
    >>> se3(np.eye(3), [1.0, 2.0, 3.0])[:3, 3]
    array([1., 2., 3.])
    """
    R = as_matrix(R, "R", (3, 3))
    t = as_vector(t, "t", 3)
    T = np.eye(4)
    T[:3, :3], T[:3, 3] = R, t
    return T


def se3_inverse(T) -> np.ndarray:
    """Inverse of rigid 4×4 transforms, ``(R^T, -R^T t)``; batched over leading axes ``(..., 4, 4)``.

    Not ``np.linalg.inv``: a pose read from a file is orthonormal only to its
    printed precision, and its inverse is still the rigid one.

    Parameters
    ----------
    T : array_like, shape (4, 4) or (..., 4, 4)
        Rigid transform(s).

    Returns
    -------
    T_inv : ndarray, same shape as ``T``
        The rigid inverse(s).

    Examples
    --------
    >>> T = se3_from_planar(1.0, 2.0, 0.5); np.allclose(se3_inverse(T) @ T, np.eye(4))
    True
    """
    T = as_finite_array(T, "T")
    if T.ndim < 2 or T.shape[-2:] != (4, 4):
        raise ValueError(f"`T` must have shape (4, 4) or (..., 4, 4); got {T.shape}")
    out = np.zeros_like(T)
    Rt = np.swapaxes(T[..., :3, :3], -1, -2)
    out[..., :3, :3] = Rt
    out[..., :3, 3] = -np.einsum("...ij,...j->...i", Rt, T[..., :3, 3])
    out[..., 3, 3] = 1.0
    return out


def rotate_points(R, points) -> np.ndarray:
    """``points @ R.T`` for ``points (N, 3)``, as three sums of products in a fixed order (our helper).

    The same bits on every machine: a matrix product goes to BLAS, whose rounding depends on its
    kernel (FMA or not, blocking) and thread count, and a renderer that quantises to grey levels
    turns that last-bit difference into a different pixel. ``R`` is cast to the points' dtype
    (float32 rays stay float32).

    Parameters
    ----------
    R : array_like, shape (3, 3)
        Rotation matrix.
    points : array_like, shape (N, 3)
        Points, floating dtype.

    Returns
    -------
    rotated : ndarray, shape (N, 3)
        ``points @ R.T`` in the dtype of ``points``.

    Examples
    --------
    >>> rotate_points(se3_from_planar(0, 0, np.pi / 2)[:3, :3], [[1.0, 0.0, 0.0]]).round(12)
    array([[0., 1., 0.]])
    """
    P = np.asarray(points)
    if P.ndim != 2 or P.shape[1] != 3:
        raise ValueError(f"`points` must have shape (N, 3); got {P.shape}")
    if not np.issubdtype(P.dtype, np.floating):
        P = P.astype(np.float64)
    out = np.empty_like(P)
    for k, component in enumerate(rotate_components(R, P[:, 0], P[:, 1], P[:, 2])):
        out[:, k] = component
    return out


def rotate_components(R, x, y, z) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """:func:`rotate_points` on points given as three coordinate arrays ``x, y, z`` (our helper).

    The same sums in the same order, so the same bits; contiguous arrays in and out, which is
    faster for large point sets (a renderer's rays). ``R`` is cast to ``x``'s dtype.

    Parameters
    ----------
    R : array_like, shape (3, 3)
        Rotation matrix.
    x, y, z : array_like
        Coordinates of the points, arrays of one shape.

    Returns
    -------
    x_rot, y_rot, z_rot : ndarray
        Rotated coordinates, each of the shape of ``x``.

    Examples
    --------
    >>> [c.tolist() for c in rotate_components(se3_from_planar(0, 0, np.pi / 2)[:3, :3], [1.0], [0.0], [0.0])]
    [[6.123233995736766e-17], [1.0], [0.0]]
    """
    x, y, z = np.asarray(x), np.asarray(y), np.asarray(z)
    R = as_matrix(R, "R", (3, 3)).astype(x.dtype if np.issubdtype(x.dtype, np.floating) else np.float64)
    return tuple(x * R[k, 0] + y * R[k, 1] + z * R[k, 2] for k in range(3))


def transform_points(T, points) -> np.ndarray:
    """``points @ R.T + t`` for a 4×4 ``T`` and ``points (N, 3)``, without BLAS (see :func:`rotate_points`).

    Parameters
    ----------
    T : array_like, shape (4, 4)
        Rigid transform.
    points : array_like, shape (N, 3)
        Points, floating dtype.

    Returns
    -------
    transformed : ndarray, shape (N, 3)
        ``points @ R.T + t``.

    Examples
    --------
    >>> transform_points(se3_from_planar(1.0, 0.0, 0.0), [[0.0, 2.0, 0.0]])
    array([[1., 2., 0.]])
    """
    T = as_matrix(T, "T", (4, 4))
    out = rotate_points(T[:3, :3], points)
    out += T[:3, 3].astype(out.dtype)
    return out


def se3_compose(A, B) -> np.ndarray:
    """``A @ B`` for 4×4 transforms (batched over leading axes), as sums in a fixed order (no BLAS).

    ``np.einsum`` without ``optimize`` never calls BLAS, so the product has the same bits under
    every BLAS kernel and thread count (``A @ B`` does not: a 1-ulp difference in a pose is
    enough to change a later inlier decision of a tracker).

    Parameters
    ----------
    A, B : array_like, shape (..., 4, 4)
        Transforms; leading axes broadcast.

    Returns
    -------
    AB : ndarray, shape (..., 4, 4)
        The product ``A @ B`` (float64).

    Examples
    --------
    >>> T = se3_from_planar(1.0, 2.0, 0.5); np.allclose(se3_compose(T, se3_inverse(T)), np.eye(4))
    True
    """
    A = np.asarray(A, dtype=np.float64)
    B = np.asarray(B, dtype=np.float64)
    if A.shape[-2:] != (4, 4) or B.shape[-2:] != (4, 4):
        raise ValueError(f"`A` and `B` must have shape (..., 4, 4); got {A.shape} and {B.shape}")
    return np.einsum("...ij,...jk->...ik", A, B)


def se3_from_planar(x_m: float, y_m: float, yaw_rad: float, z_m: float = 0.0) -> np.ndarray:
    """4×4 pose of a body at ``(x, y, z)`` turned by ``yaw`` about the vertical ``z`` axis.

    Parameters
    ----------
    x_m, y_m : float
        Position in the plane [m].
    yaw_rad : float
        Heading about ``z`` [rad].
    z_m : float
        Height [m] (default 0).

    Returns
    -------
    T : ndarray, shape (4, 4)
        The pose.

    Examples
    --------
    >>> np.round(se3_from_planar(0, 0, np.pi / 2)[:3, :3] @ [1, 0, 0], 12)
    array([0., 1., 0.])
    """
    c, s = np.cos(yaw_rad), np.sin(yaw_rad)
    T = np.eye(4)
    T[:2, :2] = [[c, -s], [s, c]]
    T[:3, 3] = (x_m, y_m, z_m)
    return T


def yaw_from_R(R) -> float:
    """Heading about ``z`` of a rotation matrix: ``atan2(R[1, 0], R[0, 0])``.

    Parameters
    ----------
    R : array_like, shape (3, 3)
        Rotation matrix.

    Returns
    -------
    yaw_rad : float
        Heading in ``[-pi, pi]``.

    Examples
    --------
    >>> round(yaw_from_R(se3_from_planar(0, 0, 0.3)[:3, :3]), 12)
    0.3
    """
    R = as_matrix(R, "R", (3, 3))
    return float(np.arctan2(R[1, 0], R[0, 0]))


def planar_from_se3(T) -> np.ndarray:
    """``(x, y, yaw)`` of a 4×4 pose (height, roll and pitch dropped).

    Parameters
    ----------
    T : array_like, shape (4, 4)
        Rigid transform.

    Returns
    -------
    pose : ndarray, shape (3,)
        ``(x_m, y_m, yaw_rad)``.

    Examples
    --------
    >>> planar_from_se3(se3_from_planar(1.0, 2.0, 0.25))
    array([1.  , 2.  , 0.25])
    """
    T = as_matrix(T, "T", (4, 4))
    return np.array([T[0, 3], T[1, 3], yaw_from_R(T[:3, :3])])
