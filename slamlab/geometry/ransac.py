"""Generic RANSAC (000 §3.5; Fischler & Bolles 1981).

000 §3.5: choose a random subset of the correspondences, compute the pose from
it, repeat "several times (for example 200)", keep the best; "the number of
iterations may be reduced if a good enough approximation was found quickly".
The sample size, score, inlier threshold, early exit and final refit are not
specified in 000 — ours: minimal samples, score = inlier count (ties broken by
the sum of inlier residuals), early exit when the standard adaptive bound
``log(1 - confidence) / log(1 - w^s)`` (``w`` = best inlier ratio so far) is
reached or the inlier ratio exceeds ``stop_ratio``; final least-squares refits on all inliers.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any, NamedTuple

import numpy as np

from .. import _validate as v

__all__ = ["RansacResult", "ransac"]


class RansacResult(NamedTuple):
    """``model`` (``None`` when nothing fitted), ``inliers`` (N,) bool mask, ``converged``
    (a model with at least ``min_inliers`` inliers was found), ``n_iters`` hypotheses tried."""

    model: Any
    inliers: np.ndarray
    converged: bool
    n_iters: int


def _take(data, idx):
    return tuple(d[idx] for d in data)


def ransac(
    data,
    fit: Callable,
    residuals: Callable,
    sample_size: int,
    threshold: float,
    *,
    max_iters: int = 200,
    min_inliers: int | None = None,
    confidence: float = 0.999,
    stop_ratio: float = 1.0,
    refit_rounds: int = 3,
    rng=None,
) -> RansacResult:
    """Robust model fit by random minimal samples (000 §3.5).

    Parameters
    ----------
    data : array (N, ...) or tuple of arrays with N rows each (e.g. ``(src, dst)``).
    fit : ``fit(*rows) -> model`` on a subset of rows; may raise ``ValueError`` or return
        ``None`` for a degenerate sample (it is then skipped).
    residuals : ``residuals(model, *data) -> (N,)`` non-negative errors.
    sample_size : rows per hypothesis (3 for a 3-D rigid transform).
    threshold : a row is an inlier when its residual is ``<= threshold``.
    max_iters : hypotheses at most (000: about 200).
    min_inliers : inliers needed to declare convergence (default ``sample_size``).
    confidence : early exit once ``log(1 - confidence) / log(1 - w^s)`` hypotheses were tried.
    stop_ratio : early exit as soon as a hypothesis has at least this inlier ratio.
    refit_rounds : least-squares refits on all inliers of the best hypothesis, each followed by a
        recount of the inliers (0 = keep the best minimal-sample model).
    rng : Generator, int or None.

    Returns
    -------
    RansacResult

    Examples
    --------
    >>> x = np.arange(10.0); y = 2 * x + 1; y[3] = 40.0
    >>> fit = lambda xs, ys: np.polyfit(xs, ys, 1)
    >>> res = lambda m, xs, ys: np.abs(np.polyval(m, xs) - ys)
    >>> r = ransac((x, y), fit, res, 2, 0.1, rng=0)
    >>> np.round(r.model, 6), int(r.inliers.sum()), r.converged
    (array([2., 1.]), 9, True)
    """
    data = data if isinstance(data, tuple) else (data,)
    if not data:
        raise ValueError("`data` must hold at least one array")
    data = tuple(np.asarray(d) for d in data)
    n = data[0].shape[0] if data[0].ndim else 0
    if any(d.ndim == 0 or d.shape[0] != n for d in data):
        raise ValueError(f"`data` arrays must all have the same number of rows; got {[d.shape for d in data]}")
    v.check_callable(fit, "fit")
    v.check_callable(residuals, "residuals")
    sample_size = v.check_int(sample_size, "sample_size", minimum=1)
    threshold = v.check_positive(threshold, "threshold")
    max_iters = v.check_int(max_iters, "max_iters", minimum=1)
    refit_rounds = v.check_int(refit_rounds, "refit_rounds", minimum=0)
    min_inliers = sample_size if min_inliers is None else v.check_int(min_inliers, "min_inliers", minimum=1)
    confidence = v.check_probability(confidence, "confidence")
    stop_ratio = v.check_positive(stop_ratio, "stop_ratio")
    if n < sample_size:
        raise ValueError(f"`data` must have at least `sample_size` = {sample_size} rows; got {n}")
    rng = v.as_rng(rng)

    best_model, best_mask, best_key = None, np.zeros(n, dtype=bool), (-1, 0.0)
    needed = max_iters
    it = 0
    while it < min(max_iters, needed):
        it += 1
        idx = rng.choice(n, size=sample_size, replace=False)
        try:
            model = fit(*_take(data, idx))
        except (ValueError, np.linalg.LinAlgError):
            continue
        if model is None:
            continue
        r = np.asarray(residuals(model, *data), dtype=float)
        mask = r <= threshold
        count = int(mask.sum())
        key = (count, -float(r[mask].sum()))
        if key > best_key:
            best_model, best_mask, best_key = model, mask, key
            w = count / n
            if w >= stop_ratio:
                break
            if w >= 1.0:
                needed = it
            elif w > 0:
                p_good = w**sample_size
                if p_good > 0:
                    needed = int(np.ceil(np.log(1.0 - confidence) / np.log1p(-p_good))) if p_good < 1 else it
    for _ in range(refit_rounds if best_model is not None else 0):
        # least-squares refit on the inliers, then recount (a few rounds, stop when stable)
        if best_mask.sum() < sample_size:
            break
        try:
            model = fit(*_take(data, best_mask))
        except (ValueError, np.linalg.LinAlgError):
            break
        if model is None:
            break
        mask = np.asarray(residuals(model, *data), dtype=float) <= threshold
        if mask.sum() < sample_size:
            break
        best_model, stable, best_mask = model, np.array_equal(mask, best_mask), mask
        if stable:
            break
    converged = best_model is not None and int(best_mask.sum()) >= min_inliers
    return RansacResult(best_model, best_mask, bool(converged), it)
