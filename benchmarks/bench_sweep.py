"""Benchmark slamlab.sweep: the cost per task on a trivial function, and a real Monte Carlo on 1 and 2 workers.

Every case runs the same sweep with n_jobs = 1 and n_jobs = 2 (joblib/loky) in this process, checks
the two tables are identical, and prints the wall times and their ratio. The real case is notebook 06's
Monte Carlo at size "full": 200 full 360° correlation localisations (one sweep task each; the
scans are drawn in the parent), run once per worker count (about a minute in all on 2 cores).

    python benchmarks/bench_sweep.py
"""

from __future__ import annotations

import os
import platform
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "tests"))

from sweep_tasks import noisy

from slamlab.sweep import sweep


def wall(fn, repeat=3):
    """Best wall time over ``repeat`` runs, and the last result."""
    best, out = float("inf"), None
    for _ in range(repeat):
        t0 = time.perf_counter()
        out = fn()
        best = min(best, time.perf_counter() - t0)
    return best, out


def overhead(n_tasks: int = 400) -> None:
    grid = {"scale": [float(s) for s in range(n_tasks)]}
    t1, a = wall(lambda: sweep(noisy, grid, rng=1, progress=False))
    sweep(noisy, {"scale": [1.0, 2.0]}, rng=1, n_jobs=2, progress=False)  # start the loky workers once
    t2, b = wall(lambda: sweep(noisy, grid, rng=1, n_jobs=2, progress=False))
    assert a.equals(b), "tables differ between 1 and 2 workers"
    print(f"trivial task x {n_tasks}: 1 worker {t1 * 1e6 / n_tasks:.0f} us/task, "
          f"2 workers {t2 * 1e6 / n_tasks:.0f} us/task (tables identical)")


def correlation_monte_carlo(size: str = "full") -> None:
    import numpy as np

    from slamlab.studies.correlation import run_monte_carlo

    t1, a = wall(lambda: run_monte_carlo(size, n_jobs=1, progress=False), repeat=1)
    t2, b = wall(lambda: run_monte_carlo(size, n_jobs=2, progress=False), repeat=1)
    same = (a.table() == b.table() and all(np.array_equal(getattr(a, f), getattr(b, f))
                                            for f in ("err_heading_rad", "err_pos_cells", "failed")))
    assert same, "Monte Carlo results differ between 1 and 2 workers"
    print(f"correlation Monte Carlo, {a.n_poses} poses: 1 worker {t1:.1f} s, 2 workers {t2:.1f} s, "
          f"ratio {t1 / t2:.2f}x (goal >= 1.7x; results identical)")


def main() -> None:
    print(f"{platform.processor() or platform.machine()}, {os.cpu_count()} cores, "
          f"load average {os.getloadavg()[0]:.2f}")
    overhead()
    correlation_monte_carlo()
    print(f"load average at the end {os.getloadavg()[0]:.2f}")


if __name__ == "__main__":
    main()
