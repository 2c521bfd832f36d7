"""Ch. 6 on real laser logs (004 §Hough SLAM, our addition): Hough SLAM with raw odometry on a URG-04LX log of the
Mines format or a CARMEN log, beside the integrated odometry (these logs carry no ground truth).

The scans of these logs are older than the odometry readings they are paired with; the lag is measured on
each log from the lines (:func:`~slamlab.hough.odometry_lag`) and Hough SLAM predicts with the odometry read at
each scan's own time. The odometry map stays the log's pairing; the re-timed odometry's map is kept beside it.

Split from :mod:`slamlab.studies.hough.experiments` (which re-exports every name here).
"""

from __future__ import annotations

import math
import os
import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..._table import format_table
from ..._validate import as_path, check_choice, check_int, check_positive, check_real
from ...geometry import wrap_angle
from ...geometry.se2 import se2_relative
from ...hough.latency import line_rotation_steps, odometry_lag, retime_poses
from ...hough.slam import HoughSlamParams, HoughSlamResult, hough_slam, scan_lines
from ...scans import GridFrame, OccupancyGrid, occupancy_grid

__all__ = ["LOG_PARAMS", "REAL_LOG_PARAMS", "SHARED_LOGS", "RealLogResult", "log_format", "map_sharpness",
           "real_log_cause_table", "rerun_real_log", "run_real_log"]

#: The shared logs run by the notebook, found by :func:`slamlab.data.find_data`.
SHARED_LOGS = {"urg04lx": "mines-urg04lx-odometry/exp2.dat", "mbicp": "mbicp-laserazos-sick/laserazosSM3.log",
               "urg04lx_exp1": "mines-urg04lx-odometry/exp1.dat"}


# --- real laser logs ---------------------------------------------------------------------------


def _steps(n: int) -> str:
    """``"1 step"`` / ``"n steps"``.

    Parameters
    ----------
    n : int
        The count.

    Returns
    -------
    str
    """
    return f"{n} step" if n == 1 else f"{n} steps"


@dataclass(frozen=True)
class RealLogResult:
    """Hough SLAM on a real log beside integrated odometry (no ground truth in these logs).

    Attributes
    ----------
    name : str
        Title: format and file name.
    slam : HoughSlamResult
        The SLAM run.
    odometry : numpy.ndarray, shape (n, 3)
        Integrated odometry ``(x_m, y_m, φ_rad)``.
    scans : list of Scan
        The scans used (metres).
    map_slam, map_odometry : OccupancyGrid
        Maps built from the SLAM and the odometry poses.
    scan_index : numpy.ndarray of int, shape (n,)
        Which scans of the log were used.
    frame : GridFrame or None
        Metric frame of the maps.
    lag_scans : float
        How many scan periods each scan was taken before its odometry reading (measured
        by :func:`~slamlab.hough.odometry_lag`, or given).
    odometry_retimed : numpy.ndarray, shape (n, 3) or None
        The odometry read at each scan's own time (:func:`~slamlab.hough.retime_poses`): what
        Hough SLAM predicts with.
    map_retimed : OccupancyGrid or None
        Map built from ``odometry_retimed`` (lines not used).
    lines : list of Lines or None
        Each scan's lines (:func:`~slamlab.hough.scan_lines`).
    timing_s : dict
        Wall times [s] (not compared).
    """

    name: str  # title: format and file name
    slam: HoughSlamResult = field(repr=False)
    odometry: np.ndarray = field(repr=False)  # (n, 3) as paired with the scans in the log
    scans: list = field(repr=False)  # the Scans used (metres)
    map_slam: OccupancyGrid = field(repr=False)
    map_odometry: OccupancyGrid = field(repr=False)
    scan_index: np.ndarray = field(repr=False)  # which scans of the log were used
    frame: GridFrame | None = field(default=None, repr=False)  # metric frame of the maps
    lag_scans: float = 0.0  # scan periods each scan is older than its odometry reading
    odometry_retimed: np.ndarray | None = field(default=None, repr=False)  # (n, 3) at each scan's time
    map_retimed: OccupancyGrid | None = field(default=None, repr=False)  # map from odometry_retimed
    lines: list | None = field(default=None, repr=False)  # each scan's Lines
    timing_s: dict = field(default_factory=dict, compare=False)

    @property
    def path_length_m(self) -> float:
        """Length of the odometry path."""
        return float(np.hypot(*np.diff(self.odometry[:, :2], axis=0).T).sum())

    def sharpness(self, which: str = "slam") -> float:
        """Obstacle cells per 100 returns in the built map: fewer = walls drawn thinner (our measure).

        Parameters
        ----------
        which : {"slam", "odometry", "retimed"}
            The map to measure: Hough SLAM's, the log's odometry's, the re-timed odometry's.

        Returns
        -------
        float
        """
        maps = {"slam": self.map_slam, "odometry": self.map_odometry, "retimed": self.map_retimed}
        m = maps[check_choice(which, "which", tuple(maps))]
        if m is None:
            raise ValueError(f"this result holds no {which!r} map")
        return float(100.0 * (m.grid == 1).sum() / max(1, m.hits.sum()))

    def sharper_than_odometry(self, which: str = "odometry") -> float:
        """1 - (obstacle cells per 100 returns, Hough SLAM map) / (the same, odometry map) (our measure).

        Parameters
        ----------
        which : {"odometry", "retimed"}
            Against the log's odometry (as paired with the scans) or the re-timed one.

        Returns
        -------
        float
            0.10 = the Hough SLAM map draws the same returns with 10 % fewer obstacle cells.
        """
        return 1.0 - self.sharpness("slam") / self.sharpness(check_choice(which, "which", ("odometry", "retimed")))

    def __str__(self) -> str:
        return (f"{self.name}: {self.odometry.shape[0]} scans, {self.path_length_m:.1f} m of odometry;\n"
                f"{_steps(int(self.slam.lost.sum()))} fell back on odometry, {int(self.slam.partial.sum())} in part")

    def table(self) -> str:
        """Hough SLAM against integrated odometry on the log (fixed precision).

        Returns
        -------
        str
        """
        d = self.slam.poses[-1] - self.odometry[-1]
        counts = self.slam.cause_counts()
        n_steps = self.odometry.shape[0] - 1
        rows = [
            ["scans used", f"{self.odometry.shape[0]}"],
            ["odometry path length [m]", f"{self.path_length_m:.1f}"],
            ["median lines per scan", f"{np.median(self.slam.n_lines):.0f}"],
            ["steps with only parallel lines (move along them from odometry)",
             f"{counts['partial'] / n_steps:.0%}"],
            ["steps with heading from lines, translation from odometry", f"{counts['heading'] / n_steps:.0%}"],
            ["steps on odometry alone (fell back)", f"{int(self.slam.lost[1:].sum()) / n_steps:.1%}"],
            ["final position, Hough SLAM - odometry [m]", f"{math.hypot(d[0], d[1]):.1f}"],
            ["final heading, Hough SLAM - odometry [°]", f"{math.degrees(float(wrap_angle(d[2]))):.0f}"],
            ["obstacle cells per 100 returns, Hough SLAM map", f"{self.sharpness('slam'):.1f}"],
            ["obstacle cells per 100 returns, odometry map", f"{self.sharpness('odometry'):.1f}"],
            ["sharper than odometry: 1 - Hough SLAM / odometry cells", f"{self.sharper_than_odometry():.1%}"],
        ]
        if self.map_retimed is not None:
            rows += [
                ["scans taken before their odometry reading [scan periods]", f"{self.lag_scans:.2f}"],
                ["obstacle cells per 100 returns, re-timed odometry map", f"{self.sharpness('retimed'):.1f}"],
                ["sharper than re-timed odometry", f"{self.sharper_than_odometry('retimed'):.1%}"],
            ]
        return format_table(["quantity", "value"], rows, title=self.name)


def real_log_cause_table(results) -> str:
    """Per log: how each step's pose was obtained (:data:`~slamlab.hough.STEP_CAUSES`) and the sharpness.

    Parameters
    ----------
    results : sequence of RealLogResult
        One run per log (columns).

    Returns
    -------
    str
        Steps per cause (count and % of the log's steps; the fallback causes first marked
        "odometry alone"), then the obstacle cells per 100 returns of both maps and
        1 - Hough SLAM / odometry.
    """
    from ...hough.slam import STEP_CAUSES

    results = list(results)
    if not results or not all(isinstance(r, RealLogResult) for r in results):
        raise TypeError("`results` must be a non-empty sequence of RealLogResult")
    counts = [r.slam.cause_counts() for r in results]
    steps = [r.odometry.shape[0] - 1 for r in results]
    label = {"lines": "pose from lines", "partial": "parallel lines + odometry along them",
             "heading": "heading from lines + odometry's translation"}
    rows = []
    for name in STEP_CAUSES:
        head = label.get(name, f"odometry alone: {name.replace('_', ' ')}")
        rows.append([head] + [f"{c[name]} ({c[name] / n:.1%})" for c, n in zip(counts, steps, strict=True)])
    rows.append(["odometry alone: all causes"]
                + [f"{int(r.slam.lost[1:].sum())} ({r.slam.lost[1:].sum() / n:.1%})"
                   for r, n in zip(results, steps, strict=True)])
    rows.append(["obstacle cells / 100 returns: Hough SLAM, odometry"]
                + [f"{r.sharpness('slam'):.2f}, {r.sharpness('odometry'):.2f}" for r in results])
    rows.append(["sharper than odometry: 1 - Hough SLAM / odometry"]
                + [f"{r.sharper_than_odometry():.1%}" for r in results])
    if all(r.map_retimed is not None for r in results):
        rows.append(["scans before their odometry reading [periods]"] + [f"{r.lag_scans:.2f}" for r in results])
        rows.append(["obstacle cells / 100 returns: re-timed odometry"]
                    + [f"{r.sharpness('retimed'):.2f}" for r in results])
        rows.append(["sharper than re-timed odometry"] + [f"{r.sharper_than_odometry('retimed'):.1%}"
                                                          for r in results])
    return format_table(["steps (of each log)"] + [r.name.split(" log ")[1].split(" ")[0] for r in results],
                        rows, title="Hough SLAM on real logs: how each step's pose was found")


#: Real-log settings (ours), one set for every log and format: rho resolution and thresholds in metres
#: (``r_max`` = the log's range limit); ``heading``: a step whose lines give no pose takes its heading change
#: from them and its translation from odometry; ``H_min_retry``: a scan with fewer than two lines is searched
#: again at 10 votes. Tuned on exp2 (URG-04LX) and the MbICP log together; exp1 (URG-04LX) set none of them.
REAL_LOG_PARAMS = {"delta_rho": 0.02, "H_min": 15, "H_min_retry": 10, "a": 0.15, "max_gap": 0.2, "rho_tol": 0.05,
                   "band": 0.03, "heading": True}
#: The settings per format (kept for old callers): both formats use :data:`REAL_LOG_PARAMS`.
LOG_PARAMS = {"urg04lx": REAL_LOG_PARAMS, "carmen": REAL_LOG_PARAMS}
_FORMAT_NAMES = {"urg04lx": "URG-04LX", "carmen": "CARMEN"}


def log_format(path) -> str:
    """``"carmen"`` or ``"urg04lx"``: the format of a laser log, from its first data line.

    CARMEN lines start with a message name (``FLASER``, ``ODOM``, ``PARAM`` …); a
    URG-04LX line of the Mines format is 707 numbers.

    Parameters
    ----------
    path : str or os.PathLike
        Log file, plain or gzip.

    Returns
    -------
    str
    """
    from ...io import open_text  # plain text or gzip, told apart by the magic bytes

    p = as_path(path, "path", kind="file")
    with open_text(p) as fh:
        for line in fh:
            tok = line.split()
            if not tok or tok[0].startswith("#"):
                continue
            try:
                float(tok[0])
            except ValueError:
                return "carmen"
            return "urg04lx"
    raise ValueError(f"{p.name}: empty log")


def _load_log(path, fmt):
    """Scans (metres) and odometry poses of a log; the log's range limit."""
    if fmt == "urg04lx":
        from ...io.urg04lx import read_urg04lx_log

        log = read_urg04lx_log(path)
        return log.scans(), log.odometry_poses(), log.max_range_m
    from ...io.carmen import read_carmen

    log = read_carmen(path)
    return log.scans(), log.odom_poses.copy(), log.max_range_m


def _maps(scans, pose_sets, cell_m):
    """Endpoint maps of the scans at each set of poses, in one frame covering them all."""
    pts = np.concatenate([P[:, :2] for P in pose_sets])
    lo = pts.min(axis=0) - 9.0
    span = np.ceil((pts.max(axis=0) + 9.0 - lo) / cell_m).astype(int)
    frame = GridFrame(float(lo[0]), float(lo[1]), cell_m, (int(span[1]), int(span[0])))
    scans_c = [s.to_cells(cell_m) for s in scans]
    return frame, [occupancy_grid(scans_c, frame.to_cells(P), frame.shape, rule="endpoints", hit_offset_cells=0.0)
                   for P in pose_sets]


def map_sharpness(scans, pose_sets, *, cell_m: float = 0.05) -> list[float]:
    """Obstacle cells per 100 returns of the scans drawn at each set of poses, one shared frame (our measure).

    The measure of :meth:`~slamlab.studies.hough.RealLogResult.sharpness` for any poses: fewer cells for the same
    returns = walls drawn thinner.

    Parameters
    ----------
    scans : sequence of Scan
        Scans in metres.
    pose_sets : sequence of (n, 3) array_like
        Poses ``(x_m, y_m, φ_rad)`` of every scan, one array per map.
    cell_m : float
        Cell size [m].

    Returns
    -------
    list of float
        One value per pose set.
    """
    scans = list(scans)
    sets = [np.asarray(P, dtype=float) for P in pose_sets]
    if not sets or any(P.shape != (len(scans), 3) for P in sets):
        raise ValueError(f"`pose_sets` must hold (n, 3) arrays with n = {len(scans)} scans")
    _, maps = _maps(scans, sets, check_positive(cell_m, "cell_m"))
    return [float(100.0 * (m.grid == 1).sum() / max(1, m.hits.sum())) for m in maps]


def _run_loaded(name, scans, odo, idx, params, lag_scans, lines, cell_m, progress, timing) -> RealLogResult:
    """Hough SLAM on loaded scans and odometry; ``lines`` None: detected here."""
    t0 = time.perf_counter()
    if lines is None:
        lines = scan_lines(scans, params)
    timing["lines"] = time.perf_counter() - t0
    if isinstance(lag_scans, str):
        check_choice(lag_scans, "lag_scans", ("measure",))
        steps = line_rotation_steps(lines) if len(lines) > 1 else np.full(0, np.nan)
        # no step measured by the lines (a few scans): the log's pairing
        lag_scans = odometry_lag(steps, odo)[0] if np.isfinite(steps).any() else 0.0
    else:
        lag_scans = check_real(lag_scans, "lag_scans")
    odo_t = retime_poses(odo, lag_scans)
    U = se2_relative(odo_t[:-1], odo_t[1:])
    t0 = time.perf_counter()
    res = hough_slam(scans, odo_t[0], U, params, progress=progress, lines=lines)
    timing["hough_slam"] = time.perf_counter() - t0
    t0 = time.perf_counter()
    frame, (m_slam, m_odo, m_ret) = _maps(scans, (res.poses, odo, odo_t), cell_m)
    timing["build_map"] = time.perf_counter() - t0
    return RealLogResult(name, res, odo, scans, m_slam, m_odo, idx, frame, float(lag_scans), odo_t, m_ret,
                         list(lines), timing)


def rerun_real_log(result: RealLogResult, *, lag_scans: float | str = "measure", cell_m: float = 0.05,
                   **overrides) -> RealLogResult:
    """:func:`run_real_log` again on the scans of ``result`` with other settings (ours, for ablations).

    The lines of ``result`` are reused unless an override changes how lines are found.

    Parameters
    ----------
    result : RealLogResult
        A run of :func:`run_real_log` (its scans, odometry and lines).
    lag_scans : float or "measure"
        As in :func:`run_real_log`.
    cell_m : float
        Cell of the built maps.
    **overrides
        Fields of :class:`~slamlab.hough.HoughSlamParams` to change from ``result``'s settings.

    Returns
    -------
    RealLogResult
    """
    if not isinstance(result, RealLogResult):
        raise TypeError(f"`result` must be a RealLogResult; got {type(result).__name__}")
    params = result.slam.params.replace(**overrides) if overrides else result.slam.params
    same = all(getattr(params, f) == getattr(result.slam.params, f) for f in _DETECTION_FIELDS)
    lines = result.lines if same else None
    return _run_loaded(result.name, result.scans, result.odometry, result.scan_index, params, lag_scans, lines,
                       check_positive(cell_m, "cell_m"), False, {})


#: The fields of :class:`~slamlab.hough.HoughSlamParams` that change the lines found (the rest: the loop).
_DETECTION_FIELDS = ("delta_rho", "delta_theta_rad", "r_max", "H_min", "H_min_retry", "max_lines", "suppress_rho",
                     "suppress_theta_rad", "refine", "band", "max_gap")


def run_real_log(path=None, *, fmt: str | None = None, n_scans: int | None = None, step: int = 1,
                 cell_m: float = 0.05, lag_scans: float | str = "measure", params: HoughSlamParams | None = None,
                 progress: bool | None = None, **overrides) -> RealLogResult:
    """Hough SLAM on a real laser log with raw odometry (a URG-04LX log of the Mines format or a CARMEN log).

    Parameters
    ----------
    path : str or os.PathLike, optional
        Any log of either format; default the Mines URG-04LX log (``SHARED_LOGS["urg04lx"]``
        found by :func:`slamlab.data.find_data`). The result's title is the format and the
        file name.
    fmt : {"urg04lx", "carmen"}, optional
        The format; default: guessed from the first line (:func:`log_format`).
    n_scans : int, optional
        Use only the first ``n_scans`` scans of the log (after ``step``).
    step : int
        Use every ``step``-th scan.
    cell_m : float
        Cell of the built maps.
    lag_scans : float or "measure"
        How many scan periods each scan was taken before its odometry reading (ours): Hough SLAM
        predicts with the odometry read at each scan's own time (:func:`~slamlab.hough.retime_poses`).
        ``"measure"`` (default): measured on the log from the lines' heading changes
        (:func:`~slamlab.hough.odometry_lag`; 0 when no step pairs lines); 0: the odometry as the log
        pairs it.
    params, **overrides
        Defaults are our settings :data:`REAL_LOG_PARAMS`, one set for every log (Δrho = 2 cm,
        H_min = 15, a = 0.15 m, the heading step on, …) with ``r_max`` = the log's range limit.
    progress : bool, optional
        A bar over the scans (None: on unless ``$SLAMLAB_PROGRESS=0``).

    Returns
    -------
    RealLogResult
        Its odometry map uses the log's odometry as paired with the scans; ``map_retimed`` the
        re-timed one.
    """
    if path is None:
        from ...data import find_data

        path = find_data(SHARED_LOGS["urg04lx"])
    elif isinstance(path, bool) or not isinstance(path, (str, os.PathLike)):
        raise TypeError(f"`path` must be a str or os.PathLike; got {type(path).__name__}")
    fmt = log_format(path) if fmt is None else check_choice(fmt, "fmt", tuple(LOG_PARAMS))
    step = check_int(step, "step", minimum=1)
    cell_m = check_positive(cell_m, "cell_m")
    if not isinstance(lag_scans, str):
        check_real(lag_scans, "lag_scans")
    timing = {}
    t0 = time.perf_counter()
    scans, odo, max_range_m = _load_log(path, fmt)
    timing["read"] = time.perf_counter() - t0
    idx = np.arange(0, len(scans), step)
    if n_scans is not None:
        idx = idx[: check_int(n_scans, "n_scans", minimum=2)]
    scans = [scans[k] for k in idx]
    base = HoughSlamParams(**LOG_PARAMS[fmt], r_max=float(max_range_m)) if params is None else params
    params = HoughSlamParams.resolve(base, **overrides)
    title = f"{_FORMAT_NAMES[fmt]} log {Path(path).name} (raw odometry)"
    return _run_loaded(title, scans, odo[idx], idx, params, lag_scans, None, cell_m, progress, timing)
