"""004's advice on the size of T_n, measured (004 §7): trim the stamp when the longest beam is far longer than most.

004 sizes every stamp T_n by the longest range, ``S = 2(l_max + 2)``, and advises: when ``l_max`` greatly exceeds the
mean distance to the surrounding objects, most of T_n stays filled with ``a_n`` and takes no part in the result,
while C_n and the work grow; so adjust the size of T_n. 004 gives no rule. :func:`run_stamp_trim_study` applies one
(ours): keep the returns up to a quantile of the scan's ranges, drop the longer ones (the stamp then shrinks to the
longest kept beam), and localise the same random poses of Table 1's room with each quantile.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np

from ..._table import format_table
from ..._validate import as_finite_array, as_rng, check_int, check_positive
from ...correlation.algorithm import LocaliseParams, heading_candidates, localise, scan_stamps
from ...scans import Scan
from ...sim.paths import random_free_poses
from ...sim.grid import measurement_room_200, test_room_200
from ...sim.rangefinder import Rangefinder
from .studies import FAIL_CELLS, FAIL_DEG, absolute_errors, within_tolerance

__all__ = ["StampTrimResult", "run_stamp_trim_study", "trim_scan"]


def trim_scan(scan: Scan, quantile: float) -> Scan:
    """The scan with its returns beyond the ``quantile`` of its ranges marked as no return (ours; 004 §7's advice).

    Parameters
    ----------
    scan : Scan
        Any scan.
    quantile : float
        In (0, 1]; 1 keeps every return.

    Returns
    -------
    Scan
        The same beams; ``valid`` is False beyond the quantile.

    Examples
    --------
    >>> s = Scan([0.0, 1.0, 2.0, 3.0], [1.0, 2.0, 3.0, 40.0], [True] * 4, unit="cell")
    >>> trim_scan(s, 0.75).valid.tolist()
    [True, True, True, False]
    """
    if not isinstance(scan, Scan):
        raise TypeError(f"`scan` must be a Scan; got {type(scan).__name__}")
    q = check_positive(quantile, "quantile")
    if q > 1:
        raise ValueError(f"`quantile` must lie in (0, 1]; got {q}")
    if q == 1 or not scan.valid.any():
        return scan
    limit = np.quantile(scan.ranges[scan.valid], q, method="inverted_cdf")
    keep = scan.valid & (scan.ranges <= limit)
    return Scan(scan.bearings_rad, scan.ranges, keep, unit=scan.unit, max_range=scan.max_range, time_s=scan.time_s,
                odom_pose=scan.odom_pose, pose=scan.pose)


@dataclass(frozen=True)
class StampTrimResult:
    """Localisation of the same poses with the scans trimmed to quantiles of their ranges (004 §7's advice; ours).

    Attributes
    ----------
    quantiles : numpy.ndarray, shape (q,)
        Share of each scan's returns kept (the shortest ones).
    true_poses : numpy.ndarray, shape (n, 3)
        The random free poses ``(x, y)`` [cells], heading [rad].
    err_pos_cells, err_heading_rad : numpy.ndarray, shape (q, n)
        Position [cells] and wrapped heading [rad] errors.
    stamp_side : numpy.ndarray of int, shape (q, n)
        Side ``S`` of the stamps T_n of each scan [cells].
    cpu_s : numpy.ndarray, shape (q,)
        Median CPU time of one localisation [s] (not compared; :meth:`timing` prints it).
    params : LocaliseParams
        Settings of the localisations.
    """

    quantiles: np.ndarray
    true_poses: np.ndarray
    err_pos_cells: np.ndarray
    err_heading_rad: np.ndarray
    stamp_side: np.ndarray
    cpu_s: np.ndarray = field(compare=False, repr=False)
    params: LocaliseParams = field(default_factory=LocaliseParams, repr=False)

    @property
    def success(self) -> np.ndarray:
        """``(q, n)``: within 2 cells and 5° of the true pose."""
        return within_tolerance(self.err_pos_cells, self.err_heading_rad)

    def table(self) -> str:
        """One row per quantile: the median stamp side and its cells against the untrimmed, the poses localised and the
        largest errors among them.

        Returns
        -------
        str
        """
        side = np.median(self.stamp_side, axis=1)
        rows = []
        for j, q in enumerate(self.quantiles):
            ok = self.success[j]
            rows.append([f"{q:g}", f"{side[j]:.0f}", f"{(side[j] / side[0]) ** 2:.2f}", f"{ok.sum()}/{ok.size}",
                         f"{self.err_pos_cells[j][ok].max():.1f}" if ok.any() else "-",
                         f"{np.degrees(self.err_heading_rad[j][ok]).max():.2f}" if ok.any() else "-"])
        return format_table(["returns kept", "median side S [cells]", "cells vs first row", "localised",
                             "max err [cells]", "max err [°]"], rows,
                            title=(f"T_n trimmed: the same {self.true_poses.shape[0]} random poses of Table 1's room, "
                                   f"returns up to a quantile of each scan's ranges;\nlocalised = within "
                                   f"{FAIL_CELLS:g} cells and {FAIL_DEG:g}°; max err among the localised"))

    def timing(self) -> str:
        """The median CPU time per localisation of each quantile, as a timing line (volatile).

        Returns
        -------
        str
        """
        return "; ".join(f"returns kept {q:g}: took {t:.3f} s" for q, t in zip(self.quantiles, self.cpu_s,
                                                                              strict=True))


def _timed(M, scan, p):
    """One localisation (no rival search) and its CPU time."""
    t0 = time.process_time()
    loc = localise(M, scan, params=p)
    return time.process_time() - t0, loc.pose


def run_stamp_trim_study(quantiles=(1.0, 0.75, 0.5), n_poses: int = 6, *, range_std_cells: float = 0.3,
                         n_beams: int = 360, max_range_cells: float = 100.0, params: LocaliseParams | None = None,
                         rng=2010, **overrides) -> StampTrimResult:
    """Localise the same random poses with scans trimmed to quantiles of their ranges (004 §7's advice; ours).

    Table 1's set-up (:func:`~slamlab.studies.correlation.run_table1`: unmapped clutter, Gaussian range noise,
    0.1-cell rounding, the full 360° search, no rival search); each scan trimmed by :func:`trim_scan`. Runs in this
    process, one localisation at a time, so that the CPU times compare.

    Parameters
    ----------
    quantiles : sequence of float, default (1, 0.75, 0.5)
        Shares of each scan's returns kept, each in (0, 1]; the first row is the reference of the cell ratio.
    n_poses : int, default 6
        Random free poses.
    range_std_cells, n_beams, max_range_cells
        The rangefinder, as in :func:`~slamlab.studies.correlation.run_table1`.
    params : LocaliseParams, optional
        Settings of every localisation (the rival search off).
    rng : int or numpy.random.Generator, default 2010
        Seed or generator of the poses and the scans' noise.
    **overrides
        :class:`LocaliseParams` fields to change.

    Returns
    -------
    StampTrimResult
    """
    p = LocaliseParams.resolve(params, **overrides).replace(ambiguity=False)
    qs = as_finite_array(quantiles, "quantiles")
    if qs.ndim != 1 or qs.size == 0 or np.any(qs <= 0) or np.any(qs > 1):
        raise ValueError(f"`quantiles` must be a non-empty list of shares in (0, 1]; got {quantiles!r}")
    n = check_int(n_poses, "n_poses", minimum=1)
    rf = Rangefinder(n_beams=n_beams, max_range_cells=max_range_cells, range_std_cells=range_std_cells)
    rng = as_rng(rng)
    M, W = test_room_200(), measurement_room_200()
    poses = random_free_poses(W, n, margin_cells=2, rng=rng)
    scans = [rf.scan(W, q, rng) for q in poses]
    heads = heading_candidates(p.delta_alpha_rad)
    est = np.empty((qs.size, n, 3))
    side = np.empty((qs.size, n), dtype=int)
    cpu = np.empty((qs.size, n))
    for j, q in enumerate(qs):
        for i, s in enumerate(scans):
            t = trim_scan(s, float(q))
            side[j, i] = scan_stamps(t, heads[:1], params=p)[0].shape[1]
            cpu[j, i], est[j, i] = _timed(M, t, p)
    ea, ex, ey = absolute_errors(np.tile(poses, (qs.size, 1)), est.reshape(-1, 3))
    return StampTrimResult(qs, poses, np.hypot(ex, ey).reshape(qs.size, n), ea.reshape(qs.size, n), side,
                           np.median(cpu, axis=1), p)
