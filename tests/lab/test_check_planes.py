"""Lab 10 tasks: solutions written from 002 pass, typical mistakes fail."""

from __future__ import annotations

import numpy as np
import pytest

from slamlab import lab

# --- independent solutions (what a student should write) --------------------------------------------


def frame_transforms(odometry):
    return np.linalg.inv(odometry[-1]) @ odometry


def planes_to_body(n_m, p_m, R, t):
    return np.c_[n_m @ R, p_m - n_m @ t]


def fit_plane(points):
    c = points.mean(axis=0)
    n = np.linalg.svd(points - c, full_matrices=False)[2][2]   # not the (K, K) U: K may be 24 000
    p = n @ c
    return np.r_[-n, -p] if p < 0 else np.r_[n, p]


def intensity_weights(sad):
    top = np.nanmax(sad) if np.isfinite(sad).any() else 0.0
    star = top - np.where(np.isnan(sad), top, sad)
    return star / star.sum() if star.sum() > 0 else np.full(len(sad), 1.0 / len(sad))


@pytest.mark.parametrize(("task_id", "fn"), [("10.frame_transforms", frame_transforms),
                                             ("10.planes_to_body", planes_to_body), ("10.fit_plane", fit_plane),
                                             ("10.intensity_weights", intensity_weights)])
def test_correct_solutions_pass(task_id, fn):
    res = lab.check(task_id, fn, quiet=True)
    assert res.passed, res.message


def test_typical_mistakes_fail():
    def wrong_order(odometry):  # oT_j^-1 oT_N: the inverse transform
        return np.linalg.inv(odometry) @ odometry[-1]

    def no_transpose(n_m, p_m, R, t):  # R n instead of R^T n
        return np.c_[n_m @ R.T, p_m - n_m @ t]

    def sign_free(points):  # forgets p >= 0
        c = points.mean(axis=0)
        n = np.linalg.svd(points - c, full_matrices=False)[2][2]   # not the (K, K) U: K may be 24 000
        return np.r_[n, n @ c]

    def normalised_sad(sad):  # 1/SAD instead of max - SAD
        w = 1.0 / np.nan_to_num(sad, nan=np.inf)
        return w / w.sum()

    assert lab.check("10.frame_transforms", wrong_order, quiet=True).status == "failed"
    assert lab.check("10.planes_to_body", no_transpose, quiet=True).status == "failed"
    assert lab.check("10.fit_plane", sign_free, quiet=True).status == "failed"
    assert lab.check("10.intensity_weights", normalised_sad, quiet=True).status == "failed"


# --- explorations: accepted ranges against independent computations ------------------------------------------


def _normal_angles(n_trials, seed, n_points=200, side=4.0, noise=0.02):
    """Angles (rad) between this file's least-squares normal and the true one, on a tilted plane."""
    rng = np.random.default_rng(seed)
    n_true = np.array([0.3, -0.2, 0.9])
    n_true /= np.linalg.norm(n_true)
    u = np.cross(n_true, [1.0, 0.0, 0.0])
    u /= np.linalg.norm(u)
    w = np.cross(n_true, u)
    out = []
    for _ in range(n_trials):
        ab = rng.uniform(-side / 2, side / 2, (n_points, 2))
        X = 1.7 * n_true + ab[:, :1] * u + ab[:, 1:] * w + rng.normal(0, noise, (n_points, 1)) * n_true
        n = fit_plane(X)[:3]
        out.append(np.arctan2(np.linalg.norm(np.cross(n, n_true)), abs(n @ n_true)))
    return np.array(out)


def test_normal_error_range_holds_for_monte_carlo_runs_of_100_trials_and_a_long_one():
    lo, hi = lab.task("10.explore.normal_error").accepted_range()
    long = np.degrees(np.sqrt(np.mean(_normal_angles(4000, 1) ** 2)))
    assert long == pytest.approx(lab.task("10.explore.normal_error").expected(), rel=0.04)  # the formula, by Monte Carlo
    for seed in range(2, 8):
        assert lo <= np.degrees(np.sqrt(np.mean(_normal_angles(100, seed) ** 2))) <= hi, seed
    assert not lo <= long / np.sqrt(2) <= hi  # one axis only


def _along_wall_shift(alpha_deg, delta=0.03):
    """Two walls and the floor in 3-D, solved before and after wall 2's offset error: the shift along wall 1."""
    a = np.radians(alpha_deg)
    N = np.array([[1.0, 0.0, 0.0], [np.cos(a), np.sin(a), 0.0], [0.0, 0.0, 1.0]])
    p = np.array([2.0, 2.0 * np.cos(a) + 1.0 * np.sin(a), 0.0])
    x0, x1 = np.linalg.solve(N, p), np.linalg.solve(N, p + np.array([0.0, delta, 0.0]))
    return abs((x1 - x0)[1])


def test_wall_angle_range_holds_for_grid_scans_and_bisection_and_the_small_angle_form():
    lo, hi = lab.task("10.explore.wall_angle").accepted_range()
    for step in (0.1, 0.05, 0.01, 0.001):
        grid = np.round(np.arange(0.5, 10.0, step), 6)
        first_safe = grid[np.flatnonzero([_along_wall_shift(g) <= 0.5 for g in grid])[0]]
        assert lo <= first_safe <= hi, step
    a, b = 1.0, 10.0
    for _ in range(60):
        m = (a + b) / 2
        a, b = (m, b) if _along_wall_shift(m) > 0.5 else (a, m)
    assert lo <= b <= hi
    assert lo <= np.degrees(0.03 / 0.5) <= hi  # the small-angle answer differs by 0.002°
    assert not lo <= 3.4 <= hi  # the last failing value of a 0.1° grid
    assert _along_wall_shift(3.4) > 0.5


def test_exploration_answers_of_the_instructor_methods():
    assert lab.answer("10.explore.wall_angle", 3.45, quiet=True).passed
    assert lab.answer("10.explore.wall_angle", 3.6, quiet=True).status == "failed"
    assert lab.answer("10.explore.normal_error", 0.1, quiet=True).passed
    assert lab.answer("10.explore.normal_error", 0.13, quiet=True).status == "failed"


def test_exploration_helpers_reject_bad_input():
    from slamlab.lab import tasks_planes as tp

    with pytest.raises(ValueError, match="`n_points`"):
        tp.normal_rms_error_deg(2)
    with pytest.raises(ValueError, match="`side_m`"):
        tp.normal_rms_error_deg(side_m=0.0)
    with pytest.raises(ValueError, match="`offset_error_m` must be smaller"):
        tp.smallest_safe_angle_deg(0.6, 0.5)
