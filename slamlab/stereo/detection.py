"""Stereo SLAM stage 1: keypoints and descriptors of one image, or of both images of a stereo pair (000 §3.3).

Part of :mod:`slamlab.stereo.stages` (through :mod:`slamlab.stereo.local_stages`, which re-exports both names).
"""

from __future__ import annotations

from concurrent.futures import ThreadPoolExecutor

from ..features.base import Features
from ..features.detect import detect
from .params import StereoParams

__all__ = ["detect_features", "detect_pair"]


def detect_features(image, *, params: StereoParams | None = None, **overrides) -> Features:
    """Keypoints and descriptors of one image with the pipeline's settings (000 §3.3).

    :func:`slamlab.features.detect` with :meth:`StereoParams.detect_kwargs`: 000 uses SURF with
    about 2000 points per 768×576 image; SURF is absent from our OpenCV, so ``"surf"`` (the default)
    is the features chapter's own SURF (its threshold, not ``n_features``, limits it to about 600
    points on the arena); ``"orb"`` and ``"sift"`` are OpenCV's (ORB is the fast one).

    Parameters
    ----------
    image : array_like
        Grey or colour image.
    params : StereoParams, optional
        Pipeline settings (default :class:`StereoParams`).
    **overrides
        :class:`StereoParams` fields to change.

    Returns
    -------
    Features

    Examples
    --------
    >>> import numpy as np
    >>> img = (np.indices((64, 64)).sum(0) % 16 < 8).astype(np.uint8) * 255
    >>> f = detect_features(img, detector="orb", n_features=50); f.uv.shape[1], f.descriptors.dtype
    (2, dtype('uint8'))
    """
    p = StereoParams.resolve(params, **overrides)
    return detect(image, p.detector, **p.detect_kwargs())


_EXECUTOR: ThreadPoolExecutor | None = None


def detect_pair(left, right, *, params: StereoParams | None = None, **overrides) -> tuple[Features, Features]:
    """Keypoints and descriptors of both images of a stereo pair with the pipeline's settings (000 §3.3).

    :func:`detect_features` on each image; with ``parallel_detect`` (the default) in two threads, which gives the
    same features in about half the time (OpenCV and numpy release the GIL).

    Parameters
    ----------
    left, right : array_like
        The two images, grey or colour.
    params : StereoParams, optional
        Pipeline settings (default :class:`StereoParams`).
    **overrides
        :class:`StereoParams` fields to change.

    Returns
    -------
    left_features, right_features : Features

    Examples
    --------
    >>> import numpy as np
    >>> img = (np.indices((64, 64)).sum(0) % 16 < 8).astype(np.uint8) * 255
    >>> fl, fr = detect_pair(img, img, detector="orb", n_features=50)
    >>> bool(np.array_equal(fl.uv, fr.uv))
    True
    """
    global _EXECUTOR
    p = StereoParams.resolve(params, **overrides)
    kwargs = p.detect_kwargs()
    if not p.parallel_detect:
        return detect(left, p.detector, **kwargs), detect(right, p.detector, **kwargs)
    if _EXECUTOR is None:
        _EXECUTOR = ThreadPoolExecutor(max_workers=2, thread_name_prefix="slamlab-detect")
    fut = _EXECUTOR.submit(detect, right, p.detector, **kwargs)
    return detect(left, p.detector, **kwargs), fut.result()
