"""The maps of MCL on real laser logs (ours): a CARMEN log by name or path, its hit/pass counts once per (file, cell
size, range), and the map a stretch of scans is localised on, built without the stretch's own scans and
``leave_margin`` scans on either side of it (as chapter 06 leaves a test scan and its ±2 neighbours out of its map),
with the coverage of the stretch's scans by that map.

- :func:`log_map` ``(path, cell_m, max_range_m) -> (log, grid, frame, scans, poses)``: the map of every scan.
- :func:`stretch_map` ``(counts, scans, poses, indices, map_leave_out, leave_margin) -> (grid, left_out)``: the map
  of a stretch (:func:`slamlab.scans.leave_out_grid`: the counts minus those of the scans left out, no recount).
- :func:`stretch_coverage` ``(grid, scans, poses, indices) -> float``: the mean over the stretch's scans of
  :func:`slamlab.scans.map_coverage` at the logged pose.
"""

from __future__ import annotations

import functools
from pathlib import Path

import numpy as np

from ..._validate import as_path, check_choice, check_int, check_positive
from ...scans import leave_out_grid, log_counts, map_coverage

__all__ = ["CARMEN_LOGS", "MAP_LEAVE_OUT", "TUNED_LOGS", "carmen_path", "is_tuned_log", "log_map", "read_log_counts",
           "stretch_coverage", "stretch_map"]

#: The five corrected Radish logs of ``../shared/data/carmen-radish-corrected``.
CARMEN_LOGS = ("intel", "csail", "fhw", "orebro", "seattle")
#: The logs the global runs' settings (:func:`~slamlab.studies.localisation.logs.global_log_settings`) were tuned
#: on (ours); the other two of :data:`CARMEN_LOGS`, CSAIL and Seattle, were not.
TUNED_LOGS = ("fhw", "intel", "orebro")
#: The maps a stretch can be localised on: ``"stretch"``, every scan but the stretch's and ``leave_margin`` on either
#: side of it; ``"none"``, every scan of the log (the stretch's own scans drew it).
MAP_LEAVE_OUT = ("stretch", "none")


def carmen_path(path):
    """Path of a CARMEN log: ``<path>-corrected.log.gz`` in the shared data for a name of :data:`CARMEN_LOGS`
    (via :func:`slamlab.data.find_data`), else ``path`` itself, which must be an existing file (ours).

    Parameters
    ----------
    path : str or os.PathLike
        One of :data:`CARMEN_LOGS`, or the path of any CARMEN log.

    Returns
    -------
    pathlib.Path
    """
    from ...data import find_data

    if isinstance(path, str) and path in CARMEN_LOGS:
        return find_data(f"carmen-radish-corrected/{path}-corrected.log.gz")
    return as_path(path, "path", kind="file")


def is_tuned_log(name) -> bool:
    """Whether a log is one of :data:`TUNED_LOGS`: its name, or a file named ``<name>-corrected.log.gz`` (ours).

    Parameters
    ----------
    name : str or os.PathLike
        A log's name or path (a log given by any other file name is untuned).

    Returns
    -------
    bool
    """
    return str(name) in TUNED_LOGS or Path(name).name in {f"{t}-corrected.log.gz" for t in TUNED_LOGS}


def read_log_counts(path, cell_m: float = 0.1, max_range_m: float = 10.0):
    """A CARMEN log read and the hit/pass counts of all its scans at the corrected poses, once per (file, cell size,
    range) (:func:`slamlab.scans.log_counts`; ours: every map of a run on the log is drawn from them).

    Parameters
    ----------
    path : str or os.PathLike
        One of :data:`CARMEN_LOGS`, or the path of any CARMEN log (see :func:`carmen_path`).
    cell_m : float
        The map's cell size [m].
    max_range_m : float
        Ranges at or beyond this [m] are not used.

    Returns
    -------
    log : CarmenLog
        The log.
    frame : GridFrame
        Cells ↔ metres.
    scans : list of Scan
        The scans in cells.
    poses : ndarray, shape (n, 3)
        The corrected poses in cells.
    counts : OccupancyGrid
        Hits and passes of every scan.
    """
    return _read_log_counts(str(carmen_path(path)), check_positive(cell_m, "cell_m"),
                            check_positive(max_range_m, "max_range_m"))


@functools.lru_cache(maxsize=6)
def _read_log_counts(path: str, cell_m: float, max_range_m: float):
    from ...io import read_carmen

    log = read_carmen(path)
    return (log, *log_counts(log, cell_m=cell_m, max_range_m=max_range_m))


def log_map(path, cell_m: float = 0.1, max_range_m: float = 10.0):
    """A CARMEN log read and its occupancy map built from all scans at the corrected poses (the counts of
    :func:`read_log_counts`; ours: the map of ``map_leave_out="none"``).

    Parameters
    ----------
    path, cell_m, max_range_m
        The log, the cell size [m] and the range limit [m], as in :func:`read_log_counts`.

    Returns
    -------
    log, grid, frame, scans, poses
        The log, the map (ndarray of int8, shape (H, W)) and the frame, scans and poses of
        :func:`read_log_counts`.
    """
    log, frame, scans_c, Pc, counts = read_log_counts(path, cell_m, max_range_m)
    return log, counts.grid, frame, scans_c, Pc


def stretch_map(counts, scans_cells, poses_cells, indices, map_leave_out: str = "stretch", leave_margin: int = 2):
    """The map a stretch of scans is localised on (ours; chapter 06 leaves a test scan and its ±2 neighbours out).

    With ``map_leave_out="stretch"`` the scans ``min(indices) − leave_margin … max(indices) + leave_margin`` (within
    the log) do not draw the map: their counts are subtracted from ``counts``
    (:func:`slamlab.scans.leave_out_grid`); with ``"none"`` the map is ``counts.grid``, drawn by every scan.

    Parameters
    ----------
    counts : OccupancyGrid
        Hits and passes of every scan (:func:`read_log_counts`).
    scans_cells : sequence of Scan
        Every scan in cells.
    poses_cells : ndarray, shape (n, 3)
        Every pose in cells.
    indices : array_like of int
        The stretch's scans.
    map_leave_out : {"stretch", "none"}
        Which map (:data:`MAP_LEAVE_OUT`).
    leave_margin : int
        Scans left out on either side of the stretch (≥ 0).

    Returns
    -------
    grid : ndarray of int8, shape (H, W)
        The map.
    left_out : range
        The scans left out (empty for ``"none"``).
    """
    mode = check_choice(map_leave_out, "map_leave_out", MAP_LEAVE_OUT)
    margin = check_int(leave_margin, "leave_margin", minimum=0)
    idx = np.asarray(indices, dtype=np.int64)
    n = len(scans_cells)
    if mode == "none":
        return counts.grid, range(0)
    left = range(max(0, int(idx.min()) - margin), min(n, int(idx.max()) + margin + 1))
    if len(left) == n:
        raise ValueError(f"`leave_margin` leaves every scan of the log out of the map (scans {left.start}..."
                         f"{left.stop - 1} of {n}); got leave_margin={margin}: use a longer log, a shorter stretch "
                         f"or map_leave_out='none'")
    return leave_out_grid(counts, scans_cells, poses_cells, left), left


def stretch_coverage(grid, scans_cells, poses_cells, indices) -> float:
    """Mean over a stretch's scans of the share of their end points within 1 cell of an obstacle cell of ``grid``
    at the logged poses (:func:`slamlab.scans.map_coverage`; ours): how much of the stretch a leave-out map knows.

    Parameters
    ----------
    grid : ndarray of int8, shape (H, W)
        The map.
    scans_cells : sequence of Scan
        Every scan in cells.
    poses_cells : ndarray, shape (n, 3)
        Every logged pose in cells.
    indices : array_like of int
        The stretch's scans.

    Returns
    -------
    float
        In [0, 1].
    """
    return float(np.mean([map_coverage(grid, scans_cells[i], poses_cells[i], radius_cells=1) for i in indices]))
