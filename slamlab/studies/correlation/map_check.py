"""Is a log's beam layout read right? End points of each scan on the obstacle cells of the grid of the other scans
(ours, issue 25).

FLASER lines do not store the beam layout: :func:`slamlab.io.read_carmen` assumes CARMEN's (first beam at
−fov/2, counter-clockwise, fov = π). A wrong layout (field of view, beam order, angular offset, laser mounted
ahead of the robot's centre, range scale) blurs the log's map: the end points of a scan then fall less often on
the walls that the *other* scans drew. :func:`endpoint_agreement` measures that fraction for one layout;
:func:`map_check` tabulates it for several layouts on several logs, so the right layout of a log is the one
where its fraction is highest.

The logged poses themselves are a SLAM solution: :func:`logged_pose_check` aligns a scan to its neighbours' scans
(ICP) and reports how far that moves its logged pose, to tell a localisation failure from a doubtful truth.
"""

from __future__ import annotations

import os

import numpy as np

from ..._table import format_table
from ..._validate import check_int, check_positive
from ...scans import OBSTACLE, UNEXPLORED, Scan
from ...scans.logmap import leave_out_grid, log_counts
from .carmen_logs import SHARED_CARMEN_LOGS, as_carmen_log, short_log_name

__all__ = ["MAP_CHECK_LAYOUTS", "endpoint_agreement", "endpoints_on_walls", "logged_pose_check", "map_check"]

#: The layouts :func:`map_check` compares: label → :func:`endpoint_agreement` keywords (CARMEN's first).
MAP_CHECK_LAYOUTS = (
    ("CARMEN (fov 180°)", {}),
    ("fov 100°", {"fov_rad": float(np.radians(100.0))}),
    ("fov 190°", {"fov_rad": float(np.radians(190.0))}),
    ("beams reversed", {"reverse": True}),
    ("offset +1°", {"offset_rad": float(np.radians(1.0))}),
    ("offset -1°", {"offset_rad": float(np.radians(-1.0))}),
    ("offset +2°", {"offset_rad": float(np.radians(2.0))}),
    ("offset -2°", {"offset_rad": float(np.radians(-2.0))}),
    ("laser x +0.1 m", {"laser_x_m": 0.1}),
    ("laser x -0.1 m", {"laser_x_m": -0.1}),
    ("laser x +0.3 m", {"laser_x_m": 0.3}),
    ("laser x -0.3 m", {"laser_x_m": -0.3}),
    ("ranges x 0.98", {"range_scale": 0.98}),
    ("ranges x 1.02", {"range_scale": 1.02}),
)


class _LaidOut:
    """A CARMEN log seen through another beam layout (duck-types the log of :func:`~slamlab.scans.log_counts`)."""

    def __init__(self, log, fov_rad, reverse, offset_rad, laser_x_m, range_scale):
        from ...io import flaser_angles

        b = flaser_angles(log.n_beams, fov_rad) + offset_rad
        self._b = b[::-1].copy() if reverse else b
        P = np.array(log.poses, dtype=float)
        P[:, 0] += laser_x_m * np.cos(P[:, 2])  # the laser sits laser_x_m ahead of the logged pose
        P[:, 1] += laser_x_m * np.sin(P[:, 2])
        self.poses, self.n_scans, self._log, self._k = P, log.n_scans, log, range_scale

    def scans(self, indices=None):
        idx = range(self.n_scans) if indices is None else indices
        out = []
        for i in idx:
            s = self._log.scan(int(i))
            out.append(Scan(self._b, s.ranges * self._k, s.valid, unit="m", max_range=s.max_range * self._k,
                            pose=self.poses[int(i)]))
        return out


def _finite(x, name: str) -> float:
    if isinstance(x, (bool, np.bool_)) or not isinstance(x, (int, float, np.integer, np.floating)):
        raise TypeError(f"`{name}` must be a real number; got {type(x).__name__}")
    if not np.isfinite(x):
        raise ValueError(f"`{name}` must be finite; got {x}")
    return float(x)


def endpoint_agreement(log, *, fov_rad: float = np.pi, reverse: bool = False, offset_rad: float = 0.0,
                       laser_x_m: float = 0.0, range_scale: float = 1.0, cell_m: float = 0.2,
                       max_range_m: float = 10.0, exclude: int = 2, every: int = 5) -> tuple[float, float]:
    """Fraction of scan end points on obstacle cells of the grid built from the other scans (ours, issue 25).

    For scans ``every, 2·every, …`` of ``log`` read with the given layout, the grid of every scan but
    ``±exclude`` around it (:func:`~slamlab.scans.leave_out_grid`, rule ``"count"``) is built and the
    scan's end points (ranges < ``max_range_m``) are looked up in it.

    Parameters
    ----------
    log : CarmenLog
        The log (its logged poses draw the grid).
    fov_rad : float, default π
        Field of view of the beams [rad] (:func:`slamlab.io.flaser_angles`).
    reverse : bool, default False
        Beams in clockwise order (the first beam on the robot's left).
    offset_rad : float, default 0
        Added to every bearing [rad].
    laser_x_m : float, default 0
        Laser mounted this far ahead of the logged pose along the heading [m].
    range_scale : float, default 1
        Factor on every range.
    cell_m : float, default 0.2
        Cell size [m].
    max_range_m : float, default 10
        End points at or beyond it are not used [m].
    exclude : int, default 2
        Scans on either side left out of each scan's grid.
    every : int, default 5
        Check every ``every``-th scan.

    Returns
    -------
    on_walls : float
        Fraction of all end points on obstacle cells.
    on_walls_seen : float
        The same among end points on cells the other scans saw (obstacle or free): a blurred map lowers
        both, a place seen by no other scan lowers only ``on_walls``.
    """
    if not all(hasattr(log, a) for a in ("poses", "n_scans", "n_beams", "scan")):
        raise TypeError(f"`log` must be a CarmenLog; got {type(log).__name__}")
    fov = check_positive(fov_rad, "fov_rad")
    if fov > 2 * np.pi:
        raise ValueError(f"`fov_rad` must be <= 2π; got {fov}")
    if not isinstance(reverse, (bool, np.bool_)):
        raise TypeError(f"`reverse` must be a bool; got {type(reverse).__name__}")
    off = _finite(offset_rad, "offset_rad")
    dx = _finite(laser_x_m, "laser_x_m")
    k = check_positive(range_scale, "range_scale")
    ex = check_int(exclude, "exclude", minimum=0)
    ev = check_int(every, "every", minimum=1)
    view = _LaidOut(log, fov, bool(reverse), off, dx, k)
    _frame, sc, Pc, full = log_counts(view, cell_m=cell_m, max_range_m=max_range_m)
    on = seen = total = 0
    for i in range(ev, view.n_scans, ev):
        g = leave_out_grid(full, sc, Pc, range(max(0, i - ex), min(view.n_scans, i + ex + 1)))
        o, sn, t = endpoints_on_walls(g, sc[i], Pc[i])
        on, seen, total = on + o, seen + sn, total + t
    return on / max(total, 1), on / max(seen, 1)


def endpoints_on_walls(grid, scan, pose) -> tuple[int, int, int]:
    """How many end points of a scan fall on obstacle cells of a grid, on seen cells, and in all (ours, issue 25).

    Parameters
    ----------
    grid : numpy.ndarray of int, shape (H, W)
        Cell codes (:mod:`slamlab.scans.grid`).
    scan : Scan
        In cell units; its returns are the end points.
    pose : array_like, shape (3,)
        The scan's pose ``(x = col, y = row, heading_rad)`` [cells, rad].

    Returns
    -------
    on_walls : int
        End points on obstacle cells (each in the cell :func:`~slamlab.scans.occupancy_grid` votes its hit in).
    on_seen : int
        End points on seen cells, obstacle or free (outside the grid counts as unseen).
    total : int
        The scan's returns.

    Examples
    --------
    >>> g = np.array([[0, 0, 1, -1]], dtype=np.int8)
    >>> endpoints_on_walls(g, Scan([0.0, 0.0], [2.0, 3.0], [True, True]), [0, 0, 0.0])
    (1, 1, 2)
    """
    H, W = grid.shape
    th = pose[2] + scan.bearings_rad[scan.valid]
    r = scan.ranges[scan.valid] + 0.01  # the hit cell, as occupancy_grid votes it
    col = np.floor(pose[0] + r * np.cos(th) + 0.5).astype(np.int64)
    row = np.floor(pose[1] + r * np.sin(th) + 0.5).astype(np.int64)
    inside = (row >= 0) & (row < H) & (col >= 0) & (col < W)
    code = grid[row[inside], col[inside]]
    return int(np.sum(code == OBSTACLE)), int(np.sum(code != UNEXPLORED)), int(scan.valid.sum())


def map_check(paths=None, layouts=MAP_CHECK_LAYOUTS, **settings) -> str:
    """Table of :func:`endpoint_agreement` for each layout (rows) on each log (columns) (ours, issue 25).

    Parameters
    ----------
    paths : sequence of (str, os.PathLike or CarmenLog), optional
        The logs; default the five shared corrected Radish logs
        (:data:`~slamlab.studies.correlation.carmen_logs.SHARED_CARMEN_LOGS`).
    layouts : sequence of (str, dict)
        Label and :func:`endpoint_agreement` keywords of each layout (default :data:`MAP_CHECK_LAYOUTS`).
    **settings
        ``cell_m``, ``max_range_m``, ``exclude``, ``every`` of :func:`endpoint_agreement`.

    Returns
    -------
    str
        Per cell ``on walls / on walls of seen cells``, the best layout of each log marked ``*``.
    """
    from ...data import find_data
    from ...io import CarmenLog

    if paths is None:
        paths = [find_data(p) for p in SHARED_CARMEN_LOGS]
    elif not isinstance(paths, (list, tuple)):
        raise TypeError(f"`paths` must be a list or tuple of logs; got {type(paths).__name__}")
    if not isinstance(layouts, (list, tuple)) or not layouts:
        raise ValueError("`layouts` must be a non-empty sequence of (label, keywords) pairs")
    logs = []
    for p in paths:
        if isinstance(p, bool) or not isinstance(p, (str, os.PathLike, CarmenLog)):
            raise TypeError(f"`paths` must hold str, os.PathLike or CarmenLog; got {type(p).__name__}")
        logs.append(as_carmen_log(p))
    vals = np.array([[endpoint_agreement(log, **kw, **settings) for log in logs] for _lb, kw in layouts])
    best = vals[..., 0].argmax(axis=0)
    rows = [[lb] + [f"{vals[j, c, 0]:.3f} / {vals[j, c, 1]:.3f}{' *' if best[c] == j else ''}"
                    for c in range(len(logs))] for j, (lb, _kw) in enumerate(layouts)]
    return format_table(["layout"] + [short_log_name(log.name) for log in logs], rows,
                        title="Scan end points on obstacle cells of the other scans' grid (all / on seen cells); "
                              "* = the log's best layout")


def logged_pose_check(log, scan_indices, *, neighbours=(-1, 1), max_range_m: float = 10.0,
                      max_pair_m: float = 0.5, doubt_m: float = 0.2, doubt_deg: float = 2.5):
    """Is a logged pose consistent with its neighbours' scans? A local scan-to-scan alignment (ours).

    The logged poses of the corrected logs are a SLAM solution, not a measured truth. For each scan ``i``, its
    returns (ranges < ``max_range_m``) are aligned by point-to-point ICP (:func:`slamlab.hough.icp`, pairs farther
    than ``max_pair_m`` rejected) to the returns of scans ``i + d`` (``d`` in ``neighbours``) placed at their logged
    poses, starting from scan ``i``'s logged pose. The alignment's move from the logged pose is what the
    neighbours say about it: when it exceeds ``doubt_m`` or ``doubt_deg`` (default half the success tolerance, 2
    cells of 0.2 m and 5°), the logged pose is a *doubtful truth*: a correct localisation could be scored a failure
    against it.

    Parameters
    ----------
    log : CarmenLog
        The log.
    scan_indices : sequence of int
        The scans to check.
    neighbours : sequence of int, default (-1, 1)
        Offsets of the scans aligned to (non-zero); those outside the log are skipped (at the log's first and last
        scans), and at least one must be in it.
    max_range_m : float, default 10
        Returns at or beyond it are not used [m].
    max_pair_m : float, default 0.5
        ICP's pair distance limit [m].
    doubt_m, doubt_deg : float
        The move [m] and turn [deg] beyond which the logged pose is doubtful.

    Returns
    -------
    pandas.DataFrame
        One row per scan: ``scan``, ``move_m``, ``turn_deg`` (the alignment's correction of the logged pose),
        ``rmse_m`` and ``pairs`` (ICP's residual and paired points), ``converged``, ``doubtful``.
    """
    import pandas as pd

    from ...hough.icp import icp

    if not all(hasattr(log, a) for a in ("poses", "n_scans", "scan")):
        raise TypeError(f"`log` must be a CarmenLog; got {type(log).__name__}")
    idx = np.asarray(scan_indices)
    if idx.ndim != 1 or idx.size == 0 or not np.issubdtype(idx.dtype, np.integer):
        raise ValueError(f"`scan_indices` must be a non-empty list of ints; got {scan_indices!r}")
    offs = np.asarray(neighbours)
    if offs.ndim != 1 or offs.size == 0 or not np.issubdtype(offs.dtype, np.integer) or np.any(offs == 0):
        raise ValueError(f"`neighbours` must be a non-empty list of non-zero int offsets; got {neighbours!r}")
    if idx.min() < 0 or idx.max() >= log.n_scans:
        raise ValueError(f"`scan_indices` must lie in [0, {log.n_scans - 1}]; got {idx.min()}..{idx.max()}")
    if log.n_scans < 2:
        raise ValueError(f"`log` must hold at least 2 scans to align one to another; got {log.n_scans}")
    rmax = check_positive(max_range_m, "max_range_m")
    pair = check_positive(max_pair_m, "max_pair_m")
    dm, dd = check_positive(doubt_m, "doubt_m"), check_positive(doubt_deg, "doubt_deg")

    def returns(i, pose):
        s = log.scan(int(i))
        keep = s.valid & (s.ranges < rmax)
        return s.points(pose)[keep[s.valid]]

    rows = []
    for i in idx:
        near = [int(i + d) for d in offs if 0 <= i + d < log.n_scans]
        if not near:
            raise ValueError(f"scan {i} has no neighbour {tuple(offs.tolist())} in the log (0..{log.n_scans - 1})")
        target = np.vstack([returns(j, log.poses[j]) for j in near])
        res = icp(returns(i, np.zeros(3)), target, init=log.poses[i], max_dist=pair)
        d = res.pose - log.poses[i]
        move, turn = float(np.hypot(d[0], d[1])), float(np.degrees(abs(np.arctan2(np.sin(d[2]), np.cos(d[2])))))
        rows.append({"scan": int(i), "move_m": move, "turn_deg": turn, "rmse_m": res.rmse, "pairs": res.n_inliers,
                     "converged": bool(res.converged), "doubtful": bool(move > dm or turn > dd)})
    return pd.DataFrame(rows)
