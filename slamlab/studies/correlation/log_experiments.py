"""Ch. 5 experiments (004 §7) on real data: correlation localisation along a CARMEN log with corrected poses.

Part of the chapter's experiments (:mod:`slamlab.studies.correlation.experiments` holds the simulated ones;
:mod:`slamlab.studies.correlation.carmen_logs` the logs). The run lives here: the per-scan task (leave-out grids,
joined localisation, votes, the truth check) runs on :func:`slamlab.sweep.sweep`, and
:class:`~slamlab.studies.correlation.LogLocalisationResult` (:mod:`slamlab.studies.correlation.log_results`)
tabulates its columns.
"""

from __future__ import annotations

import time

import numpy as np

from ..._validate import as_finite_array, as_rng, check_int, check_positive
from ...correlation.algorithm import LocaliseParams, heading_candidates, heading_error
from ...correlation.settings import check_score_norm
from ...scans.logmap import log_counts
from ._log_scan import TRUTH_COLUMNS, VOTE_SCANS, check_leave, check_unit, localise_log_scan, log_points
from .carmen_logs import as_carmen_log
from .log_results import LogLocalisationResult
from .map_check import logged_pose_check
from .studies import MIN_COVERAGE

__all__ = [
    "ODOM_STD",
    "LogLocalisationResult",
    "run_log_localisation",
]


#: Default odometry noise of the joined modes: σ_xy [m], σ_θ [rad] per step between consecutive scans (ours).
ODOM_STD = (0.05, float(np.radians(1.0)))



def run_log_localisation(path=None, scan_indices=(50, 150, 250, 350, 450, 550, 650, 750, 850), *,
                         cell_m: float = 0.2, max_range_m: float = 10.0, exclude: int | None = None, joined=(1,),
                         odom_std=ODOM_STD, hit_ratio: float = 0.25, params: LocaliseParams | None = None, rng=2017,
                         n_jobs: int = 1, progress: bool | None = None, truth_check: bool = False,
                         refine: int = 0, refine_heading_rad: float = float(np.radians(3.0)),
                         score_norm: str = "none", min_explored_fraction: float = 0.8, leave_out: str = "window",
                         votes: bool = False, min_coverage: float = MIN_COVERAGE,
                         **overrides) -> LogLocalisationResult:
    """Localise scans of a CARMEN log on grids built from the log's own poses (real data; 004 §7 + ours).

    Each test scan is localised on the grid (``cell_m`` cells, 004's three values) of every
    scan of the log except ``±exclude`` scans around it (by default; see ``leave_out``), so a scan is never
    matched against cells it or its nearest neighbours drew (ours), from no prior (full 360°), and
    compared with its logged pose (SLAM-corrected in the Radish logs). A success is a pose
    within 2 cells and 5° of the logged one.

    Modes (``joined``): 1 = the scan alone (004's method); 2 or 3 = the scan and the 1 or 2
    scans before it joined by odometry (:func:`~slamlab.correlation.localise_joined`, ours).
    The corrected logs carry no raw odometry, so each step between consecutive scans is the
    logged relative pose plus Gaussian noise ``odom_std = (σ_xy [m], σ_θ [rad])``, drawn from ``rng`` once per
    step of the log, so a scan's joined odometry does not depend on which other scans are localised.
    Every result carries the ambiguity of :class:`~slamlab.correlation.Localisation`, each scan's coverage by its
    leave-out grid (``min_coverage``) and whether its logged pose agrees with its neighbours' scans
    (:func:`~slamlab.studies.correlation.logged_pose_check`, ``result.pose_check``).

    Parameters
    ----------
    path : str, os.PathLike or CarmenLog, optional
        Any CARMEN log (plain or gzip); default the corrected Intel Research Lab log
        (``carmen-radish-corrected/intel-corrected.log.gz`` via :func:`slamlab.data.find_data`).
        Results are labelled with the file name.
    scan_indices : sequence of int
        The scans to localise (at least ``max(joined) - 1``: the joined scans come before).
    cell_m : float, default 0.2
        Grid cell size [m].
    max_range_m : float, default 10.0
        Returns farther than this are not used [m].
    exclude : int, optional
        Scans either side of each test scan left out of its grid (``"window"``; default 2, ``>= max(joined) - 1``).
        The real-log default (ours, issue 25): the scan and the 2 scans joined before it never draw its
        grid; the issue-17 runs left out ±10 (≈ ±10 m of path on the shared logs, whose scans are
        ≈ 1 m apart), which removed the map of places the robot passed once (csail, orebro:
        ``docs/benchmarks.md``, correlation section, the ablation table).
    joined : sequence of int in {1, ..., 5}
        The modes to run on the same scans (4 and 5: an issue-25 experiment, a longer baseline).
    odom_std : tuple of float
        ``(σ_xy [m], σ_θ [rad])`` of the noise added to each logged step (default ``ODOM_STD``, 0.05 m and 1°).
    hit_ratio : float, default 0.25
        A grid cell is an obstacle when its hits are at least ``hit_ratio`` times the beams that passed
        through it (:func:`~slamlab.scans.occupancy_grid`'s rule ``"count"``; 0: any hit), in [0, 1].
    params, **overrides
        :class:`LocaliseParams` of every localisation (``rival_radius_cells`` 5 = 1 m at 0.2 m cells).
    rng : int or numpy.random.Generator, default 2017
        Seed or generator of the odometry noise (one draw of ``n_scans × 3`` normals per call).
    n_jobs, progress
        The scans run on :func:`slamlab.sweep.sweep` (one task per scan; same result for any
        ``n_jobs``) with a progress bar unless ``progress=False`` or ``$SLAMLAB_PROGRESS=0``.
    truth_check : bool, default False
        Also score each scan near its logged pose with the search's own score (ours, issue 25): is a failure a
        score failure (the truth scores lower than the estimate) or a search failure?
        :meth:`~slamlab.studies.correlation.LogLocalisationResult.truth_check` tabulates it, ``terms_table()`` the
        score's terms. Needs ``a_n = 0`` (004's value).
    refine : int, default 0
        Off by default. ``refine`` > 0 (ours, issue 25): score the ``refine`` best distinct peaks of the grid
        search (more than 2 cells or 3° apart) again every 0.5 cell within 1 cell and every 0.5° within
        ``refine_heading_rad``,
        by the definition, and keep the best pose (against failures where the truth's neighbourhood scores
        higher than the estimate's only off the grid; ``docs/benchmarks.md``).
    refine_heading_rad : float, default 3°
        Half-width of the refinement's headings around each peak [rad] (3°: with 1°, intel scan 550 is lost,
        ``docs/benchmarks.md``; chosen on that one scan).
    score_norm : {"none", "explored"}, default "none"
        ``"explored"``: score per mark on an explored cell (:func:`~slamlab.correlation.localise`; ours, issue
        25); not with ``truth_check`` or ``refine`` (they score by the raw correlation).
    min_explored_fraction : float, default 0.8
        Its guard (:func:`~slamlab.correlation.localise`).
    leave_out : {"window", "used"}, default "window"
        ``"window"``: the ``±exclude`` scans, one grid for every mode. ``"used"`` (ours, issue 25): each mode's
        grid lacks exactly the scans it localises with (mode ``k``: scans ``i - k + 1 .. i``), so cells the
        scans after ``i`` drew may be in it; ``exclude`` must not be given.
    votes : bool, default False
        Also localise scans ``i - 1`` and ``i - 2`` alone (ours, issue 25), on a grid that lacks them and scan ``i``
        (with the ``±2`` window: the test scan's own grid), carry each answer to scan ``i`` by the same noisy
        odometry as the joined modes, and count per mode how many of these three single-scan answers (scans
        ``i, i-1, i-2``) lie within a success's tolerance of the mode's answer (``result.votes``; an answer with
        fewer than 2 is :meth:`~slamlab.studies.correlation.LogLocalisationResult.flagged`). The modes' answers are
        unchanged; about twice the single-scan work.

    min_coverage : float, default MIN_COVERAGE (0.5)
        A scan is *covered* when at least this share of its end points lies within one cell of an obstacle cell of
        its leave-out grid at the logged pose (ours; the reasons at
        :data:`~slamlab.studies.correlation.studies.MIN_COVERAGE`). Every scan is localised; ``result.covered``
        marks which ones count towards the goal, and the tables print the others as "not covered". In [0, 1].

    Returns
    -------
    LogLocalisationResult
    """
    from ...sweep import sweep

    p = LocaliseParams.resolve(params, **overrides)
    log = as_carmen_log(path)
    cell = check_positive(cell_m, "cell_m")
    rmax = check_positive(max_range_m, "max_range_m")
    modes = tuple(int(k) for k in np.atleast_1d(np.asarray(joined)))
    if not modes or any(k not in (1, 2, 3, 4, 5) for k in modes) or len(set(modes)) != len(modes):
        raise ValueError(f"`joined` must be distinct numbers of scans from {{1, ..., 5}}; got {joined!r}")
    kmax = max(modes)
    lo, ex = check_leave(leave_out, exclude, kmax)
    hr = check_unit(hit_ratio, "hit_ratio")
    mc = check_unit(min_coverage, "min_coverage")
    for name, flag in (("truth_check", truth_check), ("votes", votes)):
        if not isinstance(flag, (bool, np.bool_)):
            raise TypeError(f"`{name}` must be a bool; got {type(flag).__name__}")
    rf = check_int(refine, "refine", minimum=0)
    rfh = check_positive(refine_heading_rad, "refine_heading_rad", allow_zero=True)
    if (truth_check or rf) and p.a_n != 0:
        raise ValueError(f"`truth_check` and `refine` score by the definition with a_n = 0 (004's value); got a_n = "
                         f"{p.a_n}")
    sn, frac = check_score_norm(score_norm, min_explored_fraction, p)
    if (truth_check or rf) and sn != "none":
        raise ValueError(f"`truth_check` and `refine` score by the raw correlation; got score_norm = {sn!r} (use "
                         f"'none')")
    sd = as_finite_array(odom_std, "odom_std")
    if sd.shape != (2,) or np.any(sd < 0):
        raise ValueError(f"`odom_std` must be (σ_xy_m, σ_θ_rad) >= 0; got {odom_std!r}")
    idx = np.asarray(scan_indices)
    if idx.ndim != 1 or idx.size == 0 or not np.issubdtype(idx.dtype, np.integer):
        raise ValueError(f"`scan_indices` must be a non-empty list of ints; got {scan_indices!r}")
    back = max(kmax, VOTE_SCANS) if votes else kmax  # scans read back from each test scan
    if idx.min() < back - 1 or idx.max() >= log.n_scans:
        raise ValueError(f"`scan_indices` must lie in [{back - 1}, {log.n_scans - 1}] (the {back - 1} scans before "
                         f"each are joined or vote); got {idx.min()}..{idx.max()}")
    rng = as_rng(rng)
    t0 = time.perf_counter()
    frame, scans_c, Pc, full = log_counts(log, cell_m=cell, max_range_m=rmax)
    scale = np.array([sd[0] / cell, sd[0] / cell, sd[1]])
    # one noise draw per step of the log (row m: scan m-1 -> m), so a scan's odometry is the same in any list
    steps = rng.normal(size=(log.n_scans, 3)) * scale
    noise = steps[idx[:, None] - np.arange(back - 1)[None, :]]  # (n, back - 1): steps i -> i-1, i-1 -> i-2, …
    points = log_points(idx, modes, scans_c, Pc, noise, lo, ex, votes=bool(votes))
    fixed = {"full": full, "scans_c": scans_c, "Pc": Pc, "p": p, "headings": heading_candidates(p.delta_alpha_rad),
             "joined": modes, "hit_ratio": hr, "truth_check": bool(truth_check),
             "refine": rf, "refine_heading_rad": rfh, "score_norm": sn, "min_explored_fraction": frac}
    table = sweep(localise_log_scan, points, rng_arg=None, n_jobs=n_jobs, progress=progress, fixed=fixed,
                  on_error="raise", desc="localise log scans")
    true_m = log.poses[idx]
    est_m = np.stack([frame.to_metres(table[[f"x{k}", f"y{k}", f"h{k}"]].to_numpy(dtype=float)) for k in modes])
    err_p = np.hypot(est_m[..., 0] - true_m[:, 0], est_m[..., 1] - true_m[:, 1])
    err_a = heading_error(est_m[..., 2], true_m[:, 2])
    amb = np.stack([table[f"amb{k}"].to_numpy(dtype=float) for k in modes])
    margin = np.stack([table[f"mar{k}"].to_numpy(dtype=float) for k in modes])
    example = log.scan(int(idx[0])).points(est_m[0, 0])
    truth = ({c: np.stack([table[f"{c}{k}"].to_numpy(dtype=float) for k in modes]) for c in TRUTH_COLUMNS}
             if truth_check else None)
    vote = np.stack([table[f"vote{k}"].to_numpy(dtype=int) for k in modes]) if votes else None
    return LogLocalisationResult(log.name, idx, true_m, est_m, err_p, err_a, amb, cell, rmax,
                                 ex if lo == "window" else None, full.grid, frame, modes,
                                 (float(sd[0]), float(sd[1])), example, p, time.perf_counter() - t0, margin, truth, lo,
                                 vote, table["coverage"].to_numpy(dtype=float), mc, logged_pose_check(log, idx))
