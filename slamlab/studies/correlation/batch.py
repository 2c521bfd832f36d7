"""Localising a batch of simulated scans on one grid, in parallel (ours): the sweep task, the table of estimates
and the sharpness of each peak. The simulated studies of :mod:`slamlab.studies.correlation.experiments` draw the
scans; this module draws nothing (004 §7's localisation is deterministic).
"""

from __future__ import annotations

import numpy as np

from ...correlation.algorithm import localise

__all__ = ["localise_scans", "scan_estimates"]


def _localise_one(*, scan, choice: int, grid, settings, margins: bool = False, pose_index: int = 0) -> dict:
    """One sweep task: localise one ``scan`` on ``grid`` with ``settings[choice]`` (deterministic)."""
    loc = localise(grid, scan, params=settings[choice])
    row = {"x": float(loc.pose[0]), "y": float(loc.pose[1]), "heading_rad": float(loc.pose[2])}
    if margins:
        row["half_max_area"], row["heading_margin"] = _margins(loc)
    return row


def localise_scans(M, scans, settings, *, margins: bool = False, n_jobs: int = 1, progress: bool | None = None):
    """Localise every scan with every setting on :func:`slamlab.sweep.sweep`: one task per (setting, scan) (ours).

    The scans were drawn by the caller (the random part stays in the parent, in its order); a
    localisation draws nothing (``rng_arg=None``), so the table is the same for any ``n_jobs``.
    The rival search is switched off (``ambiguity=False``): these runs report no ambiguity.

    Parameters
    ----------
    M : numpy.ndarray of int, shape (H, W)
        The stored map (cell codes).
    scans : sequence of Scan
        The scans, in cell units.
    settings : sequence of LocaliseParams
        The settings each scan is localised with.
    margins : bool, default False
        Also the half-maximum area and the heading margin of each localisation.
    n_jobs : int, default 1
        Sweep workers (same table for any).
    progress : bool, optional
        Progress bar (default: in a notebook only).

    Returns
    -------
    pandas.DataFrame
        Columns ``choice``, ``pose_index``, ``x``, ``y``, ``heading_rad`` and with ``margins`` ``half_max_area``,
        ``heading_margin``; setting-major.
    """
    from ...sweep import sweep

    settings = tuple(q.replace(ambiguity=False) for q in settings)
    points = [{"choice": j, "pose_index": i, "scan": s} for j in range(len(settings)) for i, s in enumerate(scans)]
    table = sweep(_localise_one, points, rng_arg=None, n_jobs=n_jobs, progress=progress, on_error="raise",
                  desc="correlation localisation", fixed={"grid": M, "settings": settings, "margins": margins})
    return table.drop(columns=["scan", "replicate", "error"])


def scan_estimates(table) -> np.ndarray:
    """``(n, 3)`` estimated poses (x, y, heading) of a :func:`localise_scans` table.

    Parameters
    ----------
    table : pandas.DataFrame
        A :func:`localise_scans` table.

    Returns
    -------
    numpy.ndarray, shape (n, 3)
    """
    return table[["x", "y", "heading_rad"]].to_numpy(dtype=float)


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
