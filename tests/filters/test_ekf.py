"""EKF against filterpy's ExtendedKalmanFilter; Jacobian checker."""

import numpy as np
import pytest
from filterpy.kalman import ExtendedKalmanFilter as FPExtendedKalmanFilter

from slamlab.filters import ExtendedKalmanFilter, check_jacobian, ekf_predict, ekf_update, numerical_jacobian
from slamlab.sim import RangeBearingSensor, UnicycleModel, simulate_unicycle


@pytest.fixture
def robot():
    model = UnicycleModel(dt_s=0.5, v_std_mps=0.1, omega_std_radps=0.05)
    sensor = RangeBearingSensor(np.array([[5.0, 5.0], [-4.0, 6.0], [1.0, -5.0]]), 0.2, np.deg2rad(3.0))
    U = np.tile([1.0, 0.15], (40, 1))
    X, Z = simulate_unicycle(model, sensor, [0.0, 0.0, 0.0], U, rng=7)
    return model, sensor, U, X, Z


class _FPNonlinearEKF(FPExtendedKalmanFilter):
    """filterpy's EKF predicts with a linear F; give it the nonlinear f (documented recipe)."""

    def __init__(self, model, *a, **k):
        super().__init__(*a, **k)
        self.model = model

    def predict_x(self, u=0):
        self.x = self.model.f(self.x, u)


def test_ekf_matches_filterpy(robot):
    model, sensor, U, _, Z = robot
    x0, P0 = np.array([0.1, -0.1, 0.05]), np.diag([0.1, 0.1, 0.02])
    ref = _FPNonlinearEKF(model, dim_x=3, dim_z=sensor.dim_z)
    ref.x, ref.P, ref.R = x0.copy(), P0.copy(), sensor.R
    ours = ExtendedKalmanFilter(x0, P0, model.f, model.F_jac, model.Q(x0, U[0]), sensor.h, sensor.H_jac,
                                sensor.R, residual=sensor.residual)
    for u, z in zip(U, Z, strict=True):
        ref.F, ref.Q = model.F_jac(ref.x, u), model.Q(ref.x, u)
        ours.Q = model.Q(ours.x, u)
        ref.predict(u=u)
        ours.predict(u)
        np.testing.assert_allclose(ours.x, ref.x, rtol=1e-9, atol=1e-12)
        np.testing.assert_allclose(ours.P, ref.P, rtol=1e-9, atol=1e-12)
        ref.update(z, sensor.H_jac, sensor.h, residual=sensor.residual)
        ours.update(z)
        np.testing.assert_allclose(ours.x, ref.x, rtol=1e-9, atol=1e-12)
        np.testing.assert_allclose(ours.P, ref.P, rtol=1e-9, atol=1e-12)


def test_ekf_functions_equal_class(robot):
    model, sensor, U, _, Z = robot
    x, P = np.zeros(3), 0.1 * np.eye(3)
    ekf = ExtendedKalmanFilter(x, P, model.f, model.F_jac, model.Q(x, U[0]), sensor.h, sensor.H_jac, sensor.R,
                               residual=sensor.residual)
    for u, z in zip(U[:5], Z[:5], strict=True):
        Q = model.Q(x, u)
        ekf.Q = Q
        ekf.predict(u)
        ekf.update(z)
        x, P = ekf_predict(x, P, model.f, model.F_jac, Q, u)
        x, P, *_ = ekf_update(x, P, z, sensor.h, sensor.H_jac, sensor.R, residual=sensor.residual)
        # the function path symmetrises the validated Q: agreement to rounding, not bit-for-bit
        np.testing.assert_allclose(ekf.x, x, rtol=1e-13, atol=1e-15)
        np.testing.assert_allclose(ekf.P, P, rtol=1e-13, atol=1e-15)


def test_ekf_on_linear_model_is_kf():
    from slamlab.filters import kf_predict, kf_update

    F = np.array([[1.0, 0.5], [0.0, 1.0]])
    H = np.array([[1.0, 0.0]])
    x, P = np.array([1.0, 0.0]), np.eye(2)
    x1, P1 = ekf_predict(x, P, lambda x, u: F @ x, lambda x, u: F, 0.1 * np.eye(2))
    x2, P2 = kf_predict(x, P, F, 0.1 * np.eye(2))
    np.testing.assert_allclose(P1, P2, rtol=1e-14)
    a = ekf_update(x1, P1, [2.0], lambda x: H @ x, lambda x: H, [[0.5]])
    b = kf_update(x2, P2, [2.0], H, [[0.5]])
    np.testing.assert_allclose(a.x, b.x, rtol=1e-14)
    np.testing.assert_allclose(a.P, b.P, rtol=1e-14)


def test_numerical_jacobian_and_checker(robot):
    model, sensor, *_ = robot
    x, u = np.array([1.0, -2.0, 0.7]), np.array([1.2, -0.3])
    J = numerical_jacobian(sensor.h, x)
    np.testing.assert_allclose(J, sensor.H_jac(x), rtol=1e-6, atol=1e-8)
    assert check_jacobian(lambda s: model.f(s, u), lambda s: model.F_jac(s, u), x) < 1e-8
    wrong = lambda s: model.F_jac(s, u) + np.diag([0.0, 0.0, 0.01])
    with pytest.raises(ValueError, match=r"`jac` disagrees with finite differences at entry \(2, 2\)"):
        check_jacobian(lambda s: model.f(s, u), wrong, x)
