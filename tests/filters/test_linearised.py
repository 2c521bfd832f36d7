"""The linearised KF (issue 42: moved from the studies into the filters): the KF on a linear model, the error-state
filter about the nominal path written out step by step, and errors naming the argument."""

import numpy as np
import pytest

from slamlab.filters import KalmanFilter, LinearisedKalmanFilter, kf_predict, kf_update
from slamlab.sim import (
    RangeBearingSensor,
    UnicycleModel,
    constant_velocity_model,
    simulate_linear,
    simulate_unicycle,
)


def test_equals_the_kf_on_a_linear_model():
    F, Q, H, R = constant_velocity_model(1.0, 0.3, 0.5, dims=2)
    _, Z = simulate_linear(F, Q, H, R, [0.0, 1.0, 0.0, 0.5], 25, rng=4)
    x0, P0 = np.array([0.5, 0.8, -0.3, 0.4]), np.diag([1.0, 0.5, 1.0, 0.5])
    kf = KalmanFilter(x0, P0, F, Q, H, R)
    lkf = LinearisedKalmanFilter(x0, P0, lambda x, u: F @ x, lambda x, u: F, Q, lambda x: H @ x, lambda x: H, R)
    for z in Z:
        kf.predict()
        lkf.predict()
        kf.update(z)
        lkf.update(z)
        np.testing.assert_allclose(lkf.x, kf.x, rtol=1e-12, atol=1e-12)
        np.testing.assert_allclose(lkf.P, kf.P, rtol=1e-12, atol=1e-15)
        np.testing.assert_allclose(lkf.S, kf.S, rtol=1e-12)


def test_is_the_kf_on_the_deviation_about_the_nominal_path():
    """Reference: kf_predict / kf_update on dx with F, H taken on the noise-free path (what the unicycle study did)."""
    model = UnicycleModel(0.5, 0.2, np.deg2rad(10.0))
    sensor = RangeBearingSensor(np.array([[5.0, 5.0], [-4.0, 6.0], [0.0, -6.0]]), 0.5, np.deg2rad(10.0))
    U = np.tile([1.0, 0.2], (30, 1))
    _, Z = simulate_unicycle(model, sensor, np.zeros(3), U, rng=7)
    x0, P0 = np.array([0.3, -0.2, 0.4]), np.diag([1.0, 1.0, 0.5])
    lkf = LinearisedKalmanFilter(x0, P0, model.f, model.F_jac, model.Q(x0, U[0]), sensor.h, sensor.H_jac, sensor.R,
                                 residual=sensor.residual, x_wrap=lambda x: model.residual(x, np.zeros(3)))
    x_nom, dx, P = x0.copy(), np.zeros(3), P0.copy()
    for k in range(len(U)):
        Qk = model.Q(x_nom, U[k])
        lkf.Q = Qk
        lkf.predict(U[k])
        dx, P = kf_predict(dx, P, model.F_jac(x_nom, U[k]), 0.5 * (Qk + Qk.T))
        x_nom = model.f(x_nom, U[k])
        lkf.update(Z[k])
        Hk = sensor.H_jac(x_nom)
        z_dev = sensor.residual(Z[k], sensor.h(x_nom))  # z - h(x_nom) = H dx + noise: a linear measurement of dx
        upd = kf_update(dx, P, z_dev, Hk, sensor.R)
        dx, P = upd.x, upd.P
        np.testing.assert_allclose(lkf.x_nominal, x_nom, rtol=0, atol=0)
        np.testing.assert_allclose(lkf.dx, dx, rtol=1e-9, atol=1e-9)
        np.testing.assert_allclose(lkf.P, P, rtol=1e-9, atol=1e-12)
        np.testing.assert_allclose(lkf.x, model.residual(x_nom + dx, np.zeros(3)), atol=1e-9)
    assert np.abs(lkf.x[2]) <= np.pi


def test_bad_input_names_the_argument():
    args = ([0.0], [[1.0]], lambda x, u: x, lambda x, u: np.eye(1), [[0.1]], lambda x: x, lambda x: np.eye(1),
            [[1.0]])
    with pytest.raises(TypeError, match="`f` must be callable"):
        LinearisedKalmanFilter(args[0], args[1], 3.0, *args[3:])
    with pytest.raises(ValueError, match="`P` must be symmetric"):
        LinearisedKalmanFilter([0.0, 0.0], [[1.0, 0.5], [0.0, 1.0]], *args[2:])
    with pytest.raises(TypeError, match="`x_wrap` must be callable"):
        LinearisedKalmanFilter(*args, x_wrap=1)
    lkf = LinearisedKalmanFilter(*args)
    with pytest.raises(ValueError, match="`z` must have length 1"):
        lkf.update([1.0, 2.0])
    assert "dim_x=1" in repr(lkf)
