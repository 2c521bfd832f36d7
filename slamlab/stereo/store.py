"""The landmark-store interface the stereo pipeline needs, and an exact store (000 §3.4).

The pipeline talks to a store through five calls (the interface of the
landmark-store chapter, :mod:`slamlab.kdtree.stores`, so its multi kd-tree plugs in):

- ``add(X, ids)`` — descriptors of landmarks first seen in this frame, with their ids;
- ``observe(ids)`` — ids re-sighted in this frame;
- ``end_iteration()`` — close the frame: apply the base rule (000 §3.4: a landmark stays
  non-base until seen ``base_seen_times = 3`` times; a non-base landmark first seen
  ``max_non_base_time = 7`` frames ago is dropped);
- ``query(Q, k=2) -> (dist (M, k), ids (M, k))`` — the ``k`` nearest stored descriptors
  (``inf`` / ``-1`` where the store holds fewer than ``k``);
- ``len(store)``.

:class:`ExactStore` answers queries exactly by brute force in OpenCV
(``cv2.batchDistance``): Hamming distance for binary ``uint8`` descriptors (ORB),
Euclidean for float ones (SIFT, SURF).
"""

from __future__ import annotations

import cv2
import numpy as np

from .. import _validate as v

__all__ = ["ExactStore", "check_store"]

_STORE_METHODS = ("add", "observe", "end_iteration", "query", "__len__")


def check_store(store, name: str = "store"):
    """Raise ``TypeError`` unless ``store`` has the five methods of the interface."""
    missing = [m for m in _STORE_METHODS if not callable(getattr(store, m, None))]
    if missing:
        raise TypeError(f"`{name}` must implement {', '.join(_STORE_METHODS)}; {type(store).__name__} lacks {', '.join(missing)}")
    return store


class ExactStore:
    """Exact brute-force descriptor store applying 000's base rule (000 §3.4).

    Parameters
    ----------
    base_seen_times : sightings that make a landmark base (000: 3).
    max_non_base_time : frames a non-base landmark may wait (000: 7).

    Examples
    --------
    >>> s = ExactStore()
    >>> s.add(np.array([[0, 0], [3, 0]], np.float32), [10, 11]); s.end_iteration()
    >>> s.query(np.array([[1, 0]], np.float32))
    (array([[1., 2.]]), array([[10, 11]]))
    """

    def __init__(self, base_seen_times: int = 3, max_non_base_time: int = 7):
        self.base_seen_times = v.check_int(base_seen_times, "base_seen_times", minimum=1)
        self.max_non_base_time = v.check_int(max_non_base_time, "max_non_base_time", minimum=1)
        self.X: np.ndarray | None = None
        self.ids = np.empty(0, dtype=np.int64)
        self.seen = np.empty(0, dtype=np.int64)
        self.first = np.empty(0, dtype=np.int64)
        self.iteration = 0
        self.dropped_ids = np.empty(0, dtype=np.int64)

    def __len__(self) -> int:
        return int(self.ids.size)

    def __repr__(self) -> str:
        return f"ExactStore(n={len(self)})"

    @property
    def is_base(self) -> np.ndarray:
        """(n,) True for stored landmarks that reached ``base_seen_times`` sightings."""
        return self.seen >= self.base_seen_times

    def _check(self, X, name):
        X = np.asarray(X)
        if X.ndim != 2 or X.shape[1] == 0:
            raise ValueError(f"`{name}` must be a 2-D (M, k) descriptor array; got shape {X.shape}")
        if X.dtype != np.uint8:
            X = v.as_finite_array(X, name, ndim=2, dtype=np.float32)
        if self.X is not None and (X.shape[1] != self.X.shape[1] or X.dtype != self.X.dtype):
            raise ValueError(f"`{name}` must be {self.X.dtype} with {self.X.shape[1]} columns like the stored descriptors; got {X.dtype} with {X.shape[1]}")
        return X

    def add(self, X, ids) -> None:
        """Store descriptors ``X (M, k)`` of new landmarks with integer ``ids (M,)``."""
        X = self._check(X, "X")
        ids = np.asarray(ids)
        if ids.shape != (X.shape[0],) or (ids.size and not np.issubdtype(ids.dtype, np.integer)):
            raise ValueError(f"`ids` must be an integer array of shape ({X.shape[0]},); got {ids.dtype} {ids.shape}")
        if X.shape[0] == 0:
            return
        self.X = X.copy() if self.X is None else np.concatenate([self.X, X])
        self.ids = np.concatenate([self.ids, ids.astype(np.int64)])
        self.seen = np.concatenate([self.seen, np.ones(ids.size, dtype=np.int64)])
        self.first = np.concatenate([self.first, np.full(ids.size, self.iteration, dtype=np.int64)])

    def observe(self, ids) -> None:
        """Count one more sighting of each stored id in ``ids``."""
        ids = np.asarray(ids, dtype=np.int64).ravel()
        if ids.size and self.ids.size:
            o = np.argsort(self.ids)
            pos = np.minimum(np.searchsorted(self.ids, ids, sorter=o), self.ids.size - 1)
            hit = self.ids[o[pos]] == ids
            self.seen += np.bincount(o[pos[hit]], minlength=self.ids.size)

    def end_iteration(self) -> None:
        """Drop non-base landmarks first seen ``max_non_base_time`` frames ago (000 §3.4)."""
        late = (self.seen < self.base_seen_times) & (self.iteration - self.first >= self.max_non_base_time)
        self.dropped_ids = self.ids[late]
        if late.any():
            keep = ~late
            self.X, self.ids, self.seen, self.first = self.X[keep], self.ids[keep], self.seen[keep], self.first[keep]
        self.iteration += 1

    def query(self, Q, k: int = 2) -> tuple[np.ndarray, np.ndarray]:
        """The ``k`` nearest stored descriptors of each row of ``Q``: ``(dist (M, k), ids (M, k))``."""
        k = v.check_int(k, "k", minimum=1)
        Q = self._check(Q, "Q")
        return self._knn(Q, self.X, self.ids, k)

    def query_among(self, Q, among, k: int = 2) -> tuple[np.ndarray, np.ndarray]:
        """Like :meth:`query`, searching only the stored landmarks whose ids are in ``among``."""
        k = v.check_int(k, "k", minimum=1)
        Q = self._check(Q, "Q")
        rows = np.isin(self.ids, np.asarray(among, dtype=np.int64).ravel())
        return self._knn(Q, None if self.X is None else self.X[rows], self.ids[rows], k)

    @staticmethod
    def _knn(Q, X, X_ids, k):
        m = Q.shape[0]
        dist = np.full((m, k), np.inf)
        ids = np.full((m, k), -1, dtype=np.int64)
        if m == 0 or X is None or len(X_ids) == 0:
            return dist, ids
        if Q.dtype == np.uint8:
            d, nidx = cv2.batchDistance(Q, X, cv2.CV_32S, normType=cv2.NORM_HAMMING, K=min(k, len(X_ids)))
        else:
            d, nidx = cv2.batchDistance(Q, X, cv2.CV_32F, normType=cv2.NORM_L2, K=min(k, len(X_ids)))
        kk = nidx.shape[1]
        ok = nidx >= 0
        dist[:, :kk] = np.where(ok, d, np.inf)
        ids[:, :kk] = np.where(ok, X_ids[np.maximum(nidx, 0)], -1)
        return dist, ids
