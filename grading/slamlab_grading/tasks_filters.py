"""Lab 01 (Kalman filters, 000 §1.2): the tasks and the library functions they are checked against."""

from __future__ import annotations

import math

import numpy as np

from slamlab.filters import kf_predict, kf_update, sigma_points, sigma_weights
from slamlab.lab.compare import allclose

from .core import Case, ExplorationTask, Task, WrongAnswer, register


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


#: Exploration 1 of lab 01: the Q scale, run count and steps the question fixes (one run per seed).
EXPLORE_Q_SCALE, EXPLORE_Q_RUNS, EXPLORE_Q_STEPS, EXPLORE_Q_SEED = 16.0, 400, 60, 2010

#: Exploration 1's accepted range and the numbers it comes from: the per-run time-averaged NEES of filterpy's EKF
#: (:func:`run_nees_filterpy`) on seeds 0-3999, one run per seed; the median of 400 runs resampled 50 000 times
#: from them. Scale 16: population median 2.645, 400-run medians between 2.537 and 2.767 (0.05 % and 99.95 %
#: quantiles; 2.524 and 2.782 at 0.01 % and 99.99 %; sd 0.035); ten disjoint blocks of 400 seeds 2.574-2.699.
#: Scale 1 (no stabilising noise): population median 3.019, 400-run medians 2.844 (0.01 %) to 3.194 (99.99 %).
#: Pooled median of every run's and step's NEES at scale 16: 2.091 (400-run resamples 2.008-2.187). Mean over
#: 400 runs at scale 16: never below 2.837, up to tens (the diverging runs). Checked again by
#: ``test_typical_run_nees_range_and_misconceptions_over_30_blocks_of_400_runs`` (tests/lab/test_check.py): an EKF
#: batched in the test with streams of its own, 30 blocks of 400 runs all inside, their three misconceptions all
#: outside.
EXPLORE_Q_ACCEPTED = (2.50, 2.80)
EXPLORE_Q_TRUE_NOISE_MEDIAN = 3.019
EXPLORE_Q_POOLED_MEDIAN = 2.091


def _typical_run_nees() -> float:
    """The library's own run of exploration 1: one run of the chapter's study per seed, the median run."""
    from slamlab.studies.filters import run_unicycle_comparison

    per_run = [run_unicycle_comparison(1, EXPLORE_Q_STEPS, filters=("EKF",), stabilising_noise=EXPLORE_Q_SCALE,
                                       rng=seed, progress=False).mean_nees[0]
               for seed in range(EXPLORE_Q_SEED, EXPLORE_Q_SEED + EXPLORE_Q_RUNS)]
    return float(np.median(per_run))


def _wrap(a):
    return (a + np.pi) % (2 * np.pi) - np.pi


def _filterpy_unicycle_nees(seq, scale, n_steps):
    """NEES per step of one run: the chapter's unicycle simulated here, filterpy's EKF with Q x ``scale``."""
    from filterpy.kalman import ExtendedKalmanFilter

    lm = np.array([[0.0, 5.0], [4.0, 8.0], [-4.0, 2.0]])  # the chapter's scenario (000 §1.2.2's study)
    dt, v, om, sv, som = 0.5, 1.0, np.deg2rad(11.46), 0.2, np.deg2rad(10.0)
    R = np.diag(np.tile([0.5**2, np.deg2rad(10.0) ** 2], 3))
    P0 = np.diag([1.0, 1.0, np.deg2rad(90.0) ** 2])

    def move(x, vel, turn):
        return np.array([x[0] + vel * dt * np.cos(x[2]), x[1] + vel * dt * np.sin(x[2]), _wrap(x[2] + turn * dt)])

    def hx(x):  # range and bearing to every landmark, interleaved
        d = lm - x[:2]
        return np.column_stack([np.hypot(d[:, 0], d[:, 1]), _wrap(np.arctan2(d[:, 1], d[:, 0]) - x[2])]).ravel()

    def H_jac(x):
        d = lm - x[:2]
        q = (d**2).sum(axis=1)
        H = np.zeros((6, 3))
        H[0::2, 0], H[0::2, 1] = -d[:, 0] / np.sqrt(q), -d[:, 1] / np.sqrt(q)
        H[1::2, 0], H[1::2, 1], H[1::2, 2] = d[:, 1] / q, -d[:, 0] / q, -1.0
        return H

    def residual(a, b):
        y = a - b
        y[1::2] = _wrap(y[1::2])
        return y

    rng = np.random.default_rng(seq)  # the draws in the library's order: controls, measurements, start
    W = rng.normal(size=(n_steps, 2)) * [sv, som]
    Vn = rng.normal(size=(n_steps, 6)) * np.sqrt(np.diag(R))
    x, X, Z = np.zeros(3), [], []
    for k in range(n_steps):
        x = move(x, v + W[k, 0], om + W[k, 1])
        X.append(x)
        Z.append(residual(hx(x) + Vn[k], 0.0))
    ekf = ExtendedKalmanFilter(dim_x=3, dim_z=6)
    ekf.x, ekf.P, ekf.R = rng.multivariate_normal(np.zeros(3), P0), P0.copy(), R
    out = []
    for k in range(n_steps):
        th = ekf.x[2]
        F = np.array([[1.0, 0.0, -v * dt * np.sin(th)], [0.0, 1.0, v * dt * np.cos(th)], [0.0, 0.0, 1.0]])
        V = np.array([[dt * np.cos(th), 0.0], [dt * np.sin(th), 0.0], [0.0, dt]])
        ekf.x = move(ekf.x, v, om)  # x = f(x, u); P = F P F^T + scale V M V^T
        ekf.P = F @ ekf.P @ F.T + scale * V @ np.diag([sv**2, som**2]) @ V.T
        ekf.update(Z[k], H_jac, hx, residual=residual)
        e = X[k] - ekf.x
        e[2] = _wrap(e[2])
        out.append(e @ np.linalg.solve(ekf.P, e))
    return np.array(out)


def run_nees_filterpy(seeds, scale: float = EXPLORE_Q_SCALE, n_steps: int = EXPLORE_Q_STEPS) -> np.ndarray:
    """Exploration 1 of lab 01 redone with filterpy's EKF: each seed's run, its NEES per step.

    Independent of :func:`slamlab.studies.filters.run_unicycle_comparison`: the chapter's unicycle and
    range-bearing sensor are simulated here and filtered by ``filterpy.kalman.ExtendedKalmanFilter``
    (Jacobians written here, Joseph-form update) with the process noise scaled by ``scale``. Seed ``s``
    draws from child 0 of ``SeedSequence(s)`` in the library's order, so the library's one-run study with
    ``rng=s`` has the same random run (NEES equal to 1e-8).

    Parameters
    ----------
    seeds : iterable of int
        One run per seed.
    scale : float
        Factor on the process noise the filter assumes (the stabilising noise).
    n_steps : int
        Steps per run.

    Returns
    -------
    numpy.ndarray, shape (len(seeds), n_steps)
        NEES per run and step.
    """
    return np.array([_filterpy_unicycle_nees(np.random.SeedSequence(int(s)).spawn(1)[0], scale, n_steps)
                     for s in seeds])


def _rmse_quarter_metre() -> float:
    from slamlab.studies.filters import run_cv_target

    return run_cv_target(n_runs=50, n_steps=50, accel_std=0.2, pos_std_m=0.25, rng=2010,
                         progress=False).rmse_pos_m


def cv_position_rmse_analytic(pos_std_m: float, *, n_steps: int | None = 50, accel_std: float = 0.2,
                              dt_s: float = 1.0) -> float:
    """The KF's expected 2-D position RMSE on the chapter's constant-velocity target, from the Riccati recursion.

    Independent of the Monte Carlo (:func:`slamlab.studies.filters.run_cv_target`): with a matched linear
    model the posterior covariance ``P_k`` is the error covariance, so the expected mean squared
    2-D position error over steps ``1..n_steps`` is the mean of ``P_k[x,x] + P_k[y,y]`` (per axis
    ``[p, v]``, ``Q = σ_a² [[dt³/3, dt²/2], [dt²/2, dt]]``, ``P_0 = diag(σ_z², 1)``, 000 §1.2.1's
    predict and update). ``n_steps=None`` gives the steady state (many steps).

    Parameters
    ----------
    pos_std_m : float
        Standard deviation of the position measurement, in metres.
    n_steps : int or None
        Number of steps averaged; None for the steady state.
    accel_std : float
        Standard deviation of the white-noise acceleration (σ_a), in m/s².
    dt_s : float
        Time step, in seconds.

    Returns
    -------
    float
        The expected 2-D position RMSE, in metres.
    """
    F = np.array([[1.0, dt_s], [0.0, 1.0]])
    Q = accel_std**2 * np.array([[dt_s**3 / 3, dt_s**2 / 2], [dt_s**2 / 2, dt_s]])
    P = np.diag([pos_std_m**2, 1.0])
    var = []
    for _ in range(n_steps or 2000):
        P = F @ P @ F.T + Q
        k = P[:, 0] / (P[0, 0] + pos_std_m**2)
        P = P - np.outer(k, P[0, :])
        var.append(2.0 * P[0, 0])  # x and y axes alike
    return float(np.sqrt(var[-1] if n_steps is None else np.mean(var)))


def _rmse_accepted() -> tuple[float, float]:
    # 50-step mean (transient included) or the steady state (many steps), ±5 % for the Monte Carlo spread
    return 0.95 * cv_position_rmse_analytic(0.25, n_steps=None), 1.05 * cv_position_rmse_analytic(0.25)


register(ExplorationTask(
    "01.explore.q_scale",
    "Exploration 1: the median over 400 runs of the EKF's run-averaged NEES with the process noise scaled by 16",
    _typical_run_nees, accepted=lambda: EXPLORE_Q_ACCEPTED,
    why="from an independent computation over the seeds the question allows (any 400): filterpy's EKF (Jacobians, "
        "simulation and Joseph update written in tasks_filters.py; equal to the library's run for run) on seeds "
        "0-3999, one run of 60 steps each, scale 16; the median of 400 of those runs resampled 50 000 times lies in "
        "[2.537, 2.767] (0.05-99.95 %; sd 0.035; population median 2.645), so [2.50, 2.80] accepts any 400 seeds. "
        "The question changed (issue 43): it asked for the smallest scale whose mean NEES is inside the 30-run "
        "interval, decided by 3.985 against 3.938 on one seed; the mean is ruled by the 3 % of runs that diverge "
        "from the 90° heading error, the median run is not. Rejected: scale 1 (400-run medians 2.84-3.19), the "
        "pooled median of every step (2.01-2.19), the mean over runs (>= 2.84, mostly far above).",
    hint="the quantity is a median over runs of each run's NEES averaged over its own 60 steps, with the process "
         "noise the filter assumes 16 times the true one, and every other setting the chapter's.",
    more="A typical run of a consistent filter has a run-averaged NEES near the state dimension: should extra "
         "assumed process noise move it up or down?",
    unit="a NEES (dimensionless)", bounds=(0.0, math.inf),
    answered_by=("slamlab.studies.filters.run_stabilising_noise",),
    wrong=(WrongAnswer("no stabilising noise", lambda: EXPLORE_Q_TRUE_NOISE_MEDIAN, atol=0.2,
                       hint="that is what a typical run gives with the true process noise, as a consistent filter "
                            "would: the question scales the noise the filter assumes by 16."),
           WrongAnswer("the pooled median", lambda: EXPLORE_Q_POOLED_MEDIAN, atol=0.15,
                       hint="that looks like the median of every single step's NEES: the question first averages "
                            "each run over its steps, then takes the median over runs."),
           WrongAnswer("the mean over runs", lambda: 10.27, rtol=0.8,
                       hint="that looks like a mean over runs, which the few diverging runs decide: the question "
                            "asks for the median run."))))
register(ExplorationTask(
    "01.explore.rmse_quarter_metre",
    "Exploration 2: the KF's position RMSE [m] with a 0.25 m measurement sigma", _rmse_quarter_metre, rtol=0.02,
    accepted=_rmse_accepted,
    why="from the Riccati recursion (independent of the Monte Carlo): 0.95 × the steady-state 2-D RMSE to "
        "1.05 × the mean over 50 steps with the initial transient ([0.285, 0.316] m); any seed, 50 runs or more, "
        "50 steps or more pass: a KF written in the tests, 50 runs of 50 steps, gives 0.295-0.310 m over seeds "
        "0-29, the library's study 0.294-0.308 m over seeds 2010-2039. Its misconceptions over those 30 seeds: "
        "the 1 m sensor 0.96-1.02 m, one axis <= 0.22 m, the squared error <= 0.10, centimetres >= 29.",
    unit="metres", bounds=(0.0, math.inf), answered_by=("slamlab.studies.filters.run_cv_target",),
    hint="the RMSE asked for is of the filter's position estimate against the true position, as a 2-D distance, "
         "averaged over runs and steps, with the measurement noise changed and nothing else.",
    more="Compare your number with the measurement σ and with the chapter's result for σ = 1 m: which way should "
         "a better sensor move it?",
    wrong=(WrongAnswer("the chapter's sensor", lambda: cv_position_rmse_analytic(1.0), rtol=0.05,
                       hint="that is the error with the chapter's 1 m sensor: the measurement noise was not changed."),
           WrongAnswer("the measurement sigma", lambda: 0.25, atol=1e-3,
                       hint="that is the sensor's σ, not the filter's error: the filter's error is measured against "
                            "the true trajectory."),
           WrongAnswer("mean squared error", lambda: cv_position_rmse_analytic(0.25) ** 2, rtol=0.1,
                       hint="that looks like a squared error (m²): the RMSE takes the square root of the mean."),
           WrongAnswer("one axis only", lambda: cv_position_rmse_analytic(0.25) / np.sqrt(2.0), rtol=0.05,
                       hint="that looks like the error of one coordinate: the position error is the 2-D distance."),
           WrongAnswer("centimetres", lambda: 100.0 * cv_position_rmse_analytic(0.25), rtol=0.1,
                       hint="check the unit: the answer is in metres."))))
