"""Ch. 5 study helpers that need no simulated world (004 §7): the success criterion, the pose errors, 004's Table 1,
the constructed corridor and the timing of :func:`~slamlab.correlation.localise` (the simulated runs live in
:mod:`~slamlab.studies.correlation.experiments`, the real-log runs in
:mod:`~slamlab.studies.correlation.log_experiments`).
"""

from __future__ import annotations

import time

import numpy as np

from ...correlation.algorithm import heading_error, localise
from ...scans import FREE, OBSTACLE, UNEXPLORED

__all__ = ["COVERAGE_RADIUS_CELLS", "FAIL_CELLS", "FAIL_DEG", "MIN_COVERAGE", "SOURCE_TABLE1", "absolute_errors", "corridor_grid", "source_table1_errors",
           "time_localise", "within_tolerance"]

#: A localisation farther than this from the truth [cells] (or more than ``FAIL_DEG`` off) is a failure (ours).
FAIL_CELLS = 2.0
#: A localisation whose heading is more than this off [deg] is a failure (ours).
FAIL_DEG = 5.0

#: A real-log scan's end point is *covered* when an obstacle cell of its leave-out map lies within this many cells
#: (rows and columns) of the cell it falls in at the logged pose (ours, with :data:`MIN_COVERAGE`). One cell: an end
#: point is voted into the cell its hit falls in, so a wall's hits straddle two cells; the logged pose is itself a
#: SLAM estimate, good to about a cell (0.2 m); a wider radius would call covered what the success tolerance (2
#: cells) already separates.
COVERAGE_RADIUS_CELLS = 1
#: A real-log scan is *covered* by its leave-out map when at least this share of its end points is (ours; fixed
#: before the runs it is applied to). A majority: 004's score adds ``a_p`` for each end point on an obstacle cell,
#: so at the logged pose only the covered end points earn anything; below one half, the end points the map cannot
#: explain outnumber those it can, and a wrong pose that lays them on other walls can outscore the truth, whatever
#: the search. Such a scan tests the map, not the localiser: it is counted and printed as "not covered", and the
#: goal is judged on the covered scans.
MIN_COVERAGE = 0.5


def within_tolerance(err_pos, err_heading_rad, cell_m: float = 1.0) -> np.ndarray:
    """The chapter's success: position error within ``FAIL_CELLS`` cells and heading error within ``FAIL_DEG`` (ours).

    Parameters
    ----------
    err_pos : array_like
        Position errors, in cells (``cell_m`` = 1) or in metres (``cell_m`` the cell size [m]).
    err_heading_rad : array_like
        Heading errors [rad] (their absolute values count), broadcast with ``err_pos``.
    cell_m : float, default 1
        The cell size in the unit of ``err_pos``.

    Returns
    -------
    numpy.ndarray of bool
        A success per error pair.

    Examples
    --------
    >>> within_tolerance([1.0, 3.0, 0.2], np.radians([4.0, 0.0, -6.0])).tolist()
    [True, False, False]
    """
    return (np.asarray(err_pos) <= FAIL_CELLS * cell_m) & (np.degrees(np.abs(err_heading_rad)) <= FAIL_DEG)


def absolute_errors(true_poses, est_poses) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Absolute errors of estimated poses: wrapped heading, ``|Δx|`` and ``|Δy|``, 004's Table 1 columns (004 §7).

    Parameters
    ----------
    true_poses, est_poses : numpy.ndarray, shape (n, 3)
        ``(x, y, heading_rad)`` rows [cells, rad].

    Returns
    -------
    err_heading_rad : numpy.ndarray, shape (n,)
        ``|wrap(est - true)|`` of the headings [rad].
    err_x, err_y : numpy.ndarray, shape (n,)
        ``|Δx|``, ``|Δy|`` [cells].

    Examples
    --------
    >>> [e.round(6).tolist() for e in absolute_errors(np.array([[1.0, 2.0, 0.1]]), np.array([[2.0, 2.0, -0.1]]))]
    [[0.2], [1.0], [0.0]]
    """
    ea = heading_error(est_poses[:, 2], true_poses[:, 2])
    ex = np.abs(est_poses[:, 0] - true_poses[:, 0])
    ey = np.abs(est_poses[:, 1] - true_poses[:, 1])
    return ea, ex, ey


#: 004 Table 1: α0, α0 est [rad], X, X est, Y, Y est [cells].
SOURCE_TABLE1 = np.array([
    [1.8812, 1.885, 187, 187, 15, 15],
    [0.5225, 0.5236, 30, 30, 175, 175],
    [3.1297, 3.1241, 173, 173, 94, 94],
    [1.0738, 1.0821, 69, 69, 58, 58],
    [5.1389, 5.1487, 181, 181, 188, 188],
    [3.4681, 3.4732, 167, 167, 103, 102],
    [0.5715, 0.576, 162, 162, 93, 93],
    [5.5558, 5.5501, 63, 63, 81, 81],
    [2.1229, 2.1293, 30, 30, 171, 171],
    [5.2929, 5.2883, 105, 105, 45, 45],
])


def source_table1_errors() -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """004's Table 1 errors per pose, by :func:`absolute_errors` of its printed values (004 §7, Table 1).

    Returns
    -------
    err_heading_rad : numpy.ndarray, shape (10,)
        ``|α0 est - α0|`` [rad].
    err_x, err_y : numpy.ndarray, shape (10,)
        ``|X est - X|``, ``|Y est - Y|`` [cells].

    Examples
    --------
    >>> [round(float(e.max()), 6) for e in source_table1_errors()]
    [0.0098, 0.0, 1.0]
    """
    src = SOURCE_TABLE1
    return absolute_errors(src[:, [2, 4, 0]], src[:, [3, 5, 1]])


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
