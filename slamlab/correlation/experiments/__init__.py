"""Ch. 5 experiments (004 §7): Table 1, a Monte Carlo study, the constants a_c/a_p, the corridor tie (the real
CARMEN log and the closing table: :mod:`.log_experiments`).

Every ``run_*`` takes ``params=`` (a :class:`~slamlab.correlation.LocaliseParams`, the
same settings and defaults as :func:`~slamlab.correlation.localise`) plus overrides
of its fields.

Each ``run_*`` returns a frozen dataclass: ``str(result)`` is a one-line summary,
``result.table()`` a fixed-precision text table (what the notebook prints and
nbval compares); arrays for plotting live in fields, timings in ``time_s``
(never in the table).

Families (CONVENTIONS: experiments.py split by experiment family): ``table1``, ``monte_carlo``,
``constants_study``, ``corridor``; ``common`` holds the test room, its clutter and the sweep helpers.
"""

from __future__ import annotations

from ...scans.logmap import log_grid  # log_grid re-exported (one place: scans)
from .common import FAIL_CELLS, FAIL_DEG, random_clutter
from .constants_study import ConstantsResult, run_constants_study
from .corridor import CorridorResult, corridor_grid, run_corridor_tie, time_localise
from .monte_carlo import MonteCarloResult, run_monte_carlo
from .table1 import SOURCE_TABLE1, Table1Result, run_table1

__all__ = [
    "FAIL_CELLS",
    "FAIL_DEG",
    "SOURCE_TABLE1",
    "ConstantsResult",
    "CorridorResult",
    "MonteCarloResult",
    "Table1Result",
    "corridor_grid",
    "log_grid",
    "random_clutter",
    "run_constants_study",
    "run_corridor_tie",
    "run_monte_carlo",
    "run_table1",
    "time_localise",
]

