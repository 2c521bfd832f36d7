"""Reader for the Mines ParisTech Hokuyo URG-04LX log with wheel ticks (``mines-urg04lx-odometry``).

The format (see the data set's PROVENANCE.md, after BreezySLAM's ``examples/mines.py``):
one scan per line, 707 whitespace-separated numbers — field 0 the timestamp in µs,
fields 2 and 3 the cumulative left and right wheel encoder ticks, fields 24..705 the
682 ranges in mm of a URG-04LX (240° field of view, beams evenly spaced, taken here
counter-clockwise from -120° to +120°), field 706 unused. Ranges below 20 mm are
error codes (no return).

Odometry (BreezySLAM's ``Rover``): wheel radius 77 mm, half axle 165 mm, 2000 ticks
per wheel revolution (PROVENANCE.md). The data set's note also quotes BreezySLAM's
``ticks·180/2000`` "degrees"; read with the standard differential-drive formulas below
that halves every turn and distance. Our check on the log: with the full-revolution reading
the odometry path closes into the building's loop and Hough SLAM's line-based heading
ends within 10° of it, and scan-to-scan ICP on the 20 sharpest turns gives a median
rotation of 0.7 (scattered) of that reading, not 2 — so we use 2000 ticks per revolution. A step gives the travelled distance
``d = R·(Δα_l + Δα_r)/2`` and the turn ``Δθ = R·(Δα_r - Δα_l)/(2·half_axle)``. The laser
sits 145 mm ahead of the wheel axis; :func:`urg04lx_sensor_increments` moves the
increments to the laser's frame.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from .._validate import as_finite_array, as_path, check_int, check_positive, parse_numbers
from ..geometry.se2 import se2_compose, se2_integrate, se2_inverse
from ..scans import Scan

__all__ = [
    "URG04LX_FOV_RAD",
    "URG04LX_N_BEAMS",
    "UrgLog",
    "read_urg04lx_log",
    "urg04lx_bearings",
    "urg04lx_odometry",
    "urg04lx_sensor_increments",
]

URG04LX_N_BEAMS = 682
URG04LX_FOV_RAD = math.radians(240.0)
_N_FIELDS = 707
_FIRST_RANGE = 24
_MIN_VALID_MM = 20.0


@dataclass(frozen=True)
class UrgLog:
    """A URG-04LX log: ``ranges_m`` (n, 682) with NaN where there is no return, wheel ticks, times.

    Attributes
    ----------
    time_s : ndarray, shape (n,)
        Time of each scan [s] from the first scan.
    ticks : ndarray, shape (n, 2)
        Cumulative ``(left, right)`` encoder ticks.
    ranges_m : ndarray, shape (n, 682)
        Ranges [m], NaN where there is no return.
    bearings_rad : ndarray, shape (682,)
        Beam directions [rad] (:func:`urg04lx_bearings`).
    path : str
        The log file read.
    max_range_m : float
        Maximum range of the sensor [m] (default 4).
    """

    time_s: np.ndarray = field(repr=False)  # (n,) seconds from the first scan
    ticks: np.ndarray = field(repr=False)  # (n, 2) cumulative (left, right) encoder ticks
    ranges_m: np.ndarray = field(repr=False)  # (n, 682)
    bearings_rad: np.ndarray = field(repr=False)  # (682,)
    path: str = ""
    max_range_m: float = 4.0

    def __len__(self) -> int:
        return int(self.ranges_m.shape[0])

    @property
    def name(self) -> str:
        """The log's file name (what results are labelled with)."""
        return Path(self.path).name

    def __str__(self) -> str:
        valid = np.isfinite(self.ranges_m).mean()
        return (f"URG-04LX log {self.name}: {len(self)} scans of {self.ranges_m.shape[1]} beams over "
                f"{self.time_s[-1]:.1f} s, {valid:.0%} valid ranges")

    def odometry_poses(self, *, offset_m: float = 0.145) -> np.ndarray:
        """The laser's pose per scan integrated from the wheel ticks, starting at ``(0, 0, 0)``; ``(n, 3)``.

        Parameters
        ----------
        offset_m : float
            Distance of the laser ahead of the wheel axle [m] (default 0.145).

        Returns
        -------
        poses : ndarray, shape (n, 3)
            ``(x_m, y_m, heading_rad)`` of the laser per scan.
        """
        return se2_integrate(np.zeros(3), urg04lx_sensor_increments(urg04lx_odometry(self.ticks),
                                                                    offset_m=offset_m))

    def scan(self, k: int) -> Scan:
        """Scan ``k`` as a :class:`~slamlab.scans.Scan` in metres (no return: ``valid`` False, range = max range).

        ``odom_pose`` is the laser's pose integrated from the wheel ticks (:meth:`odometry_poses`).

        Parameters
        ----------
        k : int
            Scan index, negative counts from the end.

        Returns
        -------
        Scan
            ``ranges``, ``valid``, ``bearings``, ``odom_pose`` of that scan.
        """
        k = check_int(k, "k", minimum=-len(self), maximum=len(self) - 1)
        return self._scan(k, self.odometry_poses()[k])

    def _scan(self, k, odom_pose):
        r = self.ranges_m[k]
        ok = np.isfinite(r)
        return Scan(self.bearings_rad, np.where(ok, r, self.max_range_m), ok, unit="m", max_range=self.max_range_m,
                    time_s=self.time_s[k], odom_pose=odom_pose)

    def scans(self, indices=None) -> list[Scan]:
        """Every scan (or those at ``indices``) as :class:`~slamlab.scans.Scan` objects.

        Parameters
        ----------
        indices : iterable of int, optional
            Scan indices to return; ``None`` = every scan.

        Returns
        -------
        list of Scan
            One :class:`~slamlab.scans.Scan` per index, as :meth:`scan` builds it.
        """
        odo = self.odometry_poses()
        idx = range(len(self)) if indices is None else [
            check_int(int(i), "indices[k]", minimum=-len(self), maximum=len(self) - 1) for i in indices]
        return [self._scan(k, odo[k]) for k in idx]


def urg04lx_bearings(n_beams: int = URG04LX_N_BEAMS, fov_rad: float = URG04LX_FOV_RAD) -> np.ndarray:
    """Beam directions: ``n_beams`` evenly from ``-fov/2`` to ``+fov/2`` (counter-clockwise, 0 = ahead).

    Parameters
    ----------
    n_beams : int
        Number of beams, at least 2 (default 682).
    fov_rad : float
        Field of view [rad] (default 240°).

    Returns
    -------
    bearings_rad : ndarray, shape (n_beams,)
        Beam directions [rad].

    Examples
    --------
    >>> b = urg04lx_bearings()
    >>> b.size, round(float(np.degrees(b[0])), 3), round(float(np.degrees(b[1] - b[0])), 4)
    (682, -120.0, 0.3524)
    """
    n = check_int(n_beams, "n_beams", minimum=2)
    fov = check_positive(fov_rad, "fov_rad")
    return np.linspace(-fov / 2, fov / 2, n)


def read_urg04lx_log(path, *, max_range_m: float = 4.0) -> UrgLog:
    """Read a Mines URG-04LX log (``exp2.dat``): ranges in metres, NaN for no return.

    Parameters
    ----------
    path : str or Path
        The ``.dat`` file, e.g. ``slamlab.data.find_data("mines-urg04lx-odometry/exp2.dat")``.
    max_range_m : float
        Longer ranges are treated as no return (BreezySLAM uses 4000 mm as "no detection").

    Raises
    ------
    FileNotFoundError, ValueError
        When the file is missing, or a line does not have 707 numbers or holds a
        token that is not a number (the message names the file and line).
    """
    p = as_path(path, "path", kind="file")
    max_range_m = check_positive(max_range_m, "max_range_m")
    rows = []
    with p.open(encoding="ascii", errors="replace") as fh:
        for lineno, line in enumerate(fh, 1):
            if not line.strip():
                continue
            fields = line.split()
            if len(fields) != _N_FIELDS:
                raise ValueError(f"{p.name} line {lineno}: expected {_N_FIELDS} numbers; got {len(fields)}")
            rows.append(parse_numbers(fields, f"{p.name} line {lineno}"))
    if not rows:
        raise ValueError(f"{p.name}: no scans")
    data = np.array(rows)
    ranges = data[:, _FIRST_RANGE:_FIRST_RANGE + URG04LX_N_BEAMS] / 1000.0
    bad = (ranges < _MIN_VALID_MM / 1000.0) | (ranges > max_range_m)
    ranges[bad] = np.nan
    t = (data[:, 0] - data[0, 0]) * 1e-6
    return UrgLog(t, data[:, 2:4].astype(np.int64), ranges, urg04lx_bearings(), str(p), float(max_range_m))


def urg04lx_odometry(ticks, *, wheel_radius_m: float = 0.077, half_axle_m: float = 0.165,
                     ticks_per_turn: float = 2000.0) -> np.ndarray:
    """Body-frame increments ``(dx, dy, dθ)`` of the wheel-axis centre between scans (midpoint rule).

    Parameters
    ----------
    ticks : (n, 2) array_like
        Cumulative (left, right) encoder ticks.
    wheel_radius_m, half_axle_m : float
        BreezySLAM's Mines rover: 77 mm and 165 mm.
    ticks_per_turn : float
        Encoder ticks per wheel revolution.

    Returns
    -------
    (n-1, 3) array

    Examples
    --------
    >>> u = urg04lx_odometry([[0, 0], [2000, 2000], [2000, 2000 + 1000]])
    >>> u.round(4).tolist()
    [[0.4838, 0.0, 0.0], [0.1129, 0.0433, 0.733]]
    """
    T = as_finite_array(ticks, "ticks", ndim=2)
    if T.shape[1] != 2 or T.shape[0] < 1:
        raise ValueError(f"`ticks` must have shape (n, 2) = (left, right); got shape {T.shape}")
    R = check_positive(wheel_radius_m, "wheel_radius_m")
    b = check_positive(half_axle_m, "half_axle_m")
    k = check_positive(ticks_per_turn, "ticks_per_turn")
    dw = np.diff(T, axis=0) * (2 * math.pi / k) * R  # wheel travel (left, right) in metres
    d = dw.mean(axis=1)
    dth = (dw[:, 1] - dw[:, 0]) / (2 * b)
    return np.column_stack([d * np.cos(dth / 2), d * np.sin(dth / 2), dth])


def urg04lx_sensor_increments(increments, *, offset_m: float = 0.145) -> np.ndarray:
    """Move body increments to a sensor mounted ``offset_m`` ahead: ``u_s = o⁻¹ ⊕ u ⊕ o``.

    Parameters
    ----------
    increments : array_like, shape (n, 3)
        Body-frame increments ``(dx_m, dy_m, dtheta_rad)`` of the wheel axle.
    offset_m : float
        Distance of the sensor ahead of the axle [m] (default 0.145).

    Returns
    -------
    increments : ndarray, shape (n, 3)
        The sensor's increments; the turn is kept as given (not re-wrapped).

    Examples
    --------
    >>> urg04lx_sensor_increments([[0.0, 0.0, np.pi / 2]], offset_m=1.0).round(12).tolist()
    [[-1.0, 1.0, 1.570796326795]]
    """
    U = as_finite_array(increments, "increments", ndim=2)
    if U.shape[1] != 3:
        raise ValueError(f"`increments` must have shape (n, 3); got shape {U.shape}")
    o = np.array([float(offset_m), 0.0, 0.0])
    out = se2_compose(se2_compose(se2_inverse(o), U), o)
    out[:, 2] = U[:, 2]  # keep the increment's turn as given (not re-wrapped)
    return out
