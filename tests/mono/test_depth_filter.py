"""Depth filter (003 §4.1.1): exact posterior moments, SVO's initialisation and tau, 003's rules."""

from __future__ import annotations

import numpy as np
import pytest
from scipy import stats

from slamlab.geometry import triangulate_midpoint
from slamlab.mono import depth_filter as df


def _grid_posterior(mu, sigma2, a, b, x, tau2, rho_range):
    """Exact posterior moments of N(ρ|μ,σ²) Beta(π|a,b) [π N(x|ρ,τ²) + (1-π)/ρ_range] on a grid."""
    s = np.sqrt(sigma2)
    rho = np.linspace(mu - 12 * s, mu + 12 * s, 3001)
    pi = np.linspace(1e-6, 1 - 1e-6, 2001)
    prior = stats.norm.pdf(rho, mu, s)[:, None] * stats.beta.pdf(pi, a, b)[None, :]
    lik = pi[None, :] * stats.norm.pdf(x, rho, np.sqrt(tau2))[:, None] + (1 - pi[None, :]) / rho_range
    post = prior * lik
    w = post / post.sum()
    m_rho = np.sum(w * rho[:, None])
    v_rho = np.sum(w * (rho[:, None] - m_rho) ** 2)
    m_pi = np.sum(w * pi[None, :])
    m_pi2 = np.sum(w * pi[None, :] ** 2)
    return m_rho, v_rho, m_pi, m_pi2


@pytest.mark.parametrize(("x", "tau2"), [(0.52, 0.01**2), (0.9, 0.02**2), (0.5, 0.3**2), (1.7, 0.05**2)])
def test_update_matches_numerical_posterior_moments(x, tau2):
    mu, sigma2, a, b, rho_range = 0.5, 0.1**2, 6.0, 3.0, 2.0
    m_rho, v_rho, m_pi, m_pi2 = _grid_posterior(mu, sigma2, a, b, x, tau2, rho_range)
    mu1, s21, a1, b1 = df.update_seeds(mu, sigma2, a, b, x, tau2, rho_range)
    assert mu1 == pytest.approx(m_rho, abs=1e-7)
    assert s21 == pytest.approx(v_rho, rel=1e-5)
    # Beta moments: E[π] = a/(a+b), E[π²] = a(a+1)/((a+b)(a+b+1))
    assert a1 / (a1 + b1) == pytest.approx(m_pi, abs=1e-6)
    assert a1 * (a1 + 1) / ((a1 + b1) * (a1 + b1 + 1)) == pytest.approx(m_pi2, abs=1e-6)


def test_update_is_vectorised_and_equals_per_seed():
    rng = np.random.default_rng(0)
    n = 50
    args = (rng.uniform(0.2, 1, n), rng.uniform(1e-4, 0.1, n), rng.uniform(2, 20, n), rng.uniform(2, 20, n),
            rng.uniform(0, 2, n), rng.uniform(1e-5, 1e-2, n), np.full(n, 2.0))
    out = df.update_seeds(*args)
    for i in (0, 17, 49):
        one = df.update_seeds(*(a[i] for a in args))
        for u, w in zip(out, one, strict=True):
            assert u[i] == pytest.approx(float(w), rel=1e-12)


def test_svo_initialisation_values():
    s = df.init_seeds(np.zeros((3, 2)), [[0, 0, 2.0]] * 3, depth_mean_m=4.0, depth_min_m=0.25)
    np.testing.assert_allclose(s.mu, 0.25)
    np.testing.assert_allclose(s.rho_range, 4.0)
    np.testing.assert_allclose(s.sigma2, 16.0 / 36.0)
    np.testing.assert_allclose(s.a, 10.0)
    np.testing.assert_allclose(s.b, 10.0)
    np.testing.assert_allclose(s.f, [[0, 0, 1.0]] * 3)


def test_init_seeds_rejects_bad_input():
    with pytest.raises(ValueError, match="`f` must have shape"):
        df.init_seeds(np.zeros((2, 2)), np.zeros((3, 3)), 1.0, 0.5)
    with pytest.raises(ValueError, match="depth_min_m"):
        df.init_seeds(np.zeros((1, 2)), [[0, 0, 1.0]], 1.0, 0.0)
    with pytest.raises(ValueError, match="`f` rows must be non-zero"):
        df.init_seeds(np.zeros((1, 2)), [[0, 0, 0.0]], 1.0, 0.5)


def test_tau_equals_exact_ray_intersection():
    # reference camera at the origin, current camera at t; the point at depth z along f.
    f = np.array([[0.1, -0.05, 1.0]])
    f /= np.linalg.norm(f)
    t = np.array([0.3, 0.02, 0.05])
    z = np.array([2.5])
    delta = 2 * np.arctan(1.0 / (2 * 500.0))
    tau = df.compute_tau(t, f, z, delta)
    # rotate the current ray (point - t) by delta in the epipolar plane, away from t: it meets f at z + tau
    p = f[0] * z[0]
    d = p - t
    n = np.cross(f[0], t)
    n /= np.linalg.norm(n)
    # Rodrigues rotation of d about n by -delta (opening beta, the angle at the current camera)
    def rot(vec, ang):
        return vec * np.cos(ang) + np.cross(n, vec) * np.sin(ang) + n * (n @ vec) * (1 - np.cos(ang))
    cands = [triangulate_midpoint([0, 0, 0], f, t, rot(d, s * delta)[None]) for s in (1, -1)]
    depths = [c.s[0] for c in cands]
    z_plus = max(depths)  # the bigger angle at the point side: beta + delta
    assert tau[0] == pytest.approx(z_plus - z[0], rel=1e-9)


def test_tau_is_infinite_without_parallax():
    f = np.array([[0.0, 0.0, 1.0]])
    assert np.isinf(df.compute_tau([0.0, 0.0, 0.5], f, [2.0], 1e-3)[0])


def test_depth_interval_003_rule():
    lo, hi = df.depth_interval([0.5, 0.5], [0.1, 0.3])
    np.testing.assert_allclose(lo, [1 / 0.7, 1 / 1.1])
    np.testing.assert_allclose(hi, [1 / 0.3, 1e10])


def test_convergence_criteria():
    # SVO: sigma < rho_range / 200
    assert df.converged_sigma(np.array([(2.0 / 201) ** 2]), 2.0)[0]
    assert not df.converged_sigma(np.array([(2.0 / 199) ** 2]), 2.0)[0]
    # 003/Civera: L = 4 sigma_rho / rho^2 |cos a| / d; at rho = 0.5, d = 2, cos a = 1: L = 16 sigma_rho / 2
    L_idx = df.linearity_index(0.5, 0.01**2, 2.0, 1.0)
    assert L_idx == pytest.approx(4 * 0.01 / 0.25 / 2.0)
    assert df.converged_linearity(0.5, 0.01**2, 2.0, 1.0)  # 0.08 < 0.1
    assert not df.converged_linearity(0.5, 0.02**2, 2.0, 1.0)  # 0.16


@pytest.mark.parametrize("outlier_rate", [0.0, 0.3, 0.6])
def test_seed_converges_to_truth_with_outliers(outlier_rate):
    rng = np.random.default_rng(1)
    n = 2000
    rho_true = rng.uniform(0.2, 1.5, n)
    s = df.init_seeds(np.zeros((n, 2)), np.tile([0, 0, 1.0], (n, 1)), 1.0, 0.5)
    tau = 0.01
    for _ in range(60):
        out = rng.random(n) < outlier_rate
        x = np.where(out, rng.uniform(0, s.rho_range), rho_true + rng.normal(0, tau, n))
        s.mu, s.sigma2, s.a, s.b = df.update_seeds(s.mu, s.sigma2, s.a, s.b, x, tau**2, s.rho_range)
    err = np.abs(s.mu - rho_true)
    assert np.median(err) < 3 * tau / np.sqrt(60 * (1 - outlier_rate))
    # the Beta mean counts inliers on top of SVO's prior a = b = 10: (10 + 60 (1 - r)) / (20 + 60)
    expected = (10 + 60 * (1 - outlier_rate)) / 80
    assert np.median(df.inlier_ratio(s.a, s.b)) == pytest.approx(expected, abs=0.05)


def test_seed_points_eq_6_4():
    s = df.init_seeds([[0, 0]], [[0, 0, 1.0]], 2.0, 0.5)
    T = np.eye(4)
    T[:3, 3] = [1, 2, 3]
    np.testing.assert_allclose(df.seed_points(s, T[None]), [[1, 2, 5.0]])
