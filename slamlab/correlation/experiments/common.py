"""What the ch. 5 experiment families share (004 §7): the test room, its clutter and the rangefinder,
the failure thresholds, the localisations on :func:`slamlab.sweep.sweep` and their errors.
"""

from __future__ import annotations

import numpy as np

from ... import _validate as v
from ...scans import grid_to_values
from ...sim.grid import add_clutter, free_cells, measurement_room_200, test_room_200
from ...sim.rangefinder import Rangefinder
from ..algorithm import _localise, _scan_beams, heading_candidates, heading_error

__all__ = ["FAIL_CELLS", "FAIL_DEG", "random_clutter"]


FAIL_CELLS = 2.0  # a localisation farther than this from the truth (or > FAIL_DEG off) is a failure
FAIL_DEG = 5.0


def _sensor(n_beams, max_range_cells, range_std_cells, quantum_cells=0.1) -> Rangefinder:
    return Rangefinder(n_beams=n_beams, fov_rad=2 * np.pi, max_range_cells=max_range_cells,
                       range_std_cells=range_std_cells, quantum_cells=quantum_cells)


def _worlds(clutter: bool, extra_clutter: int, rng):
    M = test_room_200()
    W = measurement_room_200() if clutter else M.copy()
    if extra_clutter:
        W = add_clutter(W, random_clutter(W, extra_clutter, rng=rng))
    return M, W


def random_clutter(grid, n: int, *, radius_cells: float = 1.5, margin_cells: int = 3, rng=None) -> list[tuple]:
    """``n`` extra unmapped discs ("people's legs", bins) on free cells of ``grid`` (our addition).

    Parameters
    ----------
    grid : array_like of int, shape (H, W)
        Cell codes; discs are centred on free cells.
    n : int
        Number of discs.
    radius_cells : float, default 1.5
        Disc radius [cells].
    margin_cells : int, default 3
        Centres keep this many cells from obstacles (see :func:`slamlab.sim.grid.free_cells`).
    rng : int or numpy.random.Generator, optional
        Seed or generator of the centres.

    Returns
    -------
    list of tuple
        ``("disc", col, row, radius_cells)`` shapes for :func:`slamlab.sim.grid.add_clutter`.

    Examples
    --------
    >>> len(random_clutter(test_room_200(), 5, rng=0))
    5
    """
    n = v.check_int(n, "n", minimum=0)
    r = v.check_positive(radius_cells, "radius_cells")
    rng = v.as_rng(rng)
    cells = free_cells(grid, margin_cells)
    pick = cells[rng.integers(0, cells.shape[0], n)]
    return [("disc", int(c), int(rw), r) for rw, c in pick]


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
