"""Ch. 1 experiments (000 §1.2): seeded Monte Carlo runs returning printable results -- the linear target, the
Joseph form and 000 §3.6's landmark filter (the unicycle family: :mod:`.unicycle_experiments`).

Each ``run_*`` returns a frozen dataclass: ``str(result)`` is a one-line summary,
``result.table()`` a fixed-precision text table (what the notebook prints and
nbval compares); arrays for plotting are kept in fields.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from .. import _validate as v
from .._table import format_table
from ..sim import (
    constant_velocity_model,
    simulate_linear,
)
from .consistency import chi2_interval, nees
from .kalman import KalmanFilter, kf_update

__all__ = [
    "FILTER_NAMES",
    "CVTargetResult",
    "JosephResult",
    "LandmarkDemoResult",
    "run_cv_target",
    "run_joseph_vs_short",
    "run_landmark_filter",
]

FILTER_NAMES = ("LKF", "EKF", "UKF-aug", "UKF-add")
DIVERGED_RMSE_M = 2.0  # a run whose position RMSE exceeds this has lost track


def _nanmean(a) -> float:
    """Mean over the finite entries; NaN (without a warning) when there are none."""
    a = np.asarray(a, dtype=float)
    ok = np.isfinite(a)
    return float(a[ok].mean()) if ok.any() else float("nan")


# --- constant-velocity target: the KF is optimal --------------------------------------------------


@dataclass(frozen=True)
class CVTargetResult:
    """Linear constant-velocity target tracked by the KF (000 §1.2.1)."""

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


def _monte_carlo(run, n_runs: int, rng, n_jobs: int, progress, **fixed):
    """``n_runs`` seeded runs of ``run`` on :func:`slamlab.sweep.sweep` (run r draws from child r of ``rng``)."""
    from ..sweep import root_seed_sequence, sweep

    table = sweep(run, None, seeds=n_runs, seed=root_seed_sequence(rng, "rng"), n_jobs=n_jobs, progress=progress, fixed=fixed,
                  on_error="raise", desc=f"Monte Carlo ({run.__name__.strip('_').replace('_', ' ')})")
    return table


def run_cv_target(n_runs: int = 50, n_steps: int = 50, *, dt_s: float = 1.0, accel_std: float = 0.2,
                  pos_std_m: float = 1.0, rng=2010, n_jobs: int = 1, progress: bool | None = None) -> CVTargetResult:
    """Track a 2-D constant-velocity target with the KF over seeded Monte Carlo runs (on :func:`~slamlab.sweep.sweep`)."""
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
    """Posterior position variance from the short and Joseph forms vs the sampled truth."""

    gain_scales: np.ndarray
    var_short: np.ndarray
    var_joseph: np.ndarray
    var_sampled: np.ndarray
    n_samples: int

    def __str__(self) -> str:
        return (f"Short form matches the sampled error variance only at gain scale 1: "
                f"{len(self.gain_scales)} gains, {self.n_samples} samples each")

    def table(self) -> str:
        rows = [[f"{g:.2f}", f"{s:.4f}", f"{j:.4f}", f"{m:.4f}"]
                for g, s, j, m in zip(self.gain_scales, self.var_short, self.var_joseph, self.var_sampled,
                                      strict=True)]
        return format_table(["gain / K_opt", "short (I-KH)P", "Joseph", "sampled"], rows)


def run_joseph_vs_short(gain_scales=(0.0, 0.5, 0.8, 1.0, 1.2, 1.5, 2.0), *, n_samples: int = 100_000,
                        rng=2010) -> JosephResult:
    """Scale the optimal gain and compare both covariance updates with the sampled error variance.

    One position/velocity prior, a position measurement; the true posterior
    error is sampled ``n_samples`` times per gain.
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


# --- the static-landmark filter of 000 §3.6 ---------------------------------------------------------


@dataclass(frozen=True)
class LandmarkDemoResult:
    """Static landmarks refined by the §3.6 filter: error vs number of sightings."""

    sightings: np.ndarray
    rmse_filtered_m: np.ndarray
    rmse_single_m: np.ndarray
    predicted_std_m: np.ndarray
    n_landmarks: int

    def __str__(self) -> str:
        return (f"{self.n_landmarks} landmarks: RMSE {self.rmse_single_m[-1]:.4f} m from one sighting, "
                f"{self.rmse_filtered_m[-1]:.4f} m after {self.sightings[-1]} sightings")

    def table(self) -> str:
        rows = [[f"{n}", f"{f:.4f}", f"{p:.4f}", f"{s:.4f}", f"{s / np.sqrt(n):.4f}"]
                for n, f, p, s in zip(self.sightings, self.rmse_filtered_m, self.predicted_std_m,
                                      self.rmse_single_m, strict=True)]
        return format_table(["sightings", "filtered RMSE [m]", "predicted [m]", "one sighting [m]",
                             "one / sqrt(n) [m]"], rows)


def run_landmark_filter(n_landmarks: int = 500, n_sightings: int = 20, *, obs_std_m: float = 0.05,
                        state_std_m: float = 0.0, report=(1, 2, 3, 5, 10, 20), rng=2010) -> LandmarkDemoResult:
    """Observe static 3-D landmarks repeatedly and refine them with :class:`LandmarkFilter` (000 §3.6).

    RMSE is per coordinate, over all landmarks. With ``state_std_m = 0`` the
    estimate is the running mean of the sightings, so its error falls as
    ``1/sqrt(n)``.
    """
    from .landmark import LandmarkFilter

    g = v.as_rng(rng)
    n_landmarks = v.check_int(n_landmarks, "n_landmarks", minimum=1)
    n_sightings = v.check_int(n_sightings, "n_sightings", minimum=1)
    obs_std_m = v.check_positive(obs_std_m, "obs_std_m")
    report = [int(r) for r in report if 1 <= r <= n_sightings]
    truth = g.uniform(-5.0, 5.0, size=(n_landmarks, 3))
    lf = LandmarkFilter(state_var=state_std_m**2, obs_var=obs_std_m**2, dim=3)
    idx = lf.add(truth + obs_std_m * g.normal(size=truth.shape))
    filt, single, pred = [], [], []
    for n in range(1, n_sightings + 1):
        if n > 1:
            z = truth + obs_std_m * g.normal(size=truth.shape)
            lf.observe(idx, z)
        else:
            z = lf.X.copy()
        if n in report:
            filt.append(np.sqrt(np.mean((lf.X - truth) ** 2)))
            single.append(np.sqrt(np.mean((z - truth) ** 2)))
            pred.append(np.sqrt(np.mean(np.trace(lf.P, axis1=1, axis2=2) / 3)))
    return LandmarkDemoResult(np.array(report), np.array(filt), np.array(single), np.array(pred), n_landmarks)
