"""A map from a log: the occupancy grid of a laser log's scans at its logged poses (004 §7; ours for real logs).

API summary
-----------
- :func:`log_grid` ``(log, *, cell_m, max_range_m, leave_out) -> (grid, frame, scans_cells, poses_cells)``:
  the grid of every scan not left out (:func:`~slamlab.scans.occupancy_grid`, rule ``"count"``).
- :func:`log_counts` ``(log, *, cell_m, max_range_m) -> (frame, scans_cells, poses_cells, counts)``:
  the frame, the scans and poses in cells and the hit/pass counts of all scans (one grid).
- :func:`leave_out_grid` ``(counts, scans_cells, poses_cells, leave_out) -> grid``: the cell codes of
  the counts minus those of some scans (counts add over scans: no recount of the rest).
- :func:`map_coverage` ``(grid, scan_cells, pose_cells, radius_cells=1) -> float``: the share of a scan's end
  points, placed at a given pose, within ``radius_cells`` of an obstacle cell of a grid (ours): how much of the
  scan a leave-out map knows, from the logged pose and the map alone.

A *log* is any object with ``poses`` (``(n, 3)`` metric poses), ``n_scans`` and
``scans(indices=None)`` returning metric :class:`~slamlab.scans.Scan` objects, as
:class:`slamlab.io.CarmenLog`. Correlation localisation (Ch. 5) localises a log's scans on
such maps; Monte Carlo localisation (Ch. 8) runs on them.
"""

from __future__ import annotations

import numpy as np

from .._validate import check_positive
from .._validate import check_int
from .grid import OBSTACLE, GridFrame, check_grid
from .occupancy import OccupancyGrid, label_counts, occupancy_grid
from .scan import Scan

__all__ = ["leave_out_grid", "log_counts", "log_grid", "map_coverage"]


def _check_log(log) -> None:
    if not all(hasattr(log, a) for a in ("poses", "n_scans", "scans")):
        raise TypeError(f"`log` must be a laser log with `poses`, `n_scans` and `scans()` (e.g. a CarmenLog); "
                        f"got {type(log).__name__}")


def _limited(scan: Scan, max_range_m: float) -> Scan:
    """Readings at or beyond ``max_range_m`` become "no return" at ``max_range_m``."""
    ok = scan.valid & (scan.ranges < max_range_m)
    return Scan(scan.bearings_rad, np.where(ok, scan.ranges, max_range_m), ok, unit=scan.unit,
                max_range=max_range_m, time_s=scan.time_s, odom_pose=scan.odom_pose, pose=scan.pose)


def log_counts(log, *, cell_m: float = 0.2, max_range_m: float = 10.0):
    """Frame, cell-unit scans and poses, and the hit/pass counts of every scan of ``log`` (one grid).

    Readings at or beyond ``max_range_m`` count as "no return" (they mark the beam free up to
    ``max_range_m``). The frame covers the logged poses and the end points of every 10th scan
    within ``max_range_m`` plus the poses' extent, with a 1 m margin.

    Parameters
    ----------
    log : CarmenLog or similar
        ``poses`` (n, 3) in metres, ``n_scans``, ``scans(indices=None)`` (metric Scans).
    cell_m : float
        Cell size [m].
    max_range_m : float
        Readings at or beyond it are dropped [m].

    Returns
    -------
    frame : GridFrame
        The metric frame of the grid.
    scans_cells : list of Scan
        Every scan, range-limited, in cell units.
    poses_cells : numpy.ndarray, shape (n, 3)
        The logged poses in cells.
    counts : OccupancyGrid
        Hits and passes of all scans (rule ``"count"``).
    """
    _check_log(log)
    cell_m = check_positive(cell_m, "cell_m")
    max_range_m = check_positive(max_range_m, "max_range_m")
    scans_m = [_limited(s, max_range_m) for s in log.scans()]
    pts = np.vstack([s.points(q) for s, q in zip(log.scans(range(0, log.n_scans, 10)), log.poses[::10],
                                                    strict=True)])
    pts = pts[np.hypot(*(pts - log.poses[:, :2].mean(axis=0)).T) < max_range_m + np.ptp(log.poses[:, :2], axis=0).max()]
    frame = GridFrame.around(np.vstack([log.poses[:, :2], pts]), cell_m, 1.0)
    Pc = frame.to_cells(log.poses)
    scans_c = [s.to_cells(cell_m) for s in scans_m]
    return frame, scans_c, Pc, occupancy_grid(scans_c, Pc, frame.shape)


def leave_out_grid(counts: OccupancyGrid, scans_cells, poses_cells, leave_out=()) -> np.ndarray:
    """Cell codes of ``counts`` minus the counts of the scans ``leave_out`` (counts add over scans).

    Parameters
    ----------
    counts : OccupancyGrid
        The counts of all scans (from :func:`log_counts`).
    scans_cells : sequence of Scan
        Every scan in cell units (as counted).
    poses_cells : array_like, shape (n, 3)
        Every pose in cells.
    leave_out : iterable of int
        Indices of the scans to leave out (repeats ignored); empty gives ``counts.grid``.

    Returns
    -------
    numpy.ndarray of int8, shape (H, W)
        FREE / OBSTACLE / UNEXPLORED codes (rule ``"count"``).
    """
    if not isinstance(counts, OccupancyGrid):
        raise TypeError(f"`counts` must be an OccupancyGrid (from log_counts); got {type(counts).__name__}")
    leave = np.asarray(sorted(set(leave_out)), dtype=np.int64)
    if leave.size == 0:
        return counts.grid
    if leave[0] < 0 or leave[-1] >= len(scans_cells):
        raise ValueError(f"`leave_out` must hold scan indices in [0, {len(scans_cells) - 1}]; "
                         f"got {leave[0]}..{leave[-1]}")
    part = occupancy_grid([scans_cells[j] for j in leave], np.asarray(poses_cells)[leave], counts.grid.shape)
    return label_counts(counts.hits - part.hits, counts.passes - part.passes)


def log_grid(log, *, cell_m: float = 0.2, max_range_m: float = 10.0, leave_out=()):
    """Map of a laser log from its logged poses, leaving out some scans (for localising them on it).

    Parameters
    ----------
    log, cell_m, max_range_m
        The log, the cell size [m] and the range limit [m], as in :func:`log_counts`.
    leave_out : iterable of int
        Indices of the scans that do not draw the map.

    Returns
    -------
    grid : numpy.ndarray of int8, shape (H, W)
        The :func:`~slamlab.scans.occupancy_grid` (rule ``"count"``) of every scan not in ``leave_out``.
    frame : GridFrame
        Its metric frame.
    scans_cells : list of Scan
        Every scan (range-limited) in cell units.
    poses_cells : numpy.ndarray, shape (n, 3)
        Every logged pose in cells.
    """
    frame, scans_c, Pc, full = log_counts(log, cell_m=cell_m, max_range_m=max_range_m)
    return leave_out_grid(full, scans_c, Pc, leave_out), frame, scans_c, Pc


def map_coverage(grid, scan_cells: Scan, pose_cells, radius_cells: int = 1) -> float:
    """Share of a scan's end points within ``radius_cells`` of an obstacle cell of ``grid`` at ``pose_cells`` (ours).

    How much of the scan the map knows, judged from a pose and the map alone (never from a localiser's answer):
    each end point lies in the cell :func:`~slamlab.scans.occupancy_grid` votes its hit in, and counts as covered
    when an obstacle cell lies within ``radius_cells`` of that cell in rows and columns (a square of
    ``2·radius_cells + 1`` cells). With the logged pose and a map that leaves the scan out, a low share means the
    scan sees walls that no other scan drew.

    Parameters
    ----------
    grid : numpy.ndarray of int8, shape (H, W)
        Cell codes (:data:`~slamlab.scans.FREE`, :data:`~slamlab.scans.OBSTACLE`, :data:`~slamlab.scans.UNEXPLORED`).
    scan_cells : Scan
        The scan in cell units (its returns are the end points).
    pose_cells : array_like, shape (3,)
        The scan's pose ``(x = col, y = row, heading_rad)`` [cells, rad].
    radius_cells : int, default 1
        Chebyshev radius of the neighbourhood searched for an obstacle cell [cells], at least 0.

    Returns
    -------
    float
        In [0, 1]; 0 for a scan without returns. End points outside the grid are not covered.

    Examples
    --------
    >>> g = np.zeros((1, 5), dtype=np.int8); g[0, 3] = OBSTACLE
    >>> s = Scan([0.0, 0.0], [2.0, 4.0], [True, True])
    >>> map_coverage(g, s, [0, 0, 0.0]), map_coverage(g, s, [0, 0, 0.0], radius_cells=0)
    (1.0, 0.0)
    """
    g = check_grid(grid)
    if not isinstance(scan_cells, Scan):
        raise TypeError(f"`scan_cells` must be a Scan in cell units; got {type(scan_cells).__name__}")
    q = np.asarray(pose_cells, dtype=float)
    if q.shape != (3,) or not np.all(np.isfinite(q)):
        raise ValueError(f"`pose_cells` must be a finite (x, y, heading_rad) pose; got {pose_cells!r}")
    r = check_int(radius_cells, "radius_cells", minimum=0)
    n = int(scan_cells.valid.sum())
    if n == 0:
        return 0.0
    th = q[2] + scan_cells.bearings_rad[scan_cells.valid]
    rng = scan_cells.ranges[scan_cells.valid] + 0.01  # the hit cell, as occupancy_grid votes it
    col = np.floor(q[0] + rng * np.cos(th) + 0.5).astype(np.int64)
    row = np.floor(q[1] + rng * np.sin(th) + 0.5).astype(np.int64)
    H, W = g.shape
    d = np.arange(-r, r + 1)
    rows = row[:, None, None] + d[None, :, None]  # (n, 2r+1, 1)
    cols = col[:, None, None] + d[None, None, :]  # (n, 1, 2r+1)
    rows, cols = np.broadcast_arrays(rows, cols)
    inside = (rows >= 0) & (rows < H) & (cols >= 0) & (cols < W)
    wall = np.zeros(rows.shape, dtype=bool)
    wall[inside] = g[rows[inside], cols[inside]] == OBSTACLE
    return float(wall.any(axis=(1, 2)).sum() / n)
