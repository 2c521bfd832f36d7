"""The landmark store interface, the base rule and the counts every store keeps (000 §3.4, §4).

:class:`LandmarkStore` (the interface every store implements), :func:`base_rule` and :class:`SightingBook`
(000 §3.4's rule, kept per point) and :class:`StoreCounters` (the operation counts). The stores themselves are in
:mod:`slamlab.kdtree.stores` (which re-exports these names) and :mod:`slamlab.kdtree.multi`; their settings in
:mod:`slamlab.kdtree.store_params`.
"""

from __future__ import annotations

from abc import ABC, abstractmethod
from dataclasses import dataclass, fields

import numpy as np

from .._validate import as_finite_array, check_int
from .knn import exact_knn, pad_knn

__all__ = ["LandmarkStore", "SightingBook", "StoreCounters", "base_rule"]


@dataclass
class StoreCounters:
    """Operation counts accumulated by a store (the quantities of 000's cost model).

    Attributes
    ----------
    points_added : int
        Points inserted.
    points_rebuilt : int
        Points put into a newly built tree (build work).
    trees_built : int
        Trees built.
    queries : int
        Query points searched.
    trees_searched : int
        Non-empty trees searched, summed over query batches.
    nodes_visited : int
        Internal tree nodes passed (teaching tree only).
    distance_evals : int
        Query-to-point distances computed (0 where the backend does not say).
    """

    points_added: int = 0
    points_rebuilt: int = 0  # points put into a newly built tree (build work)
    trees_built: int = 0
    queries: int = 0
    trees_searched: int = 0  # non-empty trees searched, summed over query batches
    nodes_visited: int = 0  # internal tree nodes passed (teaching tree only)
    distance_evals: int = 0  # query-to-point distances computed (0 where the backend does not say)

    def as_dict(self) -> dict:
        """The counts as a dict.

        Returns
        -------
        dict
            Field name → count.
        """
        return {f.name: getattr(self, f.name) for f in fields(self)}

    def reset(self) -> None:
        for f in fields(self):
            setattr(self, f.name, 0)


def base_rule(seen, age, base_seen_times: int, max_non_base_time: int):
    """000 §3.4's base rule: ``(is_base, timed_out)`` per point from its sightings and age.

    A point is *base* once seen ``base_seen_times`` times (000: ``BaseSeenTimes = 3``); a
    non-base point whose first sighting is ``max_non_base_time`` iterations old (000:
    ``MaxNonBaseTime = 7``) times out and is dropped. ``age`` = iterations since the first
    sighting (0 in the iteration it was first seen).

    Parameters
    ----------
    seen : (N,) int
        Sightings per point.
    age : (N,) int
        Iterations since each point's first sighting.
    base_seen_times : int
        Sightings that make a point base.
    max_non_base_time : int
        Age at which a non-base point times out.

    Returns
    -------
    is_base, timed_out : (N,) bool

    Examples
    --------
    >>> b, late = base_rule(np.array([3, 1, 2]), np.array([2, 7, 6]), 3, 7)
    >>> b.tolist(), late.tolist()
    ([True, False, False], [False, True, False])
    """
    seen = np.asarray(seen)
    is_base = seen >= base_seen_times
    return is_base, ~is_base & (np.asarray(age) >= max_non_base_time)


class SightingBook:
    """Seen counts and first-sighting iterations of non-base points; :meth:`step` applies :func:`base_rule`.

    Parameters
    ----------
    base_seen_times : int
        Sightings that make a point base.
    max_non_base_time : int
        Age in iterations at which a non-base point times out.

    Examples
    --------
    >>> book = SightingBook(3, 7)
    >>> book.add(np.array([1, 2])); book.step()[0].tolist()
    []
    >>> for _ in range(2):
    ...     book.observe(np.array([1])); promoted, dropped = book.step()
    >>> promoted.tolist(), book.ids.tolist()
    ([1], [2])
    """

    def __init__(self, base_seen_times: int, max_non_base_time: int):
        self.base_seen_times = base_seen_times
        self.max_non_base_time = max_non_base_time
        self.ids = np.empty(0, dtype=np.int64)  # sorted
        self.seen = np.empty(0, dtype=np.int64)
        self.first = np.empty(0, dtype=np.int64)
        self.iteration = 0

    def add(self, ids):
        """Start the book of new points: seen once, first sighting this iteration.

        Parameters
        ----------
        ids : (K,) int64
            Ids not yet in the book.
        """
        allid = np.concatenate([self.ids, ids])
        o = np.argsort(allid, kind="stable")
        self.ids = allid[o]
        self.seen = np.concatenate([self.seen, np.ones(ids.size, dtype=np.int64)])[o]
        self.first = np.concatenate([self.first, np.full(ids.size, self.iteration, dtype=np.int64)])[o]

    def observe(self, ids):
        """Count one more sighting of every booked id in ``ids``.

        Parameters
        ----------
        ids : (K,) int64
            Ids seen again (ids not in the book are ignored).
        """
        if not self.ids.size or not ids.size:
            return
        pos = np.searchsorted(self.ids, ids)
        pos = np.minimum(pos, self.ids.size - 1)
        hit = self.ids[pos] == ids
        self.seen += np.bincount(pos[hit], minlength=self.ids.size)

    def step(self):
        """End the iteration: return (ids that became base, ids that timed out); forget both.

        Returns
        -------
        promoted, dropped : (K,) int64
            Ids that became base and ids that timed out.
        """
        base, late = base_rule(self.seen, self.iteration - self.first, self.base_seen_times,
                               self.max_non_base_time)
        promoted, dropped = self.ids[base], self.ids[late]
        keep = ~(base | late)
        self.ids, self.seen, self.first = self.ids[keep], self.seen[keep], self.first[keep]
        self.iteration += 1
        return promoted, dropped


def _as_points(X, name, dim=None, dtype=None, binary_ok=False):
    """Descriptors as float32 (or uint8 where the store compares binary descriptors)."""
    X = np.asarray(X)
    if X.dtype.kind not in "fiu":
        raise TypeError(f"`{name}` must be a numeric array; got dtype {X.dtype}")
    if X.dtype == np.uint8 and binary_ok and dtype != np.float32:
        if X.ndim != 2:
            raise ValueError(f"`{name}` must be a 2-D (N, d) descriptor array; got shape {X.shape}")
    else:
        if dtype == np.uint8:
            raise TypeError(f"`{name}` must be uint8 (binary) like the stored descriptors; got {X.dtype}")
        if X.dtype == np.uint8 and X.ndim == 2 and not binary_ok:
            raise TypeError(f"`{name}`: binary (uint8) descriptors need an exact store (ExactStore, "
                            "BruteForceStore); a kd-tree compares float descriptors")
        X = as_finite_array(X, name, ndim=2, dtype=np.float32)
    if dim is not None and X.shape[1] != dim:
        raise ValueError(f"`{name}` must have shape (N, {dim}) to match the store; got shape {X.shape}")
    return X


def _as_ids(ids, name, n=None):
    ids = np.asarray(ids)
    if ids.size == 0:
        ids = ids.astype(np.int64)
    if not np.issubdtype(ids.dtype, np.integer):
        raise TypeError(f"`{name}` must be an integer array; got dtype {ids.dtype}")
    if ids.ndim != 1 or (n is not None and ids.shape[0] != n):
        want = f"({n},)" if n is not None else "(N,)"
        raise ValueError(f"`{name}` must have shape {want}; got shape {ids.shape}")
    return ids.astype(np.int64)


class LandmarkStore(ABC):
    """The landmark-store interface (000 §3.4): every store, and the stereo pipeline's, derives from it.

    Subclasses implement ``_add(X, ids)`` (checked batch), ``_query(Q, k)`` (checked, non-empty),
    ``_stored() -> (X, ids)`` (every stored point) and ``__len__``; ``_observe(ids)`` (checked ids) and
    ``end_iteration`` do nothing unless the store applies the base rule or rebuilds.
    ``query_among`` is exact (brute force over the selected points) for every store.
    """

    name = "store"
    insert_only = True
    #: True for the stores that compare binary uint8 descriptors by Hamming distance (exact stores)
    binary_ok = False

    def __init__(self):
        self.counters = StoreCounters()
        self.dim: int | None = None
        self.dtype = None

    # -- interface ---------------------------------------------------------------------------------
    def add(self, X, ids) -> None:
        """Add a batch of new points (first sighting) with their ids.

        Parameters
        ----------
        X : (N, d) float or uint8
            Points (descriptors); every batch has the store's dimension.
        ids : (N,) int
            Their ids.
        """
        X, ids = self._check_batch(X, ids)
        if X.shape[0]:
            self.counters.points_added += X.shape[0]
            self._add(X, ids)

    def observe(self, ids) -> None:
        """Record re-sightings of stored ids this iteration (only the base rule uses them).

        Parameters
        ----------
        ids : (K,) int
            Ids seen again (ids the store does not hold are ignored).
        """
        self._observe(_as_ids(ids, "ids"))

    def end_iteration(self) -> None:  # noqa: B027 (a no-op unless the store rebuilds or applies the base rule)
        """Close an iteration (apply the base rule, rebuild what the store rebuilds)."""

    def query(self, Q, k: int = 2):
        """The ``k`` nearest stored points of every row of ``Q``: ``(dist (M, k), ids (M, k))``.

        Parameters
        ----------
        Q : (M, d) array
            Query points.
        k : int
            Neighbours per query.

        Returns
        -------
        dist : (M, k) float
            Ascending; ``inf`` where fewer than ``k`` points are stored.
        ids : (M, k) int
            Ids of the neighbours; -1 where missing.
        """
        Q, k = self._check_query(Q, k)
        if len(self) == 0 or Q.shape[0] == 0:
            return pad_knn(np.empty((Q.shape[0], 0)), np.empty((Q.shape[0], 0), dtype=np.int64), k)
        return self._query(Q, k)

    def query_among(self, Q, among, k: int = 2):
        """Like :meth:`query`, searching only (and exactly) the stored points whose ids are in ``among``.

        Parameters
        ----------
        Q : (M, d) array
            Query points.
        among : int array
            Ids of the stored points to search.
        k : int
            Neighbours per query.

        Returns
        -------
        dist : (M, k) float
        ids : (M, k) int
            As :meth:`query`.
        """
        Q, k = self._check_query(Q, k)
        among = _as_ids(np.asarray(among).ravel(), "among")
        X, ids = self.stored()
        rows = np.isin(ids, among)
        self.counters.distance_evals += Q.shape[0] * int(rows.sum())
        return exact_knn(Q, X[rows], k, ids[rows])

    def stored(self):
        """Every stored point and its id, buffer and base alike, in the store's own order (ours).

        Returns
        -------
        X : (n, d) array
            The stored points.
        ids : (n,) int64
            Their ids.
        """
        return self._stored()

    @abstractmethod
    def __len__(self) -> int:
        """Number of stored points."""

    def __repr__(self) -> str:
        return f"{type(self).__name__}(n={len(self)})"

    # -- what a store implements --------------------------------------------------------------------
    @abstractmethod
    def _add(self, X, ids) -> None:
        """Store a checked, non-empty batch."""

    @abstractmethod
    def _query(self, Q, k):
        """k-NN of a checked, non-empty query batch in a non-empty store."""

    @abstractmethod
    def _stored(self):
        """``(X (n, d), ids (n,))``: every stored point."""

    def _observe(self, ids) -> None:  # noqa: B027 (a no-op unless the store applies the base rule)
        """Record re-sightings of checked ``ids (K,) int64``."""

    # -- helpers -----------------------------------------------------------------------------------
    def _check_batch(self, X, ids):
        X = _as_points(X, "X", self.dim, self.dtype, self.binary_ok)
        ids = _as_ids(ids, "ids", X.shape[0])
        if self.dim is None and X.shape[0]:
            self.dim, self.dtype = X.shape[1], X.dtype
        return X, ids

    def _check_query(self, Q, k):
        Q = _as_points(Q, "Q", self.dim, self.dtype, self.binary_ok)
        k = check_int(k, "k", minimum=1)
        self.counters.queries += Q.shape[0]
        return Q, k
