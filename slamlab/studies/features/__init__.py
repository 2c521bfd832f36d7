"""Studies of Ch. 02 detectors and 03 matching (000 §1.4, §1.4.3, §3.3; 003 §3.1): Oxford pairs, k-NN, ratio test."""

from ..._lazy import lazy_exports
from .experiments import (
    EVAL_DETECTORS,
    run_blob_scale,
    run_detector_summary,
    run_pair_evaluation,
    run_surf_threshold,
)
from .matching_experiments import (
    descriptor_pool,
    run_knn_comparison,
    run_ratio_tradeoff,
    run_recall_vs_leaves,
)

__all__ = [
    "EVAL_DETECTORS",
    "descriptor_pool",
    "run_blob_scale",
    "run_detector_summary",
    "run_knn_comparison",
    "run_pair_evaluation",
    "run_ratio_tradeoff",
    "run_recall_vs_leaves",
    "run_surf_threshold",
]

#: plotting (pyplot) and widget (ipywidgets) names load on first use
_LAZY = {
    **dict.fromkeys(("plot_pair_evaluation", "plot_ratio_tradeoff", "plot_recall_vs_leaves", "plot_surf_threshold"),
                    ".plot"),
    "explore_detectors": ".widgets",
    "explore_matching": ".widgets",
}
__getattr__, __dir__ = lazy_exports(__name__, _LAZY, submodules=("plot", "widgets"))
__all__ += list(_LAZY)
