"""003's formulas worked on numbers (003 §2.1, eq. 6.4; SVO's τ): the cameras of the chapter, the pinhole
projection, the inverse-depth point and the depth uncertainty of one pixel, as printed tables.
"""

from __future__ import annotations

import numpy as np

from ..._table import format_table
from ..._validate import as_finite_array, as_matrix, as_path, as_vector, check_positive
from ...mono.depth_filter import compute_tau, init_seeds, tau_inverse

__all__ = ["chapter_cameras", "inverse_depth_point_table", "pinhole_table", "tau_table"]


# -- 003 §2.1: the pinhole camera ----------------------------------------------------------------
def chapter_cameras(kitti_folder=None) -> dict:
    """``{name: (K, width_px, height_px)}``: the rendered camera (tiny size) and KITTI 06's left camera.

    Parameters
    ----------
    kitti_folder : str or Path, optional
        KITTI odometry folder with ``calib.txt``; ``None`` = the bundled 06 set.

    Returns
    -------
    dict
        Camera name → ``(K (3, 3), width_px, height_px)``.
    """
    from ...data import find_data
    from ...io.kitti import read_kitti_calib
    from .experiments import SIZES, mono_sim

    w, h = SIZES["tiny"]
    cams = {"rendered (tiny)": (mono_sim("tiny").rig.left.K, w, h)}
    d = find_data("kitti-odometry-06-stereo") if kitti_folder is None else \
        as_path(kitti_folder, "kitti_folder", kind="dir")
    cams["KITTI 06 left"] = (read_kitti_calib(d / "calib.txt")["P0"][:, :3], 1226, 370)
    return cams


def pinhole_table(X_cam=(0.5, -0.2, 4.0), cameras=None) -> str:
    """003 §2.1 (eq. 2.1-2.4, lost; reconstruction): ``K = [[fx, 0, u0], [0, fy, v0], [0, 0, 1]]`` and
    ``u = fx X/Z + u0``, ``v = fy Y/Z + v0``, for a point ``X_cam`` (m, camera frame) in each camera.

    Parameters
    ----------
    X_cam : array_like, shape (3,)
        Point in the camera frame [m], ``Z > 0``.
    cameras : dict, optional
        Name → ``(K, width_px, height_px)``; ``None`` = :func:`chapter_cameras`.

    Returns
    -------
    str
        One row per camera: ``fx``, ``fy``, ``u0``, ``v0``, field of view and the point's pixel.
    """
    X = as_vector(X_cam, "X_cam", 3)
    if X[2] <= 0:
        raise ValueError(f"`X_cam` must lie in front of the camera (Z > 0); got Z = {X[2]}")
    cams = chapter_cameras() if cameras is None else cameras
    rows = []
    for name, (K, w, h) in cams.items():
        u = K[0, 0] * X[0] / X[2] + K[0, 2]
        v_ = K[1, 1] * X[1] / X[2] + K[1, 2]
        hfov = np.degrees(2 * np.arctan(w / (2 * K[0, 0])))
        rows.append([name, f"{w}x{h}", f"{K[0, 0]:.1f}", f"{K[1, 1]:.1f}", f"{K[0, 2]:.1f}", f"{K[1, 2]:.1f}",
                     f"{hfov:.1f}", f"({u:.1f}, {v_:.1f})"])
    return format_table(["camera", "image", "fx, px", "fy, px", "u0, px", "v0, px", "h. view, deg", "pixel of X, px"],
                        rows, title=("Pinhole model (003 §2.1): u = fx X/Z + u0, v = fy Y/Z + v0; "
                                     f"X = ({X[0]:g}, {X[1]:g}, {X[2]:g}) m"))


# -- 003 §4.1.2, eq. 6.4 ------------------------------------------------------------------------------
def inverse_depth_point_table(K=None, uv=(150.0, 40.0), rhos=(0.5, 0.2, 0.05, 1e-10), *, yaw_deg: float = 30.0,
                              T_F_m=(1.0, 0.0, 2.0)) -> str:
    """003 eq. 6.4 (lost; reconstruction): ``X = T_F + R_F · v / ρ`` for one pixel at several ρ.

    ``v`` is the unit back-projection ray ``K⁻¹ [u, v, 1]ᵀ / |·|`` of the pixel in keyframe F, whose
    pose in the world is ``R_F`` (a yaw of ``yaw_deg`` about the camera's y axis, ours) and ``T_F``.
    Computed with :func:`~slamlab.mono.seed_points`; the last column reprojects X into F (it must give
    the pixel back for every ρ: the depth moves the point along the ray only).

    Parameters
    ----------
    K : array_like, shape (3, 3), optional
        Intrinsic matrix; ``None`` = the rendered (tiny) camera.
    uv : array_like, shape (2,)
        The pixel in keyframe F [px].
    rhos : array_like, shape (n,)
        Inverse depths [1/m], one row each.
    yaw_deg : float
        Rotation of F about its camera ``y`` axis [deg] (default 30).
    T_F_m : array_like, shape (3,)
        Position of F in the world [m].

    Returns
    -------
    str
        One row per ρ: the world point and its reprojection into F.
    """
    from ...geometry.camera import project_points, rotation_xyz
    from ...mono.depth_filter import Seeds, seed_points

    K = chapter_cameras()["rendered (tiny)"][0] if K is None else as_matrix(K, "K", (3, 3))
    uv = as_vector(uv, "uv", 2)
    rhos = as_finite_array(rhos, "rhos", ndim=1)
    if np.any(rhos <= 0):
        raise ValueError("`rhos` must be positive inverse depths (1/m)")
    ray = np.array([(uv[0] - K[0, 2]) / K[0, 0], (uv[1] - K[1, 2]) / K[1, 1], 1.0])
    f = ray / np.linalg.norm(ray)
    n = rhos.size
    s = init_seeds(np.tile(uv, (n, 1)), np.tile(f, (n, 1)), 1.0, 1.0)
    s = Seeds(**{**s.__dict__, "mu": rhos.copy()})
    T = np.eye(4)
    T[:3, :3], T[:3, 3] = rotation_xyz(0.0, np.deg2rad(yaw_deg), 0.0), as_vector(T_F_m, "T_F_m", 3)
    X = seed_points(s, T[None])
    Xc = np.einsum("ji,nj->ni", T[:3, :3], X - T[:3, 3])  # back into F
    rows = []
    for rho, Xi, (u, v_) in zip(rhos, X, project_points(K, Xc), strict=True):
        big = np.max(np.abs(Xi)) > 1e4
        xs = ", ".join(f"{c:.3g}" if big else f"{c:.3f}" for c in Xi)
        rows.append([f"{rho:g}", f"{1 / rho:.4g}", f"({xs})", f"({u:.2f}, {v_:.2f})"])
    return format_table(["rho, 1/m", "range 1/rho, m", "X = T_F + R_F v / rho, m", "reprojected into F, px"], rows,
                        title=f"Eq. 6.4: pixel ({uv[0]:g}, {uv[1]:g}) of keyframe F at T_F = "
                              f"({', '.join(f'{c:g}' for c in T[:3, 3])}) m, yaw {yaw_deg:g} deg; "
                              f"v = ({', '.join(f'{c:.3f}' for c in f)})")


# -- tau: one pixel -> metres -> inverse depth ---------------------------------------------------------
def tau_table(depths_m=(2.0, 5.0, 10.0), baselines_m=(0.02, 0.1, 0.5), *, f_px: float | None = None,
              px_noise: float = 1.0) -> str:
    """SVO's ``τ``: one pixel of angle pushed through the triangle (metres), then an inverse-depth std.

    The point lies straight ahead of the reference camera (``f = (0, 0, 1)``), the current camera
    ``baseline_m`` to the side. ``τ_ρ = ½ (1/(z − τ) − 1/(z + τ))`` (SVO) is printed beside its
    first-order form ``τ / z²`` (``dρ/dz = −1/z²``).

    Parameters
    ----------
    depths_m : sequence of float
        Depths of the point straight ahead [m].
    baselines_m : sequence of float
        Sideways offsets of the current camera [m].
    f_px : float, optional
        Focal length [px]; ``None`` = the rendered (tiny) camera's.
    px_noise : float
        Measurement error [px] (default 1).

    Returns
    -------
    str
        One row per (depth, baseline): ``τ`` [m], ``τ_ρ`` [1/m] and its first-order form.
    """
    f_px = float(chapter_cameras()["rendered (tiny)"][0][0, 0]) if f_px is None else check_positive(f_px, "f_px")
    ang = 2 * np.arctan(px_noise / (2 * f_px))
    rows = []
    for z in depths_m:
        for b in baselines_m:
            tau = float(compute_tau(np.array([b, 0.0, 0.0]), np.array([[0.0, 0.0, 1.0]]), np.array([z]), ang)[0])
            t_rho = float(tau_inverse(np.array([z]), np.array([tau]))[0])
            par = np.degrees(np.arctan2(b, z))
            rows.append([f"{z:g}", f"{b:g}", f"{par:.2f}", f"{tau:.4f}", f"{t_rho:.5f}", f"{tau / z**2:.5f}"])
    return format_table(["depth z, m", "baseline, m", "parallax, deg", "tau, m", "tau_rho, 1/m", "tau / z^2, 1/m"],
                        rows, title=f"tau from {px_noise:g} px of angle (f = {f_px:.1f} px: "
                                    f"{np.degrees(ang) * 3600:.0f} arc-seconds)")
