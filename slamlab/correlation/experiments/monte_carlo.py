"""The full 360° search at many random poses (004 §7, our addition): error distribution and failure rate."""

from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np

from ... import _validate as v
from ..._table import format_table
from ...sim.paths import random_free_poses
from ..algorithm import LocaliseParams
from .common import FAIL_CELLS, FAIL_DEG, _errors, _estimates, _localise_scans, _sensor, _worlds

_SIZES = {"small": 12, "full": 200}


@dataclass(frozen=True)
class MonteCarloResult:
    """Error distribution and failure rate of the full 360° search over many random poses (our addition).

    Attributes
    ----------
    n_poses : int
        Localised poses.
    err_heading_rad : numpy.ndarray, shape (n_poses,)
        Wrapped heading errors [rad].
    err_pos_cells : numpy.ndarray, shape (n_poses,)
        Euclidean position errors [cells].
    failed : numpy.ndarray of bool, shape (n_poses,)
        Position error > 2 cells or heading error > 5°.
    range_std_cells : float
        Range noise std [cells].
    extra_clutter : int
        Random discs added to 004's clutter.
    time_s : float
        Wall time of the localisations [s] (not compared).
    """

    n_poses: int
    err_heading_rad: np.ndarray
    err_pos_cells: np.ndarray  # Euclidean position error
    failed: np.ndarray  # bool
    range_std_cells: float
    extra_clutter: int
    time_s: float = field(default=0.0, compare=False)

    @property
    def failure_rate(self) -> float:
        """Fraction of poses with position error > 2 cells or heading error > 5°."""
        return float(self.failed.mean())

    def __str__(self) -> str:
        return (f"Monte Carlo, {self.n_poses} poses: failure rate {self.failure_rate:.1%}, "
                f"exact position {np.mean(self.err_pos_cells == 0):.0%}")

    def table(self) -> str:
        """Error distribution table (exact, ≤ 1 cell, heading percentiles, failures).

        Returns
        -------
        str
        """
        ok = ~self.failed
        ea = np.degrees(self.err_heading_rad[ok]) if ok.any() else np.array([np.nan])
        ep = self.err_pos_cells
        rows = [
            ["poses", f"{self.n_poses}"],
            ["position exact (0 cells)", f"{np.mean(ep == 0):.1%}"],
            ["position error <= 1 cell", f"{np.mean(ep <= 1.0):.1%}"],
            ["position error <= 1.5 cells (incl. diagonal)", f"{np.mean(ep <= 1.5):.1%}"],
            ["heading error <= 0.5° (half the step)", f"{np.mean(np.degrees(self.err_heading_rad) <= 0.5):.1%}"],
            ["heading error <= 1°", f"{np.mean(np.degrees(self.err_heading_rad) <= 1.0):.1%}"],
            ["heading error median / 95 % / max, successes [deg]",
             f"{np.median(ea):.2f} / {np.percentile(ea, 95):.2f} / {ea.max():.2f}"],
            ["failures (> 2 cells or > 5°)", f"{self.failed.sum()} ({self.failure_rate:.1%})"],
        ]
        title = (f"Range σ = {self.range_std_cells:g} cell, clutter of 004 Fig. 3b"
                 + (f" + {self.extra_clutter} extra discs" if self.extra_clutter else ""))
        return format_table(["quantity", "value"], rows, title=title)


def run_monte_carlo(size: str | int = "small", *, range_std_cells: float = 0.3, n_beams: int = 360,
                    max_range_cells: float = 100.0, extra_clutter: int = 0, params: LocaliseParams | None = None,
                    rng=2011, n_jobs: int = 1, progress: bool | None = None, **overrides) -> MonteCarloResult:
    """Full 360° localisation at many random poses: error distribution and failure rate (our addition).

    ``size``: ``"small"`` (12 poses, the notebook), ``"full"`` (200) or an int.
    ``params`` / ``**overrides``: the :class:`LocaliseParams` of every localisation.

    The random part (clutter, poses, then one scan per pose, in that order from ``rng``)
    runs here; the localisations, which draw nothing, run on :func:`slamlab.sweep.sweep`
    with ``n_jobs`` workers (one task per pose; the result is the same for any ``n_jobs``)
    and a progress bar unless ``progress=False`` or ``$SLAMLAB_PROGRESS=0``.

    Parameters
    ----------
    size : {"small", "full"} or int
        Number of poses: "small" 12, "full" 200, or the int itself.
    range_std_cells : float, default 0.3
        Range noise std [cells].
    n_beams : int, default 360
        Beams over 360°.
    max_range_cells : float, default 100.0
        Range limit [cells].
    extra_clutter : int, default 0
        Random unmapped discs added (:func:`random_clutter`).
    params : LocaliseParams, optional
        Settings of every localisation (default :class:`LocaliseParams`).
    rng : int or numpy.random.Generator, default 2011
        Seed or generator of clutter, poses and scan noise.
    n_jobs : int, default 1
        Worker processes for the localisations (same result for any value).
    progress : bool or None
        Progress bar: None shows one in a notebook only.
    **overrides
        :class:`LocaliseParams` fields to change.

    Returns
    -------
    MonteCarloResult
    """
    p = LocaliseParams.resolve(params, **overrides)
    n = _SIZES[v.check_choice(size, "size", _SIZES)] if isinstance(size, str) else v.check_int(size, "size",
                                                                                                 minimum=1)
    ec = v.check_int(extra_clutter, "extra_clutter", minimum=0)
    rf = _sensor(n_beams, max_range_cells, range_std_cells)
    rng = v.as_rng(rng)
    M, W = _worlds(True, ec, rng)
    poses = random_free_poses(W, n, margin_cells=2, rng=rng)
    scans = [rf.scan(W, pose, rng) for pose in poses]  # every draw here, in the order of the sequential loop
    t0 = time.perf_counter()
    est = _estimates(_localise_scans(M, scans, (p,), n_jobs=n_jobs, progress=progress))
    ea, ex, ey = _errors(poses, est)
    ep = np.hypot(ex, ey)
    failed = (ep > FAIL_CELLS) | (np.degrees(ea) > FAIL_DEG)
    return MonteCarloResult(n, ea, ep, failed, float(range_std_cells), ec, time.perf_counter() - t0)
