"""Studies of Ch. 04 landmark stores (000 §4.1-4.3): descriptor workloads, Tables 1 and 2, the crossover, C fitted."""

from ..._lazy import lazy_exports
from . import crossover, experiments, tree_studies, workloads

_LAZY = {
    "plot_cost_surface": ".store_plot",
    "plot_cost_contour": ".store_plot",
    "plot_multi_tree_sizes": ".store_plot",
    "plot_crossover": ".store_plot",
    "plot_iteration_times": ".store_plot",
    "explore_cost_model": ".widgets",
    "explore_stores": ".widgets",
}
__getattr__, __dir__ = lazy_exports(__name__, _LAZY, submodules=("store_plot", "widgets"))

__all__ = [
    "crossover",
    "experiments",
    "tree_studies",
    "workloads",
]
__all__ += list(_LAZY)
