"""Scanning rangefinder and odometry on an occupancy grid (004 §7, §8), in cell units.

API summary
-----------
- :func:`beam_angles` ``(n_beams, fov_rad) -> (n,)`` beam angles relative to the heading.
- :func:`cast_rays` ``(grid, pose, angles_rad, max_range) -> (ranges, hit)``:
  exact grid traversal (Amanatides-Woo), vectorised over beams: :func:`slamlab.scans.cast_rays` for one pose.
- :class:`Rangefinder` (beam count, field of view, maximum range, Gaussian range
  noise, range quantisation, beam aperture) with ``.scan(grid, pose, rng) -> Scan``;
  :func:`simulate_scans` for a whole path.
- The scans are :class:`slamlab.scans.Scan` objects in cell units (``unit="cell"``,
  ``pose`` = the true pose); increments ↔ poses use :mod:`slamlab.geometry.se2`.
- :func:`simulate_odometry` → :class:`Odometry` (noisy increments with
  configurable drift and the integrated odometry path).

Conventions are those of :mod:`slamlab.scans.grid`: points ``(x, y)`` with x along
columns, y along rows, cell ``(row, col)`` centred on ``(col, row)``; poses
``(x, y, heading_rad)``; a beam at angle ``α_i`` points along ``heading + α_i``.
A beam stops at the first OBSTACLE cell (free and unexplored cells are
transparent); its range is the distance to the face it enters that cell by. A
beam that reaches ``max_range_cells`` or leaves the grid returns
``max_range_cells`` with ``hit = False`` (no return).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .._validate import as_rng, check_int, check_positive
from ..geometry.odometry import Odometry, simulate_odometry  # one place: geometry (re-exported here)
from ..geometry.se2 import check_pose, check_poses
from ..scans import Scan, check_grid
from ..scans.raycast import cast_rays  # the one grid ray caster (re-exported here)

__all__ = [
    "Odometry",
    "Rangefinder",
    "beam_angles",
    "cast_rays",
    "simulate_odometry",
    "simulate_scans",
]


def beam_angles(n_beams: int = 360, fov_rad: float = 2 * np.pi) -> np.ndarray:
    """Beam angles relative to the heading (004 §7).

    A full circle (``fov_rad >= 2π``) gives ``α_i = 2π·i/n`` (beam 0 straight
    ahead, no repeated beam); a sector gives ``n`` angles evenly from
    ``-fov/2`` to ``+fov/2`` inclusive (the SICK / CARMEN layout).

    Parameters
    ----------
    n_beams : int, default 360
        Number of beams.
    fov_rad : float, default 2π
        Field of view [rad], at most 2π.

    Returns
    -------
    numpy.ndarray, shape (n_beams,)

    Examples
    --------
    >>> np.degrees(beam_angles(4)).tolist()
    [0.0, 90.0, 180.0, 270.0]
    >>> np.degrees(beam_angles(3, np.pi)).tolist()
    [-90.0, 0.0, 90.0]
    """
    n = check_int(n_beams, "n_beams", minimum=1)
    fov = check_positive(fov_rad, "fov_rad")
    if fov > 2 * np.pi + 1e-9:
        raise ValueError(f"`fov_rad` must be <= 2π; got {fov}")
    if fov >= 2 * np.pi - 1e-9:
        return 2 * np.pi * np.arange(n) / n
    if n == 1:
        return np.zeros(1)
    return np.linspace(-fov / 2, fov / 2, n)


@dataclass(frozen=True)
class Rangefinder:
    """A scanning rangefinder: beams, field of view, range limit, Gaussian noise, quantisation (004 §7).

    Parameters
    ----------
    n_beams : int
        Number of beams.
    fov_rad : float
        Field of view (``2π`` = full circle, as in 004's simulations).
    max_range_cells : float
        Maximum range.
    range_std_cells : float
        σ of the additive Gaussian range noise (004 does not give its σ).
    quantum_cells : float
        Ranges are rounded to this step (004: 0.1 cell); 0 disables it.
    aperture_rad : float
        Full opening angle of each beam's cone [rad], in [0, π); 0 (default): a thin ray, a laser. A wider cone
        returns the nearest echo inside it, as an ultrasonic rangefinder does (ours: 004 §7 says such sensors,
        with apertures usually over 10°, distort the measurements; it gives no model).
    aperture_rays : int
        Rays cast evenly across a cone of ``aperture_rad > 0`` (the nearest hit among them is the return), at
        least 2.

    Examples
    --------
    >>> g = np.zeros((5, 9), dtype=np.int8); g[:, 8] = 1
    >>> s = Rangefinder(n_beams=4, max_range_cells=20).scan(g, [2.0, 2.0, 0.0])
    >>> s.ranges.tolist(), s.valid.tolist()
    ([5.5, 20.0, 20.0, 20.0], [True, False, False, False])
    """

    n_beams: int = 360
    fov_rad: float = 2 * np.pi
    max_range_cells: float = 100.0
    range_std_cells: float = 0.0
    quantum_cells: float = 0.1
    aperture_rad: float = 0.0
    aperture_rays: int = 9

    def __post_init__(self):
        beam_angles(self.n_beams, self.fov_rad)  # validates both
        check_positive(self.max_range_cells, "max_range_cells")
        check_positive(self.range_std_cells, "range_std_cells", allow_zero=True)
        check_positive(self.quantum_cells, "quantum_cells", allow_zero=True)
        if check_positive(self.aperture_rad, "aperture_rad", allow_zero=True) >= np.pi:
            raise ValueError(f"`aperture_rad` must be below π; got {self.aperture_rad}")
        check_int(self.aperture_rays, "aperture_rays", minimum=2)

    @property
    def angles_rad(self) -> np.ndarray:
        """The beam angles relative to the heading, shape ``(n_beams,)``."""
        return beam_angles(self.n_beams, self.fov_rad)

    def measure(self, true_ranges, hit, rng=None) -> np.ndarray:
        """Add noise to the returns, quantise and clip to ``[0, max_range]``; no-return beams stay at max range.

        Parameters
        ----------
        true_ranges : array_like, shape (n_beams,)
            Exact ranges [cells].
        hit : array_like of bool, shape (n_beams,)
            Beams with a return.
        rng : int or numpy.random.Generator, optional
            Seed or generator of the noise.

        Returns
        -------
        numpy.ndarray, shape (n_beams,)
        """
        rng = as_rng(rng)
        out = np.asarray(true_ranges, dtype=float).copy()
        if self.range_std_cells > 0:
            out[hit] += rng.normal(0.0, self.range_std_cells, int(np.count_nonzero(hit)))
        if self.quantum_cells > 0:
            out[hit] = np.round(out[hit] / self.quantum_cells) * self.quantum_cells
        out[hit] = np.clip(out[hit], 0.0, self.max_range_cells)
        return out

    def scan(self, grid, pose, rng=None) -> Scan:
        """Measure the scan seen from ``pose`` in ``grid`` (noise drawn from ``rng``).

        Parameters
        ----------
        grid : array_like of int, shape (H, W)
            Cell codes of the world.
        pose : array_like, shape (3,)
            ``(x, y)`` [cells], heading [rad].
        rng : int or numpy.random.Generator, optional
            Seed or generator of the noise.

        Returns
        -------
        Scan
            In cell units, with ``pose`` recorded.
        """
        ang = self.angles_rad
        if self.aperture_rad > 0:  # the nearest echo in each beam's cone
            spread = np.linspace(-self.aperture_rad / 2, self.aperture_rad / 2, self.aperture_rays)
            r, h = cast_rays(grid, pose, (ang[:, None] + spread[None, :]).ravel(), self.max_range_cells)
            r = np.where(h, r, np.inf).reshape(ang.size, spread.size)
            hit = h.reshape(ang.size, spread.size).any(axis=1)
            true_r = np.where(hit, r.min(axis=1), float(self.max_range_cells))
        else:
            true_r, hit = cast_rays(grid, pose, ang, self.max_range_cells)
        return Scan(ang, self.measure(true_r, hit, rng), hit, unit="cell", max_range=float(self.max_range_cells),
                    pose=check_pose(pose))


def simulate_scans(grid, poses, rangefinder: Rangefinder | None = None, rng=None) -> list[Scan]:
    """One :class:`~slamlab.scans.Scan` per pose of a path (004 §8), noise from one seeded stream.

    Parameters
    ----------
    grid : array_like of int, shape (H, W)
        Cell codes of the world.
    poses : array_like, shape (N, 3)
        Poses of the path.
    rangefinder : Rangefinder, optional
        The sensor (default ``Rangefinder()``).
    rng : int or numpy.random.Generator, optional
        One stream for all the scans' noise.

    Returns
    -------
    list of Scan

    Examples
    --------
    >>> g = np.zeros((5, 9), dtype=np.int8); g[:, 8] = 1
    >>> [float(s.ranges[0]) for s in simulate_scans(g, [[2, 2, 0], [3, 2, 0]], Rangefinder(4, max_range_cells=9))]
    [5.5, 4.5]
    """
    rf = Rangefinder() if rangefinder is None else rangefinder
    if not isinstance(rf, Rangefinder):
        raise TypeError(f"`rangefinder` must be a Rangefinder; got {type(rf).__name__}")
    P = check_poses(poses)
    g = check_grid(grid)
    rng = as_rng(rng)
    return [rf.scan(g, p, rng) for p in P]
