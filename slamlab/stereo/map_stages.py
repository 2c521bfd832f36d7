"""Stereo SLAM stage 3: local landmarks matched to the map (000 §3.4); the pose (stage 4) is in
:mod:`slamlab.stereo.pose_stages`.

Three searches, one set of rules (2-NN by descriptor, the ratio rule, one local point per landmark):
:func:`match_to_map` through the landmark store (000), :func:`match_to_landmarks` against a given set of
landmarks by brute force, and :func:`match_in_window`, each point against the landmarks a predicted pose
projects near it (the last two: the window search, our addition).

Part of :mod:`slamlab.stereo.stages` (which re-exports every name; its docstring gives the pipeline's order).
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from .._compiled import numba_enabled
from .._validate import as_finite_array, as_matrix, check_positive
from ..features.matching import best_per_target, ratio_rule
from ..geometry.camera import PinholeCamera, project_points
from ..kdtree.knn import exact_knn
from ..kdtree.stores import LandmarkStore
from ._pairs import pair_distances, two_nearest
from .params import StereoParams
from .window_kernel import window_hamming_2nn

__all__ = ["MapMatches", "match_in_window", "match_to_landmarks", "match_to_map"]


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
    ``positions`` ((n, 3) landmark positions indexed by id) and ``same_point_m`` (in use:
    :attr:`StereoParams.twin_gap_m`), two nearest landmarks closer than that to each other count as
    one physical point (a duplicate added when a sighting was missed), so the ratio rule does not
    reject them (our addition: without it, duplicates make every later sighting of a place ambiguous
    and the map stops closing loops).

    With ``candidates`` (landmark ids), only those landmarks are searched
    (:meth:`~slamlab.kdtree.LandmarkStore.query_among`, exact for every store).

    Parameters
    ----------
    descriptors : array_like, shape (K, D)
        Descriptors of the local points.
    store : LandmarkStore
        The map's descriptor store.
    params : StereoParams, optional
        Pipeline settings (``map_ratio``, ``same_point_m``, ``map_search``).
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
    D = _check_descriptors(descriptors)
    if not isinstance(store, LandmarkStore):
        raise TypeError(f"`store` must be a slamlab.kdtree.LandmarkStore; got {type(store).__name__}")
    X = None if positions is None else _check_positions(positions)
    cand = None if candidates is None else np.asarray(candidates, dtype=np.int64).ravel()
    max_distance = None if max_distance is None else check_positive(max_distance, "max_distance")
    k = D.shape[0]
    if k == 0 or len(store) == 0:
        return _no_matches(k)
    if cand is not None:
        dist, ids = store.query_among(D, cand, k=2)
    else:
        dist, ids = store.query(D, k=2)
    return _matches_from_knn(dist, ids, p.map_ratio, X, p.twin_gap_m, max_distance)


def match_to_landmarks(descriptors, landmark_ids, landmark_descriptors, *, positions=None,
                       params: StereoParams | None = None, **overrides) -> MapMatches:
    """Match local descriptors to a given set of landmarks by brute force (our addition to 000 §3.4).

    The first step of the window search (``map_search='window'``): the landmarks of the last located
    frame, searched exactly (:func:`slamlab.kdtree.knn.exact_knn`), with the rules of
    :func:`match_to_map` (ratio ``map_ratio``, the same-point rule, one local point per landmark).

    Parameters
    ----------
    descriptors : array_like, shape (K, D)
        Descriptors of the local points.
    landmark_ids : array_like of int, shape (L,)
        Ids of the landmarks to search.
    landmark_descriptors : array_like, shape (L, D)
        Their descriptors, in the order of ``landmark_ids``.
    positions : array_like, shape (n, 3), optional
        Landmark positions by id [m] (for the same-point rule).
    params : StereoParams, optional
        Pipeline settings (``map_ratio``, ``same_point_m``, ``map_search``).
    **overrides
        :class:`StereoParams` fields to change.

    Returns
    -------
    MapMatches

    Examples
    --------
    >>> m = match_to_landmarks(np.array([[0.1, 0.0], [2.4, 0.0]]), [7, 8], np.array([[0.0, 0.0], [5.0, 0.0]]))
    >>> m.local.tolist(), m.ids.tolist(), m.unmatched.tolist()
    ([0], [7], [1])
    """
    p = StereoParams.resolve(params, **overrides)
    D = _check_descriptors(descriptors)
    ids = np.asarray(landmark_ids, dtype=np.int64).ravel()
    D_lm = _check_descriptors(landmark_descriptors, "landmark_descriptors", len(ids))
    X = None if positions is None else _check_positions(positions)
    if len(D) == 0 or len(ids) == 0:
        return _no_matches(len(D))
    dist, nn = exact_knn(D, D_lm, 2, ids)
    return _matches_from_knn(dist, nn, p.map_ratio, X, p.twin_gap_m)


def match_in_window(descriptors, uv, landmark_ids, landmark_descriptors, positions, T_wc, camera: PinholeCamera, *,
                    params: StereoParams | None = None, **overrides) -> tuple[MapMatches, int]:
    """Map matching by projection (our addition to 000 §3.4): each point only against the landmarks projected near it.

    The landmarks ``landmark_ids`` (positions ``positions[landmark_ids]``) are projected into ``camera`` at the
    predicted pose ``T_wc``; those whose row lies within ``window_px`` of the image are candidates. Each local
    point (left keypoint ``uv``, descriptor ``descriptors``) is compared only with the candidates within
    ``window_px`` of it; the nearest and second nearest of those decide by the ratio rule ``map_ratio`` (two
    neighbours closer than ``same_point_m`` count as one), the nearest must be within ``window_max_hamming``
    (binary descriptors; no bound for float ones), one local point per landmark.

    Parameters
    ----------
    descriptors : array_like, shape (K, D)
        Descriptors of the local points.
    uv : array_like, shape (K, 2)
        Their left keypoints [px].
    landmark_ids : array_like of int, shape (L,)
        Ids of the landmarks to search (those in view of the predicted pose).
    landmark_descriptors : array_like, shape (L, D)
        Their descriptors, in the order of ``landmark_ids``.
    positions : array_like, shape (n, 3)
        Landmark positions by id in the map frame [m].
    T_wc : array_like, shape (4, 4)
        Predicted pose of the left camera in the map.
    camera : PinholeCamera
        The left camera.
    params : StereoParams, optional
        Pipeline settings (``window_px``, ``window_max_hamming``, ``map_ratio``, ``same_point_m``).
    **overrides
        :class:`StereoParams` fields to change.

    Returns
    -------
    matches : MapMatches
    n_pairs : int
        Descriptor distances computed.

    Examples
    --------
    >>> from slamlab.geometry import PinholeCamera
    >>> cam = PinholeCamera(100, 80, 50.0, 50.0, 50.0, 40.0)
    >>> X = np.array([[0.0, 0.0, 5.0], [2.0, 0.0, 5.0]])  # projected at u = 50 and u = 70
    >>> m, n = match_in_window(np.array([[0.1, 0.0]]), [[51.0, 40.0]], [0, 1], np.array([[0.0, 0.0], [0.1, 0.0]]),
    ...                        X, np.eye(4), cam, window_px=5.0)
    >>> m.ids.tolist(), n
    ([0], 1)
    """
    p = StereoParams.resolve(params, **overrides)
    D = _check_descriptors(descriptors)
    uv = as_finite_array(uv, "uv", ndim=2)
    if uv.shape != (len(D), 2):
        raise ValueError(f"`uv` must have shape ({len(D)}, 2), one pixel per descriptor; got {uv.shape}")
    ids = np.asarray(landmark_ids, dtype=np.int64).ravel()
    D_lm = _check_descriptors(landmark_descriptors, "landmark_descriptors", len(ids))
    X = _check_positions(positions)
    T_wc = as_matrix(T_wc, "T_wc", (4, 4))
    if not isinstance(camera, PinholeCamera):
        raise TypeError(f"`camera` must be a PinholeCamera; got {type(camera).__name__}")
    Xc = (X[ids] - T_wc[:3, 3]) @ T_wc[:3, :3]
    uv_lm = project_points(camera.K, Xc)
    inside = (uv_lm[:, 1] >= -p.window_px) & (uv_lm[:, 1] <= camera.height_px + p.window_px)
    max_d = p.window_max_hamming if p.binary else np.inf
    return _window_match(D, uv, D_lm[inside], uv_lm[inside], ids[inside], p.window_px, p.map_ratio, max_d, X,
                         p.twin_gap_m)


def _check_descriptors(D, name="descriptors", n=None):
    D = np.asarray(D)
    if D.ndim != 2:
        raise ValueError(f"`{name}` must be 2-D (K, D); got shape {D.shape}")
    if n is not None and len(D) != n:
        raise ValueError(f"`{name}` must have one row per landmark id ({n}); got {len(D)}")
    return D


def _check_positions(positions):
    X = as_finite_array(positions, "positions", ndim=2)
    if X.shape[1] != 3:
        raise ValueError(f"`positions` must have shape (n, 3); got {X.shape}")
    return X


def _no_matches(k) -> MapMatches:
    return MapMatches(np.empty(0, np.intp), np.empty(0, np.int64), np.empty(0), np.arange(k), np.full(k, -1))


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
    ``(query, nearest, d1, d2, second)`` as ``two_nearest``, and the number of pairs compared. Binary
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
    d = pair_distances(D, desc_lm, qi, rows)
    return (*two_nearest(qi, rows, d), int(qi.size))


def _window_match(D, uv, desc_lm, uv_lm, ids_lm, radius_px, ratio, max_distance, positions=None,
                  same_point_m=None) -> tuple[MapMatches, int]:
    """Map matching by projection (our addition to 000 §3.4): each local point (left keypoint ``uv``,
    descriptor ``D``) is compared only with the landmarks ``ids_lm`` that a predicted pose projects within
    ``radius_px`` of it (pixels ``uv_lm``, descriptors ``desc_lm``); nearest and second nearest of those
    decide by the ratio rule (two neighbours closer than ``same_point_m`` count as one), the nearest
    must be within ``max_distance``, one local point per landmark. Returns the matches and the number of
    descriptor distances computed."""
    k = D.shape[0]
    none = _no_matches(k)
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
