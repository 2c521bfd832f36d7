"""Lab 01 (Kalman filters, 000 §1.2): the tasks and the library functions they are checked against."""

from __future__ import annotations

import numpy as np

from ..filters import kf_predict, kf_update, sigma_points, sigma_weights
from .core import Case, ExplorationTask, Task, allclose, register


def _spd(rng, n, scale=1.0):
    A = rng.normal(size=(n, n))
    return scale * (A @ A.T + n * np.eye(n))


def _predict_cases(rng):
    cases = []
    for n in (1, 2, 4):
        cases.append(Case(f"random, n={n}", {"x": rng.normal(size=n), "P": _spd(rng, n), "F": rng.normal(size=(n, n)),
                                             "Q": _spd(rng, n, 0.1)}))
    z = np.zeros((2, 2))
    cases.append(Case("P = 0 and Q = 0 (singular covariances)", {"x": np.array([1.0, -2.0]), "P": z.copy(),
                                                                 "F": np.array([[1.0, 1.0], [0.0, 1.0]]), "Q": z}))
    return cases


def _update_cases(rng):
    cases = []
    for n, m in ((1, 1), (2, 1), (4, 2)):
        cases.append(Case(f"random, n={n}, m={m}", {"x": rng.normal(size=n), "P": _spd(rng, n), "z": rng.normal(size=m),
                                                    "H": rng.normal(size=(m, n)), "R": _spd(rng, m, 0.5)}))
    cases.append(Case("P = 0: a perfectly known state ignores the measurement",
                      {"x": np.array([1.0, 2.0]), "P": np.zeros((2, 2)), "z": np.array([5.0]),
                       "H": np.array([[1.0, 0.0]]), "R": np.array([[1.0]])}))
    return cases


def _joseph_cases(rng):
    cases = []
    for n, m in ((2, 1), (3, 2)):
        P, H, R = _spd(rng, n), rng.normal(size=(m, n)), _spd(rng, m, 0.5)
        K_opt = P @ H.T @ np.linalg.inv(H @ P @ H.T + R)
        cases.append(Case(f"optimal gain, n={n}", {"P": P, "K": K_opt, "H": H, "R": R}))
        cases.append(Case(f"gain 1.5 x optimal, n={n}", {"P": P, "K": 1.5 * K_opt, "H": H, "R": R}))
    cases.append(Case("zero gain: nothing learnt", {"P": np.eye(2), "K": np.zeros((2, 1)), "H": np.array([[1.0, 0.0]]),
                                                    "R": np.array([[1.0]])}))
    return cases


def _weights_cases(rng):
    return [Case("L=2, alpha=1, beta=2, kappa=1", {"L": 2, "alpha": 1.0, "beta": 2.0, "kappa": 1.0}),
            Case("L=3, alpha=0.5, beta=0, kappa=0", {"L": 3, "alpha": 0.5, "beta": 0.0, "kappa": 0.0}),
            Case("000's defaults, L=5: alpha=1e-3, beta=2, kappa=0", {"L": 5, "alpha": 1e-3, "beta": 2.0, "kappa": 0.0}),
            Case("kappa < 0, L=1", {"L": 1, "alpha": 1.0, "beta": 2.0, "kappa": -0.5})]


def _points_cases(rng):
    cases = [Case("identity P, alpha=1, kappa=2", {"x": np.zeros(2), "P": np.eye(2), "alpha": 1.0, "kappa": 2.0})]
    for n in (1, 3):
        cases.append(Case(f"random, L={n}", {"x": rng.normal(size=n), "P": _spd(rng, n), "alpha": 0.7, "kappa": 1.0}))
    cases.append(Case("000's alpha=1e-3 on a large mean", {"x": np.array([100.0, -50.0]), "P": _spd(rng, 2),
                                                          "alpha": 1e-3, "kappa": 0.0}))
    return cases


def _update_reference(x, P, z, H, R):
    u = kf_update(x, P, z, H, R)
    return u.x, u.P


def _joseph_reference(P, K, H, R):
    I_KH = np.eye(P.shape[0]) - K @ H
    return I_KH @ P @ I_KH.T + K @ R @ K.T


register(Task("01.kf_predict", "Task 1, KF predict", lambda x, P, F, Q: kf_predict(x, P, F, Q), _predict_cases,
              "The predicted covariance must stay symmetric and must grow by Q: check which "
              "products are matrix products and where a transpose belongs."))
register(Task("01.kf_update", "Task 2, KF update (short form)", _update_reference, _update_cases,
              "Check the shapes of the innovation, its covariance and the gain against the "
              "measurement's size, and that the posterior covariance is no larger than the prior;"
              " the function returns the state and the covariance."))
register(Task("01.joseph", "Task 3, Joseph covariance update", _joseph_reference, _joseph_cases,
              "The form must hold for any gain, not only the optimal one: with a non-optimal gain"
              " the two terms of the equation must both appear, and the result must stay "
              "symmetric."))
register(Task("01.sigma_weights", "Task 4, sigma-point weights", lambda L, alpha, beta, kappa:
              sigma_weights(L, alpha, beta, kappa), _weights_cases,
              "The mean weights must sum to 1. With 000's tiny alpha the value L + lambda is the "
              "difference of two nearly equal numbers: think about computing it without that "
              "cancellation.",
              compare=allclose(rtol=1e-12, atol=0.0)))
register(Task("01.sigma_points", "Task 5, sigma points", lambda x, P, alpha, kappa: sigma_points(x, P, alpha, kappa),
              _points_cases,
              "The points must be symmetric about the mean, and their weighted covariance must "
              "give back (L + lambda) P's scale: check which factor of the matrix you take and "
              "whether you use its rows or its columns.",
              compare=allclose(rtol=1e-9, atol=1e-12)))


def _smallest_q_scale() -> float:
    from ..filters.experiments import run_stabilising_noise

    res = run_stabilising_noise(scales=(1.0, 2.0, 4.0, 8.0, 16.0), n_runs=30, n_steps=60, rng=2010,
                                progress=False)
    lo, hi = res.nees_bounds
    inside = res.scales[(res.mean_nees >= lo) & (res.mean_nees <= hi)]
    return float(inside.min()) if inside.size else float("nan")


def _rmse_quarter_metre() -> float:
    from ..filters.experiments import run_cv_target

    return run_cv_target(n_runs=50, n_steps=50, accel_std=0.2, pos_std_m=0.25, rng=2010,
                         progress=False).rmse_pos_m


register(ExplorationTask(
    "01.explore.q_scale",
    "Exploration 1: the smallest Q scale of (1, 2, 4, 8, 16) that makes the EKF consistent",
    _smallest_q_scale, hint="run sl.filters.run_stabilising_noise with those scales and read the last column."))
register(ExplorationTask(
    "01.explore.rmse_quarter_metre",
    "Exploration 2: the KF's position RMSE [m] with a 0.25 m measurement sigma", _rmse_quarter_metre, rtol=0.02,
    hint="run sl.filters.run_cv_target(pos_std_m=0.25, rng=2010) with 50 runs of 50 steps; give 3 decimals."))
