"""Ch. 01's studies, Kalman filters (000 §1.2, §3.6): the Monte Carlo runs, the closing table, plots, widgets."""

from ..._lazy import lazy_exports
from .experiments import (
    default_landmarks,
    ours_vs_source,
    run_cv_target,
    run_joseph_vs_short,
    run_landmark_filter,
    run_sigma_alpha_study,
    run_stabilising_noise,
    run_unicycle_comparison,
)

__all__ = [
    "default_landmarks",
    "ours_vs_source",
    "run_cv_target",
    "run_joseph_vs_short",
    "run_landmark_filter",
    "run_sigma_alpha_study",
    "run_stabilising_noise",
    "run_unicycle_comparison",
]

# plots (pyplot) and widgets (ipywidgets) load on first use: `import slamlab.studies.filters` stays light
_PLOT = ("cv_figure", "plot_cv_example", "plot_joseph", "plot_unicycle_paths", "unicycle_figure")
_WIDGETS = ("explore_cv_target", "explore_unicycle")
__getattr__, __dir__ = lazy_exports(__name__, {**dict.fromkeys(_PLOT, ".plot"), **dict.fromkeys(_WIDGETS, ".widgets")})

__all__ += list(_PLOT + _WIDGETS)  # loaded on first use
