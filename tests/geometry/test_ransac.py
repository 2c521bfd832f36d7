"""Generic RANSAC (000 §3.5) on exact synthetic data with known outliers."""

import numpy as np
import pytest

from slamlab.geometry import apply_transform, ransac, ransac_refit, rotation_xyz, umeyama


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
    with pytest.raises(ValueError, match=r"`refit_rounds` must be 0 with `batch_size`"):
        ransac((src, dst), _rigid_fit, _rigid_res, 3, 0.05, batch_size=10)
    with pytest.raises(ValueError, match="batch_size"):
        ransac((src, dst), _rigid_fit, _rigid_res, 3, 0.05, batch_size=0, refit_rounds=0)


def _lines_fit(xs, ys):
    """Lines through 2-point samples ``(b, 2)``: slopes and intercepts of the non-degenerate ones."""
    dx = xs[:, 1] - xs[:, 0]
    ok = dx != 0
    a = (ys[ok, 1] - ys[ok, 0]) / dx[ok]
    return a, ys[ok, 0] - a * xs[ok, 0]


def _lines_res(m, xs, ys):
    return np.abs(m[0][:, None] * xs + m[1][:, None] - ys)


def _line_data(seed=0):
    rng = np.random.default_rng(seed)
    x = rng.uniform(0, 10, 120)
    y = 0.5 * x - 2.0
    out = rng.random(120) < 0.5
    y[out] = rng.uniform(-10, 10, out.sum())
    return x, y, out


def test_batched_finds_the_consensus_line():
    x, y, out = _line_data()
    r = ransac((x, y), _lines_fit, _lines_res, 2, 1e-9, max_iters=300, batch_size=100, refit_rounds=0, rng=0)
    assert r.converged
    np.testing.assert_allclose([float(r.model[0]), float(r.model[1])], [0.5, -2.0], atol=1e-9)
    assert np.array_equal(r.inliers, ~out)
    # the whole inlier set in one sample is found in the first batch: the adaptive bound stops it there
    assert r.n_iters == 100


def test_batched_keeps_the_first_of_the_most_inliers():
    # brute force over the same hypotheses: the first one with the most inliers wins the batch
    x, y, _ = _line_data(1)
    y = y + np.random.default_rng(2).normal(0, 0.01, y.size)
    idx = np.random.default_rng(3).integers(0, x.size, (60, 2))
    models = _lines_fit(x[idx], y[idx])
    counts = [int(np.sum(_lines_res(models, x, y)[k] <= 0.05)) for k in range(len(models[0]))]
    assert counts.count(max(counts)) > 1  # ties: the rule matters
    k = counts.index(max(counts))
    # the batch's samples are drawn as documented: rng.integers(0, N, (batch_size, sample_size))
    got = ransac((x, y), _lines_fit, _lines_res, 2, 0.05, max_iters=60, batch_size=60, refit_rounds=0, rng=3)
    assert float(got.model[0]) == models[0][k]
    assert float(got.model[1]) == models[1][k]
    assert int(got.inliers.sum()) == max(counts)


def test_batched_with_no_valid_sample_returns_no_model():
    x = np.zeros(10)
    r = ransac((x, x), _lines_fit, _lines_res, 2, 0.1, max_iters=5, batch_size=5, refit_rounds=0, rng=0)
    assert r.model is None
    assert not r.converged
    assert not r.inliers.any()


def test_ransac_refit_least_squares_and_stops_when_stable():
    x = np.linspace(0, 1, 40)
    y = 3 * x - 1 + np.random.default_rng(0).normal(0, 1e-3, 40)
    y[::5] += 1.0
    fit = lambda xs, ys: np.polyfit(xs, ys, 1)
    res = lambda m, xs, ys: np.abs(np.polyval(m, xs) - ys)
    m0 = np.array([3.02, -1.01])  # a rough hypothesis: some inliers missed
    mask0 = res(m0, x, y) <= 0.01
    m, mask = ransac_refit((x, y), fit, res, m0, mask0, 0.01, rounds=5)
    np.testing.assert_array_equal(mask, np.arange(40) % 5 != 0)
    np.testing.assert_allclose(m, np.polyfit(x[mask], y[mask], 1), rtol=1e-12)
    # a refit that leaves fewer than `min_rows` inliers is not taken
    m2, mask2 = ransac_refit((x, y), fit, res, m0, mask0, 0.01, rounds=5, min_rows=100)
    assert m2 is m0
    assert np.array_equal(mask2, mask0)
