"""One 2-D range scan type for the simulator and every log reader (004 §7).

API summary
-----------
- :class:`Scan`: ``bearings_rad`` (n,), ``ranges`` (n,) in ``unit``, ``valid`` (n,)
  mask, ``max_range``, ``time_s`` (NaN when unknown), ``odom_pose`` and ``pose``
  (``(3,)`` or None); ``.points(pose=None)``, ``.to_cells(cell_m)``, ``.to_metres(cell_m)``.
- :func:`scan_to_points` ``(bearings_rad, ranges, pose=None, valid=None) -> (k, 2)``:
  the one polar → world conversion (through :func:`slamlab.geometry.se2_transform`).

Units: why a ``unit`` field
---------------------------
004 works in **cells** (its simulator measures ranges to 0.1 cell on a grid) while
real logs are in **metres**. A scan therefore carries its unit, ``"cell"`` or
``"m"``, with ``ranges`` and ``max_range`` in that unit, instead of two range
fields or a simulator forced into metres. Algorithms that work on a grid
(correlation, the occupancy builder) need ``unit == "cell"`` and say so; a metric
scan enters them through ``scan.to_cells(cell_m)`` (and its poses through a
:class:`~slamlab.scans.GridFrame`). Algorithms that are unit-free (Hough lines,
ICP) take either unit and read their thresholds in the scan's unit.

Beams without a return have ``valid = False`` and ``ranges = max_range`` (the
"no return" reading, finite when the sensor has a range limit), so ``ranges`` is
always finite and non-negative.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace

import numpy as np

from .._validate import as_vector, check_choice, check_positive
from ..geometry.se2 import check_pose, se2_transform

__all__ = ["UNITS", "Scan", "scan_to_points"]

#: The length units a scan may carry.
UNITS = ("cell", "m")


def _optional_pose(value, name):
    return None if value is None else check_pose(value, name).copy()


@dataclass(frozen=True, eq=False)  # arrays: compare fields explicitly, not with ==
class Scan:
    """One scan: beams ``(α_i, l_i)`` relative to the sensor heading, with validity and poses (004 §7).

    Parameters
    ----------
    bearings_rad : array_like, shape (n,)
        Beam angles relative to the sensor's heading (counter-clockwise, 0 = ahead).
    ranges : array_like, shape (n,)
        Measured ranges in ``unit``; ``max_range`` where there is no return.
    valid : array_like of bool, shape (n,)
        Beams with a return.
    unit : {"cell", "m"}
        Unit of ``ranges`` and ``max_range`` (see the module docstring).
    max_range : float
        The sensor's range limit (``inf`` when unknown).
    time_s : float
        Time stamp, NaN when the log has none.
    odom_pose : array_like, shape (3,), optional
        Odometry pose stored with the scan (real logs).
    pose : array_like, shape (3,), optional
        The best-known pose: the simulator's truth or a corrected log's pose.

    Examples
    --------
    >>> s = Scan([0.0, np.pi / 2], [2.0, 5.0], [True, False], unit="cell", max_range=5.0, pose=[1, 1, 0])
    >>> print(s)
    Scan of 2 beams, 1 returns, max range 5 cells
    >>> s.points().tolist()
    [[3.0, 1.0]]
    """

    bearings_rad: np.ndarray
    ranges: np.ndarray
    valid: np.ndarray
    unit: str = "cell"
    max_range: float = math.inf
    time_s: float = math.nan
    odom_pose: np.ndarray | None = field(default=None, repr=False)
    pose: np.ndarray | None = field(default=None, repr=False)

    def __post_init__(self):
        b = as_vector(self.bearings_rad, "bearings_rad")
        r = as_vector(self.ranges, "ranges")
        if b.shape != r.shape:
            raise ValueError(f"`bearings_rad` and `ranges` must have the same length; got {b.size} and {r.size}")
        if np.any(r < 0):
            raise ValueError(f"`ranges` must be >= 0; got minimum {r.min()}")
        ok = np.asarray(self.valid)
        if ok.dtype != bool or ok.shape != b.shape:
            raise ValueError(f"`valid` must be a bool array of shape {b.shape}; got {ok.dtype} {ok.shape}")
        unit = check_choice(self.unit, "unit", UNITS)
        rmax = float(self.max_range)
        if not rmax > 0:
            raise ValueError(f"`max_range` must be > 0; got {self.max_range!r}")
        t = float(self.time_s)
        for name, value in (("bearings_rad", b.copy()), ("ranges", r.copy()), ("valid", ok.copy())):
            value.flags.writeable = False
            object.__setattr__(self, name, value)
        object.__setattr__(self, "unit", unit)
        object.__setattr__(self, "max_range", rmax)
        object.__setattr__(self, "time_s", t)
        object.__setattr__(self, "odom_pose", _optional_pose(self.odom_pose, "odom_pose"))
        object.__setattr__(self, "pose", _optional_pose(self.pose, "pose"))

    @property
    def n_beams(self) -> int:
        """Number of beams."""
        return int(self.bearings_rad.size)

    def __str__(self) -> str:
        return (f"Scan of {self.n_beams} beams, {int(self.valid.sum())} returns, "
                f"max range {self.max_range:g} {'cells' if self.unit == 'cell' else self.unit}")

    def points(self, pose=None) -> np.ndarray:
        """World points ``(x, y)`` of the returns, seen from ``pose``.

        Default pose: :attr:`pose`, else :attr:`odom_pose`, else the sensor frame (origin).

        Parameters
        ----------
        pose : array_like, shape (3,), optional
            Sensor pose ``(x, y, heading_rad)`` in the scan's units.

        Returns
        -------
        points : ndarray, shape (k, 2)
            End points of the valid returns.
        """
        if pose is None:
            pose = self.pose if self.pose is not None else self.odom_pose
        return scan_to_points(self.bearings_rad, self.ranges, pose, self.valid)

    def _scaled(self, factor: float, unit: str) -> Scan:
        def move(p):
            return None if p is None else np.array([p[0] * factor, p[1] * factor, p[2]])

        return replace(self, ranges=self.ranges * factor, unit=unit, max_range=self.max_range * factor,
                       odom_pose=move(self.odom_pose), pose=move(self.pose))

    def to_cells(self, cell_m: float) -> Scan:
        """This scan in cell units (ranges and pose positions divided by ``cell_m``); a cell scan is returned as is.

        Parameters
        ----------
        cell_m : float
            Cell size [m], positive.

        Returns
        -------
        Scan
            The scan with ``unit="cell"``.

        Examples
        --------
        >>> Scan([0.0], [0.5], [True], unit="m", max_range=4.0).to_cells(0.1).ranges.tolist()
        [5.0]
        """
        cell = check_positive(cell_m, "cell_m")
        return self if self.unit == "cell" else self._scaled(1.0 / cell, "cell")

    def to_metres(self, cell_m: float) -> Scan:
        """This scan in metres (ranges and pose positions times ``cell_m``); a metric scan is returned as is.

        Parameters
        ----------
        cell_m : float
            Cell size [m], positive.

        Returns
        -------
        Scan
            The scan with ``unit="m"``.
        """
        cell = check_positive(cell_m, "cell_m")
        return self if self.unit == "m" else self._scaled(cell, "m")


def scan_to_points(bearings_rad, ranges, pose=None, valid=None) -> np.ndarray:
    """Polar beams ``(α_i, l_i)`` seen from ``pose`` → world points ``(x, y)`` (004 §7).

    Parameters
    ----------
    bearings_rad, ranges : array_like, shape (n,)
    pose : array_like, shape (3,), optional
        Sensor pose; default the origin (points in the sensor frame).
    valid : array_like of bool, shape (n,), optional
        Keep only these beams.

    Returns
    -------
    numpy.ndarray, shape (k, 2)

    Examples
    --------
    >>> scan_to_points([0.0, np.pi / 2], [2.0, 3.0], [1.0, 1.0, 0.0]).round(12).tolist()
    [[3.0, 1.0], [1.0, 4.0]]
    """
    a = as_vector(bearings_rad, "bearings_rad")
    rr = as_vector(ranges, "ranges")
    if a.shape != rr.shape:
        raise ValueError(f"`bearings_rad` and `ranges` must have the same length; got {a.size} and {rr.size}")
    p = np.zeros(3) if pose is None else check_pose(pose)
    if valid is not None:
        m = np.asarray(valid)
        if m.dtype != bool or m.shape != a.shape:
            raise ValueError(f"`valid` must be a bool array of shape {a.shape}; got {m.dtype} {m.shape}")
        a, rr = a[m], rr[m]
    return se2_transform(p, np.column_stack([rr * np.cos(a), rr * np.sin(a)]))
