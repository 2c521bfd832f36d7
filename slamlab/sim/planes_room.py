"""A room of planes, a UTM-30LX-like vertical scanner on a yawing quadcopter, inertial odometry (002; ours).

002 flew a Gazebo quadcopter through a ~200 m² room "whose walls carry contrasting
elements returning different intensities" with a Hokuyo UTM-30LX (40 lines/s,
0.25°, 270°, 1081 points, intensity) mounted with a vertical scan plane; the
vehicle yaws at 45°/s so ~1 s of lines (two 45° sectors 180° apart, > 40 000
points) makes one frame. Everything numeric beyond those figures is ours and is a
field of :class:`PlaneScanner`, :func:`build_plane_room` or :func:`quad_flight`:

* room: 20 m × 10 m × 3 m (200 m²) with a pillar and a box (some faces parallel to
  the walls), each face a bounded rectangle carrying 1 m panels of reflectance;
* scanner: beams at angle ``a`` from the body ``+z`` axis in the body ``x``-``z``
  plane, ``a`` in [-135°, 135°] (the 90° gap points down, at the airframe); range
  noise N(0, σ_r); intensity ``I = I0 · ρ · |cos θ|`` (θ: incidence angle) plus
  N(0, σ_I); no return (NaN) beyond ``range_max_m``;
* odometry: the true per-line increments with Gaussian noise and a constant
  velocity / yaw-rate bias (drift), integrated from the true start pose.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.spatial.transform import Rotation

from .._params import Params, param
from .._validate import as_finite_array, as_rng, as_vector, check_positive
from ..geometry.so3 import so3_exp
from .room_of_planes import RAY_CHUNK, PlaneRoom, build_corridor, build_plane_room, cast_rays_planes

__all__ = [
    "Flight",
    "PlaneRoom",
    "PlaneScanner",
    "build_corridor",
    "build_plane_room",
    "cast_rays_planes",
    "quad_flight",
    "scanner_beam_directions",
    "simulate_flight",
    "simulate_odometry_3d",
]


@dataclass(frozen=True)
class PlaneScanner(Params):
    """A Hokuyo UTM-30LX-like line scanner with a vertical scan plane (002 "Experimental trial").

    Attributes
    ----------
    fov_deg : float
        Field of view [deg] (002: 270°).
    step_deg : float
        Beam spacing [deg] (002: 0.25°, 1081 points).
    lines_per_s : float
        Scan lines per second (002: 40).
    range_max_m : float
        Longest range [m] (ours; UTM-30LX data sheet: 30 m).
    sigma_range_m : float
        Range noise std [m] (ours; data sheet: ±30 mm up to 10 m).
    intensity_gain : float
        ``I0`` of the intensity model ``I = I0·ρ·|cos θ|`` (ours).
    sigma_intensity : float
        Intensity noise std (ours).
    mount_m : tuple of float
        Scanner origin in the body frame [m] (ours).
    """

    fov_deg: float = param(270.0, "002: 270°")
    step_deg: float = param(0.25, "002: 0.25° (1081 points)")
    lines_per_s: float = param(40.0, "002: 40 lines/s")
    range_max_m: float = param(30.0, "ours (UTM-30LX data sheet: 30 m)")
    sigma_range_m: float = param(0.01, "ours (data sheet: ±30 mm up to 10 m)")
    intensity_gain: float = param(1000.0, "ours: I = I0·ρ·|cos θ|")
    sigma_intensity: float = param(10.0, "ours")
    mount_m: tuple = param((0.0, 0.0, 0.1), "ours: scanner origin in the body frame")

    def check(self) -> None:
        check_positive(self.fov_deg, "fov_deg")
        if self.fov_deg > 360:
            raise ValueError(f"`fov_deg` must be <= 360; got {self.fov_deg}")
        check_positive(self.step_deg, "step_deg")
        check_positive(self.lines_per_s, "lines_per_s")
        check_positive(self.range_max_m, "range_max_m")
        check_positive(self.sigma_range_m, "sigma_range_m", allow_zero=True)
        check_positive(self.intensity_gain, "intensity_gain")
        check_positive(self.sigma_intensity, "sigma_intensity", allow_zero=True)
        as_vector(self.mount_m, "mount_m", 3)

    @property
    def n_beams(self) -> int:
        """Beams per line: ``fov / step + 1`` (1081 for 270° / 0.25°)."""
        return round(self.fov_deg / self.step_deg) + 1


def scanner_beam_directions(scanner: PlaneScanner | None = None) -> np.ndarray:
    """Unit beam directions ``(n_beams, 3)`` in the body frame: ``(sin a, 0, cos a)``, a from ``+z`` (ours).

    Parameters
    ----------
    scanner : PlaneScanner, optional
        The sensor (default ``PlaneScanner()``).

    Returns
    -------
    numpy.ndarray, shape (n_beams, 3)

    Examples
    --------
    >>> d = scanner_beam_directions(); d.shape, np.round(d[540], 12).tolist()
    ((1081, 3), [0.0, 0.0, 1.0])
    """
    s = PlaneScanner.resolve(scanner)
    a = np.deg2rad(np.linspace(-s.fov_deg / 2, s.fov_deg / 2, s.n_beams))
    return np.stack([np.sin(a), np.zeros_like(a), np.cos(a)], axis=1)


def quad_flight(duration_s: float = 20.0, *, rate_hz: float = 40.0, yaw_rate_deg_s: float = 45.0,
                speed_m_s: float = 0.6, waypoints_m=None, tilt_deg: float = 2.0) -> tuple[np.ndarray, np.ndarray]:
    """True poses ``mT_b`` of a quadcopter flying through the room while yawing (002 Fig. 5, 8; ours).

    A polyline through ``waypoints_m`` at ``speed_m_s`` (height varies along it), constant yaw rate
    (002: 45°/s), roll and pitch small sinusoids of amplitude ``tilt_deg`` (a stabilised airframe).

    Parameters
    ----------
    duration_s : float, default 20.0
        Flight time [s].
    rate_hz : float, default 40.0
        Poses per second (scan lines).
    yaw_rate_deg_s : float, default 45.0
        Constant yaw rate [deg/s].
    speed_m_s : float, default 0.6
        Speed along the polyline [m/s].
    waypoints_m : array_like, shape (N, 3), optional
        Polyline [m] (default a tour of the 20×10 m room).
    tilt_deg : float, default 2.0
        Roll and pitch amplitude [deg].

    Returns
    -------
    times_s (N,), poses (N, 4, 4) at ``rate_hz`` (one per scan line).

    Examples
    --------
    >>> t, T = quad_flight(1.0); T.shape, float(t[-1])
    ((40, 4, 4), 0.975)
    """
    duration_s = check_positive(duration_s, "duration_s")
    rate_hz = check_positive(rate_hz, "rate_hz")
    speed = check_positive(speed_m_s, "speed_m_s", allow_zero=True)
    if waypoints_m is None:
        waypoints_m = [[2.5, 2.5, 1.5], [9.0, 3.0, 1.6], [13.0, 3.5, 1.4], [17.5, 5.0, 1.6], [17.0, 8.0, 1.5],
                       [10.0, 8.0, 1.7], [3.0, 7.5, 1.5]]
    wp = as_finite_array(waypoints_m, "waypoints_m", ndim=2)
    if wp.shape[1] != 3 or wp.shape[0] < 2:
        raise ValueError(f"`waypoints_m` must have shape (N >= 2, 3); got {wp.shape}")
    t = np.arange(round(duration_s * rate_hz)) / rate_hz
    seg = np.linalg.norm(np.diff(wp, axis=0), axis=1)
    cum = np.concatenate([[0.0], np.cumsum(seg)])
    s = np.minimum(speed * t, cum[-1])
    pos = np.stack([np.interp(s, cum, wp[:, i]) for i in range(3)], axis=1)
    tilt = np.deg2rad(tilt_deg)
    yaw = np.deg2rad(yaw_rate_deg_s) * t
    rpy = np.stack([tilt * np.sin(0.7 * t), tilt * np.sin(0.5 * t + 1.0), yaw], axis=1)
    T = np.zeros((len(t), 4, 4))
    T[:, :3, :3] = Rotation.from_euler("xyz", rpy).as_matrix()
    T[:, :3, 3] = pos
    T[:, 3, 3] = 1.0
    return t, T


def simulate_odometry_3d(poses, *, sigma_trans_m: float = 0.002, sigma_rot_deg: float = 0.05,
                         bias_m_per_step=(0.0005, -0.0003, 0.0001), bias_yaw_deg_per_step: float = 0.01,
                         rng=None) -> np.ndarray:
    """Inertial odometry ``oT_b``: true increments with noise and a constant bias, integrated (002; ours).

    The odom frame coincides with the map frame at the first pose. The bias (per line, in the body frame) is
    the drift; roll and pitch get noise but no bias (gravity keeps them observable to an IMU).

    Parameters
    ----------
    poses : array_like, shape (N, 4, 4)
        True poses.
    sigma_trans_m : float, default 0.002
        Translation noise per step [m].
    sigma_rot_deg : float, default 0.05
        Rotation noise per step and axis [deg].
    bias_m_per_step : array_like, shape (3,)
        Translation bias per step in the body frame [m].
    bias_yaw_deg_per_step : float, default 0.01
        Yaw bias per step [deg].
    rng : int or numpy.random.Generator, optional
        Seed or generator.

    Returns
    -------
    numpy.ndarray, shape (N, 4, 4)
    """
    T = as_finite_array(poses, "poses", ndim=3)
    if T.shape[1:] != (4, 4):
        raise ValueError(f"`poses` must have shape (N, 4, 4); got {T.shape}")
    rng = as_rng(rng)
    n = T.shape[0]
    inc = np.linalg.inv(T[:-1]) @ T[1:]
    noise_rot = rng.normal(0.0, np.deg2rad(sigma_rot_deg), (n - 1, 3))
    noise_rot[:, 2] += np.deg2rad(bias_yaw_deg_per_step)
    dR = so3_exp(noise_rot)
    inc[:, :3, :3] = inc[:, :3, :3] @ dR
    inc[:, :3, 3] += rng.normal(0.0, sigma_trans_m, (n - 1, 3)) + np.asarray(bias_m_per_step, float)
    out = np.empty_like(T)
    out[0] = T[0]
    for k in range(1, n):  # a running product of 4x4s: sequential by nature, cheap
        out[k] = out[k - 1] @ inc[k - 1]
    return out


@dataclass(frozen=True)
class Flight:
    """A simulated flight: per scan line ``times_s (N,)``, true ``poses (N, 4, 4)``, ``odometry (N, 4, 4)``,
    ``ranges_m (N, B)`` (NaN: no return), ``intensities (N, B)``, ``plane_ids (N, B)`` (ground truth, -1: none),
    and the ``room`` and ``scanner``.

    Attributes
    ----------
    times_s : numpy.ndarray, shape (N,)
        Time of each scan line [s].
    poses : numpy.ndarray, shape (N, 4, 4)
        True body poses ``mT_b``.
    odometry : numpy.ndarray, shape (N, 4, 4)
        Odometry poses ``oT_b``.
    ranges_m : numpy.ndarray, shape (N, B)
        Ranges [m], NaN without a return.
    intensities : numpy.ndarray, shape (N, B)
        Return intensities.
    plane_ids : numpy.ndarray of int, shape (N, B)
        Plane hit by each beam (-1: none).
    room : PlaneRoom
        The scene.
    scanner : PlaneScanner
        The sensor.
    """

    times_s: np.ndarray
    poses: np.ndarray
    odometry: np.ndarray
    ranges_m: np.ndarray
    intensities: np.ndarray
    plane_ids: np.ndarray
    room: PlaneRoom
    scanner: PlaneScanner

    def __len__(self) -> int:
        return self.times_s.shape[0]

    def body_points(self, lines=slice(None)) -> np.ndarray:
        """Points ``(n, B, 3)`` of the chosen lines in the body frame (NaN where no return).

        Parameters
        ----------
        lines : slice or array_like of int
            Scan lines to take (default all).

        Returns
        -------
        numpy.ndarray, shape (n, B, 3)
            Points [m].
        """
        d = scanner_beam_directions(self.scanner)
        return self.ranges_m[lines][..., None] * d + np.asarray(self.scanner.mount_m)

    def __str__(self) -> str:
        hit = np.isfinite(self.ranges_m).mean()
        return f"Flight: {len(self)} lines over {self.times_s[-1] + 1 / self.scanner.lines_per_s:.1f} s, " \
               f"{self.ranges_m.shape[1]} beams, {hit:.1%} returns"


def simulate_flight(duration_s: float = 20.0, *, room: PlaneRoom | None = None, scanner: PlaneScanner | None = None,
                    yaw_rate_deg_s: float = 45.0, speed_m_s: float = 0.6, waypoints_m=None,
                    odometry_noise: float = 1.0, rng=None) -> Flight:
    """Fly :func:`quad_flight` through ``room`` and record every scan line and the odometry (002; ours).

    ``odometry_noise`` scales every noise and bias of :func:`simulate_odometry_3d` (0 = perfect odometry).

    Parameters
    ----------
    duration_s : float, default 20.0
        Flight time [s].
    room : PlaneRoom, optional
        Scene (default :func:`build_plane_room`).
    scanner : PlaneScanner, optional
        Sensor (default ``PlaneScanner()``).
    yaw_rate_deg_s : float, default 45.0
        Yaw rate [deg/s].
    speed_m_s : float, default 0.6
        Speed [m/s].
    waypoints_m : array_like, shape (N, 3), optional
        Polyline of :func:`quad_flight`.
    odometry_noise : float, default 1.0
        Factor on every odometry noise and bias.
    rng : int or numpy.random.Generator, optional
        Seed or generator of range, intensity and odometry noise.

    Returns
    -------
    Flight
    """
    rng = as_rng(rng)
    room = build_plane_room() if room is None else room
    if not isinstance(room, PlaneRoom):
        raise TypeError(f"`room` must be a PlaneRoom; got {type(room).__name__}")
    scanner = PlaneScanner.resolve(scanner)
    k = check_positive(odometry_noise, "odometry_noise", allow_zero=True)
    t, T = quad_flight(duration_s, rate_hz=scanner.lines_per_s, yaw_rate_deg_s=yaw_rate_deg_s, speed_m_s=speed_m_s,
                       waypoints_m=waypoints_m)
    d_body = scanner_beam_directions(scanner)
    n, b = len(t), d_body.shape[0]
    d_map = np.einsum("nij,bj->nbi", T[:, :3, :3], d_body).reshape(-1, 3)
    o_line = (T[:, :3, :3] @ np.asarray(scanner.mount_m) + T[:, :3, 3])
    r, k_plane, cos_inc = np.empty(n * b), np.empty(n * b, dtype=np.intp), np.empty(n * b)
    refl = np.zeros(n * b)
    step = 8 * RAY_CHUNK   # a multiple of the caster's chunk: the same chunks, less memory (60 s: 495 -> ~250 MiB)
    for a in range(0, n * b, step):
        s = slice(a, min(a + step, n * b))
        o_map = o_line[np.arange(s.start, s.stop) // b]           # each ray's origin (its line's scanner)
        r[s], k_plane[s], cos_inc[s] = cast_rays_planes(room, o_map, d_map[s], scanner.range_max_m)
        hit = k_plane[s] >= 0
        refl[s][hit] = room.reflectance(k_plane[s][hit], o_map[hit] + r[s][hit, None] * d_map[s][hit])
    hit = k_plane >= 0
    r = r + rng.normal(0.0, scanner.sigma_range_m, r.shape)
    inten = scanner.intensity_gain * refl * cos_inc + rng.normal(0.0, scanner.sigma_intensity, r.shape)
    inten = np.where(hit, np.maximum(inten, 0.0), np.nan)
    odo = simulate_odometry_3d(T, sigma_trans_m=0.002 * k, sigma_rot_deg=0.05 * k,
                               bias_m_per_step=(0.0005 * k, -0.0003 * k, 0.0001 * k),
                               bias_yaw_deg_per_step=0.01 * k, rng=rng)
    return Flight(t, T, odo, r.reshape(n, b), inten.reshape(n, b), k_plane.reshape(n, b), room, scanner)
