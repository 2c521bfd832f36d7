"""Ch. 7 on real logs: the ablation of Hough SLAM's real-log settings (ours), one row per change and log.

Each change re-runs the loop on the scans and lines of the default runs
(:func:`~slamlab.studies.hough.logs.rerun_real_log`), so a row differs from the defaults by that
change alone.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

from ..._table import format_table
from .logs import RealLogResult, rerun_real_log

__all__ = ["REAL_LOG_ABLATION", "RealLogAblation", "ablate_real_logs"]

#: The changes tried (label → overrides of :func:`~slamlab.studies.hough.run_real_log`'s defaults; ours).
REAL_LOG_ABLATION = (
    ("log's pairing (lag 0)", {"lag_scans": 0.0}),
    ("defaults (lag measured)", {}),
    ("no heading step", {"heading": False}),
    ("no parallel-line step", {"partial": False}),
    ("a_theta 2° (not 4°)", {"a_theta_rad": math.radians(2.0)}),
)
_CAUSES = ("no_lines", "not_associated", "one_line", "pose_rejected")


def _log_label(result: RealLogResult) -> str:
    return result.name.split(" log ")[1].split(" ")[0].rsplit(".", 1)[0]


@dataclass(frozen=True)
class RealLogAblation:
    """The runs of each change on each log.

    Attributes
    ----------
    labels : tuple of str
        The changes, in order.
    runs : tuple of tuple of RealLogResult
        ``runs[i][j]``: change i on log j.
    """

    labels: tuple
    runs: tuple = field(repr=False)

    def __str__(self) -> str:
        return f"Hough SLAM ablation: {len(self.labels)} settings x {len(self.runs[0])} logs"

    def table(self) -> str:
        """One row per change and log: the lag, the fallback causes, the sharpness against both odometries.

        Returns
        -------
        str
        """
        rows = []
        for label, runs in zip(self.labels, self.runs, strict=True):
            for r in runs:
                c = r.slam.cause_counts()
                rows.append([label, _log_label(r), f"{r.lag_scans:.2f}", *(str(c[k]) for k in _CAUSES),
                             f"{r.sharper_than_odometry():.1%}", f"{r.sharper_than_odometry('retimed'):.1%}"])
        heads = ["change", "log", "lag", "no_lines", "not_assoc", "one_line", "rejected", "sharper", "vs re-timed"]
        return format_table(heads, rows, title="Hough SLAM on real logs: steps on odometry alone by cause, "
                                               "sharper than odometry")


def ablate_real_logs(results, changes=REAL_LOG_ABLATION) -> RealLogAblation:
    """Re-run each log's Hough SLAM with each change (ours).

    Parameters
    ----------
    results : sequence of RealLogResult
        The default runs (:func:`~slamlab.studies.hough.run_real_log`), one per log.
    changes : sequence of (str, dict)
        Label and overrides (``lag_scans`` or fields of :class:`~slamlab.hough.HoughSlamParams`);
        an empty dict reuses the run given. Default :data:`REAL_LOG_ABLATION`.

    Returns
    -------
    RealLogAblation
    """
    results = tuple(results)
    if not results or not all(isinstance(r, RealLogResult) for r in results):
        raise TypeError("`results` must be a non-empty sequence of RealLogResult")
    changes = tuple(changes)
    if not changes or not all(isinstance(c, tuple) and len(c) == 2 and isinstance(c[1], dict) for c in changes):
        raise TypeError("`changes` must be a non-empty sequence of (label, overrides dict) pairs")
    runs = tuple(tuple(r if not over else rerun_real_log(r, **over) for r in results) for _, over in changes)
    return RealLogAblation(tuple(str(label) for label, _ in changes), runs)
