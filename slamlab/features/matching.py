"""Matching rules for descriptors (000 §1.4.3): two nearest neighbours, 000's 2× rule, ratio, mutual check.

000 §1.4.3: build a kd-tree on one set; for a query C find its two nearest
neighbours A and B; accept C→A when ``d(C, B) >= 2·d(C, A)`` and ``d(C, A)`` is
small enough. 000 gives no value for "small enough": ``max_dist`` is our
parameter (default: no limit). The usual form is Lowe's ratio
``d(C, A) < ratio·d(C, B)`` (000's rule is ratio 0.5 with ``>=``). A mutual
(cross) check keeps C→A only when A's nearest neighbour in the query set is C.
Binary descriptors (ORB) are compared with the Hamming distance (bits that differ).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .._validate import as_finite_array, check_choice, check_int, check_positive
from ..kdtree.knn import exact_knn, flann_index, hamming_distances, pad_knn
from ..kdtree.tree import KDTree

__all__ = [
    "KNN_METHODS",
    "Matches",
    "accept_000",
    "accept_ratio",
    "best_per_target",
    "hamming_distances",
    "knn2",
    "match_descriptors",
    "mutual_mask",
    "ratio_rule",
]

KNN_METHODS = ("brute", "kdtree", "bbf", "flann")


@dataclass(frozen=True)
class Matches:
    """Accepted matches: ``query_idx[i]`` ↔ ``train_idx[i]`` with distances d1 (nearest) and d2 (second).

    Attributes
    ----------
    query_idx, train_idx : (K,) int
        Row of each match in the query and in the train descriptor set.
    d1, d2 : (K,) float
        Descriptor distance to the nearest (the match) and to the second-nearest train row.
    """

    query_idx: np.ndarray
    train_idx: np.ndarray
    d1: np.ndarray
    d2: np.ndarray

    def __len__(self) -> int:
        return len(self.query_idx)

    def __str__(self) -> str:
        return f"{len(self)} matches"


def _as_descriptors(D, name):
    arr = np.asarray(D)
    if arr.ndim != 2:
        raise ValueError(f"`{name}` must be a 2-D (N, d) descriptor array; got shape {arr.shape}")
    if arr.dtype == np.uint8:
        return arr
    return as_finite_array(arr, name, ndim=2, dtype=np.float32 if arr.dtype == np.float32 else np.float64)


def knn2(query, train, *, method: str = "brute", max_leaves: int = 200, checks: int = 200,
         leaf_size: int = 1, tree=None):
    """Two nearest neighbours in ``train`` of every row of ``query`` (000 §1.4.3).

    Parameters
    ----------
    query, train : (M, d), (N, d) descriptor arrays (float, or uint8 binary -> Hamming, brute only)
    method : {'brute', 'kdtree', 'bbf', 'flann'}
        Dense exact search, our exact kd-tree, our Best-Bin-First (``max_leaves``),
        OpenCV FLANN (one randomised KD-tree, ``checks``).
    max_leaves : int
        Leaves Best-Bin-First visits per query (``method='bbf'``).
    checks : int
        Leaves FLANN checks per query (``method='flann'``).
    leaf_size : int
        Points per leaf of a kd-tree built here (kdtree/bbf without ``tree``).
    tree : slamlab.kdtree.KDTree, optional
        A tree already built on ``train`` (kdtree/bbf), or a FLANN index (flann).

    Returns
    -------
    dist : (M, 2) float
    idx : (M, 2) int (-1 where train has fewer than 2 points)
    """
    Q = _as_descriptors(query, "query")
    T = _as_descriptors(train, "train")
    method = check_choice(method, "method", KNN_METHODS)
    if Q.shape[1] != T.shape[1]:
        raise ValueError(f"`query` and `train` must have the same descriptor length; got {Q.shape[1]} and "
                         f"{T.shape[1]}")
    binary = Q.dtype == np.uint8
    if binary != (T.dtype == np.uint8):
        raise TypeError("`query` and `train` must both be binary (uint8) or both real-valued")
    if binary and method != "brute":
        raise ValueError(f"binary descriptors are matched with method='brute' (Hamming); got {method!r}")
    if Q.shape[0] == 0 or T.shape[0] == 0:
        return np.full((Q.shape[0], 2), np.inf), np.full((Q.shape[0], 2), -1, dtype=np.int64)
    if method == "brute":
        return exact_knn(Q, T, 2)
    if method in ("kdtree", "bbf"):
        if tree is None:
            tree = KDTree(T, leaf_size=leaf_size)
        return tree.query(Q, k=2, max_leaves=None if method == "kdtree" else check_int(max_leaves, "max_leaves",
                                                                                          minimum=1))
    checks = check_int(checks, "checks", minimum=1)
    index = tree if tree is not None else flann_index(T, trees=1)
    k = min(2, T.shape[0])
    idx, d2 = index.knnSearch(np.ascontiguousarray(Q, dtype=np.float32), k, params={"checks": checks})
    return pad_knn(np.sqrt(np.maximum(d2, 0)), idx, 2)


def ratio_rule(d1, d2, ratio: float) -> np.ndarray:
    """Lowe's ratio rule on nearest / second-nearest distances: ``d1 < ratio·d2``.

    The one copy of the rule, without argument checks (callers check ``ratio`` once);
    :func:`accept_ratio` is the checked version on an (M, 2) array.

    Parameters
    ----------
    d1, d2 : (M,) float
        Distances to the nearest and the second-nearest neighbour.
    ratio : float
        Lowe's ratio (0.8 in Lowe's paper).

    Returns
    -------
    (M,) bool
        True where the match is accepted.

    Examples
    --------
    >>> ratio_rule(np.array([0.1, 0.29]), np.array([0.3, 0.3]), 0.8).tolist()
    [True, False]
    """
    return d1 < ratio * d2


def best_per_target(target, dist) -> np.ndarray:
    """Indices (ascending) of the candidates to keep so that each target keeps only its closest one.

    ``target (M,)`` are the ids the candidates point at, ``dist (M,)`` their distances; ties go
    to the first candidate. Used for one-to-one matching (one right keypoint per left one, one
    local point per landmark).

    Parameters
    ----------
    target : (M,) int
        The id each candidate points at.
    dist : (M,) float
        Each candidate's distance.

    Returns
    -------
    (K,) int
        Ascending indices of the kept candidates, one per distinct target.

    Examples
    --------
    >>> best_per_target(np.array([7, 3, 7, 3]), np.array([0.5, 0.2, 0.1, 0.2])).tolist()
    [1, 2]
    """
    target = np.asarray(target)
    order = np.lexsort((np.asarray(dist), target))
    first = np.ones(order.size, dtype=bool)
    first[1:] = target[order][1:] != target[order][:-1]
    return np.sort(order[first])


def accept_000(dist, *, factor: float = 2.0, max_dist: float = np.inf) -> np.ndarray:
    """000's rule: accept C→A when d(C,B) >= factor·d(C,A) and d(C,A) <= max_dist (000 §1.4.3).

    Parameters
    ----------
    dist : (M, 2) float
        Nearest and second-nearest distances (:func:`knn2`).
    factor : float
        Required ratio d2 / d1 (000: 2).
    max_dist : float
        Largest accepted nearest distance (our parameter; default no limit).

    Returns
    -------
    (M,) bool
        True where the match is accepted.

    Examples
    --------
    >>> accept_000(np.array([[0.1, 0.3], [0.2, 0.3], [0.5, 2.0]]), max_dist=0.4).tolist()
    [True, False, False]
    """
    dist = np.asarray(dist, dtype=np.float64)
    if dist.ndim != 2 or dist.shape[1] < 2:
        raise ValueError(f"`dist` must have shape (M, 2) (nearest, second nearest); got {dist.shape}")
    factor = check_positive(factor, "factor")
    max_dist = float(max_dist) if np.isinf(max_dist) else check_positive(max_dist, "max_dist", allow_zero=True)
    return (dist[:, 1] >= factor * dist[:, 0]) & (dist[:, 0] <= max_dist)


def accept_ratio(dist, ratio: float = 0.8) -> np.ndarray:
    """Lowe's ratio test: accept when d(C,A) < ratio·d(C,B).

    Parameters
    ----------
    dist : (M, 2) float
        Nearest and second-nearest distances (:func:`knn2`).
    ratio : float
        Lowe's ratio (> 0).

    Returns
    -------
    (M,) bool
        True where the match is accepted.

    Examples
    --------
    >>> accept_ratio(np.array([[0.1, 0.3], [0.29, 0.3]]), 0.8).tolist()
    [True, False]
    """
    dist = np.asarray(dist, dtype=np.float64)
    if dist.ndim != 2 or dist.shape[1] < 2:
        raise ValueError(f"`dist` must have shape (M, 2) (nearest, second nearest); got {dist.shape}")
    ratio = check_positive(ratio, "ratio")
    return ratio_rule(dist[:, 0], dist[:, 1], ratio)


def mutual_mask(idx12, idx21) -> np.ndarray:
    """True where query i's nearest train j has i as its own nearest query (cross check).

    Parameters
    ----------
    idx12 : (M,) int
        Nearest train row of each query row (-1 for none).
    idx21 : (N,) int
        Nearest query row of each train row.

    Returns
    -------
    (M,) bool
        True for the mutual nearest neighbours.

    Examples
    --------
    >>> mutual_mask(np.array([1, 0, 1]), np.array([1, 2])).tolist()
    [False, True, True]
    """
    idx12 = np.asarray(idx12, dtype=np.int64)
    idx21 = np.asarray(idx21, dtype=np.int64)
    ok = (idx12 >= 0) & (idx12 < idx21.size)
    out = np.zeros(idx12.size, dtype=bool)
    out[ok] = idx21[idx12[ok]] == np.flatnonzero(ok)
    return out


def match_descriptors(query, train, *, rule: str = "000", factor: float = 2.0, ratio: float = 0.8,
                      max_dist: float = np.inf, mutual: bool = False, method: str = "brute",
                      max_leaves: int = 200, checks: int = 200) -> Matches:
    """Match two descriptor sets with a 2-NN search and an acceptance rule (000 §1.4.3).

    Parameters
    ----------
    query, train : (M, d), (N, d) descriptor arrays
        Float, or uint8 binary descriptors (Hamming distance, ``method='brute'`` only).
    rule : {'000', 'ratio', 'none'}
        000's ``d2 >= factor·d1`` (with ``max_dist``), Lowe's ``d1 < ratio·d2`` (with
        ``max_dist``), or every nearest neighbour (``max_dist`` only).
    factor : float
        000's factor for ``rule='000'``.
    ratio : float
        Lowe's ratio for ``rule='ratio'``.
    max_dist : float
        Largest accepted nearest distance (default no limit).
    mutual : bool
        Also require the reverse nearest neighbour to agree.
    method : {'brute', 'kdtree', 'bbf', 'flann'}
        Nearest-neighbour search, see :func:`knn2`.
    max_leaves, checks : int
        Search budgets of 'bbf' and 'flann' (:func:`knn2`).

    Returns
    -------
    Matches
        ``query_idx``, ``train_idx`` of the accepted matches with their ``d1``, ``d2``.
    """
    rule = check_choice(rule, "rule", ("000", "ratio", "none"))
    d, idx = knn2(query, train, method=method, max_leaves=max_leaves, checks=checks)
    if rule == "000":
        keep = accept_000(d, factor=factor, max_dist=max_dist)
    elif rule == "ratio":
        keep = accept_ratio(d, ratio) & (d[:, 0] <= max_dist)
    else:
        keep = d[:, 0] <= max_dist
    keep &= idx[:, 0] >= 0
    if mutual:
        _, back = knn2(train, query, method=method, max_leaves=max_leaves, checks=checks)
        keep &= mutual_mask(idx[:, 0], back[:, 0])
    q = np.flatnonzero(keep)
    return Matches(q, idx[q, 0], d[q, 0], d[q, 1])
