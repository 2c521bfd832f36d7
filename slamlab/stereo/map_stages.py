"""Stereo SLAM stage 3: local landmarks matched to the map through a store (000 §3.4); the pose (stage 4) is in
:mod:`slamlab.stereo.pose_stages`.

Part of :mod:`slamlab.stereo.stages` (which re-exports every name; its docstring gives the pipeline's order).
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from .. import _validate as v
from .._compiled import numba_enabled
from ..features.matching import best_per_target, ratio_rule
from ..geometry.camera import project_points
from ..kdtree.stores import LandmarkStore
from ._pairs import _pair_distances, _two_nearest
from .params import StereoParams
from .window_kernel import window_hamming_2nn

__all__ = ["MapMatches", "match_to_map"]


# --- local landmarks to map landmarks through a store (000 §3.4) -----------------------------------


class MapMatches(NamedTuple):
    """``local (M,)`` indices into the local cloud, ``ids (M,)`` landmark ids, ``distance (M,)``,
    ``unmatched (K - M,)`` local indices that found no landmark (candidates for new landmarks), and
    ``nearest (K,)``: every local point's nearest landmark by descriptor (-1: none), matched or not.

    Attributes
    ----------
    local : numpy.ndarray of int, shape (M,)
        Indices into the local cloud.
    ids : numpy.ndarray of int, shape (M,)
        Landmark ids.
    distance : numpy.ndarray, shape (M,)
        Descriptor distances.
    unmatched : numpy.ndarray of int, shape (K - M,)
        Local indices without a landmark.
    nearest : numpy.ndarray of int, shape (K,) or None
        Each local point's nearest landmark id (-1: none).
    """

    local: np.ndarray
    ids: np.ndarray
    distance: np.ndarray
    unmatched: np.ndarray
    nearest: np.ndarray | None = None


def match_to_map(descriptors, store: LandmarkStore, *, params: StereoParams | None = None, positions=None,
                 candidates=None, max_distance: float | None = None, **overrides) -> MapMatches:
    """Match local descriptors to the stored landmarks: 2-NN query + ratio rule, one local per landmark (000 §3.4).

    The ratio is ``map_ratio`` of ``params`` / ``overrides`` (:class:`StereoParams`). With
    ``positions`` ((n, 3) landmark positions indexed by id) and ``same_point_m``, two nearest
    landmarks closer than ``same_point_m`` to each other count as one physical point (a duplicate
    added when a sighting was missed), so the ratio rule does not reject them (our addition:
    without it, duplicates make every later sighting of a place ambiguous and the map stops
    closing loops).

    With ``candidates`` (landmark ids), only those landmarks are searched
    (:meth:`~slamlab.kdtree.LandmarkStore.query_among`, exact for every store).

    Parameters
    ----------
    descriptors : array_like, shape (K, D)
        Descriptors of the local points.
    store : LandmarkStore
        The map's descriptor store.
    params : StereoParams, optional
        Pipeline settings (``map_ratio``, ``same_point_m``).
    positions : array_like, shape (n, 3), optional
        Landmark positions by id [m] (for the same-point rule).
    candidates : array_like of int, optional
        Landmark ids to search (None: all).
    max_distance : float, optional
        Largest descriptor distance accepted.
    **overrides
        :class:`StereoParams` fields to change.

    Returns
    -------
    MapMatches

    Examples
    --------
    >>> from slamlab.kdtree import ExactStore
    >>> s = ExactStore(); s.add(np.array([[0.0, 0.0], [5.0, 0.0]]), [7, 8])
    >>> m = match_to_map(np.array([[0.1, 0.0], [2.4, 0.0]]), s)
    >>> m.local.tolist(), m.ids.tolist(), m.unmatched.tolist()
    ([0], [7], [1])
    """
    p = StereoParams.resolve(params, **overrides)
    D = np.asarray(descriptors)
    if D.ndim != 2:
        raise ValueError(f"`descriptors` must be 2-D (K, D); got shape {D.shape}")
    if not isinstance(store, LandmarkStore):
        raise TypeError(f"`store` must be a slamlab.kdtree.LandmarkStore; got {type(store).__name__}")
    X = None if positions is None else v.as_finite_array(positions, "positions", ndim=2)
    cand = None if candidates is None else np.asarray(candidates, dtype=np.int64).ravel()
    max_distance = None if max_distance is None else v.check_positive(max_distance, "max_distance")
    return _match_to_map(D, store, p.map_ratio, X, p.same_point_m or None, cand, max_distance)


def _match_to_map(D, store, ratio, positions=None, same_point_m=None, candidates=None, max_distance=None):
    """:func:`match_to_map` on checked arguments (the per-frame core)."""
    k = D.shape[0]
    if k == 0 or len(store) == 0:
        return MapMatches(np.empty(0, np.intp), np.empty(0, np.int64), np.empty(0), np.arange(k), np.full(k, -1))
    if candidates is not None:
        dist, ids = store.query_among(D, candidates, k=2)
    else:
        dist, ids = store.query(D, k=2)
    return _matches_from_knn(dist, ids, ratio, positions, same_point_m, max_distance)


def _accept_twins(ok, first, second, positions, same_point_m):
    """Set ``ok`` (in place) where the ratio rule failed only because the nearest and second-nearest
    landmarks (ids ``first``, ``second``; -1: none) lie within ``same_point_m`` of each other: one point."""
    if positions is None or same_point_m is None:
        return
    both = ~ok & (first >= 0) & (second >= 0)
    if both.any():
        gap = np.linalg.norm(positions[first[both]] - positions[second[both]], axis=1)
        ok[np.flatnonzero(both)[gap < same_point_m]] = True


def _matches_from_knn(dist, ids, ratio, positions=None, same_point_m=None, max_distance=None) -> MapMatches:
    """:class:`MapMatches` from the 2-NN ``(dist, ids)`` of every local point (the rules of :func:`match_to_map`)."""
    k = dist.shape[0]
    ok = (ids[:, 0] >= 0) & ratio_rule(dist[:, 0], dist[:, 1], ratio)
    _accept_twins(ok, ids[:, 0], ids[:, 1], positions, same_point_m)
    if max_distance is not None:
        ok &= dist[:, 0] <= max_distance
    loc = np.flatnonzero(ok)
    lid, d = ids[ok, 0], dist[ok, 0]
    sel = best_per_target(lid, d)  # one local point per landmark: the closest descriptor wins
    claimed = np.zeros(k, dtype=bool)
    claimed[loc] = True  # ratio-passing points that lost a duplicate are neither matches nor new
    return MapMatches(loc[sel], lid[sel], d[sel], np.flatnonzero(~claimed), ids[:, 0])


def _radius_cells(uv_q, uv_t, radius):
    """Targets bucketed in a grid of ``radius`` cells: ``(order, lo, hi)``, the targets sorted by cell and, for
    query ``i`` and column offset ``c`` (-1, 0, 1), its 3 cells of that column as the range ``order[lo[i, c]:hi[i, c]]``."""
    lo_xy = np.minimum(uv_q.min(axis=0), uv_t.min(axis=0))
    cq = np.floor((uv_q - lo_xy) / radius).astype(np.int64)
    ct = np.floor((uv_t - lo_xy) / radius).astype(np.int64)
    ny = int(max(cq[:, 1].max(), ct[:, 1].max())) + 3
    key_t = (ct[:, 0] + 1) * ny + ct[:, 1] + 1
    order = np.argsort(key_t, kind="stable")
    keys = key_t[order]
    # the 3 cells of a column are consecutive keys: one range per column offset
    base = (cq[:, 0:1] + 1 + np.arange(-1, 2)) * ny + cq[:, 1:2] + 1  # (k, 3) middle cell of each column
    # where each key starts in the sorted keys: searchsorted(keys, x, "left") = start[x], (x, "right") = start[x + 1]
    n_keys = (int(max(cq[:, 0].max(), ct[:, 0].max())) + 3) * ny  # above every key and every base + 1
    start = np.zeros(n_keys + 1, np.int64)
    np.cumsum(np.bincount(keys, minlength=n_keys), out=start[1:])
    return order, start[base - 1], start[base + 2]


def _radius_pairs(uv_q, uv_t, radius):
    """All pairs ``(query, target)`` of 2-D points at most ``radius`` apart, grouped by ascending query
    index: targets bucketed in a grid of ``radius`` cells, each query looks in its 3 x 3 cells."""
    order, lo, hi = _radius_cells(uv_q, uv_t, radius)
    cnt = (hi - lo).ravel()
    qi = np.repeat(np.arange(len(uv_q)), 3)
    qi = np.repeat(qi, cnt)
    ti = order[np.arange(cnt.sum()) - np.repeat(np.cumsum(cnt) - cnt - lo.ravel(), cnt)]
    d = uv_q[qi] - uv_t[ti]
    keep = np.einsum("ij,ij->i", d, d) <= radius * radius
    return qi[keep], ti[keep]


def _window_two_nearest(D, uv, desc_lm, uv_lm, radius_px):
    """Nearest and second-nearest landmark by descriptor among those within ``radius_px`` of each keypoint:
    ``(query, nearest, d1, d2, second)`` as :func:`_two_nearest`, and the number of pairs compared. Binary
    descriptors take the compiled kernel when numba is enabled (same result, tested), otherwise numpy."""
    if D.dtype == np.uint8 and D.shape[1] % 8 == 0 and numba_enabled():
        order, lo, hi = _radius_cells(uv, uv_lm, radius_px)
        r1, d1, d2, r2, n_pairs = window_hamming_2nn(D.view(np.uint64), desc_lm.view(np.uint64), uv, uv_lm,
                                                     order, lo, hi, float(radius_px))
        q = np.flatnonzero(r1 >= 0)
        return q, r1[q], d1[q], d2[q], r2[q], int(n_pairs)
    qi, rows = _radius_pairs(uv, uv_lm, radius_px)
    if qi.size == 0:
        return qi, qi, np.empty(0), np.empty(0), qi, 0
    d = _pair_distances(D, desc_lm, qi, rows)
    return (*_two_nearest(qi, rows, d), int(qi.size))


def _window_match(D, uv, desc_lm, uv_lm, ids_lm, radius_px, ratio, max_distance, positions=None,
                  same_point_m=None) -> tuple[MapMatches, int]:
    """Map matching by projection (our addition to 000 §3.4): each local point (left keypoint ``uv``,
    descriptor ``D``) is compared only with the landmarks ``ids_lm`` that a predicted pose projects within
    ``radius_px`` of it (pixels ``uv_lm``, descriptors ``desc_lm``); nearest and second nearest of those
    decide by the ratio rule (two neighbours closer than ``same_point_m`` count as one), the nearest
    must be within ``max_distance``, one local point per landmark. Returns the matches and the number of
    descriptor distances computed."""
    k = D.shape[0]
    none = MapMatches(np.empty(0, np.intp), np.empty(0, np.int64), np.empty(0), np.arange(k), np.full(k, -1))
    if k == 0 or len(ids_lm) == 0:
        return none, 0
    q, r1, d1, d2, r2, n_pairs = _window_two_nearest(D, uv, desc_lm, uv_lm, radius_px)
    if n_pairs == 0:
        return none, 0
    ok = ratio_rule(d1, d2, ratio)
    _accept_twins(ok, ids_lm[r1], np.where(r2 >= 0, ids_lm[r2], -1), positions, same_point_m)
    ok &= d1 <= max_distance
    nearest = np.full(k, -1, dtype=np.int64)
    nearest[q] = ids_lm[r1]
    loc, lid, dd = q[ok], ids_lm[r1[ok]], d1[ok]
    sel = best_per_target(lid, dd)
    claimed = np.zeros(k, dtype=bool)
    claimed[loc] = True
    return MapMatches(loc[sel], lid[sel], dd[sel], np.flatnonzero(~claimed), nearest), n_pairs


def _window_candidates(X, ids, T_wc, cam, window_px):
    """The landmarks ``X`` (ids ``ids``) projected into ``cam`` at ``T_wc`` whose row lies within ``window_px`` of
    the image: ``(ids, uv)`` of those (the window search's candidates)."""
    Xc = (X - T_wc[:3, 3]) @ T_wc[:3, :3]
    uv_lm = project_points(cam.K, Xc)
    inside = (uv_lm[:, 1] >= -window_px) & (uv_lm[:, 1] <= cam.height_px + window_px)
    return ids[inside], uv_lm[inside]
