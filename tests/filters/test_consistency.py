"""NEES/NIS: definitions, chi-square bounds, and a consistent KF inside them on a seeded run."""

import numpy as np
import pytest
from scipy import stats

from slamlab.filters import KalmanFilter, chi2_interval, nees, nis
from slamlab.sim import constant_velocity_model, simulate_linear


def test_nees_batched_definition():
    rng = np.random.default_rng(0)
    A = rng.normal(size=(5, 3, 3))
    P = A @ A.transpose(0, 2, 1) + np.eye(3)
    e = rng.normal(size=(5, 3))
    expected = [e[i] @ np.linalg.inv(P[i]) @ e[i] for i in range(5)]
    np.testing.assert_allclose(nees(e, P), expected, rtol=1e-10)
    np.testing.assert_allclose(nis(e[0], P[0]), expected[0], rtol=1e-10)


def test_chi2_interval_matches_tables():
    # Bar-Shalom et al. (2001), p. 235: 50 runs, 2 dof -> [1.5, 2.6]
    lo, hi = chi2_interval(2, 50)
    assert round(lo, 1) == 1.5
    assert round(hi, 1) == 2.6
    assert chi2_interval(1, 1, 0.95) == pytest.approx((stats.chi2.ppf(0.025, 1), stats.chi2.ppf(0.975, 1)))


def test_consistent_kf_nees_and_nis_inside_bounds():
    F, Q, H, R = constant_velocity_model(dt_s=1.0, accel_std=0.2, pos_std_m=1.0, dims=2)
    n_runs, n_steps = 50, 40
    ss = np.random.SeedSequence(2010)
    nees_runs, nis_runs = [], []
    for child in ss.spawn(n_runs):
        rng = np.random.default_rng(child)
        P0 = np.diag([1.0, 0.1, 1.0, 0.1])
        x0 = rng.multivariate_normal(np.zeros(4), P0)
        X, Z = simulate_linear(F, Q, H, R, x0, n_steps, rng=rng)
        kf = KalmanFilter(np.zeros(4), P0, F, Q, H, R)
        e_run, y_run = [], []
        for xt, z in zip(X, Z, strict=True):
            kf.predict()
            kf.update(z)
            e_run.append(nees(xt - kf.x, kf.P))
            y_run.append(nis(kf.y, kf.S))
        nees_runs.append(e_run)
        nis_runs.append(y_run)
    anees = np.mean(nees_runs, axis=0)  # average over runs, per step
    anis = np.mean(nis_runs, axis=0)
    lo4, hi4 = chi2_interval(4, n_runs, 0.99)
    lo2, hi2 = chi2_interval(2, n_runs, 0.99)
    # 99 % per-step bounds; with 40 steps allow at most 2 excursions each
    assert np.sum((anees < lo4) | (anees > hi4)) <= 2
    assert np.sum((anis < lo2) | (anis > hi2)) <= 2
    # and the time-and-run average is close to the dimension
    assert np.mean(anees) == pytest.approx(4.0, rel=0.1)
    assert np.mean(anis) == pytest.approx(2.0, rel=0.1)


def test_nees_shape_mismatch():
    with pytest.raises(ValueError, match=r"`P` must have shape \(3, 3\) to match `err`"):
        nees(np.zeros(3), np.eye(2))
