"""Generic RANSAC (000 §3.5) on exact synthetic data with known outliers."""

import numpy as np
import pytest

from slamlab.geometry import apply_transform, ransac, rotation_xyz, umeyama


def _rigid_fit(src, dst):
    return umeyama(src, dst)


def _rigid_res(T, src, dst):
    return np.linalg.norm(apply_transform(T, src) - dst, axis=1)


def _data(n=200, outlier_frac=0.4, seed=0):
    rng = np.random.default_rng(seed)
    src = rng.uniform(-3, 3, (n, 3))
    R = rotation_xyz(0.1, -0.2, 0.7)
    t = np.array([1.0, -2.0, 0.5])
    dst = src @ R.T + t + rng.normal(0, 0.01, (n, 3))
    out = rng.random(n) < outlier_frac
    dst[out] = rng.uniform(-5, 5, (out.sum(), 3))
    return src, dst, R, t, out


def test_rigid_transform_with_outliers():
    src, dst, R, t, out = _data()
    r = ransac((src, dst), _rigid_fit, _rigid_res, 3, 0.05, rng=1)
    assert r.converged
    np.testing.assert_allclose(r.model.R, R, atol=5e-3)
    np.testing.assert_allclose(r.model.t, t, atol=1e-2)
    # the mask finds the outliers (a random outlier may land within 5 cm: allow none here)
    assert np.array_equal(r.inliers, ~out)


def test_early_exit_on_clean_data():
    src, dst, *_ = _data(outlier_frac=0.0)
    r = ransac((src, dst), _rigid_fit, _rigid_res, 3, 0.05, max_iters=200, rng=0)
    assert r.n_iters < 5
    assert r.converged
    assert r.inliers.all()
    r = ransac((src, dst), _rigid_fit, _rigid_res, 3, 0.05, stop_ratio=0.5, rng=0)
    assert r.n_iters == 1


def test_no_consensus_is_not_converged():
    rng = np.random.default_rng(3)
    src, dst = rng.uniform(-3, 3, (30, 3)), rng.uniform(-3, 3, (30, 3))
    r = ransac((src, dst), _rigid_fit, _rigid_res, 3, 0.01, max_iters=50, min_inliers=10, rng=0)
    assert not r.converged
    assert r.n_iters == 50


def test_deterministic_from_seed_and_degenerate_samples_skipped():
    src, dst, *_ = _data(seed=4)
    a = ransac((src, dst), _rigid_fit, _rigid_res, 3, 0.05, rng=7)
    b = ransac((src, dst), _rigid_fit, _rigid_res, 3, 0.05, rng=7)
    assert np.array_equal(a.inliers, b.inliers)
    assert a.n_iters == b.n_iters

    def picky_fit(s, d):
        if s[0, 0] > 0:
            raise ValueError("degenerate")
        return umeyama(s, d)

    r = ransac((src, dst), picky_fit, _rigid_res, 3, 0.05, rng=0, refit_rounds=0)
    assert r.converged


def test_single_array_data_line_fit():
    x = np.linspace(0, 1, 50)
    pts = np.column_stack([x, 3 * x - 1])
    pts[::7, 1] += 5

    def fit(p):
        return np.polyfit(p[:, 0], p[:, 1], 1)

    def res(m, p):
        return np.abs(np.polyval(m, p[:, 0]) - p[:, 1])

    r = ransac(pts, fit, res, 2, 1e-6, rng=0)
    np.testing.assert_allclose(r.model, [3.0, -1.0], atol=1e-9)
    assert r.inliers.sum() == 50 - len(range(0, 50, 7))


def test_bad_input():
    src, dst, *_ = _data(n=10)
    with pytest.raises(ValueError, match="at least `sample_size` = 3 rows; got 2"):
        ransac((src[:2], dst[:2]), _rigid_fit, _rigid_res, 3, 0.05)
    with pytest.raises(ValueError, match="same number of rows"):
        ransac((src, dst[:5]), _rigid_fit, _rigid_res, 3, 0.05)
    with pytest.raises(ValueError, match="threshold"):
        ransac((src, dst), _rigid_fit, _rigid_res, 3, 0.0)
    with pytest.raises(TypeError, match="fit"):
        ransac((src, dst), None, _rigid_res, 3, 0.05)
    with pytest.raises(ValueError, match="max_iters"):
        ransac((src, dst), _rigid_fit, _rigid_res, 3, 0.05, max_iters=0)
    with pytest.raises(ValueError, match="confidence"):
        ransac((src, dst), _rigid_fit, _rigid_res, 3, 0.05, confidence=1.0)
    with pytest.raises(TypeError, match="rng"):
        ransac((src, dst), _rigid_fit, _rigid_res, 3, 0.05, rng="x")
