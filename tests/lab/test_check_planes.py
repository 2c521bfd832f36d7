"""Lab 10 tasks: solutions written from 002 pass, typical mistakes fail."""

from __future__ import annotations

import numpy as np
import pytest

import slamlab_grading as lab
from slamlab_grading import core

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


TASKS = [("10.frame_transforms", frame_transforms), ("10.planes_to_body", planes_to_body),
         ("10.fit_plane", fit_plane), ("10.intensity_weights", intensity_weights)]


@pytest.mark.parametrize(("task_id", "fn"), TASKS)
@pytest.mark.parametrize("rng", [0, None], ids=["feedback cases", "grading cases"])
def test_correct_solutions_pass(task_id, fn, rng):
    res = lab.check(task_id, fn, quiet=True) if rng is None else lab.check(task_id, fn, rng=rng, quiet=True)
    assert res.passed, res.message


def _library_wrapped():
    from slamlab import planes

    def body(n_m, p_m, R, t):
        n_b, p_b = planes.planes_to_body(n_m, p_m, R, t)
        return np.c_[n_b, p_b]

    def fit(points):
        n, p = planes.fit_plane_lsq(points)
        return np.r_[n, p]

    return {"10.frame_transforms": lambda odometry: planes.frame_transforms(odometry), "10.planes_to_body": body,
            "10.fit_plane": fit, "10.intensity_weights": lambda sad: planes.intensity_weights(sad)}


@pytest.mark.parametrize("task_id", [t for t, _ in TASKS])
def test_the_librarys_own_function_fails(task_id):
    res = lab.check(task_id, _library_wrapped()[task_id], quiet=True)
    assert res.status == "failed", res.message
    assert "called the library's slamlab.planes" in res.message, res.message


def _wrong_order(odometry):  # oT_j^-1 oT_N: the inverse transform
    return np.linalg.inv(odometry) @ odometry[-1]


def _first_line(odometry):  # relative to the first line instead of the last
    return np.linalg.inv(odometry[0]) @ odometry


def _no_transpose(n_m, p_m, R, t):  # R n instead of R^T n
    return np.c_[n_m @ R.T, p_m - n_m @ t]


def _offset_plus(n_m, p_m, R, t):  # the offset grows by the motion along the normal
    return np.c_[n_m @ R, p_m + n_m @ t]


def _sign_free(points):  # forgets p >= 0
    c = points.mean(axis=0)
    n = np.linalg.svd(points - c, full_matrices=False)[2][2]
    return np.r_[n, n @ c]


def _largest_singular(points):  # the direction of most spread, not least
    c = points.mean(axis=0)
    n = np.linalg.svd(points - c, full_matrices=False)[2][0]
    p = n @ c
    return np.r_[-n, -p] if p < 0 else np.r_[n, p]


def _normalised_sad(sad):  # 1/SAD instead of max - SAD
    w = 1.0 / np.nan_to_num(sad, nan=np.inf)
    return w / w.sum()


def _nan_as_best(sad):  # a particle without overlap counted as SAD 0 (the best)
    return intensity_weights(np.nan_to_num(sad, nan=0.0))


MISTAKES = [("10.frame_transforms", _wrong_order, None), ("10.frame_transforms", _first_line, None),
            ("10.planes_to_body", _no_transpose, None), ("10.planes_to_body", _offset_plus, "a wall x = 5"),
            ("10.fit_plane", _sign_free, "p >= 0"), ("10.fit_plane", _largest_singular, None),
            ("10.intensity_weights", _normalised_sad, None), ("10.intensity_weights", _nan_as_best, "NaN")]


@pytest.mark.parametrize(("task_id", "fn", "where"), MISTAKES, ids=[m[1].__name__ for m in MISTAKES])
@pytest.mark.parametrize("rng", [0, None], ids=["feedback cases", "grading cases"])
def test_mistakes_fail_on_the_feedback_and_the_grading_cases(task_id, fn, where, rng):
    res = lab.check(task_id, fn, quiet=True) if rng is None else lab.check(task_id, fn, rng=rng, quiet=True)
    assert res.status == "failed", res.message
    if where is not None:  # an edge case, not a lucky random one, catches it on its own
        t = lab.task(task_id)
        cases = t.cases(np.random.default_rng(core.GRADING_RNG if rng is None else rng))
        case = next(c for c in cases if where in c.label)
        assert t.compare(t.reference(**case.kwargs), fn(**case.kwargs), case.kwargs) is not None, case.label


# --- explorations: accepted ranges against independent computations ------------------------------------------


def _tilted_frame(n_true):
    u = np.cross(n_true, [1.0, 0.0, 0.0])
    u /= np.linalg.norm(u)
    return u, np.cross(n_true, u)


def _normal_angles_svd(n_draws, seed, n_points=200, side=4.0, noise=0.02):
    """Angles (rad) between the least-squares normal (a batched SVD) and the true one, on a tilted plane."""
    rng = np.random.default_rng(seed)
    n_true = np.array([0.3, -0.2, 0.9])
    n_true /= np.linalg.norm(n_true)
    u, w = _tilted_frame(n_true)
    ab = rng.uniform(-side / 2, side / 2, (n_draws, n_points, 2))
    X = 1.7 * n_true + ab[..., :1] * u + ab[..., 1:] * w + rng.normal(0, noise, (n_draws, n_points, 1)) * n_true
    n = np.linalg.svd(X - X.mean(axis=1, keepdims=True), full_matrices=False)[2][:, 2]
    return np.arctan2(np.linalg.norm(np.cross(n, n_true), axis=1), np.abs(n @ n_true))


def _normal_angles_eig(n_draws, seed, n_points=200, side=4.0, noise=0.02):
    """A second method: the smallest eigenvector of each draw's scatter matrix, on the plane z = 0, angle by acos."""
    rng = np.random.default_rng(seed)
    out = np.empty(n_draws)
    for i in range(n_draws):
        X = np.c_[rng.uniform(-side / 2, side / 2, (n_points, 2)), rng.normal(0, noise, n_points)]
        Xc = X - X.mean(axis=0)
        n = np.linalg.eigh(Xc.T @ Xc)[1][:, 0]
        out[i] = np.arccos(min(1.0, abs(n[2])))
    return out


def _rms_deg(a):
    return float(np.degrees(np.sqrt(np.mean(a**2))))


def test_normal_error_range_holds_on_30_seeds_of_2000_draws_and_rejects_the_misconceptions_on_each():
    t = lab.task("10.explore.normal_error")
    lo, hi = t.accepted_range()
    assert {w.label for w in t.wrong} == {"radians", "one axis only", "the mean angle"}
    for seed in range(100, 130):
        a = _normal_angles_svd(2000, seed)
        rms = _rms_deg(a)
        assert lo <= rms <= hi, seed
        for wrong, label in ((float(np.degrees(a.mean())), "the mean angle"), (rms / np.sqrt(2), "one axis only"),
                             (float(np.sqrt(np.mean(a**2))), "radians")):
            assert not lo <= wrong <= hi, (seed, label)
            assert t.misconception(wrong).label == label, (seed, label, wrong)


def test_normal_error_range_holds_for_a_second_method_a_long_run_and_the_formula():
    lo, hi = lab.task("10.explore.normal_error").accepted_range()
    assert lo <= _rms_deg(_normal_angles_eig(2000, 7)) <= hi  # eigenvectors, another plane, acos
    long = _rms_deg(np.concatenate([_normal_angles_svd(10000, s) for s in (1, 2)]))
    assert long == pytest.approx(0.5 * (lo + hi), rel=0.015)  # the centre, by a long Monte Carlo run
    from slamlab_grading import tasks_planes as tp

    assert lo <= tp.normal_rms_error_deg() <= hi  # reasoned out: first-order propagation


def _along_wall_shift(alpha_deg, delta=0.03):
    """Two walls and the floor in 3-D, solved before and after wall 2's offset error: the shift along wall 1."""
    a = np.radians(alpha_deg)
    N = np.array([[1.0, 0.0, 0.0], [np.cos(a), np.sin(a), 0.0], [0.0, 0.0, 1.0]])
    p = np.array([2.0, 2.0 * np.cos(a) + 1.0 * np.sin(a), 0.0])
    x0, x1 = np.linalg.solve(N, p), np.linalg.solve(N, p + np.array([0.0, delta, 0.0]))
    return abs((x1 - x0)[1])


def test_wall_angle_range_holds_for_grid_scans_rounding_bisection_and_the_small_angle_form():
    lo, hi = lab.task("10.explore.wall_angle").accepted_range()
    for step in (0.1, 0.05, 0.01, 0.001):
        grid = np.round(np.arange(0.5, 10.0, step), 6)
        safe = np.array([_along_wall_shift(g) <= 0.5 for g in grid])
        first_safe = grid[np.flatnonzero(safe)[0]]
        assert lo <= first_safe <= hi, step
        assert lo <= grid[np.flatnonzero(safe)[0] - 1] <= hi or step == 0.1  # the last failing value, finer grids
    a, b = 1.0, 10.0
    for _ in range(60):
        m = (a + b) / 2
        a, b = (m, b) if _along_wall_shift(m) > 0.5 else (a, m)
    assert lo <= b <= hi
    assert lo <= round(b, 1) <= hi
    assert lo <= np.degrees(0.03 / 0.5) <= hi  # the small-angle answer differs by 0.002°


def test_wall_angle_misconceptions_are_rejected_on_30_settings():
    """For 30 offset errors and limits, the range built as the task builds it (exact angle ± the resolution)
    rejects radians and the complement."""
    from slamlab_grading import tasks_planes as tp

    for delta, limit in zip(np.linspace(0.01, 0.05, 30), np.tile([0.3, 0.5, 0.8], 10), strict=True):
        exact = tp.smallest_safe_angle_deg(delta, limit)
        a, b = 0.01, 89.0  # bisection on this file's 3-D solve, scaled to the setting
        for _ in range(60):
            m = (a + b) / 2
            a, b = (m, b) if _along_wall_shift(m, delta) > limit else (a, m)
        assert b == pytest.approx(exact, abs=1e-6)
        for wrong in (np.radians(exact), 90.0 - exact):
            assert abs(wrong - exact) > tp.EXPLORE_ANGLE_RESOLUTION_DEG, (delta, limit)
    t = lab.task("10.explore.wall_angle")
    for w in t.wrong:
        assert lab.answer("10.explore.wall_angle", float(w.value()), quiet=True).status == "failed"


def test_exploration_answers_of_the_instructor_methods():
    assert lab.answer("10.explore.wall_angle", 3.44, quiet=True).passed
    assert lab.answer("10.explore.wall_angle", 3.4, quiet=True).passed
    assert lab.answer("10.explore.wall_angle", 3.6, quiet=True).status == "failed"
    assert lab.answer("10.explore.normal_error", 0.1, quiet=True).passed
    assert lab.answer("10.explore.normal_error", 0.11, quiet=True).status == "failed"


def test_student_visible_text_states_no_answer():
    """The feedback file and the lab's locked prose hold no accepted number and name no library function."""
    import re
    from pathlib import Path

    import nbformat

    root = Path(__file__).resolve().parents[2]
    fb = (root / "slamlab" / "lab" / "feedback" / "10.json").read_text()
    words = " ".join(re.findall(r'"(?:question|title|hint|unit)":"([^"]*)"', fb))  # what the student reads
    nb = nbformat.read(root / "notebooks" / "labs" / "10_plane_slam_3d_lab.ipynb", as_version=4)
    prose = "\n".join(c.source for c in nb.cells if not c.metadata.get("nbgrader", {}).get("solution", False))
    for needle in ("0.099", "0.0997", "3.44", "3.5°", "fit_plane_lsq"):
        assert needle not in prose, needle
    for needle in ("0.099", "3.44", "3.5"):
        assert needle not in words, needle


def test_exploration_helpers_reject_bad_input():
    from slamlab_grading import tasks_planes as tp

    with pytest.raises(ValueError, match="`n_points`"):
        tp.normal_rms_error_deg(2)
    with pytest.raises(ValueError, match="`side_m`"):
        tp.normal_rms_error_deg(side_m=0.0)
    with pytest.raises(ValueError, match="`offset_error_m` must be smaller"):
        tp.smallest_safe_angle_deg(0.6, 0.5)
