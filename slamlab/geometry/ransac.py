"""Generic RANSAC (000 §3.5; Fischler & Bolles 1981).

000 §3.5: choose a random subset of the correspondences, compute the pose from
it, repeat "several times (for example 200)", keep the best; "the number of
iterations may be reduced if a good enough approximation was found quickly".
The sample size, score, inlier threshold, early exit and final refit are not
specified in 000 — ours: minimal samples, score = inlier count (ties broken by
the sum of inlier residuals), early exit when the standard adaptive bound
``log(1 - confidence) / log(1 - w^s)`` (``w`` = best inlier ratio so far) is
reached or the inlier ratio exceeds ``stop_ratio``; final least-squares refits on all inliers.

Batched hypothesis scoring (ours, used by the plane extraction of 002): with ``batch_size``
the loop draws ``batch_size`` minimal samples at once, fits them with one vectorised ``fit`` and
scores them with one vectorised ``residuals`` (an array of residuals per hypothesis), then keeps
the best as above. :func:`ransac_refit` is the refit-and-recount step alone, for a caller that
scores hypotheses on a subset and collects the inliers among all its points.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any, NamedTuple

import numpy as np

from .._validate import as_rng, check_callable, check_int, check_positive, check_probability

__all__ = ["RansacResult", "ransac", "ransac_refit"]


class RansacResult(NamedTuple):
    """``model`` (``None`` when nothing fitted), ``inliers`` (N,) bool mask, ``converged``
    (a model with at least ``min_inliers`` inliers was found), ``n_iters`` hypotheses tried.

    Attributes
    ----------
    model : object or None
        The refitted model, ``None`` when nothing fitted.
    inliers : ndarray of bool, shape (N,)
        Inlier mask of the final model.
    converged : bool
        A model with at least ``min_inliers`` inliers was found.
    n_iters : int
        Number of hypotheses tried.
    """

    model: Any
    inliers: np.ndarray
    converged: bool
    n_iters: int


def _take(data, idx):
    return tuple(d[idx] for d in data)


def _fit_rows(fit, data, idx):
    """``fit`` on the rows ``idx`` of every array, ``None`` when it fails on a degenerate sample."""
    try:
        return fit(*_take(data, idx))
    except (ValueError, np.linalg.LinAlgError):
        return None


def ransac_refit(data, fit: Callable, residuals: Callable, model, inliers, threshold: float, *,
                 rounds: int = 3, min_rows: int = 1) -> tuple[Any, np.ndarray]:
    """Least-squares refits on the inliers, each followed by a recount (000 §3.5; ours: stop when stable).

    Parameters
    ----------
    data : array (N, ...) or tuple of arrays with N rows each.
    fit : ``fit(*rows) -> model`` on a subset of rows; a ``ValueError``, ``LinAlgError`` or ``None``
        ends the refits (the last model stays).
    residuals : ``residuals(model, *data) -> (N,)`` non-negative errors.
    model : the model to start from (e.g. the best hypothesis).
    inliers : (N,) bool mask of its inliers.
    threshold : a row is an inlier when its residual is ``<= threshold``.
    rounds : refits at most.
    min_rows : a refit needs at least this many inliers, and its recount must keep at least as many
        (else the previous model and mask stay).

    Returns
    -------
    model : the last model.
    inliers : (N,) bool mask of its inliers.

    Examples
    --------
    >>> x = np.arange(6.0); y = 2 * x + 1; y[2] += 0.05
    >>> fit = lambda xs, ys: np.polyfit(xs, ys, 1)
    >>> res = lambda m, xs, ys: np.abs(np.polyval(m, xs) - ys)
    >>> m, mask = ransac_refit((x, y), fit, res, np.array([2.0, 1.0]), np.ones(6, bool), 0.1)
    >>> bool(mask.all()), bool(abs(m[0] - 2.0) < 0.01)
    (True, True)
    """
    data = data if isinstance(data, tuple) else (data,)
    best_model, best_mask = model, np.asarray(inliers, dtype=bool)
    for _ in range(rounds):
        if best_mask.sum() < min_rows:
            break
        model = _fit_rows(fit, data, best_mask)
        if model is None:
            break
        mask = np.asarray(residuals(model, *data), dtype=float) <= threshold
        if mask.sum() < min_rows:
            break
        best_model, stable, best_mask = model, np.array_equal(mask, best_mask), mask
        if stable:
            break
    return best_model, best_mask


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
    batch_size: int | None = None,
    rng=None,
) -> RansacResult:
    """Robust model fit by random minimal samples (000 §3.5).

    Parameters
    ----------
    data : array (N, ...) or tuple of arrays with N rows each (e.g. ``(src, dst)``).
    fit : ``fit(*rows) -> model`` on a subset of rows; may raise ``ValueError`` or return
        ``None`` for a degenerate sample (it is then skipped). With ``batch_size``, see there.
    residuals : ``residuals(model, *data) -> (N,)`` non-negative errors. With ``batch_size``, see there.
    sample_size : rows per hypothesis (3 for a 3-D rigid transform).
    threshold : a row is an inlier when its residual is ``<= threshold``.
    max_iters : hypotheses at most (000: about 200).
    min_inliers : inliers needed to declare convergence (default ``sample_size``).
    confidence : early exit once ``log(1 - confidence) / log(1 - w^s)`` hypotheses were tried.
    stop_ratio : early exit as soon as a hypothesis has at least this inlier ratio.
    refit_rounds : least-squares refits on all inliers of the best hypothesis, each followed by a
        recount of the inliers (0 = keep the best minimal-sample model); see :func:`ransac_refit`.
        Must be 0 with ``batch_size`` (a batched ``fit`` fits minimal samples only).
    batch_size : None (default): one hypothesis at a time, its sample drawn by
        ``rng.choice(N, sample_size, replace=False)``. An int ``b``: ``b`` hypotheses at a time (fewer in
        the last batch), their samples drawn at once by ``rng.integers(0, N, (b, sample_size))`` (rows may
        repeat within a sample: ``fit`` must drop such degenerate samples); ``fit`` then receives the rows
        with a leading batch axis ``(b, sample_size, ...)`` and returns a tuple of arrays for the ``b' <= b``
        hypotheses it kept (``b'`` rows each; ``None`` or ``b' = 0`` when none), ``residuals(models, *data)``
        returns ``(b', N)`` errors, and hypothesis ``k`` is ``tuple(a[k] for a in models)``. Within a batch the
        first hypothesis of the most inliers stands for the batch (no residual-sum tie-break among them:
        the plane extraction's preemptive count); it replaces the best so far as above.
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

    Batched: lines through two points, all hypotheses of a batch scored at once.

    >>> def fit_many(xs, ys):
    ...     dx = xs[:, 1] - xs[:, 0]; ok = dx != 0
    ...     a = (ys[ok, 1] - ys[ok, 0]) / dx[ok]
    ...     return a, ys[ok, 0] - a * xs[ok, 0]
    >>> res_many = lambda m, xs, ys: np.abs(m[0][:, None] * xs + m[1][:, None] - ys)
    >>> r = ransac((x, y), fit_many, res_many, 2, 0.1, max_iters=20, batch_size=20, refit_rounds=0, rng=0)
    >>> [float(c) for c in r.model], int(r.inliers.sum())
    ([2.0, 1.0], 9)
    """
    data = data if isinstance(data, tuple) else (data,)
    if not data:
        raise ValueError("`data` must hold at least one array")
    data = tuple(np.asarray(d) for d in data)
    n = data[0].shape[0] if data[0].ndim else 0
    if any(d.ndim == 0 or d.shape[0] != n for d in data):
        raise ValueError(f"`data` arrays must all have the same number of rows; got {[d.shape for d in data]}")
    check_callable(fit, "fit")
    check_callable(residuals, "residuals")
    sample_size = check_int(sample_size, "sample_size", minimum=1)
    threshold = check_positive(threshold, "threshold")
    max_iters = check_int(max_iters, "max_iters", minimum=1)
    refit_rounds = check_int(refit_rounds, "refit_rounds", minimum=0)
    min_inliers = sample_size if min_inliers is None else check_int(min_inliers, "min_inliers", minimum=1)
    confidence = check_probability(confidence, "confidence")
    stop_ratio = check_positive(stop_ratio, "stop_ratio")
    if batch_size is not None:
        batch_size = check_int(batch_size, "batch_size", minimum=1)
        if refit_rounds:
            raise ValueError(f"`refit_rounds` must be 0 with `batch_size` (refit with `ransac_refit` and a "
                             f"one-model fit); got {refit_rounds}")
    if n < sample_size:
        raise ValueError(f"`data` must have at least `sample_size` = {sample_size} rows; got {n}")
    rng = as_rng(rng)

    # the best hypothesis: most inliers, ties with an earlier one broken by the smaller sum of inlier residuals;
    # within a batch, the first of the most inliers (the preemptive count of 002's extraction, ours)
    best_model, best_mask, best_key = None, np.zeros(n, dtype=bool), (-1, 0.0)
    needed = max_iters
    it = 0
    while it < min(max_iters, needed):
        if batch_size is None:
            it += 1
            model = _fit_rows(fit, data, rng.choice(n, size=sample_size, replace=False))
            if model is None:
                continue
            models, r = None, np.asarray(residuals(model, *data), dtype=float)[None]
        else:
            b = min(batch_size, max_iters - it)
            it += b
            models = _fit_rows(fit, data, rng.integers(0, n, (b, sample_size)))
            if models is None or len(models[0]) == 0:
                continue
            r = np.asarray(residuals(models, *data), dtype=float)
        masks = r <= threshold
        counts = masks.sum(axis=1)
        k = int(np.argmax(counts))  # batched: the first of the most inliers (one at a time: k = 0)
        key = (int(counts[k]), -float(r[k][masks[k]].sum()))
        if key > best_key:
            best_model = model if models is None else tuple(a[k] for a in models)
            best_mask, best_key = masks[k], key
            w = key[0] / n
            if w >= stop_ratio:
                break
            if w >= 1.0:
                needed = it
            elif w > 0:
                p_good = w**sample_size
                if p_good > 0:
                    needed = int(np.ceil(np.log(1.0 - confidence) / np.log1p(-p_good))) if p_good < 1 else it
    if best_model is not None and refit_rounds:
        best_model, best_mask = ransac_refit(data, fit, residuals, best_model, best_mask, threshold,
                                             rounds=refit_rounds, min_rows=sample_size)
    converged = best_model is not None and int(best_mask.sum()) >= min_inliers
    return RansacResult(best_model, best_mask, bool(converged), it)
