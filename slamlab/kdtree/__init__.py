"""kd-trees for descriptor matching (000 §1.4.3, §3.4): the teaching static tree with exact and BBF search.

``KDTree(points, ids, leaf_size=1)`` builds a balanced static tree (median split on the
coordinate of largest spread); ``tree.query(Q, k=2, max_leaves=None)`` returns the k
nearest neighbours exactly, or by Best-Bin-First after ``max_leaves`` leaves;
``tree.last_stats`` counts the work. :func:`bbf_trace` is the one-query teaching version.
"""

from .plot import plot_kdtree_2d
from .tree import KDTree, SearchStats, bbf_trace, build_kdtree

__all__ = ["KDTree", "SearchStats", "bbf_trace", "build_kdtree", "plot_kdtree_2d"]
