"""What the ch. 1 experiment families share (000 §1.2): the filter names, the divergence threshold, the Monte Carlo loop."""

from __future__ import annotations

import numpy as np

FILTER_NAMES = ("LKF", "EKF", "UKF-aug", "UKF-add")
DIVERGED_RMSE_M = 2.0  # a run whose position RMSE exceeds this has lost track


def _nanmean(a) -> float:
    """Mean over the finite entries; NaN (without a warning) when there are none."""
    a = np.asarray(a, dtype=float)
    ok = np.isfinite(a)
    return float(a[ok].mean()) if ok.any() else float("nan")



def _monte_carlo(run, n_runs: int, rng, n_jobs: int, progress, **fixed):
    """``n_runs`` seeded runs of ``run`` on :func:`slamlab.sweep.sweep` (run r draws from child r of ``rng``)."""
    from ...sweep import root_seed_sequence, sweep

    table = sweep(run, None, seeds=n_runs, seed=root_seed_sequence(rng, "rng"), n_jobs=n_jobs, progress=progress, fixed=fixed,
                  on_error="raise", desc=f"Monte Carlo ({run.__name__.strip('_').replace('_', ' ')})")
    return table
