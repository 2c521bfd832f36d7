"""The depth filter's convergence on synthetic seeds (003 §4.1.1, §4.3.2; our experiments).

:func:`run_depth_filter_convergence`: Gaussian × Beta seeds fed inliers and outliers at several rates.
:func:`run_convergence_tests`: 003's linearity test beside SVO's σ test on one geometry.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..._table import format_table
from ..._validate import as_rng, check_int, check_positive
from ...mono.depth_filter import (
    compute_tau,
    converged_sigma,
    init_seeds,
    linearity_index,
    tau_inverse,
    update_seeds,
)

__all__ = ["ConvergenceStudy", "ConvergenceTests", "run_convergence_tests", "run_depth_filter_convergence"]


# -- depth-filter convergence (003 §4.1.1, §4.3.2) ---------------------------------------------
@dataclass(frozen=True)
class ConvergenceStudy:
    """Seeds of a synthetic scene updated ``n_obs`` times at several outlier rates (our experiment).

    ``sigma`` (R, n_obs + 1) median σ_ρ (1/m), ``inlier`` (R, n_obs + 1) median a/(a+b),
    ``error`` (R, n_obs + 1) median ``|ρ − ρ_true|`` (1/m), ``converged`` (R, n_obs + 1) share of seeds
    passing SVO's σ test, ``mu`` (R, n_seeds) final means, ``rho_true`` (n_seeds,).

    Attributes
    ----------
    outlier_rates : tuple of float
        The outlier rates studied (R of them).
    sigma : ndarray, shape (R, n_obs + 1)
        Median σ_ρ [1/m].
    inlier : ndarray, shape (R, n_obs + 1)
        Median ``a / (a + b)``.
    error : ndarray, shape (R, n_obs + 1)
        Median ``|ρ − ρ_true|`` [1/m].
    converged : ndarray, shape (R, n_obs + 1)
        Share of seeds passing SVO's σ test.
    mu : ndarray, shape (R, n_seeds)
        Final means [1/m].
    rho_true : ndarray, shape (n_seeds,)
        True inverse depths [1/m].
    tau : float
        Measurement standard deviation [1/m].
    """

    outlier_rates: tuple
    sigma: np.ndarray = field(repr=False)
    inlier: np.ndarray = field(repr=False)
    error: np.ndarray = field(repr=False)
    converged: np.ndarray = field(repr=False)
    mu: np.ndarray = field(repr=False)
    rho_true: np.ndarray = field(repr=False)
    tau: float

    def __str__(self) -> str:
        return (f"depth filter, {self.mu.shape[1]} seeds, {self.sigma.shape[1] - 1} observations, "
                f"outlier rates {', '.join(f'{r:.0%}' for r in self.outlier_rates)}")

    def first_half(self) -> list:
        """Observations until half of the seeds pass SVO's test, per outlier rate (None: never)."""
        out = []
        for row in self.converged:
            k = np.flatnonzero(row >= 0.5)
            out.append(int(k[0]) if k.size else None)
        return out

    def table(self, at=(0, 5, 10, 20, 40)) -> str:
        """The medians per outlier rate after some numbers of observations, as a printed table.

        Parameters
        ----------
        at : tuple of int
            Numbers of observations to show (those beyond ``n_obs`` are left out).

        Returns
        -------
        str
        """
        at = [k for k in at if k < self.sigma.shape[1]]
        rows = []
        for i, r in enumerate(self.outlier_rates):
            for k in at:
                rows.append([f"{100 * r:.0f}", f"{k}", f"{self.sigma[i, k]:.4f}", f"{self.error[i, k]:.4f}",
                             f"{self.inlier[i, k]:.2f}", f"{100 * self.converged[i, k]:.0f}"])
        return format_table(["outliers, %", "observations", "median sigma_rho, 1/m", "median |rho - rho_true|",
                             "median a/(a+b)", "converged (SVO), %"], rows,
                            title=f"Depth-filter convergence (tau = {self.tau} 1/m, SVO initialisation)")


def run_depth_filter_convergence(outlier_rates=(0.0, 0.2, 0.4, 0.6), *, n_obs: int = 40, n_seeds: int = 500,
                                 tau: float = 0.01, depth_min_m: float = 0.5, rng=0) -> ConvergenceStudy:
    """Gaussian × Beta seeds (SVO's start) fed inliers ``N(ρ_true, τ²)`` and outliers ``U(0, ρ_range)``.

    Parameters
    ----------
    outlier_rates : sequence of float
        Outlier rates in ``[0, 1)``, one study each.
    n_obs : int
        Observations per seed (default 40).
    n_seeds : int
        Seeds per rate (default 500).
    tau : float
        Measurement standard deviation [1/m] (default 0.01).
    depth_min_m : float
        Smallest depth [m]; ``ρ_range = 1 / depth_min_m`` (default 0.5).
    rng : Generator, int or None
        Randomness of the scene and the measurements (default 0).

    Returns
    -------
    ConvergenceStudy
        ``sigma``, ``inlier``, ``error``, ``converged`` per rate and observation.
    """
    from ...mono.depth_filter import converged_sigma, init_seeds, inlier_ratio, update_seeds

    rng = as_rng(rng)
    n_obs = check_int(n_obs, "n_obs", minimum=1)
    n_seeds = check_int(n_seeds, "n_seeds", minimum=1)
    tau = check_positive(tau, "tau")
    rates = tuple(float(r) for r in outlier_rates)
    if not rates or any(not 0.0 <= r < 1.0 for r in rates):
        raise ValueError(f"`outlier_rates` must be rates in [0, 1); got {outlier_rates!r}")
    rho_true = rng.uniform(0.2, 1.0 / depth_min_m, n_seeds)
    R = len(rates)
    sig, inl, err, conv = (np.zeros((R, n_obs + 1)) for _ in range(4))
    mus = np.zeros((R, n_seeds))
    for i, r in enumerate(rates):
        s = init_seeds(np.zeros((n_seeds, 2)), np.tile([0.0, 0.0, 1.0], (n_seeds, 1)), 1.0 / np.mean(rho_true), depth_min_m)
        for k in range(n_obs + 1):
            sig[i, k] = np.median(np.sqrt(s.sigma2))
            inl[i, k] = np.median(inlier_ratio(s.a, s.b))
            err[i, k] = np.median(np.abs(s.mu - rho_true))
            conv[i, k] = np.mean(converged_sigma(s.sigma2, s.rho_range))
            if k == n_obs:
                break
            out = rng.random(n_seeds) < r
            x = np.where(out, rng.uniform(0.0, s.rho_range), rho_true + rng.normal(0.0, tau, n_seeds))
            s.mu, s.sigma2, s.a, s.b = update_seeds(s.mu, s.sigma2, s.a, s.b, x, tau**2, s.rho_range)
        mus[i] = s.mu
    return ConvergenceStudy(rates, sig, inl, err, conv, mus, rho_true, tau)


# -- 003 §4.3.2: L < 0.1 beside SVO's σ test --------------------------------------------------------------
@dataclass(frozen=True)
class ConvergenceTests:
    """Seeds seen from a camera moving sideways; when each test first declares them converged (ours).

    ``conv_L`` / ``conv_svo`` (R, n_obs + 1) cumulative share converged by 003's ``L < L_max`` and by
    SVO's ``σ < ρ_range/200``; ``err_L`` / ``err_svo`` (R,) median relative range error of the seeds
    at the moment each test accepted them.

    Attributes
    ----------
    outlier_rates : tuple of float
        The outlier rates studied (R of them).
    step_m : float
        Sideways camera motion per frame [m].
    L_max : float
        Threshold of 003's linearity test.
    conv_L, conv_svo : ndarray, shape (R, n_obs + 1)
        Cumulative share of seeds converged by 003's test and by SVO's.
    err_L, err_svo : ndarray, shape (R,)
        Median relative range error of the seeds when each test accepted them.
    """

    outlier_rates: tuple
    step_m: float
    L_max: float
    conv_L: np.ndarray = field(repr=False)
    conv_svo: np.ndarray = field(repr=False)
    err_L: np.ndarray = field(repr=False)
    err_svo: np.ndarray = field(repr=False)

    def __str__(self) -> str:
        return (f"convergence tests, {self.conv_L.shape[1] - 1} observations, {self.step_m} m steps, "
                f"outliers {', '.join(f'{r:.0%}' for r in self.outlier_rates)}")

    def first_half(self, which: str = "L") -> list:
        """Observations until half of the seeds pass the test (None if never), per outlier rate.

        Parameters
        ----------
        which : str
            ``"L"`` (003's test, default) or any other value for SVO's.

        Returns
        -------
        list of int or None
            One number of observations per outlier rate.
        """
        c = self.conv_L if which == "L" else self.conv_svo
        out = []
        for row in c:
            k = np.flatnonzero(row >= 0.5)
            out.append(int(k[0]) if k.size else None)
        return out

    def table(self, at=(5, 10, 20, 30)) -> str:
        """Converged shares after some numbers of observations, by both tests, as a printed table.

        Parameters
        ----------
        at : tuple of int
            Numbers of observations to show (those beyond ``n_obs`` are left out).

        Returns
        -------
        str
        """
        at = [k for k in at if k < self.conv_L.shape[1]]
        rows = []
        hL, hS = self.first_half("L"), self.first_half("svo")
        for i, r in enumerate(self.outlier_rates):
            rows.append([f"{100 * r:.0f}"] + [f"{100 * self.conv_L[i, k]:.0f} / {100 * self.conv_svo[i, k]:.0f}" for k in at]
                        + ["-" if hL[i] is None else str(hL[i]), "-" if hS[i] is None else str(hS[i]),
                           f"{100 * self.err_L[i]:.1f}", f"{100 * self.err_svo[i]:.1f}"])
        return format_table(["outliers, %", *(f"after {k}" for k in at),
                             "half: L", "half: SVO", "range err. L, %", "range err. SVO, %"], rows,
                            title=(f"003's L < {self.L_max:g} beside SVO's sigma < range/200 (camera moving sideways "
                                   f"{self.step_m:g} m per frame)\nafter k: % of the seeds converged after k "
                                   "observations (L / SVO); half: observations until half pass"))


def run_convergence_tests(outlier_rates=(0.0, 0.2, 0.4), *, n_obs: int = 30, n_seeds: int = 400,
                          step_m: float = 0.02, depth_range_m=(1.5, 6.0), f_px: float = 263.76,
                          L_max: float = 0.1, rng=0) -> ConvergenceTests:
    """Both convergence tests on one geometry (ours): seeds on random rays of a 40° view at
    ``depth_range_m``, the camera moving sideways ``step_m`` per frame; observation ``k`` is the
    true inverse range plus noise of the ``τ`` of that baseline (one pixel, :func:`compute_tau`), or
    with probability ``r`` an outlier uniform on ``[0, ρ_range]``. A seed counts as converged from
    the first observation at which a test passes (the pipeline then stops updating it).

    Parameters
    ----------
    outlier_rates : sequence of float
        Outlier rates in ``[0, 1)``, one study each.
    n_obs : int
        Observations per seed (default 30).
    n_seeds : int
        Seeds per rate (default 400).
    step_m : float
        Sideways camera motion per frame [m] (default 0.02).
    depth_range_m : tuple of float
        Range of the seeds' depths [m] (default 1.5 to 6).
    f_px : float
        Focal length [px] (default 263.76, the rendered tiny camera).
    L_max : float
        Threshold of 003's linearity test (default 0.1).
    rng : Generator, int or None
        Randomness of the scene and the measurements (default 0).

    Returns
    -------
    ConvergenceTests
        ``conv_L``, ``conv_svo``, ``err_L``, ``err_svo`` per rate.
    """
    rng = as_rng(rng)
    n_obs = check_int(n_obs, "n_obs", minimum=1)
    n_seeds = check_int(n_seeds, "n_seeds", minimum=1)
    step_m = check_positive(step_m, "step_m")
    L_max = check_positive(L_max, "L_max")
    rates = tuple(float(r) for r in outlier_rates)
    if not rates or any(not 0.0 <= r < 1.0 for r in rates):
        raise ValueError(f"`outlier_rates` must be rates in [0, 1); got {outlier_rates!r}")
    half = np.tan(np.deg2rad(20.0))
    xy = rng.uniform(-half, half, (n_seeds, 2)) * [1.0, 0.75]
    f = np.column_stack([xy, np.ones(n_seeds)])
    f /= np.linalg.norm(f, axis=1, keepdims=True)
    d_true = rng.uniform(*depth_range_m, n_seeds)
    X = f * d_true[:, None]
    ang = 2 * np.arctan(1.0 / (2 * f_px))
    R = len(rates)
    cL, cS = np.zeros((R, n_obs + 1)), np.zeros((R, n_obs + 1))
    eL, eS = np.full(R, np.nan), np.full(R, np.nan)
    for i, r in enumerate(rates):
        s = init_seeds(np.zeros((n_seeds, 2)), f, float(np.mean(d_true)), depth_range_m[0])
        at_L, at_S = np.full(n_seeds, -1), np.full(n_seeds, -1)
        err_L, err_S = np.full(n_seeds, np.nan), np.full(n_seeds, np.nan)
        for k in range(1, n_obs + 1):
            c = np.array([step_m * k, 0.0, 0.0])
            tau = compute_tau(c, f, d_true, ang)
            t_rho = tau_inverse(d_true, tau)
            out = rng.random(n_seeds) < r
            x = np.where(out, rng.uniform(0.0, s.rho_range), 1.0 / d_true + rng.normal(0.0, 1.0, n_seeds) * t_rho)
            s.mu, s.sigma2, s.a, s.b = update_seeds(s.mu, s.sigma2, s.a, s.b, x, t_rho**2, s.rho_range)
            Xe = f / np.maximum(s.mu, 1e-10)[:, None]
            dvec = Xe - c
            d = np.linalg.norm(dvec, axis=1)
            cos_a = np.sum(f * dvec, axis=1) / d
            passL = linearity_index(s.mu, s.sigma2, d, cos_a) < L_max
            passS = converged_sigma(s.sigma2, s.rho_range)
            rel = np.abs(1.0 / np.maximum(s.mu, 1e-10) - d_true) / d_true
            newL, newS = passL & (at_L < 0), passS & (at_S < 0)
            at_L[newL], at_S[newS] = k, k
            err_L[newL], err_S[newS] = rel[newL], rel[newS]
            cL[i, k], cS[i, k] = np.mean(at_L >= 0), np.mean(at_S >= 0)
        eL[i] = np.median(err_L[at_L >= 0]) if np.any(at_L >= 0) else np.nan
        eS[i] = np.median(err_S[at_S >= 0]) if np.any(at_S >= 0) else np.nan
    del X
    return ConvergenceTests(rates, step_m, L_max, cL, cS, eL, eS)
