"""004's advice on the size of T_n, measured (004 §7): trim the stamp when the longest beam is far longer than most.

004 sizes every stamp T_n by the longest range, ``S = 2(l_max + 2)``, and advises: when ``l_max`` greatly exceeds the
mean distance to the surrounding objects, most of T_n stays filled with ``a_n`` and takes no part in the result,
while C_n and the work grow; so adjust the size of T_n. 004 gives no rule. :func:`run_stamp_trim_study` applies one
(ours): keep the returns up to a quantile of the scan's ranges, drop the longer ones (the stamp then shrinks to the
longest kept beam), and localise the same random poses of Table 1's room with each quantile.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..._table import format_table
from ..._validate import check_positive
from ...correlation.algorithm import LocaliseParams
from ...scans import Scan
from .studies import FAIL_CELLS, FAIL_DEG, within_tolerance

__all__ = ["StampTrimResult", "trim_scan"]


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
