"""The correlation score taken apart (ours, issue 25): which marks of a scan's stamp earn or cost its score.

With 004's constants the map holds free cells (``a_c``), obstacle cells (``a_p``) and unexplored cells
(``a_n = 0``); the stamp marks ``a_c`` at the free samples along each beam and ``a_p`` at its end. The score
``Σ T·M`` is therefore the sum of four non-zero terms — obstacle marks on map obstacles (``a_p·a_p`` > 0) and
on map free cells (``a_p·a_c`` < 0), free marks on map free cells (``a_c·a_c`` > 0) and on map obstacles
(``a_c·a_p`` < 0) — while marks on unexplored cells count nothing. :func:`score_terms` returns the four terms
and the marks of each kind; the log runs' truth check
(:meth:`~slamlab.studies.correlation.LogLocalisationResult.terms_table`) prints them at the estimate and near the logged
pose of failures. A truth whose marks fall on unexplored cells lacks map (the score gives it nothing there); one
whose free marks cross map obstacles or whose obstacle marks fall on map free cells is in conflict with the map;
a wrong pose may win by many free marks agreeing in open space.
"""

from __future__ import annotations

import numpy as np

from ...correlation.samples import scan_samples
from ...correlation.scoring import PoseMarks, pose_marks
from ...correlation.settings import LocaliseParams
from ...geometry.se2 import check_poses
from ...scans import check_grid, grid_to_values

__all__ = ["COUNT_NAMES", "TERM_NAMES", "mark_terms", "score_terms"]

#: The four signed terms of the score (:func:`score_terms`): ``obs_on_obs + obs_on_free + free_on_free +
#: free_on_obs`` = score.
TERM_NAMES = ("obs_on_obs", "obs_on_free", "free_on_free", "free_on_obs")
#: The mark counts of :func:`score_terms`.
COUNT_NAMES = ("n_obs_on_obs", "n_obs_on_free", "n_obs_unexplored", "n_free_on_free", "n_free_on_obs",
               "n_free_unexplored")


def mark_terms(marks: PoseMarks, a_c: float, a_p: float) -> dict:
    """The four terms and six counts of one pose's marks (:data:`TERM_NAMES`, :data:`COUNT_NAMES`; ours, issue 25).

    Parameters
    ----------
    marks : PoseMarks
        One pose's marks (:func:`~slamlab.correlation.scoring.pose_marks`).
    a_c, a_p : float
        The map's values of free and obstacle cells (any other value is an unexplored cell).

    Returns
    -------
    dict
        The terms and counts by name, and ``score`` (``Σ stamp·map``).

    Examples
    --------
    >>> from slamlab.correlation.scoring import PoseMarks
    >>> mk = PoseMarks(np.zeros(3, int), np.arange(3), np.array([-1.0, -1.0, 1.0]), np.array([-1.0, 1.0, 0.0]),
    ...                np.array([False, False, True]))
    >>> t = mark_terms(mk, -1.0, 1.0); t["free_on_free"], t["free_on_obs"], t["n_obs_unexplored"], t["score"]
    (1.0, -1.0, 1, 0.0)
    """
    on_obs, on_free = marks.map == a_p, marks.map == a_c
    o, f = marks.is_obs, ~marks.is_obs
    prod = marks.stamp * marks.map
    out = {"obs_on_obs": float(np.sum(prod[o & on_obs])), "obs_on_free": float(np.sum(prod[o & on_free])),
           "free_on_free": float(np.sum(prod[f & on_free])), "free_on_obs": float(np.sum(prod[f & on_obs]))}
    unex = ~(on_obs | on_free)
    out.update({"n_obs_on_obs": int(np.sum(o & on_obs)), "n_obs_on_free": int(np.sum(o & on_free)),
                "n_obs_unexplored": int(np.sum(o & unex)), "n_free_on_free": int(np.sum(f & on_free)),
                "n_free_on_obs": int(np.sum(f & on_obs)), "n_free_unexplored": int(np.sum(f & unex))})
    out["score"] = float(np.dot(marks.stamp, marks.map))
    return out


def score_terms(grid, scan, poses, *, params: LocaliseParams | None = None, **overrides):
    """The correlation score of one scan at some poses, split into its four non-zero terms (ours, issue 25; 004 §7).

    The stamp is :func:`~slamlab.correlation.scan_stamps`'s (free marks ``a_c`` along each beam, the obstacle
    mark ``a_p`` at its end, each cell once, the obstacle mark last); the map holds ``a_c`` (free), ``a_p``
    (obstacle) and ``a_n = 0`` (unexplored, and outside the map). So ``score = obs_on_obs + obs_on_free +
    free_on_free + free_on_obs`` exactly; marks on unexplored cells add nothing and are only counted.

    Parameters
    ----------
    grid : array_like of int, shape (H, W)
        The map as cell codes (see :mod:`slamlab.scans.grid`).
    scan : Scan
        A :class:`~slamlab.scans.Scan` in cell units.
    poses : array_like, shape (m, 3)
        ``(x = col, y = row, heading_rad)`` [cells, rad], on the search's grid or off it.
    params, **overrides
        :class:`LocaliseParams` (its constants and rasterisation; with ``wall_balance`` the obstacle marks carry
        their wall weights, as in :func:`~slamlab.correlation.localise`); ``a_n`` must be 0 (004's value).

    Returns
    -------
    pandas.DataFrame
        One row per pose: the signed terms ``obs_on_obs`` (≥ 0), ``obs_on_free`` (≤ 0), ``free_on_free`` (≥ 0),
        ``free_on_obs`` (≤ 0) for 004's signs, the counts ``n_obs_on_obs``, ``n_obs_on_free``,
        ``n_obs_unexplored``, ``n_free_on_free``, ``n_free_on_obs``, ``n_free_unexplored`` and ``score``
        (their sum; equal to :func:`~slamlab.correlation.score_maps` at a grid pose).

    Examples
    --------
    >>> from slamlab.scans import Scan
    >>> grid = np.array([[0, 0, 0, 1, -1]])  # codes: free, free, free, obstacle, unexplored
    >>> d = score_terms(grid, Scan([0.0], [2.5], [True]), [[0, 0, 0.0], [1, 0, 0.0]])
    >>> d[["obs_on_obs", "obs_on_free", "free_on_free", "free_on_obs", "n_obs_unexplored", "score"]].values.tolist()
    [[1.0, 0.0, 3.0, 0.0, 0.0, 4.0], [0.0, 0.0, 2.0, -1.0, 1.0, 1.0]]
    """
    import pandas as pd

    p = LocaliseParams.resolve(params, **overrides)
    if p.a_n != 0:
        raise ValueError(f"`a_n` must be 0 (004's value: unexplored cells and the outside count nothing); got {p.a_n}")
    g = check_grid(grid)
    samples = scan_samples(scan, params=p)
    P = check_poses(poses, "poses")
    lim = 4 * (g.shape[0] + g.shape[1])
    if np.any(np.abs(P[:, :2]) > lim):
        raise ValueError(f"`poses` must lie within {lim} cells of the map; got {np.abs(P[:, :2]).max():.0f}")
    marks = pose_marks(grid_to_values(g, p.a_c, p.a_p, p.a_n), samples, P)
    rows = [mark_terms(mk, p.a_c, p.a_p) for mk in marks]
    return pd.DataFrame(rows, columns=[*TERM_NAMES, *COUNT_NAMES, "score"])

