"""Ch. 08's studies, probabilistic localisation (003 §1.2.4, §2.2): simulated runs, global, kidnapped, Markov, CARMEN logs."""

from ..._lazy import lazy_exports
from .experiments import (
    AMCL_DEFAULTS,
    FilterRun,
    MarkovVsMclResult,
    SimRun,
    amcl_defaults_table,
    demo_run,
    ours_vs_source,
    run_filter,
    run_markov_vs_mcl,
    simulate_run,
)
from .log_maps import (
    CARMEN_LOGS,
    TUNED_LOGS,
    carmen_path,
    log_map,
    read_log_counts,
    stretch_coverage,
    stretch_map,
)
from .log_protocol import LogProtocolResult, maps_table, run_log_protocol
from .logs import (
    LogMCLResult,
    global_log_settings,
    log_params,
    log_settings,
    logs_table,
    run_log_mcl,
)
from .markov_study import (
    MARKOV_PRIORS,
    MARKOV_STUDY_PARAMS,
    MarkovStudyResult,
    run_markov_kidnap,
    run_markov_prior,
)
from .side_by_side import SideBySideResult, run_correlation_side_by_side
from .studies import (
    ABLATION,
    ABLATION_MORE,
    CHAPTER_BEFORE,
    KIDNAP_VARIANTS,
    PLAIN_SETUP,
    SCORE_VARIANTS,
    AblationResult,
    GlobalResult,
    KidnapResult,
    ScoreComparison,
    run_global_ablation,
    run_global_localisation,
    run_kidnapped,
    run_score_comparison,
)

_PLOT = ("mcl_figure", "plot_clouds", "plot_errors", "plot_global", "plot_log_run", "recorded_step_figure")
_WIDGETS = ("explore_log", "explore_markov", "explore_mcl", "explore_recorded_run")
__getattr__, __dir__ = lazy_exports(__name__, {**dict.fromkeys(_PLOT, ".plot"), **dict.fromkeys(_WIDGETS, ".widgets")})

__all__ = [
    "ABLATION",
    "ABLATION_MORE",
    "AMCL_DEFAULTS",
    "CARMEN_LOGS",
    "CHAPTER_BEFORE",
    "KIDNAP_VARIANTS",
    "MARKOV_PRIORS",
    "MARKOV_STUDY_PARAMS",
    "PLAIN_SETUP",
    "SCORE_VARIANTS",
    "TUNED_LOGS",
    "AblationResult",
    "FilterRun",
    "GlobalResult",
    "KidnapResult",
    "LogMCLResult",
    "LogProtocolResult",
    "MarkovStudyResult",
    "MarkovVsMclResult",
    "ScoreComparison",
    "SideBySideResult",
    "SimRun",
    "amcl_defaults_table",
    "carmen_path",
    "demo_run",
    "global_log_settings",
    "log_map",
    "log_params",
    "log_settings",
    "logs_table",
    "maps_table",
    "ours_vs_source",
    "read_log_counts",
    "run_correlation_side_by_side",
    "run_filter",
    "run_global_ablation",
    "run_global_localisation",
    "run_kidnapped",
    "run_log_mcl",
    "run_log_protocol",
    "run_markov_kidnap",
    "run_markov_prior",
    "run_markov_vs_mcl",
    "run_score_comparison",
    "simulate_run",
    "stretch_coverage",
    "stretch_map",
]
__all__ += list(_PLOT + _WIDGETS)  # loaded on first use
