"""Independent computations behind the accepted ranges of labs 02 and 03's explorations (issue 26).

Each recomputes an exploration's answer without the library code the student is asked to use:
a brute-force repeatability count, exact nearest neighbours from SciPy, a SciPy 2-NN matcher.
"""

from __future__ import annotations

import functools

import numpy as np

from ..geometry.homography import apply_homography
from ..kdtree import KDTree


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
    from ..features import detect, load_oxford_pair
    from ..studies.features import EVAL_DETECTORS

    names = tuple(EVAL_DETECTORS)
    rep = np.zeros((5, len(names)))
    for i, j in enumerate((2, 3, 4, 5, 6)):
        a, b, H = load_oxford_pair("wall", j, scale=0.5)
        for k, name in enumerate(names):
            method, params = EVAL_DETECTORS[name]  # ORB's n_features (3000) already exceeds 2 x 500
            f1, f2 = (detect(img, method, max_points=500, **params) for img in (a, b))
            p1, p2 = apply_homography(H, f1.uv), apply_homography(np.linalg.inv(H), f2.uv)
            in1 = (p1 >= 0).all(axis=1) & (p1[:, 0] <= b.shape[1] - 1) & (p1[:, 1] <= b.shape[0] - 1)
            in2 = (p2 >= 0).all(axis=1) & (p2[:, 0] <= a.shape[1] - 1) & (p2[:, 1] <= a.shape[0] - 1)
            D = np.linalg.norm(p1[in1][:, None, :] - f2.uv[in2][None, :, :], axis=2)
            near = D < 2.5
            rep[i, k] = min(near.any(axis=1).sum(), near.any(axis=0).sum()) / min(in1.sum(), in2.sum())
    return names, rep


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

    from ..features import detect, load_oxford_pair
    from ..studies.features import descriptor_pool

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
def ratio_precision_independent(ratios: tuple[float, ...]) -> np.ndarray:
    """Lab 03's Exploration 2 with an independent matcher: precision per ratio.

    The library's SURF keypoints of boat 1 and 2 (1000 strongest, half scale), 2-NN from SciPy's
    cKDTree, Lowe's d1 < r d2, correct when the homography maps the point within 2.5 px of its match.

    Parameters
    ----------
    ratios : tuple of float
        Lowe ratios (the question's grid).

    Returns
    -------
    numpy.ndarray
        Precision per ratio (NaN where no match is kept).
    """
    from scipy.spatial import cKDTree

    from ..features import detect, load_oxford_pair

    img1, img2, H = load_oxford_pair("boat", 2, scale=0.5)
    f1, f2 = (detect(img, "surf", max_points=1000, threshold=1e-4) for img in (img1, img2))
    d, i = cKDTree(f2.descriptors).query(f1.descriptors, k=2)
    ok = np.linalg.norm(apply_homography(H, f1.uv) - f2.uv[i[:, 0]], axis=1) < 2.5
    keep = [d[:, 0] < r * d[:, 1] for r in ratios]
    return np.array([ok[k].mean() if k.any() else np.nan for k in keep])
