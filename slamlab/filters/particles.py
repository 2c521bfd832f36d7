"""The particle toolbox shared by every particle filter: log weights → weights, N_eff, resampling (003 §2.2;
PR §4.3, Table 4.4).

API summary
-----------
- :func:`normalise_log_weights` ``(log_w) -> (w, ok)``: weights summing to 1, never NaN.
- :func:`n_eff` ``(w) -> float``: ``1 / Σ w²``.
- :func:`low_variance_resample` ``(w, n, rng, *, offset) -> indices``: the low-variance
  (systematic) sampler of PR Table 4.4; :data:`systematic_resample` is the same function
  under the name the particle-filter literature uses (Kitagawa 1996; Douc et al. 2005).

Used by Monte Carlo localisation (:mod:`slamlab.localisation`) and the plane particle
filter (:mod:`slamlab.planes`). Randomness comes from an explicit ``rng`` only.
"""

from __future__ import annotations

import numpy as np

from .._validate import as_rng, check_int, check_positive

__all__ = ["low_variance_resample", "n_eff", "normalise_log_weights", "systematic_resample"]


def normalise_log_weights(log_w) -> tuple[np.ndarray, bool]:
    """Weights ``exp(log_w − max)`` normalised to sum 1, and whether any weight was finite (PR §4.3).

    All ``-inf`` (every particle impossible) or NaN gives uniform weights and ``ok = False``:
    the caller decides (inject, or report) — the weights never become NaN. NaN and ``-inf``
    entries get weight 0 otherwise.

    Parameters
    ----------
    log_w : array_like, shape (N,)
        Log weights (any offset; ``-inf`` and NaN allowed).

    Returns
    -------
    w : numpy.ndarray of float, shape (N,)
        Weights ``>= 0`` summing to 1.
    ok : bool
        False when no log weight was finite (``w`` is then uniform).

    Examples
    --------
    >>> w, ok = normalise_log_weights([0.0, np.log(3.0)]); w.tolist(), ok
    ([0.25, 0.75], True)
    >>> normalise_log_weights([-np.inf, -np.inf])[1]
    False
    """
    lw = np.asarray(log_w, dtype=float)
    if lw.ndim != 1 or lw.size == 0:
        raise ValueError(f"`log_w` must be a non-empty 1-D array; got shape {lw.shape}")
    finite = np.isfinite(lw)
    if not finite.any():
        return np.full(lw.size, 1.0 / lw.size), False
    w = np.where(finite, np.exp(np.where(finite, lw, -np.inf) - lw[finite].max()), 0.0)
    return w / w.sum(), True


def n_eff(weights) -> float:
    """Effective sample size ``1 / Σ w_i²`` of normalised weights (Kong, Liu & Wong 1994; PR §4.3.4).

    Parameters
    ----------
    weights : array_like, shape (N,)
        Normalised weights (finite, summing to 1).

    Returns
    -------
    float
        Between 1 (one particle carries all the weight) and N (uniform weights).

    Examples
    --------
    >>> n_eff([0.25, 0.25, 0.25, 0.25]), n_eff([1.0, 0.0])
    (4.0, 1.0)
    """
    w = np.asarray(weights, dtype=float)
    if w.ndim != 1 or w.size == 0 or not np.all(np.isfinite(w)):
        raise ValueError(f"`weights` must be a non-empty 1-D array of finite numbers; got shape {w.shape}")
    return float(1.0 / np.sum(w * w))


def low_variance_resample(weights, n: int | None = None, rng=None, *, offset: float | None = None) -> np.ndarray:
    """Indices of ``n`` particles drawn by the low-variance (systematic) sampler (PR Table 4.4).

    One random offset ``r ∈ [0, 1/n)``; pointer ``m`` is ``u_m = r + m/n`` (``m = 0 … n−1``)
    and draws the particle ``i`` whose slice ``[c_{i−1}, c_i)`` of the cumulative normalised
    weights holds it, so a particle of weight ``w`` is drawn ``⌊n·w⌋`` or ``⌈n·w⌉`` times
    and a particle of weight 0 never. PR Table 4.4 draws ``r`` in ``[0, 1/M]``; ours
    ``r = rng.uniform(0, 1/n)``: one double from ``rng`` (``U/n`` with ``U ~ U[0, 1)``, the
    same stream position as the form ``u_m = (U + m)/n``).

    Parameters
    ----------
    weights : array_like, shape (N,)
        Weights ``>= 0``, not all 0 (normalised here).
    n : int, optional
        Number of indices to draw (default ``N``).
    rng : Generator, int or None
        Source of the offset (unused when ``offset`` is given).
    offset : float, optional
        The offset ``r`` itself, in ``[0, 1/n)`` (for a reproducible draw: tests, labs).

    Returns
    -------
    numpy.ndarray of int, shape (n,)
        Indices into the particles, in increasing order.

    Examples
    --------
    >>> low_variance_resample([0.5, 0.25, 0.25], 4, rng=0).tolist()
    [0, 0, 1, 2]
    >>> low_variance_resample([0.0, 0.5, 0.5], 2, offset=0.0).tolist()
    [1, 2]
    """
    w = np.asarray(weights, dtype=float)
    if w.ndim != 1 or w.size == 0 or not np.all(np.isfinite(w)) or np.any(w < 0):
        raise ValueError("`weights` must be a non-empty 1-D array of finite numbers >= 0")
    total = w.sum()
    if total <= 0:
        raise ValueError("`weights` must not all be 0")
    m = w.size if n is None else check_int(n, "n", minimum=1)
    rng = as_rng(rng)
    c = np.cumsum(w / total)
    c[-1] = 1.0
    if offset is None:
        r = rng.uniform(0.0, 1.0 / m)
    else:
        r = check_positive(offset, "offset", allow_zero=True)
        if r >= 1.0 / m:
            raise ValueError(f"`offset` must be in [0, 1/n) = [0, {1.0 / m:g}); got {r}")
    u = r + np.arange(m) / m
    return np.minimum(np.searchsorted(c, u, side="right"), w.size - 1)


#: The same sampler under the name of the particle-filter literature ("systematic resampling").
systematic_resample = low_variance_resample
