"""KF against filterpy, Joseph vs short form, class vs function."""

import numpy as np
import pytest
from filterpy.kalman import KalmanFilter as FPKalmanFilter

from slamlab.filters import KalmanFilter, kf_predict, kf_update
from slamlab.sim import constant_velocity_model, simulate_linear


@pytest.fixture
def cv_problem():
    F, Q, H, R = constant_velocity_model(dt_s=0.5, accel_std=0.3, pos_std_m=0.8, dims=2)
    x0 = np.array([0.0, 1.0, 0.0, -0.5])
    X, Z = simulate_linear(F, Q, H, R, x0, 60, rng=1)
    return F, Q, H, R, x0, X, Z


def test_kf_matches_filterpy(cv_problem):
    F, Q, H, R, x0, _, Z = cv_problem
    P0 = np.diag([4.0, 1.0, 4.0, 1.0])
    ref = FPKalmanFilter(dim_x=4, dim_z=2)
    ref.x, ref.P, ref.F, ref.Q, ref.H, ref.R = x0.copy(), P0.copy(), F, Q, H, R
    ours = KalmanFilter(x0, P0, F, Q, H, R)
    for z in Z:
        ref.predict()
        ours.predict()
        np.testing.assert_allclose(ours.x_prior, ref.x_prior, rtol=1e-9, atol=1e-12)
        np.testing.assert_allclose(ours.P_prior, ref.P_prior, rtol=1e-9, atol=1e-12)
        ref.update(z)
        ours.update(z)
        np.testing.assert_allclose(ours.x, ref.x, rtol=1e-9, atol=1e-12)
        np.testing.assert_allclose(ours.P, ref.P, rtol=1e-9, atol=1e-12)
        np.testing.assert_allclose(ours.S, ref.S, rtol=1e-9, atol=1e-12)
        np.testing.assert_allclose(ours.K, ref.K, rtol=1e-9, atol=1e-12)


def test_kf_with_control_matches_filterpy():
    F = np.array([[1.0, 1.0], [0.0, 1.0]])
    B = np.array([[0.5], [1.0]])
    Q, H, R = 0.01 * np.eye(2), np.array([[1.0, 0.0]]), np.array([[0.25]])
    ref = FPKalmanFilter(dim_x=2, dim_z=1, dim_u=1)
    ref.x, ref.P, ref.F, ref.B, ref.Q, ref.H, ref.R = np.zeros(2), np.eye(2), F, B, Q, H, R
    x, P = np.zeros(2), np.eye(2)
    for k in range(20):
        u = np.array([np.sin(k)])
        ref.predict(u=u)
        x, P = kf_predict(x, P, F, Q, B, u)
        np.testing.assert_allclose(x, ref.x, rtol=1e-9, atol=1e-12)
        z = np.array([0.1 * k])
        ref.update(z)
        x, P, *_ = kf_update(x, P, z, H, R)
        np.testing.assert_allclose(P, ref.P, rtol=1e-9, atol=1e-12)


def test_class_agrees_with_functions(cv_problem):
    F, Q, H, R, x0, _, Z = cv_problem
    P0 = np.eye(4)
    kf = KalmanFilter(x0, P0, F, Q, H, R, form="joseph")
    x, P = x0, P0
    for z in Z[:10]:
        kf.predict()
        kf.update(z)
        x, P = kf_predict(x, P, F, Q)
        upd = kf_update(x, P, z, H, R, form="joseph")
        x, P = upd.x, upd.P
        np.testing.assert_array_equal(kf.x, x)
        np.testing.assert_array_equal(kf.P, P)
        np.testing.assert_array_equal(kf.y, upd.y)


def test_joseph_equals_short_at_optimal_gain_only():
    rng = np.random.default_rng(3)
    A = rng.normal(size=(4, 4))
    P = A @ A.T + np.eye(4)
    H = rng.normal(size=(2, 4))
    R = np.diag([0.5, 2.0])
    x, z = rng.normal(size=4), rng.normal(size=2)
    short = kf_update(x, P, z, H, R, form="short")
    joseph = kf_update(x, P, z, H, R, form="joseph")
    np.testing.assert_allclose(joseph.P, short.P, rtol=1e-10, atol=1e-12)
    K_bad = 0.7 * short.K
    short_bad = kf_update(x, P, z, H, R, form="short", K=K_bad)
    joseph_bad = kf_update(x, P, z, H, R, form="joseph", K=K_bad)
    assert np.max(np.abs(joseph_bad.P - short_bad.P)) > 1e-2
    # The Joseph form is the true error covariance for any gain: check by sampling.
    n = 200_000
    x_true = rng.multivariate_normal(x, P, size=n)
    z_s = x_true @ H.T + rng.multivariate_normal(np.zeros(2), R, size=n)
    x_est = x + (z_s - x @ H.T) @ K_bad.T
    err_cov = np.cov((x_true - x_est).T)
    np.testing.assert_allclose(err_cov, joseph_bad.P, rtol=0.03, atol=0.03)
    assert np.max(np.abs(err_cov - short_bad.P)) > 0.1


def test_covariance_stays_symmetric(cv_problem):
    F, Q, H, R, x0, _, Z = cv_problem
    kf = KalmanFilter(x0, 100 * np.eye(4), F, Q, H, R)
    for z in Z:
        kf.predict()
        kf.update(z)
        np.testing.assert_array_equal(kf.P, kf.P.T)
