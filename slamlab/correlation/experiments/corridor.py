"""A constructed corridor (ours): the half-turn tie of one scan and how joined scans break it; timing."""

from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np

from ... import _validate as v
from ..._table import format_table
from ...scans import FREE, OBSTACLE, UNEXPLORED
from ...sim.rangefinder import Rangefinder
from ..algorithm import Localisation, LocaliseParams, heading_error, localise, localise_joined


def corridor_grid() -> np.ndarray:
    """A straight corridor (rows 20..30 free, walls at rows 19 and 31) open at the map's left edge, with a dead
    end at column 150 (52×160 cells; our test case): symmetric under a half turn wherever a 25-cell scan sees
    neither end.

    Returns
    -------
    numpy.ndarray of int8, shape (52, 160)
        Cell codes.

    Examples
    --------
    >>> g = corridor_grid(); g.shape, int(g[25, 150]), int(g[25, 149])
    ((52, 160), 1, 0)
    """
    g = np.full((52, 160), UNEXPLORED, dtype=np.int8)
    g[19:32, :151] = OBSTACLE
    g[20:31, :150] = FREE
    return g


@dataclass(frozen=True)
class CorridorResult:
    """One scan vs two scans joined by odometry in :func:`corridor_grid` (ours).

    Attributes
    ----------
    true_pose : numpy.ndarray, shape (3,)
        Pose of the last scan [cells, rad].
    odom_poses : numpy.ndarray, shape (k, 3)
        The scans' poses, last scan first.
    single : Localisation
        The last scan alone.
    joined : Localisation
        The scans joined by odometry.
    """

    true_pose: np.ndarray  # (3,) cells, rad: the pose of the last scan
    odom_poses: np.ndarray  # (k, 3) the scans' poses, last scan first
    single: Localisation
    joined: Localisation

    def __str__(self) -> str:
        e1 = np.degrees(heading_error(self.single.pose[2], self.true_pose[2]))
        e2 = np.degrees(heading_error(self.joined.pose[2], self.true_pose[2]))
        return f"corridor: one scan {e1:.0f}° off (ambiguity {self.single.ambiguity:.3f}), " \
               f"{self.joined.n_scans} joined {e2:.0f}° off (ambiguity {self.joined.ambiguity:.3f})"

    def table(self) -> str:
        """One row per mode: estimate, errors, score, rival and ambiguity.

        Returns
        -------
        str
        """
        t = self.true_pose
        rows = []
        for label, loc in (("1 scan", self.single), (f"{self.joined.n_scans} scans + odometry", self.joined)):
            rows.append([label, f"{loc.pose[0]:.0f}", f"{loc.pose[1]:.0f}", f"{np.degrees(loc.pose[2]):.0f}",
                         f"{np.hypot(loc.pose[0] - t[0], loc.pose[1] - t[1]):.0f}",
                         f"{np.degrees(heading_error(loc.pose[2], t[2])):.0f}", f"{loc.score:.0f}",
                         f"{loc.rival_score:.0f}", f"{loc.ambiguity:.3f}"])
        title = (f"Corridor with a dead end, truth x = {t[0]:.0f}, y = {t[1]:.0f}, θ = {np.degrees(t[2]):.0f}° "
                 f"(cells, deg); noise-free scans, Δα = {np.degrees(self.single.headings_rad[1] - self.single.headings_rad[0]):g}°")
        return format_table(["mode", "x est", "y est", "θ est", "pos. err", "θ err", "score", "rival", "ambiguity"],
                            rows, title=title)


def run_corridor_tie(*, max_range_cells: float = 25.0, step_cells: float = 30.0,
                     params: LocaliseParams | None = None, **overrides) -> CorridorResult:
    """The half-turn tie of one scan in a corridor, broken by joining the scan before it (ours).

    The robot drives towards −x along :func:`corridor_grid`; the last scan, at (100, 25), sees a plain
    corridor (every shift and the half turn score alike: ambiguity 1, and the tie rule picks heading 0°,
    180° off); the scan ``step_cells`` before it sees the dead end, which pins the pose once both are
    joined by (exact) odometry. ``params`` / ``**overrides``: :class:`LocaliseParams` (default float64,
    Δα = 10°, for exact scores).

    Parameters
    ----------
    max_range_cells : float, default 25.0
        Range limit of the noise-free scans [cells].
    step_cells : float, default 30.0
        Distance between the two scans [cells].
    params : LocaliseParams, optional
        Settings of every localisation (default :class:`LocaliseParams`).
    **overrides
        :class:`LocaliseParams` fields to change.

    Returns
    -------
    CorridorResult
    """
    p = LocaliseParams.resolve(params, **{"dtype": "float64", "delta_alpha_rad": float(np.radians(10.0)),
                                          **overrides})
    rmax = v.check_positive(max_range_cells, "max_range_cells")
    step = v.check_positive(step_cells, "step_cells")
    g = corridor_grid()
    poses = np.array([[100.0, 25.0, np.pi], [100.0 + step, 25.0, np.pi]])
    rf = Rangefinder(n_beams=360, max_range_cells=rmax, quantum_cells=0.0)
    scans = [rf.scan(g, q) for q in poses]
    return CorridorResult(poses[0].copy(), poses, localise(g, scans[0], params=p),
                          localise_joined(g, scans, poses, params=p))


def time_localise(grid, scan, *, dtypes=("float64", "float32")) -> dict:
    """Wall time in seconds of one full 360° :func:`localise` per dtype (volatile: print only in ignored cells).

    Parameters
    ----------
    grid : array_like of int, shape (H, W)
        Map as cell codes.
    scan : Scan
        Scan in cell units.
    dtypes : sequence of str or dtype
        FFT precisions to time.

    Returns
    -------
    dict
        dtype name -> seconds.
    """
    out = {}
    for dt in dtypes:
        t0 = time.perf_counter()
        localise(grid, scan, dtype=np.dtype(dt).name)
        out[np.dtype(dt).name] = time.perf_counter() - t0
    return out
