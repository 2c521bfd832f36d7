"""Studies of chapter 06, correlation localisation (004 §7): its runs, tables, figures and widgets."""

from ..._lazy import lazy_exports
from .aperture import ApertureResult
from .carmen_logs import DEFAULT_CARMEN_LOG, SHARED_CARMEN_LOGS
from .experiments import (
    SOURCE_TABLE1,
    ConstantsResult,
    CorridorResult,
    MonteCarloResult,
    Table1Result,
    corridor_grid,
    random_clutter,
    run_aperture_study,
    run_constants_study,
    run_corridor_tie,
    run_monte_carlo,
    run_stamp_trim_study,
    run_table1,
    time_localise,
)
from .log_experiments import run_log_localisation
from .log_results import LogLocalisationResult
from .log_suite import GOAL, LogSuiteResult, goal_text, more_confident, run_log_suite
from .map_check import MAP_CHECK_LAYOUTS, endpoint_agreement, logged_pose_check, map_check
from .source_table import ours_vs_source
from .stamp_trim import StampTrimResult, trim_scan
from .terms import TERM_NAMES, score_terms

_PLOT = ("constants_figure", "plot_error_distribution", "plot_log_localisation", "plot_table1")
_WIDGETS = ("explore_localisation", "explore_log_scan")
__getattr__, __dir__ = lazy_exports(__name__, {**dict.fromkeys(_PLOT, ".plot"), **dict.fromkeys(_WIDGETS, ".widgets")})

__all__ = [
    "DEFAULT_CARMEN_LOG",
    "GOAL",
    "MAP_CHECK_LAYOUTS",
    "SHARED_CARMEN_LOGS",
    "SOURCE_TABLE1",
    "TERM_NAMES",
    "ApertureResult",
    "ConstantsResult",
    "CorridorResult",
    "LogLocalisationResult",
    "LogSuiteResult",
    "MonteCarloResult",
    "StampTrimResult",
    "Table1Result",
    "corridor_grid",
    "endpoint_agreement",
    "goal_text",
    "logged_pose_check",
    "map_check",
    "more_confident",
    "ours_vs_source",
    "random_clutter",
    "run_aperture_study",
    "run_constants_study",
    "run_corridor_tie",
    "run_log_localisation",
    "run_log_suite",
    "run_monte_carlo",
    "run_stamp_trim_study",
    "run_table1",
    "score_terms",
    "time_localise",
    "trim_scan",
]
__all__ += list(_PLOT + _WIDGETS)  # loaded on first use
