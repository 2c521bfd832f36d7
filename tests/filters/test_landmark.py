"""Landmark filter of 000 §3.6: batched update = per-landmark KF; convergence to the mean."""

import numpy as np
import pytest

from slamlab.filters import LandmarkFilter, kf_predict, kf_update, landmark_predict, landmark_update


def test_batched_update_equals_kf_per_landmark():
    rng = np.random.default_rng(2)
    N = 7
    X = rng.normal(size=(N, 3))
    A = rng.normal(size=(N, 3, 3))
    P = A @ A.transpose(0, 2, 1) + 0.1 * np.eye(3)
    Z = rng.normal(size=(N, 3))
    R = np.diag([0.2, 0.3, 0.5])
    Pp = landmark_predict(P, 0.01)
    Xb, Pb = landmark_update(X, Pp, Z, R)
    for i in range(N):
        x, Pi = kf_predict(X[i], P[i], np.eye(3), 0.01 * np.eye(3))
        upd = kf_update(x, Pi, Z[i], np.eye(3), R)
        np.testing.assert_allclose(Xb[i], upd.x, rtol=1e-12, atol=1e-12)
        np.testing.assert_allclose(Pb[i], upd.P, rtol=1e-12, atol=1e-12)


def test_static_landmark_estimate_is_running_mean_without_process_noise():
    # With Q = 0 and equal R, the KF estimate of a static point is the sample mean
    # of its observations and P = R / n: an independent closed form.
    rng = np.random.default_rng(4)
    truth = np.array([1.0, -2.0, 0.5])
    obs = truth + 0.1 * rng.normal(size=(50, 3))
    lf = LandmarkFilter(state_var=0.0, obs_var=0.01, dim=3)
    lf.add(obs[:1])
    for z in obs[1:]:
        lf.observe(np.array([0]), z[None])
    np.testing.assert_allclose(lf.X[0], obs.mean(axis=0), rtol=1e-10)
    np.testing.assert_allclose(lf.P[0], 0.01 / 50 * np.eye(3), rtol=1e-10)


def test_landmark_filter_bad_input():
    lf = LandmarkFilter(dim=3)
    with pytest.raises(ValueError, match=r"`Z` must have shape \(M, 3\)"):
        lf.add(np.zeros((2, 2)))
    lf.add(np.zeros((2, 3)))
    with pytest.raises(ValueError, match=r"`idx` must index existing landmarks 0\.\.1"):
        lf.observe(np.array([5]), np.zeros((1, 3)))
    with pytest.raises(TypeError, match="`idx` must be a 1-D integer index array"):
        lf.observe(np.array([0.5]), np.zeros((1, 3)))
    with pytest.raises(ValueError, match="`idx` must not repeat a landmark"):
        lf.observe(np.array([0, 0]), np.zeros((2, 3)))
    with pytest.raises(ValueError, match=r"`R` must be a scalar variance, \(3, 3\) or \(2, 3, 3\)"):
        landmark_update(np.zeros((2, 3)), np.tile(np.eye(3), (2, 1, 1)), np.zeros((2, 3)), np.eye(2))
    with pytest.raises(ValueError, match="`obs_var` must be > 0"):
        LandmarkFilter(obs_var=0.0)
