"""Ch. 1 experiments on linear models (000 §1.2.1, §1.2.3): the constant-velocity target, the Joseph form, the sigma-point weight."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ... import _validate as v
from ..._table import format_table
from ...sim import constant_velocity_model, simulate_linear
from ..consistency import chi2_interval, nees
from ..kalman import KalmanFilter, _predict, _update, kf_update
from ..ukf import sigma_weights, ukf_predict, ukf_update
from ._common import _monte_carlo

# --- constant-velocity target: the KF is optimal --------------------------------------------------


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

    def __str__(self) -> str:
        return (f"CV target, {self.n_runs} runs x {self.n_steps} steps: KF position RMSE "
                f"{self.rmse_pos_m:.3f} m vs raw measurements {self.rmse_meas_m:.3f} m; "
                f"mean NEES {self.anees.mean():.2f} (dim 4), mean NIS {self.anis.mean():.2f} (dim 2)")

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
            ["mean NEES (expect 4)", f"{self.anees.mean():.2f}"],
            [f"steps with run-averaged NEES in [{lo:.2f}, {hi:.2f}]", f"{inside_nees:.0%}"],
            ["mean NIS (expect 2)", f"{self.anis.mean():.2f}"],
            [f"steps with run-averaged NIS in [{nlo:.2f}, {nhi:.2f}]", f"{inside_nis:.0%}"],
        ]
        return format_table(["quantity", "value"], rows)


def _cv_run(*, F, Q, H, R, P0, n_steps: int, rng: np.random.Generator) -> dict:
    """One Monte Carlo run of the constant-velocity target: squared errors, NEES and NIS per step."""
    x_true0 = rng.multivariate_normal(np.array([0.0, 1.0, 0.0, 0.5]), P0)
    X, Z = simulate_linear(F, Q, H, R, x_true0, n_steps, rng=rng)
    kf = KalmanFilter(np.array([0.0, 1.0, 0.0, 0.5]), P0, F, Q, H, R)
    est = np.empty_like(X)
    nees_k, nis_k = np.empty(n_steps), np.empty(n_steps)
    var_pred = 0.0
    for k in range(n_steps):
        kf.predict()
        kf.update(Z[k])
        est[k] = kf.x
        nees_k[k] = nees(X[k] - kf.x, kf.P)
        nis_k[k] = nees(kf.y, kf.S)
        var_pred += kf.P[0, 0] + kf.P[2, 2]
    return {"se_pos": float(np.sum((est[:, [0, 2]] - X[:, [0, 2]]) ** 2)),
            "se_meas": float(np.sum((Z - X[:, [0, 2]]) ** 2)), "var_pred": var_pred,
            "nees": nees_k, "nis": nis_k, "example": (X, Z, est)}




def run_cv_target(n_runs: int = 50, n_steps: int = 50, *, dt_s: float = 1.0, accel_std: float = 0.2,
                  pos_std_m: float = 1.0, rng=2010, n_jobs: int = 1, progress: bool | None = None) -> CVTargetResult:
    """Track a 2-D constant-velocity target with the KF over seeded Monte Carlo runs (on :func:`~slamlab.sweep.sweep`).

    Parameters
    ----------
    n_runs : int, default 50
        Monte Carlo runs.
    n_steps : int, default 50
        Steps per run.
    dt_s : float, default 1.0
        Time step [s].
    accel_std : float, default 0.2
        Std of the white acceleration noise [m/s²].
    pos_std_m : float, default 1.0
        Std of each position measurement coordinate [m]; also the prior position std.
    rng : int, numpy.random.Generator or SeedSequence, default 2010
        Seed or generator; run ``r`` draws from child ``r`` of its seed sequence.
    n_jobs : int, default 1
        Worker processes for the runs.
    progress : bool or None
        Progress bar: None shows one in a notebook only.

    Returns
    -------
    CVTargetResult
    """
    n_runs = v.check_int(n_runs, "n_runs", minimum=1)
    n_steps = v.check_int(n_steps, "n_steps", minimum=1)
    F, Q, H, R = constant_velocity_model(dt_s, accel_std, pos_std_m, dims=2)
    P0 = np.diag([pos_std_m**2, 1.0, pos_std_m**2, 1.0])
    runs = _monte_carlo(_cv_run, n_runs, rng, n_jobs, progress, F=F, Q=Q, H=H, R=R, P0=P0, n_steps=n_steps)
    n = n_runs * n_steps
    return CVTargetResult(
        n_runs, n_steps, float(np.sqrt(runs["se_pos"].sum() / n)), float(np.sqrt(runs["se_meas"].sum() / n)),
        float(np.sqrt(runs["var_pred"].sum() / n)), np.stack(runs["nees"]).mean(axis=0),
        np.stack(runs["nis"]).mean(axis=0), chi2_interval(4, n_runs), chi2_interval(2, n_runs), *runs["example"][0],
    )


# --- Joseph vs short covariance update -------------------------------------------------------------


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


def run_joseph_vs_short(gain_scales=(0.0, 0.5, 0.8, 1.0, 1.2, 1.5, 2.0), *, n_samples: int = 100_000,
                        rng=2010) -> JosephResult:
    """Scale the optimal gain and compare both covariance updates with the sampled error variance.

    One position/velocity prior, a position measurement; the true posterior
    error is sampled ``n_samples`` times per gain.

    Parameters
    ----------
    gain_scales : sequence of float
        Multiples of the optimal gain to try.
    n_samples : int, default 100000
        Sampled prior states and measurements (at least 100).
    rng : int or numpy.random.Generator, default 2010
        Seed or generator of the samples.

    Returns
    -------
    JosephResult
    """
    g = v.as_rng(rng)
    n_samples = v.check_int(n_samples, "n_samples", minimum=100)
    scales = v.as_vector(gain_scales, "gain_scales")
    P = np.array([[4.0, 1.0], [1.0, 1.0]])
    H, R = np.array([[1.0, 0.0]]), np.array([[1.0]])
    x = np.zeros(2)
    K_opt = kf_update(x, P, [0.0], H, R).K
    x_true = g.multivariate_normal(x, P, size=n_samples)
    z = x_true @ H.T + g.normal(size=(n_samples, 1))
    vs, vj, vm = [], [], []
    for s in scales:
        K = s * K_opt
        vs.append(kf_update(x, P, [0.0], H, R, form="short", K=K).P[0, 0])
        vj.append(kf_update(x, P, [0.0], H, R, form="joseph", K=K).P[0, 0])
        err = x_true - (x + (z - x @ H.T) @ K.T)
        vm.append(np.mean(err[:, 0] ** 2))
    return JosephResult(scales, np.array(vs), np.array(vj), np.array(vm), n_samples)


# --- the sigma-point weight W_s^0 = lambda/(L+lambda) with alpha = 1e-3 ---------------------------


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


def run_sigma_alpha_study(alphas=(1e-5, 1e-4, 1e-3, 1e-2, 0.1, 1.0), n_steps: int = 30, *,
                          form: str = "additive", rng=2010) -> SigmaAlphaResult:
    """Run the UKF on a linear CV model (where it must equal the KF) for several ``alpha``.

    The centre weight is ``W_s^0 = 1 - 1/alpha^2`` for ``kappa = 0``: about
    ``-10^6`` at 000's default ``alpha = 1e-3``. The mean is then a difference of
    numbers ~10^6 times larger than itself, so rounding errors are amplified.

    Parameters
    ----------
    alphas : sequence of float
        Values of ``alpha`` to try (``kappa = 0``, ``beta = 2``).
    n_steps : int, default 30
        Steps of the 1-D constant-velocity run.
    form : str, default "additive"
        Not used: the study always runs the additive UKF (the model is linear with additive noise).
    rng : int or numpy.random.Generator, default 2010
        Seed or generator of the simulated measurements.

    Returns
    -------
    SigmaAlphaResult
    """
    alphas = v.as_vector(alphas, "alphas")
    F, Q, H, R = constant_velocity_model(1.0, 0.5, 1.0, dims=1)
    _, Z = simulate_linear(F, Q, H, R, [100.0, 1.0], n_steps, rng=rng)
    w0, eP, ex = [], [], []
    for a in alphas:
        w0.append(sigma_weights(2, float(a))[0][0])
        xk, Pk = np.array([100.0, 1.0]), 10 * np.eye(2)
        xu, Pu = xk.copy(), Pk.copy()
        worst_P = worst_x = 0.0
        try:
            for z in Z:
                xk, Pk = _predict(xk, Pk, F, Q)
                xu, Pu = ukf_predict(xu, Pu, lambda x, u: x @ F.T, Q, form="additive", alpha=float(a),
                                     vectorized=True)
                upk = _update(xk, Pk, z - H @ xk, H, R)
                upu = ukf_update(xu, Pu, z, lambda x: x @ H.T, R, form="additive", alpha=float(a),
                                 vectorized=True)
                xk, Pk, xu, Pu = upk.x, upk.P, upu.x, upu.P
                worst_P = max(worst_P, np.max(np.abs(Pu - Pk)) / np.max(np.abs(Pk)))
                worst_x = max(worst_x, np.max(np.abs(xu - xk)) / np.max(np.abs(xk)))
        except np.linalg.LinAlgError:
            worst_P = worst_x = np.inf
        eP.append(worst_P)
        ex.append(worst_x)
    return SigmaAlphaResult(alphas, np.array(w0), np.array(eP), np.array(ex), n_steps)
