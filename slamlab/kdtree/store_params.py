"""The settings of the landmark stores (:class:`StoreParams`), every one with its source (000 §1.4.3, §3.4, §4.1).

One settings object for every store of :mod:`slamlab.kdtree.stores`: the base rule (``base_seen_times``,
``max_non_base_time``), the multi kd-tree's sizes (``n1``, ``q``) and the trees inside the stores (``tree``,
``leaf_size``, ``checks``). A store reads the fields it uses; one that needs another value than the default
says so by an explicit argument (:class:`~slamlab.kdtree.stores.BruteForceStore` keeps every point:
``base_seen_times=1``).
"""

from __future__ import annotations

from dataclasses import dataclass

from .._params import Params, param
from .._validate import check_choice, check_int, check_positive

__all__ = ["TREE_KINDS", "StoreParams", "resolve_store_params"]

#: the tree inside a store: ``"bbf"`` our kd-tree searched by Best-Bin-First, ``"exact"`` the same tree searched
#: exactly, ``"ckdtree"`` scipy's exact ``cKDTree``, ``"brute"`` exact search by brute force
TREE_KINDS = ("bbf", "exact", "ckdtree", "brute")


@dataclass(frozen=True)
class StoreParams(Params):
    """Settings of the landmark stores, one object for all of them (000 §1.4.3, §3.4, §4.1.2).

    Each store reads the fields it uses.

    Parameters
    ----------
    base_seen_times : int
        Sightings that make a point *base* (000's BaseSeenTimes); 1 makes every point base at once.
    max_non_base_time : int
        Iterations after its first sighting at which a non-base point is dropped (000's MaxNonBaseTime).
    n1 : int
        Maximum size of the multi kd-tree's first tree.
    q : float
        Size ratio between consecutive trees of the multi kd-tree, > 1.
    tree : str
        Search in the stores' trees (:data:`TREE_KINDS`).
    leaf_size : int
        Points per leaf of our trees.
    checks : int
        Points examined per tree by the Best-Bin-First search (leaf budget ``ceil(checks / leaf_size)``), and
        the checks of FLANN's search.

    Examples
    --------
    >>> p = StoreParams()
    >>> p.base_seen_times, p.max_non_base_time, p.n1, p.q
    (3, 7, 3500, 5.5)
    >>> StoreParams(base_seen_times=0)
    Traceback (most recent call last):
    ...
    ValueError: `base_seen_times` must be >= 1; got 0
    """

    base_seen_times: int = param(3, "000 §3.4: BaseSeenTimes, 'the value used was three'")
    max_non_base_time: int = param(7, "000 §3.4: MaxNonBaseTime, 'the value used was seven'")
    n1: int = param(3500, "000 §4.1.2: minimum of the cost model at n1 = 3500 (Figs 13-14, read off the plot)")
    q: float = param(5.5, "000 §4.1.2: minimum of the cost model at q = 5.5 (Figs 13-14)")
    tree: str = param("bbf", "000 §1.4.3: Best-Bin-First search (Beis & Lowe) in our kd-tree")
    leaf_size: int = param(8, "ours (000 §1.4.3 splits down to single points; buckets of 8 search faster)")
    checks: int = param(200, "000 §1.4.3: BBF stops after 'about 200' leaves (000's leaves hold one point: 200 "
                             "points examined)")

    def check(self) -> None:
        super().check()
        check_int(self.base_seen_times, "base_seen_times", minimum=1)
        check_int(self.max_non_base_time, "max_non_base_time", minimum=1)
        check_int(self.n1, "n1", minimum=1)
        q = check_positive(self.q, "q")
        if q <= 1:
            raise ValueError(f"`q` must be > 1; got {self.q}")
        check_choice(self.tree, "tree", TREE_KINDS)
        check_int(self.leaf_size, "leaf_size", minimum=1)
        check_int(self.checks, "checks", minimum=1)


def resolve_store_params(params: StoreParams | None = None, **fields) -> StoreParams:
    """``params`` with the ``fields`` that are not None changed: how a store resolves its settings (ours).

    A store's constructor names the fields it reads as keyword arguments with the default None ("from
    ``params``"); this turns them into one :class:`StoreParams`, resolved once.

    Parameters
    ----------
    params : StoreParams, optional
        The base settings (default :class:`StoreParams`).
    **fields
        :class:`StoreParams` fields; None leaves the field as ``params`` has it.

    Returns
    -------
    StoreParams

    Examples
    --------
    >>> resolve_store_params(StoreParams(n1=1000), n1=None, q=4).n1, resolve_store_params(q=4).q
    (1000, 4)
    """
    return StoreParams.resolve(params, **{k: v for k, v in fields.items() if v is not None})
