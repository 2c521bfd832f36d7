"""Ch. 6 experiments (004 §Hough SLAM): 004's example line, the 121-pose run, the noise study; the real logs are
in :mod:`slamlab.studies.hough.logs` (re-exported here).

Each ``run_*`` returns a frozen dataclass: ``str(result)`` is a one-line summary,
``result.table()`` a fixed-precision text table (the source's figure beside ours where
there is one); timings live in their own field, never in the table.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field

import numpy as np

from ..._table import format_table
from ..._validate import as_finite_array, check_choice, check_int, check_positive
from ...geometry import wrap_angle
from ...hough.icp import icp_odometry
from ...hough.mapping import map_agreement
from ...hough.slam import HoughSlamParams, HoughSlamResult, hough_slam
from ...scans import OccupancyGrid, occupancy_grid, scan_to_points
from .example import ExampleLineResult, check_pose_from_two_lines, run_example_line, time_polar_vs_opencv
from .logs import LOG_PARAMS, SHARED_LOGS, RealLogResult, log_format, run_real_log

__all__ = [  # LOG_PARAMS, SHARED_LOGS, RealLogResult, log_format, run_real_log: re-exported from .logs;
    # ExampleLineResult, check_pose_from_two_lines, run_example_line, time_polar_vs_opencv: from .example
    "LOG_PARAMS",
    "SHARED_LOGS",
    "ExampleLineResult",
    "NoiseStudyResult",
    "RealLogResult",
    "SimSlamResult",
    "check_pose_from_two_lines",
    "log_format",
    "pose_errors",
    "run_example_line",
    "run_noise_study",
    "run_real_log",
    "run_sim_slam",
    "time_polar_vs_opencv",
]


def pose_errors(estimate, truth) -> np.ndarray:
    """``(Ex, Ey, Ea)`` per pose: estimate minus truth, heading wrapped (004 Fig. 10).

    Parameters
    ----------
    estimate, truth : array_like, shape (n, 3)
        Poses ``(x, y, φ)``.

    Returns
    -------
    numpy.ndarray, shape (n, 3)

    Examples
    --------
    >>> pose_errors([[1.0, 2.0, 0.1]], [[0.5, 2.0, 2 * np.pi]]).round(6).tolist()
    [[0.5, 0.0, 0.1]]
    """
    E = as_finite_array(estimate, "estimate", ndim=2)
    T = as_finite_array(truth, "truth", ndim=2)
    if E.shape != T.shape or E.shape[1] != 3:
        raise ValueError(f"`estimate` and `truth` must both have shape (n, 3); got {E.shape} and {T.shape}")
    err = E - T
    err[:, 2] = wrap_angle(err[:, 2])
    return err


#: Our odometry model of :func:`run_sim_slam` at ``odometry_noise = 1`` (004 gives none; 000 §1.3.2 asks for
#: at most 2 cm per metre and 2° per 45° of turn).
ODOMETRY_NOISE = {"trans_std_frac": 0.05, "rot_std_rad": 0.01, "drift_rad_per_cell": 0.002}


# --- 004's experiment: the 121-pose path on the test room -------------------------------------


@dataclass(frozen=True)
class SimSlamResult:
    """Hough SLAM, integrated odometry and ICP on 004's path (004 Fig. 9-11).

    Attributes
    ----------
    truth : numpy.ndarray, shape (n, 3)
        True poses ``(x, y)`` [cells], φ [rad].
    slam : HoughSlamResult
        The Hough SLAM run.
    odometry : numpy.ndarray, shape (n, 3)
        Integrated odometry.
    icp : numpy.ndarray, shape (n, 3) or None
        Chained ICP (None when not run).
    built_map : OccupancyGrid
        Map built from the SLAM poses.
    reference_map : numpy.ndarray of int
        The mapped test room (without the clutter), to compare ``built_map`` with.
    range_std_cells : float
        Range noise std [cells].
    clutter : bool
        Scans taken in the cluttered room.
    timing_s : dict
        Wall times [s] (not compared).
    odometry_noise : float
        Factor on the odometry noise.
    """

    truth: np.ndarray = field(repr=False)  # (n, 3)
    slam: HoughSlamResult = field(repr=False)
    odometry: np.ndarray = field(repr=False)  # (n, 3) integrated odometry
    icp: np.ndarray | None = field(repr=False)  # (n, 3) chained ICP, None when not run
    built_map: OccupancyGrid = field(repr=False)
    reference_map: np.ndarray = field(repr=False)
    range_std_cells: float = 0.0
    clutter: bool = False
    timing_s: dict = field(default_factory=dict, compare=False)
    odometry_noise: float = 1.0

    @property
    def errors(self) -> dict[str, np.ndarray]:
        """``(n, 3)`` errors (Ex, Ey, Ea) of each method."""
        out = {"Hough SLAM": pose_errors(self.slam.poses, self.truth),
               "odometry": pose_errors(self.odometry, self.truth)}
        if self.icp is not None:
            out["ICP"] = pose_errors(self.icp, self.truth)
        return out

    def __str__(self) -> str:
        e = self.errors["Hough SLAM"]
        return (f"Hough SLAM on {self.truth.shape[0]} poses: max |Ex| {np.abs(e[:, 0]).max():.2f}, "
                f"|Ey| {np.abs(e[:, 1]).max():.2f} cells, |Ea| {np.degrees(np.abs(e[:, 2]).max()):.2f}°; "
                f"{int(self.slam.lost.sum())} lost")

    def table(self) -> str:
        """Error maxima and final errors of Hough SLAM, odometry and ICP (fixed precision).

        Returns
        -------
        str
        """
        rows = []
        for name, e in self.errors.items():
            rows.append([name, f"{np.abs(e[:, 0]).max():.2f}", f"{np.abs(e[:, 1]).max():.2f}",
                         f"{np.degrees(np.abs(e[:, 2]).max()):.2f}",
                         f"{np.hypot(e[-1, 0], e[-1, 1]):.2f}", f"{np.degrees(abs(e[-1, 2])):.2f}"])
        agree = map_agreement(self.built_map, self.reference_map)
        title = (f"{self.truth.shape[0]} poses, range σ {self.range_std_cells:g} cell, clutter "
                 f"{'on' if self.clutter else 'off'}; {int(self.slam.lost.sum())} lost steps;\nbuilt map: "
                 f"{agree['precision']:.0%} of obstacle cells on a true obstacle (±1 cell)")
        return format_table(["method", "max |Ex|", "max |Ey|", "max |Ea| [°]", "final pos err", "final |Ea| [°]"],
                            rows, title=title)


def run_sim_slam(n_poses: int = 121, *, range_std_cells: float = 0.1, clutter: bool = False,
                 n_beams: int = 360, max_range_cells: float = 100.0, odometry_noise: float = 1.0,
                 with_icp: bool = True, start: str = "truth", params: HoughSlamParams | None = None,
                 rng=2010, progress: bool | None = None, **overrides) -> SimSlamResult:
    """004's experiment: Hough SLAM along the 121-pose path on the test room (004 Fig. 9-11).

    Δθ = 1°, Δrho = 1 cell, ranges quantised to 0.1 cell (004). Our choices (004 gives none):
    360 beams over 360°, range noise σ = ``range_std_cells``, and odometry with 5 % translation
    noise, 0.01 rad heading noise and a drift of 0.002 rad per cell, all times
    ``odometry_noise``. The SLAM starts from the true pose (004: correlation localisation gives
    it). ``clutter`` measures in the room with unmapped chair legs, people and bins.

    Parameters
    ----------
    n_poses : int
        Poses along the path (121 in 004).
    range_std_cells : float, default 0.1
        Range noise std [cells].
    clutter : bool, default False
        Measure in the room with unmapped chair legs, people and bins.
    n_beams : int, default 360
        Beams over 360°.
    max_range_cells : float, default 100.0
        Range limit [cells].
    odometry_noise : float, default 1.0
        Factor on our odometry noise (5 % translation, 0.01 rad heading, 0.002 rad per cell drift).
    with_icp : bool
        Also run the ICP baseline (scan-to-scan, odometry as the initial guess).
    start : {"truth", "correlation"}
        Where the SLAM starts: the true first pose, or the pose that correlation localisation
        (:func:`slamlab.correlation.localise`, Δα = 1°, on the mapped room) finds from the first
        scan — 004's whole system (Fig. 2). The ICP baseline and odometry start from the truth.
    params, **overrides
        :class:`HoughSlamParams` and fields to change.
    rng : int, numpy.random.Generator or SeedSequence, default 2010
        Seed or generator: one child stream for the scans, one for the odometry.
    progress : bool, optional
        A bar over the scans of the SLAM run (None: on unless ``$SLAMLAB_PROGRESS=0``).

    Returns
    -------
    SimSlamResult
    """
    from ... import sim

    n_poses = check_int(n_poses, "n_poses", minimum=5)
    sigma = check_positive(range_std_cells, "range_std_cells", allow_zero=True)
    start = check_choice(start, "start", ("truth", "correlation"))
    noise = check_positive(odometry_noise, "odometry_noise", allow_zero=True)
    from ...sweep import root_seed_sequence

    # a Generator spawns its own children; an int seed, a SeedSequence or None: SeedSequence(rng)'s
    seeds = rng.spawn(2) if isinstance(rng, np.random.Generator) else root_seed_sequence(rng, "rng").spawn(2)
    room = sim.test_room_200()
    world = sim.measurement_room_200() if clutter else room
    truth = sim.path_004(n_poses)
    rf = sim.Rangefinder(n_beams=n_beams, max_range_cells=max_range_cells, range_std_cells=sigma,
                         quantum_cells=0.1)
    timing = {}
    t0 = time.perf_counter()
    scans = sim.simulate_scans(world, truth, rf, rng=np.random.default_rng(seeds[0]))
    odo = sim.simulate_odometry(truth, **{k: x * noise for k, x in ODOMETRY_NOISE.items()},
                                rng=np.random.default_rng(seeds[1]))
    timing["simulate"] = time.perf_counter() - t0
    start_pose = truth[0]
    if start == "correlation":
        from ...correlation import localise

        t0 = time.perf_counter()
        start_pose = localise(room, scans[0]).pose  # LocaliseParams defaults: Δα = 1° (004 §7)
        timing["correlation"] = time.perf_counter() - t0
    t0 = time.perf_counter()
    res = hough_slam(scans, start_pose, odo.increments, params, progress=progress, **overrides)
    timing["hough_slam"] = time.perf_counter() - t0
    icp_poses = None
    if with_icp:
        t0 = time.perf_counter()
        pts = [scan_to_points(s.bearings_rad, s.ranges, None, s.valid) for s in scans]
        icp_poses, _ = icp_odometry(pts, truth[0], odo.increments, max_dist=3.0)
        timing["icp"] = time.perf_counter() - t0
    t0 = time.perf_counter()
    built = occupancy_grid(scans, res.poses, room.shape, rule="count", step_cells=1.0)
    timing["build_map"] = time.perf_counter() - t0
    return SimSlamResult(truth, res, odo.poses, icp_poses, built, room, sigma, bool(clutter), timing, noise)


# --- noise study (our addition): Monte Carlo over range noise and seeds on slamlab.sweep -------------


def _noise_run(*, range_std_cells: float, n_poses: int, clutter: bool, rng: np.random.Generator,
               params: HoughSlamParams) -> dict:
    """One seeded Hough SLAM run of the noise study: its worst and final errors (cells, degrees)."""
    r = run_sim_slam(n_poses, range_std_cells=range_std_cells, clutter=clutter, with_icp=False, params=params,
                     rng=rng, progress=False)
    e = r.errors["Hough SLAM"]
    pos = np.hypot(e[:, 0], e[:, 1])
    return {"max_pos_err": float(pos.max()), "final_pos_err": float(pos[-1]),
            "max_heading_err_deg": float(np.degrees(np.abs(e[:, 2]).max())),
            "lost_steps": int(r.slam.lost.sum()), "map_precision": map_agreement(r.built_map, r.reference_map)["precision"]}


@dataclass(frozen=True)
class NoiseStudyResult:
    """Hough SLAM errors against range noise, over seeded runs (our addition; 004 gives one run).

    Attributes
    ----------
    runs : pandas.DataFrame
        The sweep's table, one row per run.
    n_poses : int
        Poses per run.
    clutter : bool
        Scans taken in the cluttered room.
    bad_pos_cells : float
        Final position error above which a run counts as bad [cells].
    """

    runs: object = field(repr=False)  # the sweep's table (pandas DataFrame), one row per run
    n_poses: int = 121
    clutter: bool = False
    bad_pos_cells: float = 2.0

    def table(self) -> str:
        """Errors per range noise level over the runs (fixed precision).

        Returns
        -------
        str
        """
        rows = []
        for sigma, g in self.runs.groupby("range_std_cells", sort=True):
            rows.append([f"{sigma:g}", f"{len(g)}", f"{g['max_pos_err'].mean():.2f}", f"{g['max_pos_err'].max():.2f}",
                         f"{g['max_heading_err_deg'].mean():.2f}", f"{g['final_pos_err'].mean():.2f}",
                         f"{int(g['lost_steps'].sum())}", f"{int((g['max_pos_err'] > self.bad_pos_cells).sum())}",
                         f"{g['map_precision'].mean():.0%}"])
        title = (f"Hough SLAM vs range noise: {self.n_poses} poses of 004's path, clutter "
                 f"{'on' if self.clutter else 'off'}; errors in cells, means over the runs\n"
                 "(worst = the largest max pos err of a run; lost = lost steps of all runs; map precision = obstacle "
                 "cells of\nthe built map on a true obstacle, ±1 cell)")
        return format_table(["range σ [cells]", "runs", "max pos err", "worst", "max |Ea| [°]", "final pos err",
                             "lost", f"runs > {self.bad_pos_cells:g} cells", "map precision"], rows, title=title)


def run_noise_study(range_std_cells=(0.0, 0.1, 0.3, 0.5), n_runs: int = 4, *, n_poses: int = 61,
                    clutter: bool = False, bad_pos_cells: float = 2.0, params: HoughSlamParams | None = None,
                    n_jobs: int = 1, rng=2010, progress=None, **overrides) -> NoiseStudyResult:
    """Hough SLAM on 004's room at several range noises σ, ``n_runs`` seeded runs each (our addition).

    Runs on :func:`slamlab.sweep.sweep` (run i draws from child i of ``SeedSequence(rng)``), so the
    table is the same for any ``n_jobs``. Each run: :func:`run_sim_slam` without ICP on the first
    ``n_poses`` poses. A run counts as bad when its largest position error passes ``bad_pos_cells``.

    Parameters
    ----------
    range_std_cells : float or sequence of float
        The range noises σ [cells], one grid point each.
    n_runs : int
        Seeded runs per noise level.
    n_poses : int
        Poses of 004's path per run.
    clutter : bool
        Add unmapped clutter to the room.
    bad_pos_cells : float
        A run is bad when its largest position error passes this.
    params : HoughSlamParams, optional
        Settings of Hough SLAM (default: :func:`run_sim_slam`'s).
    n_jobs : int
        Parallel workers of :func:`slamlab.sweep.sweep`.
    rng : int, SeedSequence or Generator
        Where every run's stream is spawned from.
    progress : bool, callable or None
        See :mod:`slamlab._progress`.
    **overrides
        :class:`HoughSlamParams` fields.

    Returns
    -------
    NoiseStudyResult
    """
    from ...sweep import root_seed_sequence, sweep

    p = HoughSlamParams.resolve(params, **overrides)
    sigmas = [check_positive(s, "range_std_cells", allow_zero=True) for s in np.atleast_1d(range_std_cells)]
    if not sigmas:
        raise ValueError("`range_std_cells` must hold at least one noise level")
    n_runs = check_int(n_runs, "n_runs", minimum=1)
    n_poses = check_int(n_poses, "n_poses", minimum=5)
    bad = check_positive(bad_pos_cells, "bad_pos_cells")
    table = sweep(_noise_run, {"range_std_cells": sigmas}, seeds=n_runs, rng=root_seed_sequence(rng, "rng"),
                  n_jobs=n_jobs, progress=progress,
                  fixed={"n_poses": n_poses, "clutter": bool(clutter), "params": p},
                  on_error="raise", desc="Hough SLAM noise study")
    return NoiseStudyResult(table, n_poses, bool(clutter), bad)


#: Notes under :func:`ours_vs_source`'s table (what its short labels stand for).
_SOURCE_NOTES = (
    'Fig. 10 errors: max |Ex| / |Ey| [cells], max |Ea|; 004 Fig. 10: "orders of magnitude below the resolution"',
    "(≪ 1 cell, ≪ 1°). Final error: 004 argues that Hough SLAM beats odometry, with no numbers.",
    "Real logs: obstacle cells per 100 returns of the maps drawn from the SLAM and the odometry paths.",
)


def ours_vs_source(sim: SimSlamResult, *, example: ExampleLineResult | None = None,
                   exact: SimSlamResult | None = None, variants=(), two_lines_error: float | None = None,
                   real=()) -> str:
    """The notebook's closing table: 004's statements (§Hough SLAM, Fig. 5-11) and 000 §1.3.2's odometry
    figures beside ours, computed from the runs' results.

    ``variants``: ``(label, SimSlamResult)`` pairs (e.g. 004's two-line pose, no refit);
    ``two_lines_error``: :func:`check_pose_from_two_lines`'s result; ``real``: :class:`RealLogResult` objects.

    Parameters
    ----------
    sim : SimSlamResult
        From :func:`run_sim_slam` (the noisy run).
    example : ExampleLineResult, optional
        From :func:`run_example_line`.
    exact : SimSlamResult, optional
        A run without range noise.
    variants : sequence of (str, SimSlamResult)
        Labelled variant runs.
    two_lines_error : float, optional
        :func:`check_pose_from_two_lines`'s result.
    real : sequence of RealLogResult
        Real-log runs.

    Returns
    -------
    str
        The table: 004's statement, ours.
    """
    if not isinstance(sim, SimSlamResult):
        raise TypeError(f"`sim` must be a SimSlamResult; got {type(sim).__name__}")

    def maxima(r):
        e = r.errors["Hough SLAM"]
        return (f"{np.abs(e[:, 0]).max():.2f} / {np.abs(e[:, 1]).max():.2f} cell, "
                f"{np.degrees(np.abs(e[:, 2]).max()):.2f}°")

    below = "≪ 1 cell, ≪ 1°"  # 004 Fig. 10: "orders of magnitude below the resolution" (1 cell, 1°)
    rows = []
    if example is not None:
        rows += [["example line: accumulator polar / classic", "180×33 / 180×93",
                  (f"{example.polar_size[0]}×{example.polar_size[1]} / "
                  f"{example.classic_size[0]}×{example.classic_size[1]}")],
                 ["example line found (rho, θ°), polar", "(10, 45)",
                  f"({example.polar_line[0]:.1f}, {example.polar_line[1]:.1f})"]]
    if two_lines_error is not None:
        rows.append(["pose from two lines: largest error", "formula lost, reconstructed",
                     "< 1e-12 (rounding)" if two_lines_error < 1e-12 else f"{two_lines_error:.1e}"])
    if exact is not None:
        rows.append([f"Fig. 10 errors, range σ = {exact.range_std_cells:g}", below, maxima(exact)])
    rows.append([f"Fig. 10 errors, range σ = {sim.range_std_cells:g}", below, maxima(sim)])
    for label, r in variants:
        rows.append([f"Fig. 10 errors, {label}", below, f"{maxima(r)}; {int(r.slam.lost.sum())} lost"])
    agree = map_agreement(sim.built_map, sim.reference_map)
    rows.append(["Fig. 11 map: cells on a true obstacle (±1 cell)", "every shape kept", f"{agree['precision']:.0%}"])
    for k, e in ((k, e[-1]) for k, e in sim.errors.items()):
        rows.append([f"final error, {k}", "better than odometry" if k == "Hough SLAM" else "",
                     f"{math.hypot(e[0], e[1]):.2f} cell, {math.degrees(abs(e[2])):.2f}°"])
    n = {k: x * sim.odometry_noise for k, x in ODOMETRY_NOISE.items()}
    rows += [["odometry translation noise (000 §1.3.2)", "≤ 2 cm per m: 2 %",
              f"{100 * n['trans_std_frac']:g} % of each step (σ)"],
             ["odometry turn error (000 §1.3.2)", "≤ 2° per 45° of turn: 4.4 %",
              f"σ {math.degrees(n['rot_std_rad']):.2f}°/step + {math.degrees(n['drift_rad_per_cell']):.2f}°/cell"]]
    for r in real:
        rows.append([f"{r.name.split(' log ')[1].split(' ')[0]}: cells per 100 returns", "no real data",
                     f"{r.sharpness('slam'):.1f} / {r.sharpness('odometry'):.1f} (SLAM / odometry)"])
    return format_table(["quantity", "source", "ours"], rows,
                        title="Ours vs the source (004 §Hough SLAM; 000 §1.3.2)") + "\n" + "\n".join(_SOURCE_NOTES)
