"""Lab 09 (monocular mapping, 003 §4): the tasks and the library functions they are checked against."""

from __future__ import annotations

import numpy as np

from ..mono import depth_filter as df
from .core import Case, ExplorationTask, Task, allclose, register

#: Exploration 1: the outlier rate and the seed of the convergence study
EXPLORE_OUTLIERS = 0.4
EXPLORE_SEED = 2019


def _update_reference(mu, sigma2, a, b, x, tau2, rho_range):
    return tuple(float(z) for z in df.update_seeds(mu, sigma2, a, b, x, tau2, rho_range))


def _update_cases(rng):
    cases = []
    for _ in range(3):
        mu = float(rng.uniform(0.2, 1.5))
        cases.append(Case("random seed, an inlier-like measurement",
                          {"mu": mu, "sigma2": float(rng.uniform(1e-4, 0.05)), "a": float(rng.uniform(2, 30)),
                           "b": float(rng.uniform(2, 30)), "x": mu + float(rng.normal(0, 0.02)),
                           "tau2": float(rng.uniform(1e-5, 1e-3)), "rho_range": 2.0}))
    cases.append(Case("a measurement far from the mean: mostly an outlier",
                      {"mu": 0.5, "sigma2": 1e-4, "a": 10.0, "b": 10.0, "x": 1.8, "tau2": 1e-4, "rho_range": 2.0}))
    cases.append(Case("SVO's fresh seed (a = b = 10, sigma^2 = rho_range^2 / 36)",
                      {"mu": 0.25, "sigma2": 4.0 / 36, "a": 10.0, "b": 10.0, "x": 0.3, "tau2": 1e-3, "rho_range": 2.0}))
    return cases


def _interval_reference(mu, sigma):
    lo, hi = df.depth_interval(np.array([mu]), np.array([sigma]))
    return (float(lo[0]), float(hi[0]))


def _interval_cases(rng):
    cases = [Case("random", {"mu": float(rng.uniform(0.3, 1.0)), "sigma": float(rng.uniform(0.01, 0.1))}) for _ in range(3)]
    cases.append(Case("rho - 2 sigma exactly 0: 003's 1e-10", {"mu": 0.2, "sigma": 0.1}))
    cases.append(Case("rho - 2 sigma < 0: the far end at 1 / 1e-10", {"mu": 0.1, "sigma": 0.3}))
    return cases


def _linearity_reference(mu, sigma2, d_m, cos_alpha):
    return float(df.linearity_index(mu, sigma2, d_m, cos_alpha))


def _linearity_cases(rng):
    cases = [Case("random", {"mu": float(rng.uniform(0.2, 1.0)), "sigma2": float(rng.uniform(1e-6, 1e-3)),
                             "d_m": float(rng.uniform(1, 6)), "cos_alpha": float(rng.uniform(0.9, 1.0))})
             for _ in range(3)]
    cases.append(Case("negative cos alpha (|cos|)", {"mu": 0.5, "sigma2": 1e-4, "d_m": 2.0, "cos_alpha": -0.99}))
    return cases


def _tau_reference(t, f, z, px_error_angle):
    return float(df.compute_tau(np.asarray(t), np.asarray(f)[None], np.array([z]), px_error_angle)[0])


def _tau_cases(rng):
    cases = []
    for _ in range(3):
        f = np.array([rng.uniform(-0.3, 0.3), rng.uniform(-0.2, 0.2), 1.0])
        cases.append(Case("random", {"t": rng.uniform(-0.3, 0.3, 3), "f": f / np.linalg.norm(f),
                                     "z": float(rng.uniform(1, 8)), "px_error_angle": 2 * np.arctan(0.5 / 500)}))
    cases.append(Case("sideways baseline, point straight ahead", {"t": np.array([0.5, 0.0, 0.0]), "f": np.array([0.0, 0.0, 1.0]),
                                                                  "z": 4.0, "px_error_angle": 0.002}))
    return cases


register(Task("09.update_seed", "Task 1, the Gaussian x Beta update of one seed", _update_reference, _update_cases,
              "C1 ∝ a/(a+b) N(x | mu, sigma2 + tau2), C2 ∝ b/(a+b) / rho_range, normalise; s2 = 1/(1/sigma2 + 1/tau2), "
              "m = s2 (mu/sigma2 + x/tau2); mu' = C1 m + C2 mu; sigma2' = C1 (s2 + m²) + C2 (sigma2 + mu²) - mu'²; "
              "f = E[pi], e = E[pi²], a' = (e - f)/(f - e/f), b' = a' (1 - f)/f. Return (mu', sigma2', a', b').",
              compare=allclose(rtol=1e-9, atol=1e-12), points=3))
register(Task("09.depth_interval", "Task 2, 003's depth band", _interval_reference, _interval_cases,
              "(1/(mu + 2 sigma), 1/max) where max = mu - 2 sigma, replaced by 1e-10 when it is <= 0.",
              compare=allclose(rtol=1e-12, atol=0.0)))
register(Task("09.linearity", "Task 3, 003's convergence test L", _linearity_reference, _linearity_cases,
              "L = 4 sigma_d |cos alpha| / d with sigma_d = sqrt(sigma2) / mu² (the depth std from the inverse-depth std).",
              compare=allclose(rtol=1e-12, atol=0.0)))
register(Task("09.tau", "Task 4, SVO's measurement noise tau", _tau_reference, _tau_cases,
              "a = f z - t; alpha = angle(f, t); beta = angle(a, -t); beta+ = beta + px_error_angle; "
              "gamma+ = pi - alpha - beta+; z+ = |t| sin(beta+) / sin(gamma+); tau = z+ - z.",
              compare=allclose(rtol=1e-9, atol=1e-12)))


def _observations_to_half() -> float:
    from ..mono.experiments import run_depth_filter_convergence

    c = run_depth_filter_convergence((EXPLORE_OUTLIERS,), n_obs=40, rng=EXPLORE_SEED)
    k = np.flatnonzero(c.converged[0] >= 0.5)
    return float(k[0]) if k.size else float("nan")


def _kitti_tracked() -> float:
    from ..mono.kitti import run_kitti_mono

    return float(run_kitti_mono().tracked.sum())


register(ExplorationTask(
    "09.explore.half_converged",
    "Exploration 1: observations until half of the seeds pass SVO's test at 40 % outliers",
    _observations_to_half,
    hint="sl.mono.run_depth_filter_convergence((0.4,), n_obs=40, rng=SEED); the first k with converged[0][k] >= 0.5."))
register(ExplorationTask(
    "09.explore.kitti_tracked",
    "Exploration 2: frames of the KITTI snippet with a tracked pose (defaults)",
    _kitti_tracked,
    hint="sl.mono.run_kitti_mono(); count r.tracked (the initialisation frame counts)."))
