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


@pytest.mark.slow
def test_exploration_answers():
    import slamlab as sl

    e = sl.planes.run_intensity_figure(n_particles=200, rng=2017).error_without_m
    assert lab.answer("10.explore.fig4", e, quiet=True).passed
    assert lab.answer("10.explore.fig4", e + 0.01, quiet=True).status == "failed"
    a = sl.planes.run_flight(6.0, rng=2017, n_particles=100, intensity_weights=False).ate_m
    assert lab.answer("10.explore.flight", a, quiet=True).passed
    assert lab.answer("10.explore.flight", a + 0.01, quiet=True).status == "failed"
