"""SE(3) pose helpers as 4×4 homogeneous matrices (000 §3.5; our helpers).

000 estimates a rotation and a translation (6 degrees of freedom is our
reading); the robot drives on a floor, so the pose is reported as planar
``(x, y, yaw)`` — :func:`yaw_from_R` and :func:`planar_from_se3`.
"""

from __future__ import annotations

import numpy as np

from .. import _validate as v

__all__ = ["planar_from_se3", "se3", "se3_from_planar", "se3_inverse", "yaw_from_R"]


def se3(R, t) -> np.ndarray:
    """4×4 matrix from rotation ``R`` (3, 3) and translation ``t`` (3,).

    >>> se3(np.eye(3), [1.0, 2.0, 3.0])[:3, 3]
    array([1., 2., 3.])
    """
    R = v.as_matrix(R, "R", (3, 3))
    t = v.as_vector(t, "t", 3)
    T = np.eye(4)
    T[:3, :3], T[:3, 3] = R, t
    return T


def se3_inverse(T) -> np.ndarray:
    """Inverse of rigid 4×4 transforms, ``(R^T, -R^T t)``; batched over leading axes ``(..., 4, 4)``.

    Not ``np.linalg.inv``: a pose read from a file is orthonormal only to its
    printed precision, and its inverse is still the rigid one.

    >>> T = se3_from_planar(1.0, 2.0, 0.5); np.allclose(se3_inverse(T) @ T, np.eye(4))
    True
    """
    T = v.as_finite_array(T, "T")
    if T.ndim < 2 or T.shape[-2:] != (4, 4):
        raise ValueError(f"`T` must have shape (4, 4) or (..., 4, 4); got {T.shape}")
    out = np.zeros_like(T)
    Rt = np.swapaxes(T[..., :3, :3], -1, -2)
    out[..., :3, :3] = Rt
    out[..., :3, 3] = -np.einsum("...ij,...j->...i", Rt, T[..., :3, 3])
    out[..., 3, 3] = 1.0
    return out


def se3_from_planar(x_m: float, y_m: float, yaw_rad: float, z_m: float = 0.0) -> np.ndarray:
    """4×4 pose of a body at ``(x, y, z)`` turned by ``yaw`` about the vertical ``z`` axis.

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

    >>> round(yaw_from_R(se3_from_planar(0, 0, 0.3)[:3, :3]), 12)
    0.3
    """
    R = v.as_matrix(R, "R", (3, 3))
    return float(np.arctan2(R[1, 0], R[0, 0]))


def planar_from_se3(T) -> np.ndarray:
    """``(x, y, yaw)`` of a 4×4 pose (height, roll and pitch dropped).

    >>> planar_from_se3(se3_from_planar(1.0, 2.0, 0.25))
    array([1.  , 2.  , 0.25])
    """
    T = v.as_matrix(T, "T", (4, 4))
    return np.array([T[0, 3], T[1, 3], yaw_from_R(T[:3, :3])])
