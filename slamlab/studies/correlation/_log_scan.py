"""Package-private: the per-scan task of :func:`~slamlab.studies.correlation.run_log_localisation` (ours, issue 25).

For one test scan of a CARMEN log: its leave-out grids (the log's grid without the scans it must not see), its
localisation in every mode (1 scan, or 2-5 joined by odometry), optionally the votes of the single scans before
it, and the truth check (is a failure a score failure or a search failure?): the search's own score at its
estimate and near the logged pose, the score's terms there, and where the truth's marks on unexplored cells come
from. :mod:`slamlab.studies.correlation.log_experiments` builds the points and runs this task on
:func:`slamlab.sweep.sweep`; :mod:`slamlab.studies.correlation.log_results` tabulates the columns.
"""

from __future__ import annotations

import numpy as np

from ..._validate import check_choice, check_int, check_positive
from ...correlation.algorithm import heading_error, localise_samples
from ...correlation.samples import ScanSamples, joined_samples
from ...correlation.scoring import pose_marks, pose_scores
from ...geometry.se2 import se2_compose, se2_inverse, se2_relative
from ...scans import grid_to_values
from ...scans.logmap import leave_out_grid, map_coverage
from ...scans.occupancy import label_counts, occupancy_grid
from .map_check import endpoints_on_walls
from .studies import COVERAGE_RADIUS_CELLS, FAIL_CELLS, FAIL_DEG, within_tolerance
from .terms import COUNT_NAMES, TERM_NAMES, mark_terms

#: ``leave_out`` of :func:`~slamlab.studies.correlation.run_log_localisation`: which scans a test scan's grid lacks.
LEAVE_OUT = ("window", "used")


def leave_sets(index: int, joined, exclude: int, n_scans: int, leave_out: str = "window") -> dict:
    """Per mode ``k`` the scans left out of scan ``index``'s grid: ``"window"``, the ``±exclude`` scans around it
    (the same for every mode); ``"used"``, exactly the mode's own scans ``index - k + 1 .. index`` (ours, issue 25)."""
    if leave_out == "used":
        return {k: range(index - k + 1, index + 1) for k in joined}
    window = range(max(0, index - exclude), min(n_scans, index + exclude + 1))
    return dict.fromkeys(joined, window)


def check_leave(leave_out, exclude, kmax: int) -> tuple[str, int]:
    """``leave_out`` and ``exclude`` of :func:`~slamlab.studies.correlation.run_log_localisation` checked, with
    ``max(joined) = kmax``: ``(leave_out, exclude)``, ``exclude`` 2 when not given."""
    lo = check_choice(leave_out, "leave_out", LEAVE_OUT)
    if lo == "used" and exclude is not None:
        raise ValueError(f"`exclude` is for leave_out='window'; leave_out='used' leaves out each mode's own scans "
                         f"(got exclude={exclude!r})")
    ex = check_int(2 if exclude is None else exclude, "exclude", minimum=0)
    if lo == "window" and ex < kmax - 1:
        raise ValueError(f"`exclude` must be >= {kmax - 1} so the joined scans are not in the map; got {ex}")
    return lo, ex


def check_unit(x, name: str) -> float:
    """A number in [0, 1], named ``name`` in the error."""
    x = check_positive(x, name, allow_zero=True)
    if x > 1:
        raise ValueError(f"`{name}` must lie in [0, 1]; got {x}")
    return x


def log_points(idx, modes, scans_c, Pc, noise, leave_out: str = "window", exclude: int = 2,
                votes: bool = False) -> list[dict]:
    """The sweep's points of :func:`localise_log_scan`, one per test scan ``i`` of ``idx``: its leave-out sets
    (:func:`leave_sets`; with ``votes`` also ``"votes"``, :func:`vote_leave`), scans ``i, i-1, …`` (``max(modes)``
    scans, at least :data:`VOTE_SCANS` with ``votes``; each must have a return) and their poses relative to scan
    ``i`` (the logged steps plus ``noise[n]``, cells and rad, chained back from scan ``i``)."""
    back = noise.shape[1] + 1
    points = []
    for n, i in enumerate(idx):
        rel = [np.zeros(3)]
        for j in range(1, back):  # chain the noisy steps back from scan i
            rel.append(se2_compose(rel[-1], se2_relative(Pc[i - j + 1], Pc[i - j]) + noise[n, j - 1]))
        leave = leave_sets(int(i), modes, exclude, len(scans_c), leave_out)
        if votes:
            leave["votes"] = vote_leave(int(i), leave)
        for j in range(back):
            if not scans_c[i - j].valid.any():  # here, naming the scan, rather than in a worker
                raise ValueError(f"`scan {i - j}` has no return (every beam is a miss): nothing to localise with")
        points.append({"index": int(i), "leave": leave, "scans": [scans_c[i - j] for j in range(back)],
                       "rel": np.array(rel)})
    return points


#: Single-scan localisations that vote on each answer (``run_log_localisation(votes=True)``): scans i, i-1, i-2.
VOTE_SCANS = 3


def vote_leave(index: int, leave: dict) -> tuple[int, ...]:
    """The scans the voters' grid lacks: the largest mode's leave-out set and the voters ``index - 2 .. index``, so
    no voter is matched against cells it drew (with the ``±2`` window: the window itself, no new grid)."""
    own = set(leave[max(leave)]) | set(range(index - VOTE_SCANS + 1, index + 1))
    return tuple(sorted(own))


def agrees(a, b) -> bool:
    """Two poses (cells, rad) within a success's tolerance of each other (2 cells and 5°)."""
    return bool(within_tolerance(np.hypot(a[0] - b[0], a[1] - b[1]), heading_error(a[2], b[2])))


def leave_grid(full, scans_c, Pc, leave, hit_ratio: float = 0.25) -> np.ndarray:
    """The log's grid without the scans ``leave`` (cell codes), labelled with ``hit_ratio``."""
    if hit_ratio == 0.25:  # occupancy_grid's default rule: leave_out_grid labels the counts
        return leave_out_grid(full, scans_c, Pc, leave)
    # the same counts labelled with another hit ratio (ours, issue 25)
    part = occupancy_grid([scans_c[j] for j in leave], Pc[list(leave)], full.grid.shape)
    return label_counts(full.hits - part.hits, full.passes - part.passes, hit_ratio=hit_ratio)


def mode_grids(leaves: dict, full, scans_c, Pc, hit_ratio: float = 0.25) -> dict:
    """Per mode its leave-out grid (:func:`leave_grid` of ``leaves[k]``), built once per distinct set."""
    built, out = {}, {}
    for k, leave in leaves.items():
        key = tuple(leave)
        if key not in built:
            built[key] = leave_grid(full, scans_c, Pc, leave, hit_ratio)
        out[k] = built[key]
    return out


def localise_log_scan(*, index: int, leave, scans, rel, full, scans_c, Pc, p, headings, joined,
                      hit_ratio: float = 0.25, truth_check: bool = False, refine: int = 0,
                      refine_heading_rad: float = float(np.radians(3.0)), score_norm: str = "none",
                      min_explored_fraction: float = 0.8) -> dict:
    """One sweep task: the leave-out grids of scan ``index`` (``leave``: per mode the scans left out,
    :func:`leave_sets`), the scan's coverage by the largest mode's grid at the logged pose (``coverage``,
    :func:`~slamlab.scans.map_coverage`) and its localisation in every mode (deterministic); with ``truth_check`` also
    :func:`truth_check_row`'s columns per mode; with a ``"votes"`` leave-out set also each mode's votes
    (:func:`count_votes`)."""
    grids = mode_grids(leave, full, scans_c, Pc, hit_ratio)
    values = {}  # the score's map values per distinct grid

    def map_values(grid):
        if id(grid) not in values:
            values[id(grid)] = grid_to_values(grid, p.a_c, p.a_p, p.a_n)
        return values[id(grid)]

    def search(grid, sc, q):
        """Scans ``sc`` at poses ``q`` relative to the first, joined and localised on ``grid``; and their samples."""
        samples = joined_samples(sc, q, params=p)
        loc = localise_samples(map_values(grid), samples, refine=refine, refine_heading_rad=refine_heading_rad,
                               score_norm=score_norm, min_explored_fraction=min_explored_fraction)
        return loc, samples

    row = {"coverage": map_coverage(grids[max(joined)], scans_c[index], Pc[index], COVERAGE_RADIUS_CELLS)}
    poses = {}
    for k in joined:
        grid = grids[k]
        loc, samples = search(grid, scans[:k], rel[:k])
        Mv = map_values(grid)
        poses[k] = loc.pose
        row.update({f"x{k}": loc.pose[0], f"y{k}": loc.pose[1], f"h{k}": loc.pose[2], f"amb{k}": loc.ambiguity,
                    f"mar{k}": loc.margin})
        if truth_check:
            own = {index - j for j in range(k)}
            seen = [(j - index, explored_cells(scans_c[j], Pc[j], grid.shape)) for j in leave[k] if j not in own]
            chk = truth_check_row(Mv, grid, samples, headings, loc.pose, Pc[index], scans[:k],
                                  Pc[[index - j for j in range(k)]], rel[:k], left_out_seen=seen)
            row.update({f"{name}{k}": val for name, val in chk.items()})
    if "votes" in leave:
        vgrid = grids["votes"]
        reuse = 1 in joined and vgrid is grids[1]  # scan i alone on the same grid: mode 1's answer
        voters = [poses[1] if reuse and j == 0 else search(vgrid, [scans[j]], np.zeros((1, 3)))[0].pose
                  for j in range(VOTE_SCANS)]
        row.update(count_votes(voters, rel, poses))
    return row


def count_votes(voters, rel, poses: dict) -> dict:
    """Per mode ``k`` (``vote{k}``): how many of the voters — scan ``i - j`` localised alone, ``voters[j]``, carried
    to scan ``i`` by the (noisy) odometry ``rel[j]`` — agree with the mode's answer ``poses[k]`` (:func:`agrees`;
    ours, issue 25)."""
    carried = [se2_compose(v_, se2_inverse(rel[j])) for j, v_ in enumerate(voters)]
    return {f"vote{k}": sum(agrees(c, pose) for c in carried) for k, pose in poses.items()}


#: Where the truth's marks on unexplored cells come from (:func:`unexplored_origin`): obstacle / free marks
#: on a cell a left-out scan 1 or 2 steps away saw, or no other scan.
#: ``conf_obs_…``: obstacle marks on map free cells that a left-out scan 1 or 2 steps away hit, or none did.
ORIGIN_COLUMNS = tuple(f"{what}_{w}" for what in ("unex_obs", "unex_free", "conf_obs") for w in ("1", "2", "none"))
#: Columns of :func:`truth_check_row` (per mode) and of :meth:`LogLocalisationResult.truth_check`: the scores, the
#: wall fractions, the score's terms (:mod:`slamlab.studies.correlation.terms`) at the estimate (``est_…``) and at
#: the best grid pose near the truth (``truth_…``), and the origin of the truth's unexplored obstacle marks.
TRUTH_COLUMNS = ("score_est", "score_truth", "score_est_fine", "score_truth_fine", "walls_truth", "walls_est",
                 *(f"{w}_{t}" for w in ("est", "truth") for t in (*TERM_NAMES, *COUNT_NAMES)), *ORIGIN_COLUMNS)


def explored_cells(scan_c, pose_c, shape) -> tuple[np.ndarray, np.ndarray]:
    """Cells one scan (cells, at ``pose_c``) hit or passed through, and the cells it hit
    (:func:`~slamlab.scans.occupancy_grid`)."""
    og = occupancy_grid([scan_c], np.asarray(pose_c)[None], shape)
    return (og.hits > 0) | (og.passes > 0), og.hits > 0


def unexplored_origin(marks, shape, left_out_seen, a_c: float) -> dict:
    """Where ``marks`` lack map (ours, issue 25). Its marks on unexplored cells (map value 0), obstacle and free
    ones apart (``unex_obs_…``, ``unex_free_…``): how many lie on a cell that a scan left out of the grid (other
    than the joined ones) saw, by its nearest such scan's distance in the log (``…_1``, ``…_2``; farther ones drew
    the grid), and how many no other scan saw or lie outside the map (``…_none``). Its obstacle marks on map free
    cells (value ``a_c``; ``conf_obs_…``): the same for a left-out scan that *hit* the cell. ``left_out_seen``:
    ``(offset in the log, (explored, hit) masks)`` per left-out scan."""
    H, W = shape
    out = {}
    for what, sel, which in (("unex_obs", marks.is_obs & (marks.map == 0), 0),
                             ("unex_free", ~marks.is_obs & (marks.map == 0), 0),
                             ("conf_obs", marks.is_obs & (marks.map == a_c), 1)):
        r, c = marks.row[sel], marks.col[sel]
        inside = (r >= 0) & (r < H) & (c >= 0) & (c < W)
        nearest = np.full(r.size, np.inf)
        for off, masks in left_out_seen:
            hit = np.zeros(r.size, dtype=bool)
            hit[inside] = masks[which][r[inside], c[inside]]
            nearest = np.where(hit, np.minimum(nearest, abs(off)), nearest)
        out.update({f"{what}_1": int(np.sum(nearest == 1)), f"{what}_2": int(np.sum(nearest == 2)),
                    f"{what}_none": int(np.sum(~np.isfinite(nearest) | (nearest > 2)))})
    return out


def tolerance_poses(center, headings, radius_cells: float, heading_rad: float) -> np.ndarray:
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


def fine_poses(center, radius_cells: float, heading_rad: float, step_cells: float = 0.5,
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


def walls_fraction(grid, scans_c, poses_c) -> float:
    """Fraction of the scans' end points (placed at ``poses_c``, cells) on obstacle cells of ``grid``."""
    on = total = 0
    for s, q in zip(scans_c, poses_c, strict=True):
        o, _seen, t = endpoints_on_walls(grid, s, q)
        on, total = on + o, total + t
    return on / max(total, 1)


def truth_check_row(Mv, grid, samples: ScanSamples, headings, est_pose, truth_pose, scans_c, true_poses_c, rel,
                    left_out_seen=()) -> dict:
    """Score failure or search failure? The search's score at its estimate and near the truth (ours, issue 25).

    ``score_est``: the score of ``samples`` (the joined scans ``scans_c``) at the estimate; ``score_truth``: the
    best score of the grid poses that count as a success (within 2 cells and 5° of ``truth_pose``: the search
    scored them all). If the estimate is a failure, also ``score_est_fine`` / ``score_truth_fine``: the best score
    off the grid (every 0.5 cell and 0.5°) within the same tolerance of the estimate / the truth (NaN for a
    success). ``walls_truth``: fraction of the joined scans' end points at their logged poses ``true_poses_c`` on
    obstacle cells of ``grid``; ``walls_est``: the same at the estimate (the joined scans placed by ``rel``).
    Scores by :func:`~slamlab.correlation.scoring.pose_scores` (float64, the definition; ``a_n`` must be 0).
    ``est_<term>`` / ``truth_<term>``: :func:`~slamlab.studies.correlation.terms.mark_terms` at the estimate and
    at the best grid pose near the truth; ``unex_…``: :func:`unexplored_origin` of the latter's marks with
    ``left_out_seen`` (``(offset in the log, explored mask)`` of each left-out scan that is not a joined one).
    """
    p = samples.params
    tol_c, tol_h = FAIL_CELLS, float(np.radians(FAIL_DEG))
    est = np.asarray(est_pose, dtype=float)
    score_est = float(pose_scores(Mv, samples, est[None])[0])
    near = tolerance_poses(truth_pose, headings, tol_c, tol_h)
    near_scores = pose_scores(Mv, samples, near)
    best_near = near[int(np.argmax(near_scores))]
    score_truth = float(np.max(near_scores))
    failed = np.hypot(*(est[:2] - truth_pose[:2])) > tol_c + 1e-9 or heading_error(est[2], truth_pose[2]) > tol_h
    if failed:
        est_fine = float(np.max(pose_scores(Mv, samples, fine_poses(est, tol_c, tol_h))))
        truth_fine = float(np.max(pose_scores(Mv, samples, fine_poses(truth_pose, tol_c, tol_h))))
    else:
        est_fine = truth_fine = float("nan")
    est_poses = np.array([se2_compose(est, q) for q in rel])
    marks = dict(zip(("est", "truth"), pose_marks(Mv, samples, np.vstack([est, best_near])), strict=True))
    terms = {f"{who}_{k}": val for who, mk in marks.items() for k, val in mark_terms(mk, p.a_c, p.a_p).items()
             if k != "score"}
    return {"score_est": score_est, "score_truth": score_truth, "score_est_fine": est_fine,
            "score_truth_fine": truth_fine, "walls_truth": walls_fraction(grid, scans_c, true_poses_c),
            "walls_est": walls_fraction(grid, scans_c, est_poses), **terms,
            **unexplored_origin(marks["truth"], grid.shape, left_out_seen, p.a_c)}
