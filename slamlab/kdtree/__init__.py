"""kd-trees for descriptor matching and landmark stores (000 §1.4.3, §3.4, §4).

``KDTree(points, ids, leaf_size=1)`` builds a balanced static tree (median split on the
coordinate of largest spread); ``tree.query(Q, k=2, max_leaves=None)`` returns the k
nearest neighbours exactly, or by Best-Bin-First after ``max_leaves`` leaves;
``tree.last_stats`` counts the work. :func:`bbf_trace` is the one-query teaching version.
The landmark stores of 000 §3.4 (``stores``), their workloads, the multi kd-tree cost
model (``cost_model``), experiments, plots and widgets are submodules.
"""

from . import cost_model, experiments, store_plot, stores, widgets, workloads
from .plot import plot_kdtree_2d
from .tree import KDTree, SearchStats, bbf_trace, build_kdtree

__all__ = [
    "KDTree",
    "SearchStats",
    "bbf_trace",
    "build_kdtree",
    "cost_model",
    "experiments",
    "plot_kdtree_2d",
    "store_plot",
    "stores",
    "widgets",
    "workloads",
]
