"""The truth check of the real-log runs (ours, issue 25): is a failure of
:func:`~slamlab.correlation.run_log_localisation` a score failure or a search failure? Its scores, its tables,
and the per-scan sweep task that computes it beside the localisation (a scan's leave-out grid, its localisation in
every mode, optionally refined).

Split from :mod:`slamlab.correlation.log_experiments` (which runs it; its result's methods call the tables here).
"""

from __future__ import annotations

import numpy as np

from .._table import format_table
from ..geometry.se2 import se2_compose
from ..scans import grid_to_values
from ..scans.logmap import leave_out_grid
from ..scans.occupancy import label_counts, occupancy_grid
from .algorithm import LocaliseParams, _joined_samples, _localise_samples, _wall_weights, heading_error
from .experiments import FAIL_CELLS, FAIL_DEG

__all__: list[str] = []


def _localise_log_scan(*, index: int, leave, beams, rel, full, scans_c, Pc, p, headings, joined,
                       hit_ratio: float = 0.25, truth_check: bool = False, refine: int = 0,
                       refine_heading_rad: float = float(np.radians(3.0)), score_norm: str = "none",
                       min_explored_fraction: float = 0.8) -> dict:
    """One sweep task: the leave-out grid of scan ``index`` and its localisation in every mode (deterministic);
    with ``truth_check`` also :func:`_truth_check`'s columns per mode."""
    if hit_ratio == 0.25:  # occupancy_grid's default rule: leave_out_grid labels the counts
        grid = leave_out_grid(full, scans_c, Pc, leave)
    else:  # the same counts labelled with another hit ratio (ours, issue 25)
        part = occupancy_grid([scans_c[j] for j in leave], Pc[list(leave)], full.grid.shape)
        grid = label_counts(full.hits - part.hits, full.passes - part.passes, hit_ratio=hit_ratio)
    Mv = grid_to_values(grid, p.a_c, p.a_p, p.a_n)
    row = {}
    for k in joined:
        free, obs, o = _joined_samples(beams[:k], rel[:k], p)
        loc = _localise_samples(Mv, free, obs, o, headings, p, tracking=False, n_scans=k,
                                obs_weights=_wall_weights(beams[:k], rel[:k], p) if p.wall_balance else None,
                                refine=refine, refine_heading_rad=refine_heading_rad, score_norm=score_norm,
                                min_explored_fraction=min_explored_fraction)
        row.update({f"x{k}": loc.pose[0], f"y{k}": loc.pose[1], f"h{k}": loc.pose[2], f"amb{k}": loc.ambiguity,
                    f"mar{k}": loc.margin})
        if truth_check:
            w = _wall_weights(beams[:k], rel[:k], p) if p.wall_balance else None
            chk = _truth_check(Mv, grid, free, obs, w, headings, loc.pose, Pc[index], p,
                               [scans_c[index - j] for j in range(k)], Pc[[index - j for j in range(k)]], rel[:k])
            row.update({f"{name}{k}": val for name, val in chk.items()})
    return row


#: Columns of :func:`_truth_check` (per mode) and of :meth:`LogLocalisationResult.truth_check`.
_TRUTH_COLUMNS = ("score_est", "score_truth", "score_est_fine", "score_truth_fine", "walls_truth", "walls_est")


def _tolerance_poses(center, headings, radius_cells: float, heading_rad: float) -> np.ndarray:
    """Grid poses (integer cells, the candidate ``headings``) within ``radius_cells`` and ``heading_rad`` of
    ``center`` (cells, rad): the search's poses that count as a success there."""
    x, y, th = center
    r = int(np.ceil(radius_cells)) + 1
    cx, cy = np.meshgrid(np.arange(np.floor(x) - r, np.floor(x) + r + 2),
                         np.arange(np.floor(y) - r, np.floor(y) + r + 2))
    near = np.hypot(cx - x, cy - y) <= radius_cells + 1e-9
    hs = headings[heading_error(headings, th) <= heading_rad + 1e-9]
    cells = np.column_stack([cx[near], cy[near]])
    return np.array([[c[0], c[1], h] for h in hs for c in cells]).reshape(-1, 3)


def _fine_poses(center, radius_cells: float, heading_rad: float, step_cells: float = 0.5,
                step_rad: float = float(np.radians(0.5))) -> np.ndarray:
    """Off-grid poses around ``center``: positions every ``step_cells`` within ``radius_cells``, headings every
    ``step_rad`` within ``heading_rad`` (``center`` itself included)."""
    x, y, th = center
    k = int(np.floor(radius_cells / step_cells + 1e-9))
    d = step_cells * np.arange(-k, k + 1)
    dx, dy = np.meshgrid(d, d)
    near = np.hypot(dx, dy) <= radius_cells + 1e-9
    m = int(np.floor(heading_rad / step_rad + 1e-9))
    hs = th + step_rad * np.arange(-m, m + 1)
    return np.array([[x + a, y + b, h] for h in hs for a, b in zip(dx[near], dy[near], strict=True)])


def _walls_fraction(grid, scans_c, poses_c) -> float:
    """Fraction of the scans' end points (placed at ``poses_c``, cells) on obstacle cells of ``grid``."""
    from .map_check import _endpoints_on_walls

    on = total = 0
    for s, q in zip(scans_c, poses_c, strict=True):
        o, _seen, t = _endpoints_on_walls(grid, s, q)
        on, total = on + o, total + t
    return on / max(total, 1)


def _truth_check(Mv, grid, free, obs, obs_weights, headings, est_pose, truth_pose, p: LocaliseParams, scans_c,
                 true_poses_c, rel) -> dict:
    """Score failure or search failure? The search's score at its estimate and near the truth (ours, issue 25).

    ``score_est``: the score at the estimate; ``score_truth``: the best score of the grid poses that count as
    a success (within 2 cells and 5° of ``truth_pose``: the search scored them all). If the estimate is a
    failure, also ``score_est_fine`` / ``score_truth_fine``: the best score off the grid (every 0.5 cell and
    0.5°) within the same tolerance of the estimate / the truth (NaN for a success). ``walls_truth``: fraction
    of the joined scans' end points at their logged poses on obstacle cells of ``grid``; ``walls_est``: the
    same at the estimate (the joined scans placed by ``rel``). Scores by :func:`_pose_scores` (float64, the
    definition; ``a_n`` must be 0).
    """
    from .scoring import _pose_scores

    a_p = p.a_p if obs_weights is None else p.a_p * np.asarray(obs_weights, dtype=float)
    tol_c, tol_h = FAIL_CELLS, float(np.radians(FAIL_DEG))
    est = np.asarray(est_pose, dtype=float)
    score_est = float(_pose_scores(Mv, free, obs, p.a_c, a_p, est[None])[0])
    score_truth = float(np.max(_pose_scores(Mv, free, obs, p.a_c, a_p,
                                            _tolerance_poses(truth_pose, headings, tol_c, tol_h))))
    failed = np.hypot(*(est[:2] - truth_pose[:2])) > tol_c + 1e-9 or heading_error(est[2], truth_pose[2]) > tol_h
    if failed:
        est_fine = float(np.max(_pose_scores(Mv, free, obs, p.a_c, a_p, _fine_poses(est, tol_c, tol_h))))
        truth_fine = float(np.max(_pose_scores(Mv, free, obs, p.a_c, a_p, _fine_poses(truth_pose, tol_c, tol_h))))
    else:
        est_fine = truth_fine = float("nan")
    est_poses = np.array([se2_compose(est, q) for q in rel])
    return {"score_est": score_est, "score_truth": score_truth, "score_est_fine": est_fine,
            "score_truth_fine": truth_fine, "walls_truth": _walls_fraction(grid, scans_c, true_poses_c),
            "walls_est": _walls_fraction(grid, scans_c, est_poses)}


def _truth_frame(res):
    """``LogLocalisationResult.truth_check``: the table of the truth check's columns per mode and scan."""
    import pandas as pd

    if res.truth is None:
        raise ValueError("this result has no truth check: run run_log_localisation(..., truth_check=True)")
    rows = []
    for m, k in enumerate(res.joined):
        for j, i in enumerate(res.scan_indices):
            t = {c: float(res.truth[c][m, j]) for c in _TRUTH_COLUMNS}
            ok = bool(res.success[m, j])
            if ok:
                kind = "ok"
            elif t["score_truth"] >= t["score_est"]:
                kind = "search"
            elif t["score_truth_fine"] > t["score_est_fine"]:
                kind = "grid"
            else:
                kind = "score"
            rows.append({"scan": int(i), "joined": k, "ok": ok, "err_m": float(res.err_pos_m[m, j]),
                         "err_deg": float(np.degrees(res.err_heading_rad[m, j])), **t, "kind": kind})
    return pd.DataFrame(rows)


def _failure_table(res) -> str:
    """``LogLocalisationResult.failure_table``: the failures of the truth check as a text table."""
    d = res.truth_check()
    d = d[~d["ok"]]
    rows = [[int(r.scan), res._mode(int(r.joined)), f"{r.err_m:.2f}", f"{r.err_deg:.1f}", f"{r.score_est:.0f}",
             f"{r.score_truth:.0f}", f"{r.score_truth - r.score_est:+.0f}", f"{r.score_est_fine:.0f}",
             f"{r.score_truth_fine:.0f}", f"{r.walls_truth:.2f}", f"{r.walls_est:.2f}", r.kind]
            for r in d.itertuples()]
    return format_table(["scan", "mode", "err [m]", "err [°]", "score est.", "truth (grid)", "truth - est.",
                         "est. fine", "truth fine", "walls at truth", "walls at est.", "kind"], rows,
                        title=(f"{res.name}: failures, the search's score at its estimate and the best within "
                               f"{FAIL_CELLS:g} cells and {FAIL_DEG:g}° of the logged pose (grid; fine = every "
                               "0.5 cell and 0.5°); walls = end points on obstacle cells of the leave-out grid"))
