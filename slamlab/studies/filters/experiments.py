"""Ch. 1 experiments (000 §1.2): seeded Monte Carlo runs returning printable results.

Each ``run_*`` returns a frozen dataclass: ``str(result)`` is a one-line summary,
``result.table()`` a fixed-precision text table (what the notebook prints and
nbval compares); arrays for plotting are kept in fields.

This module builds the simulated worlds and runs the experiments on them (constant-velocity target,
sigma-point weight, unicycle filter comparison, stabilising noise) in a seeded Monte Carlo loop; the result
dataclasses live in :mod:`~slamlab.studies.filters.results`, the sim-free studies in
:mod:`~slamlab.studies.filters.studies`, the closing table in :mod:`~slamlab.studies.filters.source_table`
(all re-exported here).
"""

from __future__ import annotations

import numpy as np

from ..._validate import as_vector, check_choice, check_int, check_positive
from ...filters.consistency import chi2_interval, nees
from ...filters.ekf import ExtendedKalmanFilter
from ...filters.kalman import KalmanFilter, LinearisedKalmanFilter
from ...filters.ukf import UnscentedKalmanFilter, sigma_weights, ukf_predict, ukf_update
from ...sim import (
    RangeBearingSensor,
    UnicycleModel,
    constant_velocity_model,
    simulate_linear,
    simulate_unicycle,
)
from .results import (
    DIVERGED_RMSE_M,
    FILTER_NAMES,
    CVTargetResult,
    JosephResult,
    LandmarkDemoResult,
    SigmaAlphaResult,
    StabilisingNoiseResult,
    UnicycleResult,
)
from .source_table import ours_vs_source
from .studies import default_landmarks, run_joseph_vs_short, run_landmark_filter

__all__ = [
    "DIVERGED_RMSE_M",
    "FILTER_NAMES",
    "CVTargetResult",
    "JosephResult",
    "LandmarkDemoResult",
    "SigmaAlphaResult",
    "StabilisingNoiseResult",
    "UnicycleResult",
    "default_landmarks",
    "ours_vs_source",
    "run_cv_target",
    "run_joseph_vs_short",
    "run_landmark_filter",
    "run_sigma_alpha_study",
    "run_stabilising_noise",
    "run_unicycle_comparison",
]


def _monte_carlo(run, n_runs: int, rng, n_jobs: int, progress, **fixed):
    """``n_runs`` seeded runs of ``run`` on :func:`slamlab.sweep.sweep` (run r draws from child r of ``rng``)."""
    from ...sweep import root_seed_sequence, sweep

    table = sweep(run, None, seeds=n_runs, rng=root_seed_sequence(rng, "rng"), n_jobs=n_jobs, progress=progress, fixed=fixed,
                  on_error="raise", desc=f"Monte Carlo ({run.__name__.strip('_').replace('_', ' ')})")
    return table


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
    n_runs = check_int(n_runs, "n_runs", minimum=1)
    n_steps = check_int(n_steps, "n_steps", minimum=1)
    F, Q, H, R = constant_velocity_model(dt_s, accel_std, pos_std_m, dims=2)
    P0 = np.diag([pos_std_m**2, 1.0, pos_std_m**2, 1.0])
    runs = _monte_carlo(_cv_run, n_runs, rng, n_jobs, progress, F=F, Q=Q, H=H, R=R, P0=P0, n_steps=n_steps)
    n = n_runs * n_steps
    return CVTargetResult(
        n_runs, n_steps, float(np.sqrt(runs["se_pos"].sum() / n)), float(np.sqrt(runs["se_meas"].sum() / n)),
        float(np.sqrt(runs["var_pred"].sum() / n)), np.stack(runs["nees"]).mean(axis=0),
        np.stack(runs["nis"]).mean(axis=0), chi2_interval(4, n_runs), chi2_interval(2, n_runs), *runs["example"][0],
    )


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
    alphas = as_vector(alphas, "alphas")
    F, Q, H, R = constant_velocity_model(1.0, 0.5, 1.0, dims=1)
    _, Z = simulate_linear(F, Q, H, R, [100.0, 1.0], n_steps, rng=rng)
    w0, eP, ex = [], [], []
    for a in alphas:
        w0.append(sigma_weights(2, float(a))[0][0])
        kf = KalmanFilter(np.array([100.0, 1.0]), 10 * np.eye(2), F, Q, H, R)
        xu, Pu = kf.x.copy(), kf.P.copy()
        worst_P = worst_x = 0.0
        try:
            for z in Z:
                kf.predict()
                xu, Pu = ukf_predict(xu, Pu, lambda x, u: x @ F.T, Q, form="additive", alpha=float(a),
                                     vectorized=True)
                kf.update(z)
                upu = ukf_update(xu, Pu, z, lambda x: x @ H.T, R, form="additive", alpha=float(a),
                                 vectorized=True)
                xk, Pk, xu, Pu = kf.x, kf.P, upu.x, upu.P
                worst_P = max(worst_P, np.max(np.abs(Pu - Pk)) / np.max(np.abs(Pk)))
                worst_x = max(worst_x, np.max(np.abs(xu - xk)) / np.max(np.abs(xk)))
        except np.linalg.LinAlgError:
            worst_P = worst_x = np.inf
        eP.append(worst_P)
        ex.append(worst_x)
    return SigmaAlphaResult(alphas, np.array(w0), np.array(eP), np.array(ex), n_steps)


def _make_filters(names, x0, P0, model, sensor, u0, alpha, beta, kappa, q_scale):
    filt = {}
    for name in names:
        if name == "LKF":  # the KF of a nonlinear robot: linear about the nominal (noise-free, commanded) path
            filt[name] = LinearisedKalmanFilter(x0, P0, model.f, model.F_jac, q_scale * model.Q(x0, u0), sensor.h,
                                                sensor.H_jac, sensor.R, residual=sensor.residual,
                                                x_wrap=lambda x: model.residual(x, np.zeros(3)))
        elif name == "EKF":
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


def _unicycle_run(*, filters, model, sensor, U, P0, alpha, beta, kappa, q_scale, rng) -> dict:
    """One Monte Carlo run of every filter on the same simulated unicycle path (see run_unicycle_comparison)."""
    n_steps, nf = U.shape[0], len(filters)
    x_true0 = np.zeros(3)
    X, Z = simulate_unicycle(model, sensor, x_true0, U, rng=rng)
    x0 = x_true0 + rng.multivariate_normal(np.zeros(3), P0)
    filt = _make_filters(filters, x0, P0, model, sensor, U[0], alpha, beta, kappa, q_scale)
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
                elif name == "LKF":  # Q on the nominal path, like the Jacobians
                    f.Q = q_scale * model.Q(f.x_nominal, U[k])
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
    n_runs = check_int(n_runs, "n_runs", minimum=1)
    n_steps = check_int(n_steps, "n_steps", minimum=1)
    filters = tuple(filters)
    for name in filters:
        check_choice(name, "filters", FILTER_NAMES)
    q_scale = check_positive(stabilising_noise, "stabilising_noise")
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
    scales = as_vector(scales, "scales")
    rm, nn = [], []
    bounds = (0.0, 0.0)
    for s in scales:
        res = run_unicycle_comparison(n_runs, n_steps, filters=("EKF",), stabilising_noise=float(s), rng=rng,
                                      **scenario)
        rm.append(res.rmse_pos_m[0])
        nn.append(res.mean_nees[0])
        bounds = res.nees_bounds
    return StabilisingNoiseResult(scales, np.array(rm), np.array(nn), bounds, n_runs)
