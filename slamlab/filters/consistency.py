"""Filter consistency: NEES, NIS and their chi-square bounds (Bar-Shalom's tests)."""

from __future__ import annotations

import numpy as np
from scipy import stats

from .._validate import as_finite_array, check_int, check_probability

__all__ = ["chi2_interval", "nees", "nis"]


def nees(err, P):
    """Normalised estimation error squared ``e^T P^-1 e``, batched over leading axes.

    ``err`` is ``(..., n)`` (true minus estimated state, angles wrapped), ``P``
    is ``(..., n, n)``. For a consistent filter its mean is ``n``.

    Parameters
    ----------
    err : array_like, shape (..., n)
        Estimation error, true minus estimated state (angles wrapped).
    P : array_like, shape (..., n, n)
        The filter's covariance for each error.

    Returns
    -------
    numpy.ndarray or float
        NEES per leading index, shape ``(...)``.

    Examples
    --------
    >>> float(nees(np.array([1.0, 2.0]), np.diag([1.0, 4.0])))
    2.0
    """
    err = as_finite_array(err, "err")
    P = as_finite_array(P, "P")
    if err.ndim < 1 or P.shape != err.shape + err.shape[-1:]:
        raise ValueError(f"`P` must have shape {err.shape + err.shape[-1:]} to match `err`; got {P.shape}")
    sol = np.linalg.solve(P, err[..., None])[..., 0]
    return np.einsum("...i,...i->...", err, sol)


def nis(y, S):
    """Normalised innovation squared ``y^T S^-1 y`` (same maths as :func:`nees`).

    Parameters
    ----------
    y : array_like, shape (..., m)
        Innovation ``z - h(x_{k|k-1})``.
    S : array_like, shape (..., m, m)
        Innovation covariance.

    Returns
    -------
    numpy.ndarray or float
        NIS per leading index, shape ``(...)``.

    Examples
    --------
    >>> float(nis(np.array([3.0]), np.array([[9.0]])))
    1.0
    """
    return nees(y, S)


def chi2_interval(dof: int, n_runs: int = 1, prob: float = 0.95):
    """Two-sided ``prob`` interval of the mean of ``n_runs`` chi-square(``dof``) values.

    The average NEES of ``N`` independent runs times ``N`` is chi-square with
    ``N * dof`` degrees of freedom, so the bounds are ``chi2.ppf(.., N dof) / N``.

    Parameters
    ----------
    dof : int
        Degrees of freedom of one value (the state dimension for NEES, the measurement dimension for NIS).
    n_runs : int, default 1
        Number of independent runs averaged.
    prob : float, default 0.95
        Probability mass inside the interval.

    Returns
    -------
    lo, hi : float
        Bounds of the run-averaged statistic.

    Examples
    --------
    >>> [round(b, 3) for b in chi2_interval(2, 50)]
    [1.484, 2.591]
    """
    dof = check_int(dof, "dof", minimum=1)
    n_runs = check_int(n_runs, "n_runs", minimum=1)
    prob = check_probability(prob, "prob")
    a = (1.0 - prob) / 2.0
    k = dof * n_runs
    return float(stats.chi2.ppf(a, k) / n_runs), float(stats.chi2.ppf(1.0 - a, k) / n_runs)
