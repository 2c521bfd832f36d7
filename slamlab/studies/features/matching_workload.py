"""The matching workload of Ch. 3 (000 §1.4.3): SURF descriptors of an Oxford pair plus distractors from the
other sequences (used by :mod:`.matching_experiments` and the feature benchmark).
"""

from __future__ import annotations

from functools import lru_cache

import numpy as np

from ... import _validate as v
from ...features.base import Features
from ...features.detect import detect
from ...features.evaluation import OXFORD_SEQUENCES, load_oxford_image, load_oxford_pair

__all__ = ["descriptor_pool", "surf_features"]


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
    n = v.check_int(n, "n", minimum=0)
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


def _matching_workload(n_stored, n_queries, sequence, j, scale, threshold):
    img1, img2, H = load_oxford_pair(sequence, j, scale=scale)
    f1 = surf_features(img1, threshold)
    f2 = surf_features(img2, threshold)
    n_true = min(len(f1), n_stored)
    f1 = f1.strongest(n_true)
    distract = descriptor_pool(n_stored - n_true, exclude=sequence, scale=scale, threshold=threshold)
    train = np.concatenate([f1.descriptors, distract]) if len(distract) else f1.descriptors
    q = f2.strongest(n_queries)
    return f1, q, train, H
