"""The matching workload of Ch. 3 (000 §1.4.3): SURF descriptors of an Oxford pair plus distractors from the
other sequences (used by :mod:`.matching_experiments` and the feature benchmark).
"""

from __future__ import annotations

from functools import lru_cache

import numpy as np

from ..._validate import check_int
from ...features.base import Features
from ...features.detect import detect
from ...features.evaluation import OXFORD_SEQUENCES, load_oxford_image, load_oxford_pair

__all__ = ["descriptor_pool", "matching_workload", "surf_features"]


@lru_cache(maxsize=64)
def _surf_cached(sequence, index, scale, threshold):
    img = load_oxford_image(sequence, index, scale=scale)
    return surf_features(img, threshold)


def surf_features(img, threshold) -> Features:
    """Our SURF keypoints with 64-d descriptors of one image (000 §1.4.2).

    Parameters
    ----------
    img : (H, W) array
        Grey image (uint8, or float in [0, 1]).
    threshold : float
        SURF Hessian threshold on our scale (image in [0, 1]).

    Returns
    -------
    Features
        Keypoints with float32 descriptors.
    """
    return detect(img, "surf", threshold=threshold)


def descriptor_pool(n: int, *, exclude: str = "graf", scale: float = 0.5, threshold: float = 5e-5) -> np.ndarray:
    """``n`` SURF descriptors (float32) from the Oxford images other than ``exclude``'s (distractors).

    Parameters
    ----------
    n : int
        Number of descriptors (>= 0); raises ``ValueError`` when the images give fewer.
    exclude : str
        Shared sequence whose images are skipped (the one being matched).
    scale : float
        Image resize factor.
    threshold : float
        SURF Hessian threshold on our scale.

    Returns
    -------
    (n, 64) float32
        Descriptors, taken sequence by sequence, image 1..6.
    """
    n = check_int(n, "n", minimum=0)
    out, have = [], 0
    for seq in OXFORD_SEQUENCES:
        if seq == exclude:
            continue
        for idx in range(1, 7):
            if have >= n:
                break
            d = _surf_cached(seq, idx, float(scale), float(threshold)).descriptors
            out.append(d[: n - have])
            have += len(out[-1])
    if have < n:
        raise ValueError(f"the Oxford images give only {have} SURF descriptors at scale {scale:g}, threshold "
                         f"{threshold:g}; asked for `n`={n}")
    return np.concatenate(out) if out else np.zeros((0, 64), np.float32)


def matching_workload(n_stored: int, n_queries: int, sequence: str = "graf", j: int = 2, scale: float = 0.5,
                      threshold: float = 5e-5):
    """Ch. 3's matching workload: image 1's SURF descriptors and distractors to search, image j's to query (000 §1.4.3).

    Ours: the distractors, from the other Oxford sequences, grow the store to ``n_stored``.

    Parameters
    ----------
    n_stored : int
        Descriptors to search: image 1's strongest (at most all of them), then distractors (>= 1).
    n_queries : int
        Query keypoints: image ``j``'s strongest (>= 1).
    sequence : str or os.PathLike
        Oxford sequence: a name of :data:`~slamlab.features.evaluation.OXFORD_SEQUENCES` or its folder.
    j : int
        The query image (>= 2).
    scale : float
        Image resize factor.
    threshold : float
        SURF Hessian threshold on our scale.

    Returns
    -------
    f1 : Features
        Image 1's keypoints among the stored descriptors (the first ``len(f1)`` rows of ``train``).
    queries : Features
        Image ``j``'s keypoints (the queries).
    train : (n_stored, 64) float32
        The descriptors searched.
    H : (3, 3) float
        The homography from image 1 to image ``j`` (at ``scale``).
    """
    n_stored = check_int(n_stored, "n_stored", minimum=1)
    n_queries = check_int(n_queries, "n_queries", minimum=1)
    img1, img2, H = load_oxford_pair(sequence, j, scale=scale)
    f1 = surf_features(img1, threshold)
    f2 = surf_features(img2, threshold)
    n_true = min(len(f1), n_stored)
    f1 = f1.strongest(n_true)
    distract = descriptor_pool(n_stored - n_true, exclude=sequence, scale=scale, threshold=threshold)
    train = np.concatenate([f1.descriptors, distract]) if len(distract) else f1.descriptors
    q = f2.strongest(n_queries)
    return f1, q, train, H
