"""Independent computations behind the accepted ranges of labs 02 and 03's explorations (issues 26, 43).

Each recomputes an exploration's answer without the library code the student is asked to use:
a brute-force repeatability count, exact nearest neighbours from SciPy, a SciPy 2-NN matcher; and
the values of the typical mistakes (one-to-one pairs, no common region, squared distances, a store
without distractors) the tests check over many settings.
"""

from __future__ import annotations

import functools

import numpy as np

from slamlab.geometry.homography import apply_homography
from slamlab.kdtree import KDTree


@functools.lru_cache(maxsize=1)
def wall_repeatability_brute_force() -> tuple[tuple[str, ...], np.ndarray]:
    """Lab 02's Exploration 2 recounted by brute force (not :func:`slamlab.features.repeatability`'s kd-tree).

    The library's keypoints (500 strongest, half scale), mapped through the ground-truth homography;
    each image keeps the points the other sees; a point is repeated when a point of the other image
    lies within 2.5 px (all pairwise distances); min(repeated 1, repeated 2) / min(n1, n2) (000 §1.4).

    Returns
    -------
    detectors : tuple of str
        The four detectors, in column order.
    rep : numpy.ndarray, shape (5, 4)
        Repeatability per pair (rows 1→2 ... 1→6) and detector.
    """
    names, _ = _wall_keypoints()
    return names, wall_repeatability_variants((2.5,))["pixel centres 0..W-1"][0]


@functools.lru_cache(maxsize=1)
def bbf_recall_exact_truth(budgets: tuple[int, ...]) -> dict[str, np.ndarray]:
    """Lab 03's Exploration 1 with the true nearest neighbours from SciPy's exact cKDTree: BBF recall.

    The store rebuilt from its definition (graf img1's SURF descriptors, threshold 5e-5, half scale,
    plus distractors to 10000); the library's BBF (the question's subject) at every budget; query
    sets of img2: the 200 strongest (the question's), ranks 200-399 and ranks 400-599.

    Parameters
    ----------
    budgets : tuple of int
        Leaf budgets (the question's grid).

    Returns
    -------
    dict of str to numpy.ndarray
        Recall per budget, keyed by query set.
    """
    from scipy.spatial import cKDTree

    from slamlab.features import detect, load_oxford_pair
    from slamlab.studies.features import descriptor_pool

    img1, img2, _ = load_oxford_pair("graf", 2, scale=0.5)
    f1 = detect(img1, "surf", threshold=5e-5).strongest(10000)
    train = np.concatenate([f1.descriptors, descriptor_pool(10000 - len(f1), exclude="graf", scale=0.5,
                                                            threshold=5e-5)])
    f2 = detect(img2, "surf", threshold=5e-5)
    rank = np.argsort(-f2.response, kind="stable")  # strongest first
    _, nn = cKDTree(train).query(f2.descriptors, k=1)
    tree = KDTree(train)
    out = {}
    for lo in (0, 200, 400):
        q = rank[lo:lo + 200]
        found = [tree.query(f2.descriptors[q], k=2, max_leaves=b)[1][:, 0] for b in budgets]
        out[f"ranks {lo}-{lo + 199}"] = np.array([np.mean(f == nn[q]) for f in found])
    return out


@functools.lru_cache(maxsize=1)
def _boat_matches() -> tuple[np.ndarray, np.ndarray]:
    """Lab 03's Exploration 2 matched by SciPy's cKDTree: each img1 point's two distances and its match's error (px)."""
    from scipy.spatial import cKDTree

    from slamlab.features import detect, load_oxford_pair

    img1, img2, H = load_oxford_pair("boat", 2, scale=0.5)
    f1, f2 = (detect(img, "surf", max_points=1000, threshold=1e-4) for img in (img1, img2))
    d, i = cKDTree(f2.descriptors).query(f1.descriptors, k=2)
    return d, np.linalg.norm(apply_homography(H, f1.uv) - f2.uv[i[:, 0]], axis=1)


def ratio_precision_independent(ratios: tuple[float, ...], tol: float = 2.5, *, squared: bool = False) -> np.ndarray:
    """Lab 03's Exploration 2 with an independent matcher: precision per ratio.

    The library's SURF keypoints of boat 1 and 2 (1000 strongest, half scale, threshold 1e-4: all of
    them), 2-NN from SciPy's cKDTree, Lowe's d1 < r d2 alone, correct when the homography maps the
    point within ``tol`` px of its match.

    Parameters
    ----------
    ratios : tuple of float
        Lowe ratios (the question's grid).
    tol : float
        The correct-match tolerance in half-scale pixels (the question's is 2.5).
    squared : bool
        Test d1² < r d2² instead (a typical mistake).

    Returns
    -------
    numpy.ndarray
        Precision per ratio (NaN where no match is kept).
    """
    d, err = _boat_matches()
    ok = err < tol
    e = 2 if squared else 1
    keep = [d[:, 0] ** e < r * d[:, 1] ** e for r in ratios]
    return np.array([ok[k].mean() if k.any() else np.nan for k in keep])


@functools.lru_cache(maxsize=1)
def _wall_keypoints():
    """Lab 02's Exploration 2: per pair 1→j of wall, (shape1, shape2, H, [(uv1, uv2) per detector])."""
    from slamlab.features import detect, load_oxford_pair
    from slamlab.studies.features import EVAL_DETECTORS

    out = []
    for j in (2, 3, 4, 5, 6):
        a, b, H = load_oxford_pair("wall", j, scale=0.5)
        uv = []
        for method, params in EVAL_DETECTORS.values():  # ORB's n_features (3000) already exceeds 2 x 500
            f1, f2 = (detect(img, method, max_points=500, **params) for img in (a, b))
            uv.append((f1.uv, f2.uv))
        out.append((a.shape, b.shape, H, uv))
    return tuple(EVAL_DETECTORS), out


def _inside(p, shape, region):
    u, v = p[:, 0], p[:, 1]
    H, W = shape[:2]
    if region == "pixel centres 0..W-1":
        return (u >= 0) & (v >= 0) & (u <= W - 1) & (v <= H - 1)
    if region == "pixel areas -0.5..W-0.5":
        return (u > -0.5) & (v > -0.5) & (u < W - 0.5) & (v < H - 0.5)
    if region == "0 <= u < W":
        return (u >= 0) & (v >= 0) & (u < W) & (v < H)
    return np.ones(len(p), dtype=bool)  # "no common region"


@functools.lru_cache(maxsize=4)
def wall_repeatability_variants(tols: tuple[float, ...]) -> dict[str, np.ndarray]:
    """Lab 02's Exploration 2 counted in several ways, brute force, for several tolerances.

    The question's count under three readings of "inside the other image" (``WALL_REGIONS`` of the
    task module), and two mistakes: "one-to-one" (a maximum one-to-one pairing of the points within
    the tolerance, pixel-centre region) and "no common region" (every keypoint counts).

    Parameters
    ----------
    tols : tuple of float
        Tolerances in half-scale pixels (the question's is 2.5).

    Returns
    -------
    dict of str to numpy.ndarray
        Repeatability, shape (len(tols), 5 pairs, 4 detectors), per variant.
    """
    from scipy.sparse import csr_matrix
    from scipy.sparse.csgraph import maximum_bipartite_matching

    regions = ("pixel centres 0..W-1", "pixel areas -0.5..W-0.5", "0 <= u < W", "no common region")
    _, pairs = _wall_keypoints()
    out = {v: np.zeros((len(tols), 5, 4)) for v in (*regions, "one-to-one")}
    for i, (s1, s2, H, uv) in enumerate(pairs):
        for k, (u1, u2) in enumerate(uv):
            p1, p2 = apply_homography(H, u1), apply_homography(np.linalg.inv(H), u2)
            for v in (*regions, "one-to-one"):
                region = regions[0] if v == "one-to-one" else v
                in1, in2 = _inside(p1, s2, region), _inside(p2, s1, region)
                D = np.linalg.norm(p1[in1][:, None, :] - u2[in2][None, :, :], axis=2)
                den = min(in1.sum(), in2.sum())
                for t, tol in enumerate(tols):
                    near = tol > D
                    if v == "one-to-one":
                        m = int((maximum_bipartite_matching(csr_matrix(near), perm_type="column") >= 0).sum())
                    else:
                        m = min(near.any(axis=1).sum(), near.any(axis=0).sum())
                    out[v][t, i, k] = m / den
    return out


@functools.lru_cache(maxsize=1)
def bbf_recall_without_distractors(budgets: tuple[int, ...]) -> np.ndarray:
    """Lab 03's Exploration 1 with img1's descriptors alone stored (a typical mistake): recall per budget.

    Parameters
    ----------
    budgets : tuple of int
        Leaf budgets (the question's grid).

    Returns
    -------
    numpy.ndarray
        Recall of img2's 200 strongest queries per budget.
    """
    found, nn, rank = bbf_found_all_queries(budgets, distractors=False)
    q = rank[:200]
    return (found[:, q] == nn[q]).mean(axis=1)


@functools.lru_cache(maxsize=2)
def bbf_found_all_queries(budgets: tuple[int, ...], *, distractors: bool = True):
    """BBF's first neighbour of every img2 SURF query at every budget, the exact neighbour, the strength ranks.

    Parameters
    ----------
    budgets : tuple of int
        Leaf budgets.
    distractors : bool
        The question's store of 10000 (True) or img1's descriptors alone.

    Returns
    -------
    found : numpy.ndarray, shape (len(budgets), M)
        BBF's first id per budget and query.
    nn : numpy.ndarray, shape (M,)
        The exact nearest neighbour (SciPy's cKDTree).
    rank : numpy.ndarray, shape (M,)
        Query indices, strongest first.
    """
    from scipy.spatial import cKDTree

    from slamlab.features import detect, load_oxford_pair
    from slamlab.studies.features import descriptor_pool

    img1, img2, _ = load_oxford_pair("graf", 2, scale=0.5)
    f1 = detect(img1, "surf", threshold=5e-5).strongest(10000)
    train = f1.descriptors
    if distractors:
        train = np.concatenate([train, descriptor_pool(10000 - len(f1), exclude="graf", scale=0.5, threshold=5e-5)])
    f2 = detect(img2, "surf", threshold=5e-5)
    _, nn = cKDTree(train).query(f2.descriptors, k=1)
    tree = KDTree(train)
    found = np.stack([tree.query(f2.descriptors, k=2, max_leaves=b)[1][:, 0] for b in budgets])
    return found, nn, np.argsort(-f2.response, kind="stable")
