"""The simulated runs of Ch. 8 (003 §2.2) and the experiments on them that are not studies of MCL's settings:
Markov grid vs MCL, the correlation method side by side, AMCL's defaults, "Ours vs the source", the recorded demo.
The MCL studies are in :mod:`~slamlab.studies.localisation.studies`, the Markov studies in
:mod:`~slamlab.studies.localisation.markov_study`, the real logs in :mod:`~slamlab.studies.localisation.logs`.

Simulation: 004's test room (the Ch. 5/6 simulator), a rangefinder of 60 beams over
360° (range limit 100 cells, σ = 0.5 cell, 0.1-cell quantisation), 004's path, and
odometry with 5 % translation noise and 0.01 rad heading noise per step (ours: 003
gives none). Success at a step: position error < 3 cells and heading error < 5° (ours). Every Monte Carlo study runs on :func:`slamlab.sweep.sweep` with one
seeded stream per run.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np

from ..._table import format_table
from ..._validate import as_rng, check_choice, check_int
from ...geometry import se2_integrate, se2_relative, wrap_angle
from ...localisation.markov import MarkovGrid, MarkovParams
from ...localisation.mcl import MCL, MCLParams
from ...localisation.particles import FAIL_DEG, FAIL_POS_CELLS, uniform_free_particles
from ...scans import Scan, cast_rays
from ...sim.grid import measurement_room_200, test_room_200
from ...sim.paths import path_004
from ...sim.rangefinder import Rangefinder, simulate_odometry
from ._tables import table
from .amcl_tables import AMCL_DEFAULTS, amcl_defaults_table, ours_vs_source

__all__ = [
    "AMCL_DEFAULTS",
    "FAIL_DEG",
    "FAIL_POS_CELLS",
    "FilterRun",
    "MarkovVsMclResult",
    "SimRun",
    "amcl_defaults_table",
    "ours_vs_source",
    "run_filter",
    "run_markov_vs_mcl",
    "simulate_run",
]

#: The simulated sensor's range limit (cells).
MAX_RANGE = 100.0


@dataclass(frozen=True)
class SimRun:
    """One simulated run in the test room: true poses, odometry poses, scans, the kidnap step (or None).

    Parameters
    ----------
    grid : ndarray, shape (H, W)
        The map the filters use.
    true_poses, odom_poses : ndarray, shape (n, 3)
        True poses and the noisy odometry (cells, rad).
    scans : list of Scan
        One scan per step, in cells.
    kidnap_step : int or None
        The step the robot is carried away before (None: no kidnap).
    max_range : float
        The rangefinder's maximum range (cells).
    start : int
        Index of the first pose on 004's path.
    """

    grid: np.ndarray = field(repr=False)
    true_poses: np.ndarray = field(repr=False)  # (n, 3)
    odom_poses: np.ndarray = field(repr=False)  # (n, 3)
    scans: list = field(repr=False)
    kidnap_step: int | None = None
    max_range: float = MAX_RANGE
    start: int = 0  # index of the first pose on 004's path

    @property
    def n_steps(self) -> int:
        """Number of poses (= scans)."""
        return int(self.true_poses.shape[0])


def simulate_run(n_steps: int = 40, start: int | None = None, *, kidnap_step: int | None = None,
                 kidnap_to: int | None = None, n_beams: int = 60, range_std_cells: float = 0.5,
                 odo_trans_frac: float = 0.05, odo_rot_std_rad: float = 0.01, world: str = "map",
                 rng=None) -> SimRun:
    """A run along 004's path in the test room: ``n_steps`` poses from pose ``start`` (random when None).

    With ``kidnap_step = k`` the robot is carried, between steps ``k−1`` and ``k``, to pose
    ``kidnap_to`` of the path (random, at least 40 poses away, when None); the odometry
    reports an ordinary step there. Noise: Gaussian range noise, odometry noise per step. ``world``:
    "map" (the scans see the map itself) or "cluttered" (they see 004's room with its unmapped clutter,
    :func:`slamlab.sim.measurement_room_200`, while the filter keeps the map).

    Parameters
    ----------
    n_steps : int
        Poses of the run.
    start : int, optional
        Index of the first pose on 004's path (random when None).
    kidnap_step : int, optional
        The step the robot is carried away before (None: no kidnap).
    kidnap_to : int, optional
        The path pose it is carried to (random, at least 40 poses away, when None).
    n_beams : int
        Beams per scan.
    range_std_cells : float
        σ of the range noise (cells).
    odo_trans_frac, odo_rot_std_rad : float
        Odometry noise: share of each step's length, radians per step.
    world : {"map", "cluttered"}
        What the scans see.
    rng : Generator, int or None
        Random source.

    Returns
    -------
    SimRun
    """
    check_choice(world, "world", ("map", "cluttered"))
    rng = as_rng(rng)
    n = check_int(n_steps, "n_steps", minimum=2)
    P = path_004(121)
    n_path = P.shape[0]
    if n > n_path:
        raise ValueError(f"`n_steps` must be <= {n_path} (004's path); got {n}")
    s0 = int(rng.integers(0, n_path - n + 1)) if start is None else check_int(start, "start", minimum=0,
                                                                                 maximum=n_path - n)
    idx = np.arange(s0, s0 + n)
    if kidnap_step is not None:
        k = check_int(kidnap_step, "kidnap_step", minimum=1, maximum=n - 1)
        rest = n - k
        if kidnap_to is None:
            far = [j for j in range(n_path - rest + 1) if abs(j - idx[k]) >= 40]
            kidnap_to = int(far[int(rng.integers(0, len(far)))])
        j0 = check_int(kidnap_to, "kidnap_to", minimum=0, maximum=n_path - rest)
        idx = np.concatenate([idx[:k], np.arange(j0, j0 + rest)])
    true = P[idx]
    inc = se2_relative(true[:-1], true[1:])
    if kidnap_step is not None:
        inc[kidnap_step - 1] = se2_relative(P[s0 + kidnap_step - 1], P[s0 + kidnap_step]) \
            if s0 + kidnap_step < n_path else np.zeros(3)
    believed = se2_integrate(true[0], inc)  # what perfect odometry would report
    odo = simulate_odometry(believed, trans_std_frac=odo_trans_frac, rot_std_rad=odo_rot_std_rad, rng=rng).poses
    M = test_room_200()
    rf = Rangefinder(n_beams=n_beams, max_range_cells=MAX_RANGE, range_std_cells=range_std_cells)
    W = M if world == "map" else measurement_room_200()
    # the rangefinder's exact traversal for every pose at once (slamlab.scans.cast_rays), then
    # its noise pose by pose in order (the same draws as Rangefinder.scan)
    ang = rf.angles_rad
    Z = cast_rays(W, true, ang, MAX_RANGE)[0]
    scans = []
    for z, p in zip(Z, true, strict=True):
        hit = z < MAX_RANGE
        scans.append(Scan(ang, rf.measure(z, hit, rng), hit, unit="cell", max_range=MAX_RANGE, pose=p))
    return SimRun(M, true, odo, scans, kidnap_step, start=s0)


@dataclass(frozen=True)
class FilterRun:
    """A filter run along a :class:`SimRun`: estimates, errors, the step records (MCL) and the time.

    Parameters
    ----------
    est : ndarray, shape (n, 3)
        Estimates (cells, rad).
    err_pos : ndarray, shape (n,)
        Position errors (cells).
    err_heading_rad : ndarray, shape (n,)
        Heading errors (rad).
    records : list of StepRecord
        MCL's step records (empty for the Markov grid).
    snapshots : list
        Weighted particle sets per step (when kept).
    time_s : float
        Wall time of the run.
    """

    est: np.ndarray = field(repr=False)  # (n, 3)
    err_pos: np.ndarray = field(repr=False)  # (n,) cells
    err_heading_rad: np.ndarray = field(repr=False)
    records: list = field(repr=False)
    snapshots: list = field(repr=False)
    time_s: float = field(default=0.0, compare=False)

    @property
    def ok(self) -> np.ndarray:
        """Within 3 cells and 5° at each step."""
        return (self.err_pos < FAIL_POS_CELLS) & (np.degrees(self.err_heading_rad) < FAIL_DEG)

    def converged_at(self, after: int = 0) -> int | None:
        """First step (≥ ``after``) from which the estimate stays within the bounds to the end; None if never.

        Parameters
        ----------
        after : int
            First step to consider.

        Returns
        -------
        int or None
        """
        ok = self.ok
        bad = np.flatnonzero(~ok[after:])
        if bad.size == 0:
            return after
        k = after + int(bad[-1]) + 1
        return k if k < ok.size else None


def run_filter(run: SimRun, *, method: str = "mcl", init: str = "global", params: MCLParams | MarkovParams | None = None, rng=None,
               keep_particles: bool = False, **overrides) -> FilterRun:
    """Run MCL (``method="mcl"``) or the Markov grid (``"markov"``) along ``run`` from no prior
    (``init="global"``) or from the true start (``"tracking"``, MCL only).

    Parameters
    ----------
    run : SimRun
        The simulated run.
    method : {"mcl", "markov"}
        The filter.
    init : {"global", "tracking"}
        No prior, or the true start (MCL only).
    params : MCLParams or MarkovParams, optional
        The filter's settings.
    rng : Generator, int or None
        Random source (MCL).
    keep_particles : bool
        Keep MCL's weighted set of every step.
    **overrides
        Fields of the filter's params.

    Returns
    -------
    FilterRun
    """
    check_choice(method, "method", ("mcl", "markov"))
    check_choice(init, "init", ("global", "tracking"))
    rng = as_rng(rng)
    t0 = time.perf_counter()
    est = np.empty((run.n_steps, 3))
    if method == "mcl":
        kw = {} if init == "global" else {"init_pose": run.true_poses[0], "init_std": (1.0, 1.0, 0.05)}
        f = MCL(run.grid, run.max_range, params=params, rng=rng, keep_particles=keep_particles, **kw, **overrides)
        for k in range(run.n_steps):
            prev, now = (run.odom_poses[k - 1], run.odom_poses[k]) if k else (None, None)
            est[k] = f.step(prev, now, run.scans[k]).mean
        records, snaps = f.records, f.snapshots
    else:
        if init != "global":
            raise ValueError("the Markov grid runs from the uniform prior here (`init` must be 'global')")
        g = MarkovGrid(run.grid, run.max_range, params=params, **overrides)
        for k in range(run.n_steps):
            prev, now = (run.odom_poses[k - 1], run.odom_poses[k]) if k else (None, None)
            est[k] = g.step(prev, now, run.scans[k])
        records, snaps = [g.nbytes], []
    dt = time.perf_counter() - t0
    e = np.hypot(*(est[:, :2] - run.true_poses[:, :2]).T)
    eh = np.abs(wrap_angle(est[:, 2] - run.true_poses[:, 2]))
    return FilterRun(est, e, eh, records, snaps, dt)


# --- Markov grid vs MCL -------------------------------------------------------------------------------


def _compare_task(method: str, rng, n_steps: int, params: MCLParams, variant: str = "", n_particles: int = 0,
                  resolution: int = 0, n_headings: int = 0):
    """One run of :func:`run_markov_vs_mcl`: a Markov grid (``resolution``, ``n_headings``) or MCL (``params`` with
    ``n_particles``) on the run that ``rng`` simulates."""
    run = simulate_run(n_steps, rng=rng)
    if method == "markov":
        r = run_filter(run, method="markov", resolution=resolution, n_headings=n_headings)
        mem = r.records[0]
    else:
        r = run_filter(run, rng=rng, params=params.replace(n_particles=n_particles))
        mem = n_particles * 4 * 8  # particles (x, y, θ) and weights, float64
    return {"start_x": float(run.true_poses[0, 0]), "start_y": float(run.true_poses[0, 1]),
            "success": bool(r.ok[-1]), "final_err_cells": float(r.err_pos[-1]),
            "final_err_deg": float(np.degrees(r.err_heading_rad[-1])), "memory_bytes": int(mem),
            "time_per_step_s": r.time_s / run.n_steps}


@dataclass(frozen=True)
class MarkovVsMclResult:
    """Markov grid vs MCL on the same runs: accuracy, memory and time.

    Parameters
    ----------
    table_df : pandas.DataFrame
        One row per (variant, run): ``method``, ``variant`` (the label), the grid's ``resolution`` and
        ``n_headings`` or MCL's ``n_particles``, the run's results.
    n_runs, n_steps : int
        Runs per method, steps per run.
    """

    table_df: object = field(repr=False)
    n_runs: int = 0
    n_steps: int = 0

    def _groups(self):
        return self.table_df.groupby("variant", sort=False)

    def table(self) -> str:
        rows = [[label, f"{g['memory_bytes'].iloc[0] // 8}" if (g["method"] == "markov").all() else "-",
                 f"{g['success'].mean():.2f}", f"{g['final_err_cells'].median():.2f}",
                 f"{g['final_err_deg'].median():.1f}", f"{g['memory_bytes'].iloc[0] / 2**20:.2f}"]
                for label, g in self._groups()]
        return table(["method", "belief cells", "success", "median err [cells]", "median err [°]", "memory [MiB]"],
                     rows, title=f"Markov grid vs MCL: the same {self.n_runs} runs of {self.n_steps} steps, global start",
                     notes=[(f"belief cells: the grid's (x, y, θ) cells, one float64 each; success: share of runs "
                            f"within {FAIL_POS_CELLS:g} cells and {FAIL_DEG:g}° at the last step; median err: at the "
                            f"last step")])

    def timing_table(self) -> str:
        rows = [[label, f"{1e3 * g['time_per_step_s'].median():.1f}"] for label, g in self._groups()]
        return format_table(["method", "median ms per step"], rows, title="Time per step (wall clock)")

    def __str__(self) -> str:
        return f"Markov grid vs MCL, {self.n_runs} runs"


def run_markov_vs_mcl(markov=((4, 36), (2, 72)), particle_counts=(1000, 4000), *, n_runs: int = 5,
                      n_steps: int = 30, params: MCLParams | None = None, rng=2, n_jobs: int = 1,
                      progress=None, **overrides) -> MarkovVsMclResult:
    """Markov grids (belief cell size in map cells, headings) and MCL (particle counts) on the same seeded
    runs (every method's run ``i`` uses the same stream, so the same path, scans and odometry).

    The study varies the particle count itself (one MCL run per count of ``particle_counts``): ``params`` and the
    overrides must leave ``n_particles`` at its default (a ``ValueError`` names it otherwise).

    Parameters
    ----------
    markov : sequence of (int, int)
        Markov grids: (belief cell size in map cells, number of headings), each with the other
        :class:`~slamlab.localisation.markov.MarkovParams` at their defaults.
    particle_counts : sequence of int
        MCL particle counts, one variant each (the study's own axis: not ``params.n_particles``).
    n_runs, n_steps : int
        Runs per method and steps per run.
    params : MCLParams, optional
        Settings of the MCL runs (default: the defaults), but for ``n_particles``.
    rng : int, SeedSequence or Generator
        Where every run's stream is spawned from (run ``i`` the same for every method).
    n_jobs : int
        Parallel workers of :func:`slamlab.sweep.sweep`.
    progress : bool, callable or None
        See :mod:`slamlab._progress`.
    **overrides
        :class:`MCLParams` fields for the MCL runs.

    Returns
    -------
    MarkovVsMclResult
    """
    import pandas as pd

    from ..._params import refuse_set_fields
    from ...sweep import fresh_seed_sequence, sweep

    p = MCLParams.resolve(params, **overrides)
    refuse_set_fields(p, ["n_particles"], "one MCL run per count of `particle_counts`")
    pts = [{"method": "markov", "variant": f"Markov, {int(s)}-cell grid, {int(h)} headings", "resolution": int(s),
            "n_headings": int(h)} for s, h in markov]
    pts += [{"method": "mcl", "variant": f"MCL, {int(n_particles)} particles",
             "n_particles": check_int(n_particles, "particle_counts[]", minimum=1)} for n_particles in particle_counts]
    n_runs = check_int(n_runs, "n_runs", minimum=1)
    # one stream per run index, shared by all methods: one sweep per method from a fresh copy of the same
    # SeedSequence (spawn() is stateful: the same object would give each sweep the next children)
    frames = [sweep(_compare_task, [pt], seeds=n_runs, rng=fresh_seed_sequence(rng), n_jobs=n_jobs,
                    progress=progress, fixed={"n_steps": n_steps, "params": p}, on_error="raise",
                    desc="Markov grid vs MCL") for pt in pts]
    df = pd.concat(frames, ignore_index=True)
    return MarkovVsMclResult(df, n_runs, n_steps)


def demo_run(*, kidnap_step: int | None = 25, n_steps: int = 60, params: MCLParams | None = None, rng=7,
             **overrides):
    """One recorded global run (with an optional kidnap) for the plots and the time slider (003 §2.2).

    Parameters
    ----------
    kidnap_step : int or None
        Step at which the robot is carried elsewhere (None: no kidnap).
    n_steps : int
        Steps of the run.
    params : MCLParams, optional
        Settings of MCL (default: the defaults, 2000 particles).
    rng : int, SeedSequence or Generator
        The one stream of the simulated run and then of the filter.
    **overrides
        :class:`MCLParams` fields (e.g. ``n_particles=5000``).

    Returns
    -------
    (SimRun, FilterRun)
        The simulated run and the recorded filter run.
    """
    p = MCLParams.resolve(params, **overrides)
    rng = as_rng(rng)
    run = simulate_run(n_steps, start=0, kidnap_step=kidnap_step, rng=rng)
    return run, run_filter(run, params=p, rng=rng, keep_particles=True)


__all__ += ["demo_run", "uniform_free_particles"]
