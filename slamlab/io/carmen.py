"""Reader for CARMEN laser logs: ``FLASER`` scans with poses and ``ODOM`` messages (plain or ``.gz``).

API summary
-----------
- :func:`read_carmen` ``(path, *, max_range_m=None) -> CarmenLog``.
- :class:`CarmenLog`: ``ranges_m`` (n_scans, n_beams) with NaN kept, ``valid``
  mask, ``poses`` (laser pose per scan: x_m, y_m, heading_rad),
  ``odom_poses`` (the odometry pose stored in each FLASER line), ``timestamps_s``,
  ``odom`` (ODOM messages), ``params`` (PARAM lines), ``bearings_rad``, ``name``
  (the file name, for labels) and ``scan(i)`` / ``scans()``: the scans as
  :class:`slamlab.scans.Scan` objects in metres.
- :func:`flaser_angles` ``(n_beams, fov_rad=π) -> (n,)``: the CARMEN beam layout.

Formats handled (see each data set's PROVENANCE.md): the corrected Radish logs
(``FLASER n r_1..r_n x y θ odom_x odom_y odom_θ ipc_ts host logger_ts``, plus
``ODOM``, ``PARAM``, ``NEFF`` lines) and the MbICP SICK log (``FLASER`` lines
only, without timestamps, ``NaN`` for invalid readings). Other message types
are skipped and counted in ``CarmenLog.skipped``.
"""

from __future__ import annotations

import gzip
import math
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from .._validate import as_path, check_int, check_positive
from ..scans import Scan

__all__ = ["CarmenLog", "flaser_angles", "open_text", "read_carmen"]


def flaser_angles(n_beams: int, fov_rad: float = np.pi) -> np.ndarray:
    """Beam angles of a CARMEN front laser: first beam at ``-fov/2`` (the robot's right), counter-clockwise.

    An odd beam count spans ``-fov/2 .. +fov/2`` inclusive (181 beams at 1°,
    361 at 0.5°); an even count has the resolution ``fov/n`` and stops one step
    short of ``+fov/2`` (180 beams: -90° .. +89°), as in the CARMEN/GMapping
    convention described in the data's PROVENANCE.md.

    Parameters
    ----------
    n_beams : int
        Beams per scan.
    fov_rad : float
        Field of view [rad] (default ``pi``, 180°).

    Returns
    -------
    bearings_rad : ndarray, shape (n_beams,)
        Beam angles relative to the robot heading [rad].

    Examples
    --------
    >>> np.degrees(flaser_angles(181))[[0, 1, -1]].round(6).tolist()
    [-90.0, -89.0, 90.0]
    >>> np.degrees(flaser_angles(180))[[0, 1, -1]].round(6).tolist()
    [-90.0, -89.0, 89.0]
    """
    n = check_int(n_beams, "n_beams", minimum=2)
    fov = check_positive(fov_rad, "fov_rad")
    if n % 2:
        return np.linspace(-fov / 2, fov / 2, n)
    return -fov / 2 + fov * np.arange(n) / n


@dataclass(frozen=True)
class CarmenLog:
    """A CARMEN laser log read by :func:`read_carmen`; metres and radians.

    Attributes
    ----------
    path : str
        The log file read.
    ranges_m : ndarray, shape (n_scans, n_beams)
        FLASER ranges [m], NaN where the log has NaN.
    valid : ndarray of bool, shape (n_scans, n_beams)
        Reading finite, > 0 and < ``max_range_m``.
    poses : ndarray, shape (n_scans, 3)
        Laser pose of each FLASER line ``(x_m, y_m, heading_rad)``.
    odom_poses : ndarray, shape (n_scans, 3)
        Odometry pose of each FLASER line.
    timestamps_s : ndarray, shape (n_scans,)
        ipc timestamp [s], NaN when absent.
    odom : ndarray, shape (n_odom, 4)
        ODOM messages: ``x_m, y_m, heading_rad, timestamp_s`` (NaN when absent).
    max_range_m : float
        Maximum range of the laser [m].
    params : dict
        ``PARAM`` lines of the log, name → value string.
    skipped : dict
        Message type → number of lines skipped.
    """

    path: str
    ranges_m: np.ndarray  # (n_scans, n_beams), NaN where the log has NaN
    valid: np.ndarray  # (n_scans, n_beams) bool: finite, > 0 and < max_range_m
    poses: np.ndarray  # (n_scans, 3) laser pose of each FLASER line (x_m, y_m, heading_rad)
    odom_poses: np.ndarray  # (n_scans, 3) odometry pose of each FLASER line
    timestamps_s: np.ndarray  # (n_scans,) ipc timestamp, NaN when absent
    odom: np.ndarray  # (n_odom, 4) ODOM messages: x_m, y_m, heading_rad, timestamp_s (NaN when absent)
    max_range_m: float
    params: dict = field(default_factory=dict)
    skipped: dict = field(default_factory=dict)  # message type -> number of lines skipped

    @property
    def n_scans(self) -> int:
        """Number of FLASER scans."""
        return self.ranges_m.shape[0]

    @property
    def n_beams(self) -> int:
        """Beams per scan."""
        return self.ranges_m.shape[1]

    @property
    def bearings_rad(self) -> np.ndarray:
        """Beam angles relative to the robot heading (:func:`flaser_angles`)."""
        return flaser_angles(self.n_beams)

    @property
    def name(self) -> str:
        """The log's file name (what results are labelled with)."""
        return Path(self.path).name

    def __str__(self) -> str:
        return (f"CARMEN log {self.name}: {self.n_scans} scans x {self.n_beams} beams, "
                f"{self.odom.shape[0]} ODOM, {self.valid.mean():.1%} valid readings (< {self.max_range_m:g} m)")

    def scan(self, i: int) -> Scan:
        """Scan ``i`` as a :class:`~slamlab.scans.Scan` in metres.

        ``pose`` is the FLASER line's laser pose (SLAM-corrected in the corrected Radish
        logs, the odometry in the MbICP log), ``odom_pose`` its odometry pose. Invalid
        readings get ``ranges = max_range_m`` and ``valid = False``.

        Parameters
        ----------
        i : int
            Scan index, negative counts from the end.

        Returns
        -------
        Scan
            ``ranges``, ``valid``, ``bearings``, ``pose``, ``odom_pose``, ``time_s`` of that scan.
        """
        i = check_int(i, "i", minimum=-self.n_scans, maximum=self.n_scans - 1)
        return self._scan(i, self.bearings_rad)

    def _scan(self, i, bearings):
        fill = self.max_range_m if np.isfinite(self.max_range_m) else 0.0
        ok = self.valid[i]
        return Scan(bearings, np.where(ok, self.ranges_m[i], fill), ok, unit="m", max_range=self.max_range_m,
                    time_s=self.timestamps_s[i], odom_pose=self.odom_poses[i],
                    pose=self.poses[i])

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
        idx = range(self.n_scans) if indices is None else [
            check_int(int(i), "indices[k]", minimum=-self.n_scans, maximum=self.n_scans - 1) for i in indices]
        b = self.bearings_rad
        return [self._scan(i, b) for i in idx]


def open_text(path):
    """Open a log as text, plain or gzip, told apart by its magic bytes (not its name).

    Parameters
    ----------
    path : str or os.PathLike
        The file.

    Returns
    -------
    io.TextIOBase
        A text stream (ASCII; undecodable bytes replaced), to be closed by the caller (``with``).
    """
    with open(path, "rb") as fh:
        gz = fh.read(2) == b"\x1f\x8b"
    return gzip.open(path, "rt", encoding="ascii", errors="replace") if gz else open(path, encoding="ascii",
                                                                                         errors="replace")


def _float(tok: str) -> float:
    return float(tok)  # accepts "NaN", "nan", "inf"


def read_carmen(path, *, max_range_m: float | None = None) -> CarmenLog:
    """Read the ``FLASER``, ``ODOM`` and ``PARAM`` lines of a CARMEN log (plain text or gzip).

    Parameters
    ----------
    path : str or pathlib.Path
        The log file (gzip detected from its magic bytes, not its name).
    max_range_m : float, optional
        Readings ``>= max_range_m`` are "no return" (``valid = False``). Default:
        when the log marks invalid readings with ``NaN`` (the MbICP log), the largest
        reading rounded up to a whole metre (MbICP: 7.999 → 8 m, its reader's
        ``0 < r < 8``); otherwise the largest reading of the log (the sensor's
        maximum value, which the corrected Radish logs use for no return).

    Returns
    -------
    CarmenLog

    Raises
    ------
    FileNotFoundError
        When ``path`` does not exist.
    ValueError
        When the log holds no FLASER line, a FLASER line is short or
        malformed, or the beam count changes between scans (the message names
        the line number).
    """
    p = as_path(path, "path", kind="file")
    if max_range_m is not None:
        max_range_m = check_positive(max_range_m, "max_range_m")
    ranges: list[list[float]] = []
    poses: list[list[float]] = []
    odom_p: list[list[float]] = []
    stamps: list[float] = []
    odom: list[list[float]] = []
    params: dict[str, str] = {}
    skipped: dict[str, int] = {}
    n_beams = None
    with open_text(p) as fh:
        for lineno, line in enumerate(fh, start=1):
            tok = line.split()
            if not tok or tok[0].startswith("#"):
                continue
            kind = tok[0]
            try:
                if kind == "FLASER":
                    n = int(tok[1])
                    if n < 2 or len(tok) < 2 + n + 6:
                        raise ValueError(f"expected {n} ranges and 6 pose values, got {len(tok) - 2} fields")
                    if n_beams is None:
                        n_beams = n
                    elif n != n_beams:
                        raise ValueError(f"beam count {n} differs from the first scan's {n_beams}")
                    vals = [_float(t) for t in tok[2:2 + n + 6]]
                    ranges.append(vals[:n])
                    poses.append(vals[n:n + 3])
                    odom_p.append(vals[n + 3:n + 6])
                    stamps.append(_float(tok[2 + n + 6]) if len(tok) > 2 + n + 6 else math.nan)
                elif kind == "ODOM":
                    vals = [_float(t) for t in tok[1:4]]
                    if len(vals) != 3:
                        raise ValueError(f"expected x y theta, got {len(tok) - 1} fields")
                    stamp = _float(tok[7]) if len(tok) > 7 else math.nan
                    odom.append([*vals, stamp])
                elif kind == "PARAM":
                    if len(tok) >= 3:
                        params[tok[1]] = tok[2]
                else:
                    skipped[kind] = skipped.get(kind, 0) + 1
            except (ValueError, IndexError) as exc:
                raise ValueError(f"{p.name}, line {lineno}: malformed {kind} message: {exc}") from None
    if not ranges:
        raise ValueError(f"{p.name}: no FLASER message found")
    R = np.array(ranges, dtype=float)
    finite = np.isfinite(R)
    if max_range_m is None:
        if not finite.any():
            max_range_m = math.inf
        elif np.isnan(R).any():  # NaN marks invalid readings: every finite reading below the limit is valid
            max_range_m = float(np.floor(R[finite].max()) + 1.0)
        else:
            max_range_m = float(R[finite].max())
    with np.errstate(invalid="ignore"):
        valid = finite & (R > 0) & (max_range_m > R)
    P = np.array(poses, dtype=float)
    O = np.array(odom_p, dtype=float)
    for name, arr in (("pose", P), ("odometry pose", O)):
        if not np.all(np.isfinite(arr)):
            raise ValueError(f"{p.name}: a FLASER {name} is not finite")
    return CarmenLog(
        path=str(p), ranges_m=R, valid=valid, poses=P, odom_poses=O, timestamps_s=np.array(stamps, dtype=float),
        odom=np.array(odom, dtype=float).reshape(-1, 4), max_range_m=float(max_range_m), params=params,
        skipped=skipped,
    )
