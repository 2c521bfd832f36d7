"""Ch. 5's closing table (004 §7): the source's figures beside ours, from the notebook's runs.

Split from :mod:`slamlab.studies.correlation.log_experiments` unchanged.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from ..._table import format_table
from .aperture import ApertureResult
from .experiments import (
    FAIL_CELLS,
    FAIL_DEG,
    SOURCE_TABLE1,
    ConstantsResult,
    MonteCarloResult,
    Table1Result,
    run_table1,  # noqa: F401 (ours_vs_source's example)
)
from .stamp_trim import StampTrimResult
from .studies import source_table1_errors

if TYPE_CHECKING:
    from .log_experiments import LogLocalisationResult

__all__ = ["ours_vs_source"]


def ours_vs_source(table1: Table1Result, monte_carlo: MonteCarloResult | None = None,
                   constants: ConstantsResult | None = None, log: LogLocalisationResult | None = None,
                   aperture: ApertureResult | None = None, trim: StampTrimResult | None = None) -> str:
    """The notebook's closing table: 004's figures (§7, Table 1) beside ours, from the runs' results.

    Parameters
    ----------
    table1 : Table1Result
        From :func:`run_table1`.
    monte_carlo : MonteCarloResult, optional
        From :func:`run_monte_carlo`; its row is left out when None.
    constants : ConstantsResult, optional
        From :func:`run_constants_study`.
    log : LogLocalisationResult, optional
        From :func:`run_log_localisation`.
    aperture : ApertureResult, optional
        From :func:`~slamlab.studies.correlation.run_aperture_study`: a row per aperture.
    trim : StampTrimResult, optional
        From :func:`~slamlab.studies.correlation.run_stamp_trim_study`: a row per trimmed quantile.

    Returns
    -------
    str
        The table: 004's claim, our figures, agreement.

    Examples
    --------
    >>> print(ours_vs_source(run_table1(2, rng=1)).splitlines()[0])
    Ours vs the source (004 §7)
    """
    if not isinstance(table1, Table1Result):
        raise TypeError(f"`table1` must be a Table1Result; got {type(table1).__name__}")
    src = SOURCE_TABLE1
    s_ea, s_ex, s_ey = source_table1_errors()
    t = table1
    rows = [
        ["Table 1: poses", f"{src.shape[0]}", f"{t.true_poses.shape[0]}"],
        ["Table 1: max position error [cells]", f"{max(s_ex.max(), s_ey.max()):.0f}",
         f"{max(t.err_x_cells.max(), t.err_y_cells.max()):.0f}"],
        ["Table 1: max heading error [rad]", f"{s_ea.max():.4f}", f"{t.err_heading_rad.max():.4f}"],
        ["Table 1: range noise σ [cells]", "normal, σ not given", f"{t.range_std_cells:g}"],
    ]
    if monte_carlo is not None:
        mc = monte_carlo
        rows += [[f"Monte Carlo ({mc.n_poses} poses): position exact", "no study", f"{np.mean(mc.err_pos_cells == 0):.1%}"],
                 [f"Monte Carlo ({mc.n_poses} poses): failures (> 2 cells or > 5°)", "no study",
                  f"{mc.failure_rate:.1%}"]]
    if constants is not None:
        c = constants
        for k, lb in enumerate(c.labels):
            rows.append([f"{lb}: heading margin / half-max area [cells]",
                         "sharpest at a_p = -a_c" if k == 0 else "more robust to clutter",
                         f"{np.median(c.heading_margin[k]):.3f} / {np.median(c.half_max_area[k]):.0f}"])
            n = c.err_pos_cells.shape[1]
            rows.append([f"{lb}: failures in the crowded room", "not measured",
                         f"{c.failure_rate[k]:.0%} ({round(c.failure_rate[k] * n)}/{n})"])
    if aperture is not None:
        for j, a in enumerate(aperture.apertures_deg):
            ok = aperture.success[j]
            claim = "a laser's beam works" if a == 0 else ("ultrasonic >10°: inaccurate" if j == 1 else "")
            rows.append([f"beam aperture {a:g}°: poses localised", claim, f"{ok.sum()}/{ok.size}"])
    if trim is not None:
        side = np.median(trim.stamp_side, axis=1)
        for j, q in enumerate(trim.quantiles):
            if q == 1:
                continue
            ok = trim.success[j]
            rows.append([f"T_n trimmed to {q:g} of the returns: cells / poses", "trim if l_max >> mean l",
                         f"{(side[j] / side[0]) ** 2:.2f} / {ok.sum()}/{ok.size}"])
    if log is not None:
        for m, k in enumerate(log.joined):
            rows.append([(f"real log, {log.mode_name(k)}: scans within {FAIL_CELLS * log.cell_m:.1f} m "
                          f"and {FAIL_DEG:g}°"), "none (simulation only)",
                         f"{int(log.success[m].sum())}/{log.success.shape[1]}"])
    title = "Ours vs the source (004 §7)" + ("" if log is None else f"; real log: {log.name}")
    return format_table(["quantity", "004", "ours"], rows, title=title)
