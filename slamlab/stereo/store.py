"""The landmark store of the stereo SLAM loop (000 §3.4): the default one, and the ``store`` argument resolved."""

from __future__ import annotations

from ..kdtree.stores import ExactStore, LandmarkStore, make_store
from .params import StereoParams

__all__ = ["default_store", "resolve_store"]


def default_store(params: StereoParams | None = None) -> LandmarkStore:
    """The landmark store the pipeline uses unless told otherwise (000 §3.4, §4).

    Float descriptors (SURF, SIFT): 000's multi kd-tree (n1 = 3500, q = 5.5, BBF with 200
    checks) behind the non-base buffer (:func:`slamlab.kdtree.make_store`). Binary descriptors
    (ORB, Hamming distance): a kd-tree does not apply, so :class:`~slamlab.kdtree.ExactStore`
    (brute force). Both apply the base rule with ``params``' ``base_seen_times`` / ``max_non_base_time``.

    Parameters
    ----------
    params : StereoParams, optional
        Settings (``detector``, ``base_seen_times``, ``max_non_base_time``); default :class:`StereoParams`.

    Returns
    -------
    LandmarkStore
    """
    p = StereoParams.resolve(params)
    if p.binary:
        return ExactStore(p.base_seen_times, p.max_non_base_time)
    return make_store("multi", base_seen_times=p.base_seen_times, max_non_base_time=p.max_non_base_time)


def resolve_store(store, p: StereoParams) -> LandmarkStore:
    """``StereoSLAM``'s ``store`` argument: None (:func:`default_store`), a store, or a class / factory of one.

    Parameters
    ----------
    store : LandmarkStore, type, callable or None
        The store, a class or factory returning one, or None for :func:`default_store` of ``p``.
    p : StereoParams
        Settings of the default store.

    Returns
    -------
    LandmarkStore

    Raises
    ------
    TypeError
        When ``store`` neither is nor makes a :class:`~slamlab.kdtree.LandmarkStore`.
    """
    if store is None:
        store = default_store(p)
    elif isinstance(store, type) or (callable(store) and not isinstance(store, LandmarkStore)):
        store = store()  # a class or a factory
    if not isinstance(store, LandmarkStore):
        raise TypeError(f"`store` must be a slamlab.kdtree.LandmarkStore or a factory of one; "
                        f"got {type(store).__name__}")
    return store
