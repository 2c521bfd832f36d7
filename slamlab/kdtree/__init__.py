"""kd-trees, exact k-NN and the landmark stores (000 §1.4.3, §3.4, §4).

The generic layer under the features and stereo chapters (it imports neither):

- ``KDTree(points, ids, leaf_size=1)`` builds a balanced static tree (median split on the
  coordinate of largest spread; ``split=`` and ``gap=`` choose other split rules, such as FLANN's
  variance-mean, and keep each split's gap: :func:`build_kdtree`, our addition, issue 25);
  ``tree.query(Q, k=2, max_leaves=None)`` returns the k
  nearest neighbours exactly, or by Best-Bin-First after ``max_leaves`` leaves;
  ``tree.last_stats`` counts the work. :func:`bbf_trace` is the one-query teaching version.
- :func:`exact_knn` (brute force, Hamming or Euclidean), :func:`pad_knn`, :func:`merge_knn`
  (:mod:`.knn`): the one exact 2-NN and the one "pad to k".
- :class:`LandmarkStore`, the interface every store implements, the stores of 000 §3.4
  and §4 and the base rule (:func:`base_rule`, :class:`SightingBook`) in :mod:`.stores`, with their one
  settings object :class:`StoreParams` (:mod:`.store_params`);
  the multi kd-tree cost model (:mod:`.cost_model`); the 2-D tree plot (loaded on first use).
"""

from .._lazy import lazy_exports
from . import cost_model, stores
from .knn import exact_knn, hamming_distances, merge_knn, pad_knn
from .stores import (
    BruteForceStore,
    ExactStore,
    FlannStore,
    LandmarkStore,
    MultiKDTree,
    NonBaseBuffer,
    RebuildStore,
    SightingBook,
    StoreParams,
    base_rule,
    make_store,
)
from .trace import bbf_trace
from .tree import KDTree, SearchStats, build_kdtree

_LAZY = {"plot_kdtree_2d": ".plot"}
__getattr__, __dir__ = lazy_exports(__name__, _LAZY, submodules=("plot",))

__all__ = [
    "BruteForceStore",
    "ExactStore",
    "FlannStore",
    "KDTree",
    "LandmarkStore",
    "MultiKDTree",
    "NonBaseBuffer",
    "RebuildStore",
    "SearchStats",
    "SightingBook",
    "StoreParams",
    "base_rule",
    "bbf_trace",
    "build_kdtree",
    "cost_model",
    "exact_knn",
    "hamming_distances",
    "make_store",
    "merge_knn",
    "pad_knn",
    "stores",
]
__all__ += list(_LAZY)
