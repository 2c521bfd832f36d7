"""Pinhole camera and stereo rig (000 §3.2-3.3).

Camera frame as in OpenCV: ``x`` right, ``y`` down, ``z`` forward (optical axis).
Pixel coordinates are ``(u, v) = (column, row)`` with the centre of the top-left
pixel at ``(0, 0)``. The rig of 000 §3.2: two cameras of 768×576 pixels and a 40°
horizontal field of view, which gives a focal length of
``f = (768 / 2) / tan(20°) ≈ 1055 px``.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from .._validate import as_finite_array, as_matrix, as_vector, check_int, check_positive
from .so3 import hat

__all__ = [
    "PinholeCamera",
    "StereoRig",
    "backproject_points",
    "focal_from_hfov",
    "fundamental_matrix",
    "project_points",
    "rotation_xyz",
]


def focal_from_hfov(width_px: int, hfov_rad: float) -> float:
    """Focal length in pixels for a horizontal field of view (000 §3.2).

    ``f = (W / 2) / tan(hfov / 2)``.

    Parameters
    ----------
    width_px : int
        Image width [px], at least 1.
    hfov_rad : float
        Horizontal field of view [rad], in ``(0, pi)``.

    Returns
    -------
    f : float
        Focal length [px].

    Examples
    --------
    >>> round(focal_from_hfov(768, np.deg2rad(40.0)), 3)
    1055.031
    """
    width_px = check_int(width_px, "width_px", minimum=1)
    hfov_rad = check_positive(hfov_rad, "hfov_rad")
    if hfov_rad >= np.pi:
        raise ValueError(f"`hfov_rad` must be < pi; got {hfov_rad}")
    return float(0.5 * width_px / np.tan(0.5 * hfov_rad))


def rotation_xyz(rx_rad: float = 0.0, ry_rad: float = 0.0, rz_rad: float = 0.0) -> np.ndarray:
    """Rotation ``Rz @ Ry @ Rx`` from three angles (small extrinsic changes, our helper).

    Parameters
    ----------
    rx_rad, ry_rad, rz_rad : float
        Rotation angles about ``x``, ``y`` and ``z`` [rad] (default 0), applied in that order.

    Returns
    -------
    R : ndarray, shape (3, 3)
        The rotation matrix ``Rz @ Ry @ Rx``.

    Examples
    --------
    >>> np.allclose(rotation_xyz(0, 0, np.pi / 2) @ [1, 0, 0], [0, 1, 0])
    True
    """
    cx, sx = np.cos(rx_rad), np.sin(rx_rad)
    cy, sy = np.cos(ry_rad), np.sin(ry_rad)
    cz, sz = np.cos(rz_rad), np.sin(rz_rad)
    Rx = np.array([[1, 0, 0], [0, cx, -sx], [0, sx, cx]])
    Ry = np.array([[cy, 0, sy], [0, 1, 0], [-sy, 0, cy]])
    Rz = np.array([[cz, -sz, 0], [sz, cz, 0], [0, 0, 1]])
    return Rz @ Ry @ Rx


def project_points(K, X, *, min_depth: float | None = None, jacobian: bool = False):
    """Pixels ``u = fx x / z + cx``, ``v = fy y / z + cy`` of camera-frame points (000 §3.3; 003 §2).

    The one pinhole projection of the library, batched over leading axes. No checks of ``X`` (hot
    path: trackers call it every iteration) and no matrix product (element-wise, so the same bits on
    every machine).

    Parameters
    ----------
    K : array_like, shape (3, 3)
        Intrinsic matrix ``[[fx, 0, cx], [0, fy, cy], [0, 0, 1]]`` (the skew ``K[0, 1]`` is not used).
    X : ndarray, shape (N, 3) or (..., 3)
        Points in the camera frame (``x`` right, ``y`` down, ``z`` forward) [m].
    min_depth : float, optional
        When given, ``z`` is clamped to at least this value (keeps points behind the camera finite).
    jacobian : bool, default False
        Also return the derivatives of the pixels with respect to the point,
        ``[[fx / z, 0, -fx x / z²], [0, fy / z, -fy y / z²]]`` (at the clamped ``z``).

    Returns
    -------
    uv : ndarray, shape (N, 2) or (..., 2)
        Pixel coordinates ``(u, v)``.
    J : ndarray, shape (N, 2, 3) or (..., 2, 3)
        Only with ``jacobian=True``: ``d(u, v) / d(x, y, z)`` [px/m].

    Examples
    --------
    >>> K = np.array([[100.0, 0.0, 50.0], [0.0, 100.0, 40.0], [0.0, 0.0, 1.0]])
    >>> project_points(K, np.array([[0.2, -0.1, 2.0]]))
    array([[60., 35.]])
    >>> uv, J = project_points(K, np.array([[0.2, -0.1, 2.0]]), jacobian=True)
    >>> J[0]
    array([[50. ,  0. , -5. ],
           [ 0. , 50. ,  2.5]])
    """
    K, X = np.asarray(K), np.asarray(X)
    if K.shape != (3, 3):
        raise ValueError(f"`K` must have shape (3, 3); got {K.shape}")
    if X.ndim < 1 or X.shape[-1] != 3:
        raise ValueError(f"`X` must have shape (N, 3) or (..., 3); got {X.shape}")
    fx, fy = K[0, 0], K[1, 1]
    z = X[..., 2] if min_depth is None else np.maximum(X[..., 2], min_depth)
    uv = np.stack([fx * X[..., 0] / z + K[0, 2], fy * X[..., 1] / z + K[1, 2]], axis=-1)
    if not jacobian:
        return uv
    iz = 1.0 / z
    J = np.zeros((*X.shape[:-1], 2, 3))
    J[..., 0, 0] = fx * iz
    J[..., 0, 2] = -fx * X[..., 0] * iz * iz
    J[..., 1, 1] = fy * iz
    J[..., 1, 2] = -fy * X[..., 1] * iz * iz
    return uv, J


def backproject_points(K, uv) -> np.ndarray:
    """Viewing-ray directions ``((u - cx) / fx, (v - cy) / fy, 1)`` through pixels (the inverse of :func:`project_points`).

    No checks of ``uv`` beyond its shape (hot path), element-wise (the same bits on every machine).

    Parameters
    ----------
    K : array_like, shape (3, 3)
        Intrinsic matrix ``[[fx, 0, cx], [0, fy, cy], [0, 0, 1]]``.
    uv : ndarray, shape (N, 2)
        Pixel coordinates ``(u, v)``.

    Returns
    -------
    ndarray, shape (N, 3)
        Ray directions in the camera frame with ``z = 1`` (not unit length).

    Examples
    --------
    >>> K = np.array([[100.0, 0.0, 50.0], [0.0, 100.0, 40.0], [0.0, 0.0, 1.0]])
    >>> backproject_points(K, np.array([[60.0, 35.0]]))
    array([[ 0.1 , -0.05,  1.  ]])
    """
    K, uv = np.asarray(K), np.asarray(uv)
    if K.shape != (3, 3):
        raise ValueError(f"`K` must have shape (3, 3); got {K.shape}")
    if uv.ndim != 2 or uv.shape[1] != 2:
        raise ValueError(f"`uv` must have shape (N, 2); got {uv.shape}")
    return np.column_stack([(uv[:, 0] - K[0, 2]) / K[0, 0], (uv[:, 1] - K[1, 2]) / K[1, 1], np.ones(len(uv))])


@dataclass(frozen=True)
class PinholeCamera:
    """Pinhole camera ``u = fx x / z + cx``, ``v = fy y / z + cy`` (000 §3.3).

    Build it from the field of view with :meth:`from_hfov`.

    Attributes
    ----------
    width_px, height_px : int
        Image size [px], at least 1.
    fx, fy : float
        Focal lengths [px] along ``u`` and ``v``, positive.
    cx, cy : float
        Principal point ``(u, v)`` [px].

    Examples
    --------
    >>> cam = PinholeCamera.from_hfov(768, 576, np.deg2rad(40.0))
    >>> cam.project([[0.0, 0.0, 2.0]])
    array([[383.5, 287.5]])
    """

    width_px: int
    height_px: int
    fx: float
    fy: float
    cx: float
    cy: float

    def __post_init__(self):
        check_int(self.width_px, "width_px", minimum=1)
        check_int(self.height_px, "height_px", minimum=1)
        for name in ("fx", "fy"):
            check_positive(getattr(self, name), name)
        for name in ("cx", "cy"):
            val = getattr(self, name)
            if isinstance(val, bool) or not np.isfinite(float(val)):
                raise ValueError(f"`{name}` must be a finite number; got {val!r}")

    @classmethod
    def from_hfov(cls, width_px: int = 768, height_px: int = 576, hfov_rad: float = np.deg2rad(40.0)) -> PinholeCamera:
        """Square pixels, principal point at the image centre, focal length from ``hfov_rad``.

        Parameters
        ----------
        width_px, height_px : int
            Image size, pixels.
        hfov_rad : float
            Horizontal field of view, radians.

        Returns
        -------
        PinholeCamera
        """
        f = focal_from_hfov(width_px, hfov_rad)
        height_px = check_int(height_px, "height_px", minimum=1)
        return cls(width_px, height_px, f, f, (width_px - 1) / 2.0, (height_px - 1) / 2.0)

    @property
    def K(self) -> np.ndarray:
        """The 3×3 intrinsic matrix."""
        return np.array([[self.fx, 0.0, self.cx], [0.0, self.fy, self.cy], [0.0, 0.0, 1.0]])

    def project(self, points_cam) -> np.ndarray:
        """Pixel coordinates ``(N, 2)`` of camera-frame points ``(N, 3)`` (``z`` must be > 0).

        Parameters
        ----------
        points_cam : array_like, shape (N, 3)
            Points in the camera frame [m]; ``z > 0`` (raises ``ValueError`` otherwise).

        Returns
        -------
        uv : ndarray, shape (N, 2)
            Pixel coordinates ``(u, v)``.
        """
        P = as_finite_array(points_cam, "points_cam", ndim=2)
        if P.shape[1] != 3:
            raise ValueError(f"`points_cam` must have shape (N, 3); got {P.shape}")
        if np.any(P[:, 2] <= 0):
            raise ValueError("`points_cam` must lie in front of the camera (z > 0)")
        return project_points(self.K, P)

    def backproject(self, uv) -> np.ndarray:
        """Viewing-ray directions ``(N, 3)`` with ``z = 1`` through pixels ``uv (N, 2)``.

        Parameters
        ----------
        uv : array_like, shape (N, 2)
            Pixel coordinates ``(u, v)``.

        Returns
        -------
        rays : ndarray, shape (N, 3)
            Ray directions in the camera frame, ``z = 1`` (not unit length).
        """
        uv = as_finite_array(uv, "uv", ndim=2)
        if uv.shape[1] != 2:
            raise ValueError(f"`uv` must have shape (N, 2); got {uv.shape}")
        return backproject_points(self.K, uv)

    def pixel_rays(self) -> np.ndarray:
        """Ray directions ``(H, W, 3)`` (``z = 1``) through every pixel centre, for rendering."""
        u = (np.arange(self.width_px) - self.cx) / self.fx
        w = (np.arange(self.height_px) - self.cy) / self.fy
        rays = np.empty((self.height_px, self.width_px, 3))
        rays[..., 0] = u[None, :]
        rays[..., 1] = w[:, None]
        rays[..., 2] = 1.0
        return rays


def fundamental_matrix(K_left, K_right, R, t) -> np.ndarray:
    """``F`` with ``x_r^T F x_l = 0`` for a right camera at ``x_r = R x_l + t`` (000 §3.3).

    Parameters
    ----------
    K_left, K_right : array_like, shape (3, 3)
        Intrinsic matrices of the left and right cameras.
    R : array_like, shape (3, 3)
        Rotation from the left to the right camera frame.
    t : array_like, shape (3,)
        Translation of that transform [m] (``x_r = R x_l + t``).

    Returns
    -------
    F : ndarray, shape (3, 3)
        ``K_right^-T [t]x R K_left^-1``.

    Examples
    --------
    >>> K = np.eye(3); F = fundamental_matrix(K, K, np.eye(3), [-1.0, 0, 0])
    >>> float(np.array([0.5, 0.2, 1.0]) @ F @ np.array([0.7, 0.2, 1.0]))
    0.0
    """
    K_left = as_matrix(K_left, "K_left", (3, 3))
    K_right = as_matrix(K_right, "K_right", (3, 3))
    R = as_matrix(R, "R", (3, 3))
    t = as_vector(t, "t", 3)
    E = hat(t) @ R
    return np.linalg.inv(K_right).T @ E @ np.linalg.inv(K_left)


@dataclass(frozen=True)
class StereoRig:
    """Two pinhole cameras; the right one at ``x_r = R_rl x_l + t_rl`` (000 §3.2-3.3).

    ``R_rl, t_rl`` is the calibrated "transfer matrix from one camera to the
    other" of 000 §3.3. :meth:`parallel` builds the usual rig: same camera
    twice, the right one ``baseline_m`` to the right of the left one.

    Attributes
    ----------
    left, right : PinholeCamera
        The two cameras.
    R_rl : ndarray, shape (3, 3)
        Proper rotation from the left to the right camera frame.
    t_rl : ndarray, shape (3,)
        Translation [m] of that transform; ``(-baseline_m, 0, 0)`` for a parallel rig.

    Examples
    --------
    >>> rig = StereoRig.parallel(baseline_m=0.2)
    >>> rig.right_center_m
    array([0.2, 0. , 0. ])
    """

    left: PinholeCamera
    right: PinholeCamera
    R_rl: np.ndarray = field(repr=False)
    t_rl: np.ndarray = field(repr=False)

    def __post_init__(self):
        if not isinstance(self.left, PinholeCamera) or not isinstance(self.right, PinholeCamera):
            raise TypeError("`left` and `right` must be PinholeCamera instances")
        R = as_matrix(self.R_rl, "R_rl", (3, 3))
        if not np.allclose(R.T @ R, np.eye(3), atol=1e-9) or np.linalg.det(R) <= 0:
            raise ValueError("`R_rl` must be a proper rotation matrix")
        object.__setattr__(self, "R_rl", R)
        object.__setattr__(self, "t_rl", as_vector(self.t_rl, "t_rl", 3))

    @classmethod
    def parallel(
        cls,
        baseline_m: float = 0.2,
        width_px: int = 768,
        height_px: int = 576,
        hfov_rad: float = np.deg2rad(40.0),
    ) -> StereoRig:
        """A rectified rig: identical cameras, parallel axes, ``baseline_m`` apart along ``x``.

        Parameters
        ----------
        baseline_m : float
            Distance between the optical centres, metres (> 0).
        width_px, height_px : int
            Image size of both cameras, pixels.
        hfov_rad : float
            Horizontal field of view of both cameras, radians.

        Returns
        -------
        StereoRig
        """
        baseline_m = check_positive(baseline_m, "baseline_m")
        cam = PinholeCamera.from_hfov(width_px, height_px, hfov_rad)
        return cls(cam, cam, np.eye(3), np.array([-baseline_m, 0.0, 0.0]))

    @property
    def baseline_m(self) -> float:
        """Distance between the two optical centres."""
        return float(np.linalg.norm(self.t_rl))

    @property
    def right_center_m(self) -> np.ndarray:
        """Optical centre of the right camera in the left camera's frame: ``-R^T t``."""
        return -self.R_rl.T @ self.t_rl

    @property
    def F(self) -> np.ndarray:
        """Fundamental matrix, ``x_r^T F x_l = 0``."""
        return fundamental_matrix(self.left.K, self.right.K, self.R_rl, self.t_rl)

    def project(self, points_left) -> tuple[np.ndarray, np.ndarray]:
        """Pixels in the left and right images of points given in the left camera frame.

        Parameters
        ----------
        points_left : array_like, shape (N, 3)
            Points in the left camera frame [m], in front of both cameras.

        Returns
        -------
        uv_left, uv_right : ndarray, shape (N, 2)
            Pixel coordinates in the left and right images.
        """
        P = as_finite_array(points_left, "points_left", ndim=2)
        if P.shape[1] != 3:
            raise ValueError(f"`points_left` must have shape (N, 3); got {P.shape}")
        return self.left.project(P), self.right.project(P @ self.R_rl.T + self.t_rl)

    def stereo_pixels(self, points_left, *, jacobian: bool = False):
        """The stereo measurement ``(u_l, v_l, u_r, v_r)`` of points in the left camera frame (our addition, issue 25).

        Both projections by :func:`project_points` (no checks of the depths: hot path of the pose
        refinement and the landmark filter in pixels).

        Parameters
        ----------
        points_left : array_like, shape (N, 3)
            Points in the left camera frame [m], in front of both cameras.
        jacobian : bool, default False
            Also return the derivatives of the four pixels with respect to the point (left frame).

        Returns
        -------
        z : ndarray, shape (N, 4)
            ``(u_l, v_l, u_r, v_r)`` [px].
        J : ndarray, shape (N, 4, 3)
            Only with ``jacobian=True``: ``dz / d(x, y, z)`` [px/m].

        Examples
        --------
        >>> cam = PinholeCamera(100, 80, 50.0, 50.0, 50.0, 40.0)
        >>> rig = StereoRig(cam, cam, np.eye(3), [-0.5, 0.0, 0.0])
        >>> rig.stereo_pixels([[0.0, 0.0, 5.0]])
        array([[50., 40., 45., 40.]])
        """
        P = np.asarray(points_left, dtype=float)
        if P.ndim != 2 or P.shape[1] != 3:
            raise ValueError(f"`points_left` must have shape (N, 3); got {P.shape}")
        if not jacobian:
            return np.hstack([project_points(self.left.K, P), project_points(self.right.K, P @ self.R_rl.T + self.t_rl)])
        uv_l, J_l = project_points(self.left.K, P, jacobian=True)
        uv_r, J_r = project_points(self.right.K, P @ self.R_rl.T + self.t_rl, jacobian=True)
        return np.hstack([uv_l, uv_r]), np.concatenate([J_l, J_r @ self.R_rl], axis=1)

    def rays(self, uv_left, uv_right) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """Both viewing rays in the left frame: ``(c_left, d_left, c_right, d_right)`` (000 §3.3).

        Parameters
        ----------
        uv_left, uv_right : array_like, shape (N, 2)
            Matched pixel coordinates in the left and right images (same number of rows).

        Returns
        -------
        c_left : ndarray, shape (3,)
            Left optical centre (the origin).
        d_left : ndarray, shape (N, 3)
            Left ray directions.
        c_right : ndarray, shape (3,)
            Right optical centre in the left frame [m].
        d_right : ndarray, shape (N, 3)
            Right ray directions rotated into the left frame.
        """
        d_l = self.left.backproject(uv_left)
        d_r = self.right.backproject(uv_right) @ self.R_rl  # R^T d for each row
        if d_l.shape != d_r.shape:
            raise ValueError(f"`uv_left` and `uv_right` must have the same shape; got {d_l.shape[0]} and {d_r.shape[0]} rows")
        return np.zeros(3), d_l, self.right_center_m, d_r
