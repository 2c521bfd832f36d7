"""Ch. 5 study helpers that need no simulated world (004 §7): the failure thresholds, localising a batch of scans on
:func:`slamlab.sweep.sweep` with their errors and margins, 004's Table 1, the constructed corridor and the timing of
:func:`~slamlab.correlation.localise` (the simulated runs live in :mod:`~slamlab.studies.correlation.experiments`)."""

from __future__ import annotations

import time

import numpy as np

from ...correlation.algorithm import (
    _localise,
    _scan_beams,
    heading_candidates,
    heading_error,
    localise,
)
from ...scans import FREE, OBSTACLE, UNEXPLORED, grid_to_values

FAIL_CELLS = 2.0  # a localisation farther than this from the truth (or > FAIL_DEG off) is a failure

FAIL_DEG = 5.0


def _within_tolerance(err_pos, err_heading_rad, cell_m: float = 1.0) -> np.ndarray:
    """A success by the chapter's criterion: position error ``err_pos`` within ``FAIL_CELLS`` cells (in the units of
    ``cell_m``: cells by default, metres with the cell size) and absolute heading error within ``FAIL_DEG``."""
    return (np.asarray(err_pos) <= FAIL_CELLS * cell_m) & (np.degrees(np.abs(err_heading_rad)) <= FAIL_DEG)


def _localise_one(*, beams, choice: int, Mvs, settings, headings, margins: bool = False, pose_index: int = 0) -> dict:
    """One sweep task: localise one scan's ``beams`` on map ``Mvs[choice]`` with ``settings[choice]`` (deterministic)."""
    loc = _localise(Mvs[choice], *beams, headings, settings[choice], tracking=False)
    row = {"x": float(loc.pose[0]), "y": float(loc.pose[1]), "heading_rad": float(loc.pose[2])}
    if margins:
        row["half_max_area"], row["heading_margin"] = _margins(loc)
    return row


def _localise_scans(M, scans, settings, *, margins: bool = False, n_jobs: int = 1, progress: bool | None = None):
    """Localise every scan with every setting on :func:`slamlab.sweep.sweep`: one task per (setting, scan).

    The scans were drawn by the caller (the random part stays in the parent, in its order); a
    localisation draws nothing (``rng_arg=None``), so the table is the same for any ``n_jobs``.
    The map is turned into 004's values once per setting. Returns the table (columns ``choice``,
    ``pose_index``, ``x``, ``y``, ``heading_rad`` and with ``margins`` ``half_max_area``,
    ``heading_margin``), setting-major.
    """
    from ...sweep import sweep

    beams = [_scan_beams(s) for s in scans]
    settings = tuple(q.replace(ambiguity=False) for q in settings)  # these runs report no ambiguity: no rival search
    Mvs = tuple(grid_to_values(M, q.a_c, q.a_p, q.a_n) for q in settings)
    headings = heading_candidates(settings[0].delta_alpha_rad)
    points = [{"choice": j, "pose_index": i, "beams": b} for j in range(len(settings)) for i, b in enumerate(beams)]
    table = sweep(_localise_one, points, rng_arg=None, n_jobs=n_jobs, progress=progress, on_error="raise", desc="correlation localisation",
                  fixed={"Mvs": Mvs, "settings": tuple(settings), "headings": headings, "margins": margins})
    return table.drop(columns=["beams", "replicate", "error"])


def _estimates(table) -> np.ndarray:
    """``(n, 3)`` estimated poses (x, y, heading) of a :func:`_localise_scans` table."""
    return table[["x", "y", "heading_rad"]].to_numpy(dtype=float)


def _errors(true, est):
    ea = heading_error(est[:, 2], true[:, 2])
    ex = np.abs(est[:, 0] - true[:, 0])
    ey = np.abs(est[:, 1] - true[:, 1])
    return ea, ex, ey


def _margins(loc, heading_window=3):
    """Half-maximum area of the score map [cells] and relative heading margin of one localisation."""
    dmap = loc.score_map
    med = float(np.median(dmap))
    area = float(np.count_nonzero(dmap >= med + 0.5 * (loc.score - med)))
    b = loc.best_per_heading
    n = b.size
    idx = (np.arange(n) - loc.heading_index) % n
    far = np.minimum(idx, n - idx) >= heading_window
    bmed = float(np.median(b))
    head = (loc.score - b[far].max()) / max(loc.score - bmed, 1e-12)
    return area, head


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
