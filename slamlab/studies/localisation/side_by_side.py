"""MCL and chapter 06's correlation search (one scan, no prior) on the same final scans of simulated runs.

:mod:`slamlab.studies.localisation` exports its names.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np

from ..._table import format_table
from ..._validate import check_int
from ...geometry import wrap_angle
from ...localisation.mcl import MCLParams
from .experiments import FAIL_DEG, FAIL_POS_CELLS, run_filter, simulate_run

__all__ = []


# --- Ch. 5's correlation method on the same scans -----------------------------------------------------


def _side_task(rng, n_steps: int, delta_alpha_deg: float, params: MCLParams):
    """One run: global MCL with ``params`` over the run that ``rng`` simulates, and Ch. 5's correlation search on
    its last scan."""
    from ...correlation import localise

    run = simulate_run(n_steps, rng=rng)
    r = run_filter(run, rng=rng, params=params)
    t0 = time.perf_counter()
    loc = localise(run.grid, run.scans[-1], delta_alpha_rad=float(np.radians(delta_alpha_deg)))
    t_corr = time.perf_counter() - t0
    true = run.true_poses[-1]
    e = float(np.hypot(*(loc.pose[:2] - true[:2])))
    h = float(np.degrees(abs(wrap_angle(loc.pose[2] - true[2]))))
    return {"mcl_success": bool(r.ok[-1]), "mcl_err": float(r.err_pos[-1]),
            "corr_success": bool(e < FAIL_POS_CELLS and h < FAIL_DEG), "corr_err": e,
            "mcl_time_s": r.time_s, "corr_time_s": t_corr}


@dataclass(frozen=True)
class SideBySideResult:
    """MCL (global, over a run) and Ch. 5's correlation search (one scan, no prior) on the same final scans.

    Parameters
    ----------
    table_df : pandas.DataFrame
        One row per run.
    n_runs, n_steps, n_particles : int
        Runs, MCL steps per run, MCL particles.
    delta_alpha_deg : float
        The correlation search's heading step [deg].
    """

    table_df: object = field(repr=False)
    n_runs: int = 0
    n_steps: int = 0
    n_particles: int = 0
    delta_alpha_deg: float = 5.0

    def table(self) -> str:
        df = self.table_df
        rows = [[f"MCL, {self.n_particles} particles, {self.n_steps} steps from no prior",
                 f"{df['mcl_success'].mean():.2f}", f"{df['mcl_err'].median():.2f}"],
                [f"correlation (Ch. 5), last scan only, Δα = {self.delta_alpha_deg:g}°",
                 f"{df['corr_success'].mean():.2f}", f"{df['corr_err'].median():.2f}"]]
        return format_table(["method", "success", "median err [cells]"], rows,
                            title=f"The same {self.n_runs} runs: pose at the last scan")

    def timing_table(self) -> str:
        df = self.table_df
        rows = [["MCL, whole run", f"{df['mcl_time_s'].median():.3f}"],
                ["correlation, one scan", f"{df['corr_time_s'].median():.3f}"]]
        return format_table(["method", "median s"], rows, title="Time (wall clock)")

    def __str__(self) -> str:
        return f"MCL vs correlation on {self.n_runs} runs"


def run_correlation_side_by_side(*, n_runs: int = 10, n_steps: int = 25, delta_alpha_deg: float = 5.0,
                                 params: MCLParams | None = None, rng=3, n_jobs: int = 1, progress=None,
                                 **overrides) -> SideBySideResult:
    """Global MCL over each run and Ch. 5's correlation localisation of the run's last scan (on sweep; 003 §2.2).

    Parameters
    ----------
    n_runs, n_steps : int
        Runs, and steps per run.
    delta_alpha_deg : float
        The correlation search's heading step.
    params : MCLParams, optional
        Settings of MCL (default: the defaults, 2000 particles).
    rng : int, SeedSequence or Generator
        Where every run's stream is spawned from.
    n_jobs : int
        Parallel workers of :func:`slamlab.sweep.sweep`.
    progress : bool, callable or None
        See :mod:`slamlab._progress`.
    **overrides
        :class:`MCLParams` fields (e.g. ``n_particles``).

    Returns
    -------
    SideBySideResult
    """
    from ...sweep import root_seed_sequence, sweep

    p = MCLParams.resolve(params, **overrides)
    df = sweep(_side_task, None, seeds=check_int(n_runs, "n_runs", minimum=1), rng=root_seed_sequence(rng, "rng"),
               n_jobs=n_jobs, progress=progress, on_error="raise", desc="MCL vs correlation",
               fixed={"n_steps": n_steps, "delta_alpha_deg": delta_alpha_deg, "params": p})
    return SideBySideResult(df, n_runs, n_steps, p.n_particles, float(delta_alpha_deg))


__all__ += ["SideBySideResult", "run_correlation_side_by_side"]
