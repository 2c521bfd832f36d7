"""UKF: weights, sigma points, filterpy agreement (additive and augmented), UKF = KF on linear models."""

import numpy as np
import pytest
from filterpy.kalman import MerweScaledSigmaPoints
from filterpy.kalman import UnscentedKalmanFilter as FPUnscentedKalmanFilter
from scipy.linalg import block_diag

from slamlab.filters import (
    CholeskyError,
    UnscentedKalmanFilter,
    kf_predict,
    kf_update,
    sigma_points,
    sigma_weights,
    ukf_predict,
    ukf_update,
    unscented_transform,
)
from slamlab.sim import (
    RangeBearingSensor,
    UnicycleModel,
    constant_velocity_model,
    simulate_linear,
    simulate_unicycle,
)


@pytest.mark.parametrize(("L", "alpha", "beta", "kappa"), [(3, 1e-3, 2.0, 0.0), (5, 0.5, 2.0, 1.0), (2, 1.0, 0.0, 3.0)])
def test_sigma_weights_match_filterpy_and_sum_to_one(L, alpha, beta, kappa):
    Ws, Wc, lam = sigma_weights(L, alpha, beta, kappa)
    ref = MerweScaledSigmaPoints(L, alpha=alpha, beta=beta, kappa=kappa)
    # filterpy forms L + lambda as a difference, which loses ~1e-10 relative at alpha = 1e-3
    np.testing.assert_allclose(Ws, ref.Wm, rtol=1e-9)
    np.testing.assert_allclose(Wc, ref.Wc, rtol=1e-9)
    assert Ws.sum() == pytest.approx(1.0, abs=1e-9 * max(1.0, abs(Ws[0])))
    assert lam == pytest.approx(alpha**2 * (L + kappa) - L)
    assert Wc[0] - Ws[0] == pytest.approx(1 - alpha**2 + beta)


def test_default_alpha_gives_huge_negative_centre_weight():
    Ws, Wc, _ = sigma_weights(3)  # 000's defaults alpha=1e-3, kappa=0, beta=2
    # kappa = 0: lambda/(L+lambda) = 1 - 1/alpha^2 exactly; computed without cancellation
    assert Ws[0] == pytest.approx(1.0 - 1.0 / 1e-6, rel=1e-14)
    assert Ws[1:].sum() == pytest.approx(1.0 / 1e-6, rel=1e-14)
    assert Wc[0] == pytest.approx(Ws[0] + 3.0 - 1e-6, rel=1e-14)


def test_sigma_points_match_filterpy_and_reproduce_moments():
    rng = np.random.default_rng(0)
    A = rng.normal(size=(4, 4))
    P = A @ A.T + 0.1 * np.eye(4)
    x = rng.normal(size=4)
    ours = sigma_points(x, P, alpha=0.5, kappa=1.0)
    ref = MerweScaledSigmaPoints(4, alpha=0.5, beta=2.0, kappa=1.0).sigma_points(x, P)
    np.testing.assert_allclose(ours, ref, rtol=1e-12, atol=1e-12)
    Ws, Wc, _ = sigma_weights(4, 0.5, 2.0, 1.0)
    m, C = unscented_transform(ours, Ws, Wc - np.r_[1 - 0.25 + 2.0, np.zeros(8)])
    np.testing.assert_allclose(m, x, atol=1e-12)
    np.testing.assert_allclose(C, P, atol=1e-12)


@pytest.fixture
def robot():
    model = UnicycleModel(dt_s=0.5, v_std_mps=0.15, omega_std_radps=0.08)
    sensor = RangeBearingSensor(np.array([[5.0, 5.0], [-4.0, 6.0], [1.0, -5.0]]), 0.2, np.deg2rad(3.0))
    U = np.tile([1.0, 0.2], (30, 1))
    X, Z = simulate_unicycle(model, sensor, [0.0, 0.0, 0.0], U, rng=11)
    return model, sensor, U, X, Z


def test_additive_ukf_matches_filterpy(robot):
    model, sensor, U, _, Z = robot
    x0, P0 = np.array([0.2, -0.1, 0.1]), np.diag([0.2, 0.2, 0.05])
    pts = MerweScaledSigmaPoints(3, alpha=0.3, beta=2.0, kappa=0.0)
    ref = FPUnscentedKalmanFilter(3, sensor.dim_z, model.dt_s, hx=sensor.h, fx=lambda x, dt, u: model.f(x, u),
                                  points=pts, x_mean_fn=model.mean, z_mean_fn=sensor.mean,
                                  residual_x=model.residual, residual_z=sensor.residual)
    ref.x, ref.P, ref.R = x0.copy(), P0.copy(), sensor.R
    ours = UnscentedKalmanFilter(x0, P0, model.f, model.Q(x0, U[0]), sensor.h, sensor.R, form="additive",
                                 alpha=0.3, x_mean_fn=model.mean, x_residual_fn=model.residual,
                                 z_mean_fn=sensor.mean, z_residual_fn=sensor.residual, vectorized=True)
    for u, z in zip(U, Z, strict=True):
        Q = model.Q(ours.x, u)
        ref.Q, ours.Q = Q, Q
        ref.predict(u=u)
        ours.predict(u)
        np.testing.assert_allclose(ours.x, ref.x, rtol=1e-9, atol=1e-12)
        np.testing.assert_allclose(ours.P, ref.P, rtol=1e-9, atol=1e-12)
        ref.update(z)
        ours.update(z)
        np.testing.assert_allclose(ours.x, ref.x, rtol=1e-9, atol=1e-12)
        np.testing.assert_allclose(ours.P, ref.P, rtol=1e-9, atol=1e-12)


def test_augmented_ukf_matches_filterpy_on_augmented_state(robot):
    """000's augmented form = filterpy's UKF run on [x; w] (predict) and [x; v] (update)."""
    model, sensor, U, _, Z = robot
    alpha, beta, kappa = 0.4, 2.0, 0.0
    x, P = np.array([0.2, -0.1, 0.1]), np.diag([0.2, 0.2, 0.05])
    M, R = model.M, sensor.R
    nz = sensor.dim_z
    for u, z in zip(U[:15], Z[:15], strict=True):
        # ours
        xo, Po = ukf_predict(x, P, model.f, M, u, form="augmented", alpha=alpha, beta=beta, kappa=kappa,
                             mean_fn=model.mean, residual_fn=model.residual, vectorized=True)
        # filterpy on the augmented state [x; w], Q = 0: take the state block
        def fx(xa, dt, u=u):
            return np.r_[model.f(xa[:3], u, xa[3:]), xa[3:]]

        def mean_a(s, w):
            return np.r_[model.mean(s[:, :3], w), w @ s[:, 3:]]

        def res_a(a, b):
            return np.r_[model.residual(a[:3], b[:3]), a[3:] - b[3:]]

        pa = MerweScaledSigmaPoints(5, alpha=alpha, beta=beta, kappa=kappa)
        fa = FPUnscentedKalmanFilter(5, 1, 1.0, hx=lambda s: s[:1], fx=fx, points=pa, x_mean_fn=mean_a,
                                     residual_x=res_a)
        fa.x, fa.P, fa.Q = np.r_[x, 0.0, 0.0], block_diag(P, M), np.zeros((5, 5))
        fa.predict()
        np.testing.assert_allclose(xo, fa.x[:3], rtol=1e-9, atol=1e-11)
        np.testing.assert_allclose(Po, fa.P[:3, :3], rtol=1e-9, atol=1e-11)
        # update: filterpy on [x; v] with h(x, v), R = 0
        upd = ukf_update(xo, Po, z, sensor.h, R, form="augmented", alpha=alpha, beta=beta, kappa=kappa,
                         z_mean_fn=sensor.mean, z_residual_fn=sensor.residual, x_residual_fn=model.residual,
                         vectorized=True)
        L = 3 + nz
        pb = MerweScaledSigmaPoints(L, alpha=alpha, beta=beta, kappa=kappa)

        def res_b(a, b):
            return np.r_[model.residual(a[:3], b[:3]), a[3:] - b[3:]]

        fb = FPUnscentedKalmanFilter(L, nz, 1.0, hx=lambda s: sensor.h(s[:3], s[3:]), fx=lambda s, dt: s,
                                     points=pb, z_mean_fn=sensor.mean, residual_z=sensor.residual,
                                     residual_x=res_b)
        fb.x, fb.P = np.r_[xo, np.zeros(nz)], block_diag(Po, R)
        fb.sigmas_f = pb.sigma_points(fb.x, fb.P)
        fb.update(z, R=np.zeros((nz, nz)))
        np.testing.assert_allclose(upd.x, fb.x[:3], rtol=1e-9, atol=1e-11)
        np.testing.assert_allclose(upd.P, fb.P[:3, :3], rtol=1e-9, atol=1e-11)
        x, P = upd.x, upd.P


@pytest.mark.parametrize("form", ["additive", "augmented"])
@pytest.mark.parametrize("alpha", [1e-3, 0.5, 1.0])
def test_ukf_equals_kf_on_linear_model(form, alpha):
    F, Q, H, R = constant_velocity_model(dt_s=1.0, accel_std=0.5, pos_std_m=1.0, dims=1)
    _, Z = simulate_linear(F, Q, H, R, [0.0, 1.0], 25, rng=5)
    Lq = np.linalg.cholesky(Q + 1e-15 * np.eye(2))
    if form == "additive":
        f, h, Qu, Ru = (lambda x, u: x @ F.T), (lambda x: x @ H.T), Q, R
    else:  # noise enters through w ~ N(0, I) scaled by chol(Q); v ~ N(0, R)
        f = lambda x, u, w: x @ F.T + w @ Lq.T
        h = lambda x, v: x @ H.T + v
        Qu, Ru = np.eye(2), R
    x_k, P_k = np.zeros(2), 10 * np.eye(2)
    x_u, P_u = x_k.copy(), P_k.copy()
    # Cancellation in the centre weight (-1/alpha^2) costs digits at alpha=1e-3.
    tol = 1e-9 if alpha >= 0.5 else 1e-5
    for z in Z:
        x_k, P_k = kf_predict(x_k, P_k, F, Q)
        x_u, P_u = ukf_predict(x_u, P_u, f, Qu, None, form=form, alpha=alpha, vectorized=True)
        np.testing.assert_allclose(P_u, P_k, rtol=tol, atol=tol)
        upd_k = kf_update(x_k, P_k, z, H, R)
        upd_u = ukf_update(x_u, P_u, z, h, Ru, form=form, alpha=alpha, vectorized=True)
        x_k, P_k, x_u, P_u = upd_k.x, upd_k.P, upd_u.x, upd_u.P
        np.testing.assert_allclose(x_u, x_k, rtol=tol, atol=tol)
        np.testing.assert_allclose(P_u, P_k, rtol=tol, atol=tol)


def test_vectorized_equals_per_point(robot):
    model, _sensor, U, _, _Z = robot
    x, P = np.zeros(3), 0.1 * np.eye(3)
    kw = {"form": "augmented", "alpha": 0.5, "mean_fn": model.mean, "residual_fn": model.residual}
    a = ukf_predict(x, P, model.f, model.M, U[0], vectorized=True, **kw)
    b = ukf_predict(x, P, model.f, model.M, U[0], vectorized=False, **kw)
    np.testing.assert_allclose(a[1], b[1], rtol=1e-13)


def test_cholesky_failure_names_the_step():
    bad_P = np.array([[1.0, 0.0], [0.0, 1e-30]])  # PSD within tolerance, not PD after scaling at alpha=1e-3
    bad_P[1, 1] = 0.0
    bad_P[0, 1] = bad_P[1, 0] = 0.0
    with pytest.raises(CholeskyError, match=r"Cholesky factorisation failed in ukf_predict \(sigma points\)"):
        ukf_predict(np.zeros(2), bad_P, lambda x, u: x, np.zeros((2, 2)), form="additive")
    assert issubclass(CholeskyError, ValueError)


@pytest.mark.parametrize("form", ["augmented", "additive"])
def test_class_agrees_with_functions(robot, form):
    model, sensor, U, _, Z = robot
    x, P = np.array([0.1, 0.0, 0.05]), 0.2 * np.eye(3)
    Q = model.M if form == "augmented" else model.Q(x, U[0])
    hooks = {"z_mean_fn": sensor.mean, "z_residual_fn": sensor.residual}
    ukf = UnscentedKalmanFilter(x, P, model.f, Q, sensor.h, sensor.R, form=form, alpha=0.5, x_mean_fn=model.mean,
                                x_residual_fn=model.residual, vectorized=True, **hooks)
    for u, z in zip(U[:8], Z[:8], strict=True):
        ukf.predict(u)
        ukf.update(z)
        x, P = ukf_predict(x, P, model.f, Q, u, form=form, alpha=0.5, mean_fn=model.mean,
                           residual_fn=model.residual, vectorized=True)
        upd = ukf_update(x, P, z, sensor.h, sensor.R, form=form, alpha=0.5, x_residual_fn=model.residual,
                         vectorized=True, **hooks)
        x, P = upd.x, upd.P
        np.testing.assert_allclose(ukf.x, x, rtol=1e-13, atol=1e-15)
        np.testing.assert_allclose(ukf.P, P, rtol=1e-13, atol=1e-15)
        np.testing.assert_allclose(ukf.S, upd.S, rtol=1e-13, atol=1e-15)
