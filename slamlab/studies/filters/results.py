"""Ch. 1 experiment results (000 §1.2, §3.6): the printable result dataclasses with their tables, the filter names
and the divergence threshold (no simulator here: the runs live in :mod:`~slamlab.studies.filters.experiments`)."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..._table import format_table

FILTER_NAMES = ("LKF", "EKF", "UKF-aug", "UKF-add")

DIVERGED_RMSE_M = 2.0  # a run whose position RMSE exceeds this has lost track


def _nanmean(a) -> float:
    """Mean over the finite entries; NaN (without a warning) when there are none."""
    a = np.asarray(a, dtype=float)
    ok = np.isfinite(a)
    return float(a[ok].mean()) if ok.any() else float("nan")


@dataclass(frozen=True)
class CVTargetResult:
    """Linear constant-velocity target tracked by the KF (000 §1.2.1).

    Attributes
    ----------
    n_runs, n_steps : int
        Monte Carlo runs and steps per run.
    rmse_pos_m : float
        KF position RMSE over all runs and steps [m].
    rmse_meas_m : float
        RMSE of the raw position measurements [m].
    predicted_pos_std_m : float
        RMS of the KF's predicted position std, ``sqrt(P_xx + P_yy)`` [m].
    anees, anis : numpy.ndarray, shape (n_steps,)
        NEES (dim 4) and NIS (dim 2) averaged over runs.
    nees_bounds, nis_bounds : tuple of float
        95 % chi-square intervals of the run-averaged NEES and NIS.
    example_truth : numpy.ndarray, shape (n_steps, 4)
        First run's true state ``(x, vx, y, vy)``.
    example_meas : numpy.ndarray, shape (n_steps, 2)
        First run's measured positions [m].
    example_est : numpy.ndarray, shape (n_steps, 4)
        First run's KF estimates.
    """

    n_runs: int
    n_steps: int
    rmse_pos_m: float
    rmse_meas_m: float
    predicted_pos_std_m: float
    anees: np.ndarray = field(repr=False)  # (n_steps,) NEES averaged over runs
    anis: np.ndarray = field(repr=False)
    nees_bounds: tuple[float, float] = (0.0, 0.0)
    nis_bounds: tuple[float, float] = (0.0, 0.0)
    example_truth: np.ndarray = field(default=None, repr=False)
    example_meas: np.ndarray = field(default=None, repr=False)
    example_est: np.ndarray = field(default=None, repr=False)

    @property
    def mean_nees(self) -> float:
        """The run-averaged NEES averaged over the steps (over the finite ones; consistent: 4)."""
        return _nanmean(self.anees)

    @property
    def mean_nis(self) -> float:
        """The run-averaged NIS averaged over the steps (over the finite ones; consistent: 2)."""
        return _nanmean(self.anis)

    def __str__(self) -> str:
        return (f"CV target, {self.n_runs} runs x {self.n_steps} steps: KF RMSE {self.rmse_pos_m:.3f} m vs raw "
                f"{self.rmse_meas_m:.3f} m; NEES {self.mean_nees:.2f} (dim 4), NIS {self.mean_nis:.2f} (dim 2)")

    def table(self) -> str:
        """Fixed-precision table: RMSEs, predicted std, mean NEES/NIS and the share of steps inside their bounds.

        Returns
        -------
        str
        """
        lo, hi = self.nees_bounds
        nlo, nhi = self.nis_bounds
        inside_nees = np.mean((self.anees >= lo) & (self.anees <= hi))
        inside_nis = np.mean((self.anis >= nlo) & (self.anis <= nhi))
        rows = [
            ["position RMSE, KF [m]", f"{self.rmse_pos_m:.3f}"],
            ["position RMSE, raw measurement [m]", f"{self.rmse_meas_m:.3f}"],
            ["predicted position std, KF [m]", f"{self.predicted_pos_std_m:.3f}"],
            ["mean NEES (expect 4)", f"{self.mean_nees:.2f}"],
            [f"steps with run-averaged NEES in its 95 % interval [{lo:.2f}, {hi:.2f}]", f"{inside_nees:.0%}"],
            ["mean NIS (expect 2)", f"{self.mean_nis:.2f}"],
            [f"steps with run-averaged NIS in its 95 % interval [{nlo:.2f}, {nhi:.2f}]", f"{inside_nis:.0%}"],
        ]
        return format_table(["quantity", "value"], rows)


@dataclass(frozen=True)
class JosephResult:
    """Posterior position variance from the short and Joseph forms vs the sampled truth.

    Attributes
    ----------
    gain_scales : numpy.ndarray, shape (G,)
        Gain as a multiple of the optimal gain ``K_opt``.
    var_short, var_joseph : numpy.ndarray, shape (G,)
        Posterior position variance from the short and the Joseph form [m²].
    var_sampled : numpy.ndarray, shape (G,)
        Sampled variance of the true posterior error [m²].
    n_samples : int
        Samples per gain.
    """

    gain_scales: np.ndarray
    var_short: np.ndarray
    var_joseph: np.ndarray
    var_sampled: np.ndarray
    n_samples: int

    def __str__(self) -> str:
        return (f"Short form matches the sampled error variance only at gain scale 1: "
                f"{len(self.gain_scales)} gains, {self.n_samples} samples each")

    def table(self) -> str:
        """Fixed-precision table: one row per gain scale, the three variances.

        Returns
        -------
        str
        """
        rows = [[f"{g:.2f}", f"{s:.4f}", f"{j:.4f}", f"{m:.4f}"]
                for g, s, j, m in zip(self.gain_scales, self.var_short, self.var_joseph, self.var_sampled,
                                      strict=True)]
        return format_table(["gain / K_opt", "short (I-KH)P", "Joseph", "sampled"], rows)


@dataclass(frozen=True)
class SigmaAlphaResult:
    """UKF vs KF on a linear model for several ``alpha``: centre weight and rounding error.

    Attributes
    ----------
    alphas : numpy.ndarray, shape (A,)
        Tried values of ``alpha``.
    w0 : numpy.ndarray, shape (A,)
        Centre mean weight ``W_s^0`` for ``L = 2``.
    max_rel_err_P, max_rel_err_x : numpy.ndarray, shape (A,)
        Largest relative UKF-KF difference of the covariance and the state over the run (inf when the UKF failed).
    n_steps : int
        Steps of the run.
    """

    alphas: np.ndarray
    w0: np.ndarray
    max_rel_err_P: np.ndarray
    max_rel_err_x: np.ndarray
    n_steps: int

    def __str__(self) -> str:
        return (f"alpha={self.alphas[0]:g}: W_s^0={self.w0[0]:.3g}, UKF-KF covariance error "
                f"{self.max_rel_err_P[0]:.0e}; alpha={self.alphas[-1]:g}: {self.max_rel_err_P[-1]:.0e}")

    def table(self) -> str:
        """Table of ``alpha``, ``W_s^0`` and the decade of each rounding error.

        Returns
        -------
        str
        """
        rows = [[f"{a:g}", f"{w:.6g}", _order(e), _order(ex)]
                for a, w, e, ex in zip(self.alphas, self.w0, self.max_rel_err_P, self.max_rel_err_x, strict=True)]
        return format_table(["alpha", "W_s^0", "max rel. error of P", "max rel. error of x"], rows)


def _order(x: float) -> str:
    """Decade of a rounding error (``'1e-12'`` means between 3e-13 and 3e-12): stable across BLAS builds."""
    if not np.isfinite(x) or x <= 0:
        return "0" if x == 0 else "failed"
    return f"1e{int(np.round(np.log10(x))):+03d}"


@dataclass(frozen=True)
class UnicycleResult:
    """KF/EKF/UKF on the range-bearing unicycle: RMSE and NEES over Monte Carlo runs.

    Attributes
    ----------
    filters : tuple of str
        Filter names, in row order (from ``FILTER_NAMES``).
    n_runs, n_steps : int
        Monte Carlo runs and steps per run.
    params : dict
        The noise and sigma-point settings of the run.
    rmse_pos_m : numpy.ndarray, shape (n_filters,)
        Position RMSE over the runs that did not fail [m].
    rmse_heading_rad : numpy.ndarray, shape (n_filters,)
        Heading RMSE [rad].
    anees : numpy.ndarray, shape (n_filters, n_steps)
        NEES averaged over runs (dim 3).
    failures : numpy.ndarray, shape (n_filters,)
        Runs with a numerical failure (excluded from the averages).
    run_rmse_pos_m : numpy.ndarray, shape (n_filters, n_runs)
        Per-run position RMSE, NaN for a failed run [m].
    nees_bounds : tuple of float
        95 % chi-square interval of the run-averaged NEES.
    example_truth : numpy.ndarray, shape (n_steps, 3)
        First run's true poses ``(x_m, y_m, theta_rad)``.
    example_est : numpy.ndarray, shape (n_filters, n_steps, 3)
        First run's estimates.
    example_P : numpy.ndarray, shape (n_filters, n_steps, 3, 3)
        First run's covariances.
    landmarks_m : numpy.ndarray, shape (L, 2)
        Landmark positions [m].
    """

    filters: tuple[str, ...]
    n_runs: int
    n_steps: int
    params: dict
    rmse_pos_m: np.ndarray      # (n_filters,)
    rmse_heading_rad: np.ndarray
    anees: np.ndarray           # (n_filters, n_steps) NEES averaged over runs
    failures: np.ndarray        # (n_filters,) runs with a numerical failure (then excluded)
    run_rmse_pos_m: np.ndarray  # (n_filters, n_runs) per-run position RMSE (NaN for a failed run)
    nees_bounds: tuple[float, float]
    example_truth: np.ndarray = field(repr=False)
    example_est: np.ndarray = field(repr=False)     # (n_filters, n_steps, 3)
    example_P: np.ndarray = field(repr=False)       # (n_filters, n_steps, 3, 3)
    landmarks_m: np.ndarray = field(repr=False)

    def __str__(self) -> str:
        finite = np.where(np.isfinite(self.rmse_pos_m), self.rmse_pos_m, np.inf)
        best = self.filters[int(np.argmin(finite))]
        return (f"Unicycle, {self.n_runs} runs x {self.n_steps} steps: lowest position RMSE {best}; "
                + ", ".join(f"{f} {r:.3f} m" for f, r in zip(self.filters, self.rmse_pos_m, strict=True)))

    @property
    def mean_nees(self) -> np.ndarray:
        """(n_filters,) run-averaged NEES averaged over the finite steps (consistent: 3).

        NaN for a filter that failed in every run."""
        return np.array([_nanmean(a) for a in self.anees])

    @property
    def diverged(self) -> np.ndarray:
        """Runs per filter whose position RMSE exceeds ``DIVERGED_RMSE_M`` (failed runs not included)."""
        return np.sum(np.nan_to_num(self.run_rmse_pos_m, nan=0.0) > DIVERGED_RMSE_M, axis=1)

    def table(self) -> str:
        """Fixed-precision table: one row per filter (RMSEs, NEES, diverged and failed runs).

        ``pos RMSE`` is over every step of every run that did not fail, ``median run`` the median of the
        runs' own position RMSEs, ``heading`` the heading RMSE; ``diverged`` counts the runs whose position
        RMSE exceeds ``DIVERGED_RMSE_M`` (2 m), ``failed`` the runs with a numerical failure.

        Returns
        -------
        str
        """
        lo, hi = self.nees_bounds
        rows = []
        for i, name in enumerate(self.filters):
            a = self.anees[i]
            ok = np.isfinite(self.run_rmse_pos_m[i])
            med = np.median(self.run_rmse_pos_m[i, ok]) if ok.any() else np.nan
            rows.append([name, f"{self.rmse_pos_m[i]:.3f}", f"{med:.3f}",
                         f"{np.rad2deg(self.rmse_heading_rad[i]):.2f}", f"{self.mean_nees[i]:.2f}",
                         f"{_nanmean(np.where(np.isfinite(a), (a >= lo) & (a <= hi), np.nan)):.0%}",
                         f"{int(self.diverged[i])}",
                         f"{int(self.failures[i])}"])
        return format_table(["filter", "pos RMSE [m]", "median run [m]", "heading [deg]", "mean NEES (3)",
                             f"NEES in [{lo:.2f}, {hi:.2f}]", "diverged", "failed"], rows)


@dataclass(frozen=True)
class StabilisingNoiseResult:
    """EKF consistency as the assumed process noise is inflated.

    Attributes
    ----------
    scales : numpy.ndarray, shape (S,)
        Process-noise factors tried.
    rmse_pos_m : numpy.ndarray, shape (S,)
        EKF position RMSE per factor [m].
    mean_nees : numpy.ndarray, shape (S,)
        EKF NEES averaged over runs and steps per factor (consistent: 3).
    nees_bounds : tuple of float
        95 % chi-square interval of the run-averaged NEES.
    n_runs : int
        Monte Carlo runs per factor.
    """

    scales: np.ndarray
    rmse_pos_m: np.ndarray
    mean_nees: np.ndarray
    nees_bounds: tuple[float, float]
    n_runs: int

    def __str__(self) -> str:
        return (f"EKF mean NEES {self.mean_nees[0]:.1f} without stabilising noise, "
                f"{self.mean_nees[-1]:.1f} with x{self.scales[-1]:g} process noise (consistent: 3)")

    def table(self) -> str:
        """Table: one row per Q scale, RMSE, mean NEES and whether it lies in the bounds.

        Returns
        -------
        str
        """
        lo, hi = self.nees_bounds
        rows = [[f"{s:g}", f"{r:.3f}", f"{n:.2f}", "yes" if lo <= n <= hi else ("over-confident" if n > hi else
                                                                                   "pessimistic")]
                for s, r, n in zip(self.scales, self.rmse_pos_m, self.mean_nees, strict=True)]
        return format_table(["Q scale", "pos RMSE [m]", "mean NEES (3)", f"in [{lo:.2f}, {hi:.2f}]?"], rows)


@dataclass(frozen=True)
class LandmarkDemoResult:
    """Static landmarks refined by the §3.6 filter: error vs number of sightings.

    Attributes
    ----------
    sightings : numpy.ndarray of int, shape (S,)
        Sighting counts reported.
    rmse_filtered_m : numpy.ndarray, shape (S,)
        RMSE per coordinate of the filtered landmarks after that many sightings [m].
    rmse_single_m : numpy.ndarray, shape (S,)
        RMSE of the latest single sighting [m].
    predicted_std_m : numpy.ndarray, shape (S,)
        RMS of the filter's predicted std per coordinate [m].
    n_landmarks : int
        Landmarks observed.
    """

    sightings: np.ndarray
    rmse_filtered_m: np.ndarray
    rmse_single_m: np.ndarray
    predicted_std_m: np.ndarray
    n_landmarks: int

    def __str__(self) -> str:
        return (f"{self.n_landmarks} landmarks: RMSE {self.rmse_single_m[-1]:.4f} m from one sighting, "
                f"{self.rmse_filtered_m[-1]:.4f} m after {self.sightings[-1]} sightings")

    def table(self) -> str:
        """Table: one row per reported sighting count, with the ``1/sqrt(n)`` reference.

        Returns
        -------
        str
        """
        rows = [[f"{n}", f"{f:.4f}", f"{p:.4f}", f"{s:.4f}", f"{s / np.sqrt(n):.4f}"]
                for n, f, p, s in zip(self.sightings, self.rmse_filtered_m, self.predicted_std_m,
                                      self.rmse_single_m, strict=True)]
        return format_table(["sightings", "filtered RMSE [m]", "predicted [m]", "one sighting [m]",
                             "one / sqrt(n) [m]"], rows)
