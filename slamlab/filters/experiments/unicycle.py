"""Ch. 1 experiments on the range-bearing unicycle (000 §1.2.2, §1.2.3): where LKF, EKF and UKF differ; stabilising noise."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ... import _validate as v
from ..._table import format_table
from ...sim import RangeBearingSensor, UnicycleModel, simulate_unicycle
from ..consistency import chi2_interval, nees
from ..ekf import ExtendedKalmanFilter
from ..kalman import _predict, _update
from ..ukf import UnscentedKalmanFilter
from ._common import DIVERGED_RMSE_M, FILTER_NAMES, _monte_carlo, _nanmean

# --- unicycle with range-bearing landmarks: where the filters differ -----------------------------


def default_landmarks() -> np.ndarray:
    """Three landmarks near the circular path (start at the origin heading +x, radius 5 m).

    Returns
    -------
    numpy.ndarray, shape (3, 2)
        Landmark positions [m].
    """
    return np.array([[0.0, 5.0], [4.0, 8.0], [-4.0, 2.0]])


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
    def diverged(self) -> np.ndarray:
        """Runs per filter whose position RMSE exceeds ``DIVERGED_RMSE_M`` (failed runs not included)."""
        return np.sum(np.nan_to_num(self.run_rmse_pos_m, nan=0.0) > DIVERGED_RMSE_M, axis=1)

    def table(self) -> str:
        """Fixed-precision table: one row per filter (RMSEs, NEES, diverged and failed runs).

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
                         f"{np.rad2deg(self.rmse_heading_rad[i]):.2f}", f"{_nanmean(a):.2f}",
                         f"{_nanmean(np.where(np.isfinite(a), (a >= lo) & (a <= hi), np.nan)):.0%}",
                         f"{int(self.diverged[i])}",
                         f"{int(self.failures[i])}"])
        return format_table(["filter", "pos RMSE [m]", "median run [m]", "heading RMSE [deg]", "mean NEES (3)",
                             f"NEES in [{lo:.2f}, {hi:.2f}]", f"diverged (>{DIVERGED_RMSE_M:g} m)", "failed"],
                            rows)


def _make_filters(names, x0, P0, model, sensor, u0, alpha, beta, kappa, q_scale):
    filt = {}
    for name in names:
        if name == "EKF":
            filt[name] = ExtendedKalmanFilter(x0, P0, model.f, model.F_jac, q_scale * model.Q(x0, u0), sensor.h,
                                              sensor.H_jac, sensor.R, residual=sensor.residual)
        elif name == "UKF-aug":
            filt[name] = UnscentedKalmanFilter(x0, P0, model.f, q_scale * model.M, sensor.h, sensor.R,
                                               form="augmented", alpha=alpha, beta=beta, kappa=kappa,
                                               x_mean_fn=model.mean, x_residual_fn=model.residual,
                                               z_mean_fn=sensor.mean, z_residual_fn=sensor.residual,
                                               vectorized=True)
        elif name == "UKF-add":
            filt[name] = UnscentedKalmanFilter(x0, P0, model.f, q_scale * model.Q(x0, u0), sensor.h, sensor.R,
                                               form="additive", alpha=alpha, beta=beta, kappa=kappa,
                                               x_mean_fn=model.mean, x_residual_fn=model.residual,
                                               z_mean_fn=sensor.mean, z_residual_fn=sensor.residual,
                                               vectorized=True)
    return filt


class _LinearisedKF:
    """KF on the error about the nominal (noise-free, commanded) path: a *linear* filter for a nonlinear robot."""

    def __init__(self, x0, P0, model, sensor, q_scale):
        self.model, self.sensor, self.q_scale = model, sensor, q_scale
        self.x_nom, self.dx, self.P = np.array(x0, float), np.zeros(3), np.array(P0, float)

    @property
    def x(self):
        """Estimate = nominal + estimated deviation (heading wrapped)."""
        return self.model.residual(self.x_nom + self.dx, np.zeros(3))

    def predict(self, u):
        F = self.model.F_jac(self.x_nom, u)
        Q = self.q_scale * self.model.Q(self.x_nom, u)
        self.dx, self.P = _predict(self.dx, self.P, F, Q)
        self.x_nom = self.model.f(self.x_nom, u)

    def update(self, z):
        H = self.sensor.H_jac(self.x_nom)
        y = self.sensor.residual(z, self.sensor.h(self.x_nom)) - H @ self.dx
        self.dx, self.P, *_ = _update(self.dx, self.P, y, H, self.sensor.R)


def _unicycle_run(*, filters, model, sensor, U, P0, alpha, beta, kappa, q_scale, rng) -> dict:
    """One Monte Carlo run of every filter on the same simulated unicycle path (see run_unicycle_comparison)."""
    n_steps, nf = U.shape[0], len(filters)
    x_true0 = np.zeros(3)
    X, Z = simulate_unicycle(model, sensor, x_true0, U, rng=rng)
    x0 = x_true0 + rng.multivariate_normal(np.zeros(3), P0)
    filt = _make_filters(filters, x0, P0, model, sensor, U[0], alpha, beta, kappa, q_scale)
    if "LKF" in filters:
        filt["LKF"] = _LinearisedKF(x0, P0, model, sensor, q_scale)
    est = np.full((nf, n_steps, 3), np.nan)
    cov = np.full((nf, n_steps, 3, 3), np.nan)
    err = np.full((nf, n_steps, 3), np.nan)
    nees_k = np.full((nf, n_steps), np.nan)
    failed = np.zeros(nf, dtype=bool)
    for i, name in enumerate(filters):
        f = filt[name]
        try:
            for k in range(n_steps):
                if name in ("EKF", "UKF-add"):
                    f.Q = q_scale * model.Q(f.x, U[k])
                f.predict(U[k])
                f.update(Z[k])
                est[i, k] = f.x
                cov[i, k] = f.P
        except (np.linalg.LinAlgError, ValueError):  # a numerical failure: counted, left out of the averages
            failed[i] = True
            est[i], cov[i] = np.nan, np.nan
            continue
        err[i] = model.residual(X, est[i])
        nees_k[i] = nees(err[i], cov[i])
    return {"err": err, "nees": nees_k, "failed": failed, "example": (X, est, cov)}


def run_unicycle_comparison(n_runs: int = 30, n_steps: int = 60, *, filters=FILTER_NAMES,
                            range_std_m: float = 0.5, bearing_std_deg: float = 10.0,
                            v_std_mps: float = 0.2, omega_std_degps: float = 10.0,
                            init_pos_std_m: float = 1.0, init_heading_std_deg: float = 90.0,
                            landmarks_m=None, dt_s: float = 0.5, speed_mps: float = 1.0,
                            turn_rate_degps: float = 11.46, alpha: float = 1e-3, beta: float = 2.0,
                            kappa: float = 0.0, stabilising_noise: float = 1.0, rng=2010, n_jobs: int = 1,
                            progress: bool | None = None) -> UnicycleResult:
    """Compare the linearised KF, EKF and augmented/additive UKF on a range-bearing unicycle (000 §1.2).

    The robot drives a circle (``speed_mps``, ``turn_rate_degps``); its control
    is perturbed by ``v_std_mps``, ``omega_std_degps``; every step it measures
    range and bearing to all ``landmarks_m``. Each filter starts from the same
    estimate drawn from ``P0`` around the truth. ``stabilising_noise`` scales
    the process noise the filters assume (000's "stabilising noise" for the
    EKF; 1 = the true noise). A run in which a filter fails numerically (e.g. a
    Cholesky failure) is counted in ``failures`` and left out of its averages.

    Parameters
    ----------
    n_runs : int, default 30
        Monte Carlo runs.
    n_steps : int, default 60
        Steps per run.
    filters : sequence of str
        Any of ``FILTER_NAMES``: "LKF" (KF about the nominal path), "EKF", "UKF-aug", "UKF-add".
    range_std_m : float, default 0.5
        Range noise std [m].
    bearing_std_deg : float, default 10.0
        Bearing noise std [deg].
    v_std_mps : float, default 0.2
        Speed noise std [m/s].
    omega_std_degps : float, default 10.0
        Turn-rate noise std [deg/s].
    init_pos_std_m : float, default 1.0
        Initial position std of ``P0`` [m].
    init_heading_std_deg : float, default 90.0
        Initial heading std of ``P0`` [deg].
    landmarks_m : array_like, shape (L, 2), optional
        Landmark positions [m]; None for :func:`default_landmarks`.
    dt_s : float, default 0.5
        Time step [s].
    speed_mps : float, default 1.0
        Commanded speed [m/s].
    turn_rate_degps : float, default 11.46
        Commanded turn rate [deg/s].
    alpha, beta, kappa : float
        Sigma-point parameters of both UKFs (000's defaults 1e-3, 2, 0).
    stabilising_noise : float, default 1.0
        Factor on the process noise the filters assume (> 0).
    rng : int, numpy.random.Generator or SeedSequence, default 2010
        Seed or generator; run ``r`` draws from child ``r`` of its seed sequence.
    n_jobs : int, default 1
        Worker processes for the runs.
    progress : bool or None
        Progress bar: None shows one in a notebook only.

    Returns
    -------
    UnicycleResult
    """
    n_runs = v.check_int(n_runs, "n_runs", minimum=1)
    n_steps = v.check_int(n_steps, "n_steps", minimum=1)
    filters = tuple(filters)
    for name in filters:
        v.check_choice(name, "filters", FILTER_NAMES)
    q_scale = v.check_positive(stabilising_noise, "stabilising_noise")
    lm = default_landmarks() if landmarks_m is None else landmarks_m
    model = UnicycleModel(dt_s, v_std_mps, np.deg2rad(omega_std_degps))
    sensor = RangeBearingSensor(lm, range_std_m, np.deg2rad(bearing_std_deg))
    U = np.tile([speed_mps, np.deg2rad(turn_rate_degps)], (n_steps, 1))
    P0 = np.diag([init_pos_std_m**2, init_pos_std_m**2, np.deg2rad(init_heading_std_deg) ** 2])
    runs = _monte_carlo(_unicycle_run, n_runs, rng, n_jobs, progress, filters=filters, model=model, sensor=sensor,
                        U=U, P0=P0, alpha=alpha, beta=beta, kappa=kappa, q_scale=q_scale)
    ok = ~np.stack(runs["failed"])  # (n_runs, nf)
    err = np.stack(runs["err"])  # (n_runs, nf, n_steps, 3), NaN for a failed filter
    sq_pos = np.sum(err[..., :2] ** 2, axis=-1)  # (n_runs, nf, n_steps)
    se_pos = np.where(ok, sq_pos.sum(axis=-1), 0.0).sum(axis=0)
    se_head = np.where(ok, np.sum(err[..., 2] ** 2, axis=-1), 0.0).sum(axis=0)
    counts = ok.sum(axis=0) * n_steps
    failures = (~ok).sum(axis=0)
    run_rmse = np.where(ok, np.sqrt(np.mean(sq_pos, axis=-1)), np.nan).T  # (nf, n_runs)
    nees_runs = np.stack(runs["nees"])  # (n_runs, nf, n_steps)
    nees_sum = np.where(ok[..., None], nees_runs, 0.0).sum(axis=0)
    nees_cnt = np.broadcast_to(ok.sum(axis=0)[:, None], nees_sum.shape).astype(float)
    ex_truth, ex_est, ex_P = runs["example"][0]
    with np.errstate(invalid="ignore", divide="ignore"):
        rmse_pos = np.sqrt(se_pos / counts)
        rmse_head = np.sqrt(se_head / counts)
        anees = nees_sum / nees_cnt
    params = {"range_std_m": range_std_m, "bearing_std_deg": bearing_std_deg, "v_std_mps": v_std_mps,
                  "omega_std_degps": omega_std_degps, "init_heading_std_deg": init_heading_std_deg, "alpha": alpha,
                  "beta": beta, "kappa": kappa, "stabilising_noise": stabilising_noise}
    ok_runs = max(1, int(n_runs - failures.max()))
    return UnicycleResult(filters, n_runs, n_steps, params, rmse_pos, rmse_head, anees, failures, run_rmse,
                          chi2_interval(3, ok_runs), ex_truth, ex_est, ex_P, sensor.landmarks_m)


# --- 000's "stabilising noise" for the EKF ----------------------------------------------------------


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


def run_stabilising_noise(scales=(1.0, 2.0, 4.0, 8.0), n_runs: int = 30, n_steps: int = 60, *, rng=2010,
                          **scenario) -> StabilisingNoiseResult:
    """EKF on the unicycle scenario with the assumed process noise scaled by ``scales`` (000 §1.2.2).

    Parameters
    ----------
    scales : sequence of float
        Process-noise factors (``stabilising_noise`` of :func:`run_unicycle_comparison`).
    n_runs : int, default 30
        Monte Carlo runs per factor.
    n_steps : int, default 60
        Steps per run.
    rng : int or numpy.random.Generator, default 2010
        Seed or generator; the same runs for every factor.
    **scenario
        Further keywords of :func:`run_unicycle_comparison` (noise levels, landmarks...).

    Returns
    -------
    StabilisingNoiseResult
    """
    scales = v.as_vector(scales, "scales")
    rm, nn = [], []
    bounds = (0.0, 0.0)
    for s in scales:
        res = run_unicycle_comparison(n_runs, n_steps, filters=("EKF",), stabilising_noise=float(s), rng=rng,
                                      **scenario)
        rm.append(res.rmse_pos_m[0])
        nn.append(_nanmean(res.anees[0]))
        bounds = res.nees_bounds
    return StabilisingNoiseResult(scales, np.array(rm), np.array(nn), bounds, n_runs)
