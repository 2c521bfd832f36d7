"""Lab 08 tasks: solutions written from PR / 003 §2.2 pass, typical mistakes fail at the expected case."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy import ndimage

import slamlab_grading as lab

# --- independent solutions (what a student should write) --------------------------------------------


def low_variance(weights, n, r):
    w = np.asarray(weights, float)
    c = np.cumsum(w / w.sum())
    out, i = [], 0
    for m in range(n):  # PR Table 4.4, the loop form
        u = r + m / n
        while u >= c[i] and i < len(c) - 1:
            i += 1
        out.append(i)
    return np.array(out)


def _wrap(a):
    return (a + np.pi) % (2 * np.pi) - np.pi


def motion_sample(poses, odom_prev, odom_now, alpha, noise, *, squares=True):
    a1, a2, a3, a4 = alpha
    dx, dy = odom_now[0] - odom_prev[0], odom_now[1] - odom_prev[1]
    trans = math.hypot(dx, dy)
    rot1 = 0.0 if trans < 1e-6 else _wrap(math.atan2(dy, dx) - odom_prev[2])
    rot2 = _wrap(odom_now[2] - odom_prev[2] - rot1)
    p = (lambda x: x * x) if squares else abs  # the mistake: the printed PR Table 5.6 without squares
    r1 = rot1 - math.sqrt(a1 * p(rot1) + a2 * p(trans)) * noise[0]
    t = trans - math.sqrt(a3 * p(trans) + a4 * (p(rot1) + p(rot2))) * noise[1]
    r2 = rot2 - math.sqrt(a1 * p(rot2) + a2 * p(trans)) * noise[2]
    x, y, th = poses[:, 0], poses[:, 1], poses[:, 2]
    return np.column_stack([x + t * np.cos(th + r1), y + t * np.sin(th + r1), _wrap(th + r1 + r2)])


def likelihood_field(grid, pose, bearings_rad, ranges, z_hit, z_rand, z_max, sigma_hit, max_dist, *, skip=True,
                     outside=True):
    d = np.minimum(ndimage.distance_transform_edt(grid != 1), max_dist)
    H, W = grid.shape
    total = 0.0
    for a, r in zip(bearings_rad, ranges, strict=True):
        if skip and r >= z_max:
            continue
        ex, ey = pose[0] + r * math.cos(pose[2] + a), pose[1] + r * math.sin(pose[2] + a)
        row, col = math.floor(ey + 0.5), math.floor(ex + 0.5)
        if 0 <= row < H and 0 <= col < W:
            dist = d[row, col]
        else:
            dist = max_dist if outside else d[min(max(row, 0), H - 1), min(max(col, 0), W - 1)]
        g = math.exp(-0.5 * (dist / sigma_hit) ** 2) / (math.sqrt(2 * math.pi) * sigma_hit)
        total += math.log(z_hit * g + z_rand / z_max)
    return total


def augmented(w_avg, w_slow, w_fast, alpha_slow, alpha_fast, *, guard=True):
    s = w_slow + alpha_slow * (w_avg - w_slow)
    f = w_fast + alpha_fast * (w_avg - w_fast)
    if guard and s == 0:
        return np.array([s, f, 0.0])
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.array([s, f, max(0.0, 1.0 - f / s)])


TASKS = ("08.low_variance", "08.motion_sample", "08.likelihood_field", "08.augmented")


def _fails_both(task_id, fn):
    """The check of ``fn`` on the student's feedback cases (seed 0: the grading's check and the student's own
    ``sl.lab.check`` on the shipped feedback file) and on the grading cases: none passes."""
    from slamlab.lab import check as student_check

    results = [lab.check(task_id, fn, rng=rng, quiet=True) for rng in (0, lab.core.GRADING_RNG)]
    results.append(student_check(task_id, fn, quiet=True))
    assert not any(r.passed for r in results), [r.message for r in results]
    return results


@pytest.mark.parametrize(("task_id", "fn"), [("08.low_variance", low_variance), ("08.motion_sample", motion_sample),
                                             ("08.likelihood_field", likelihood_field),
                                             ("08.augmented", augmented)])
def test_correct_solutions_pass(task_id, fn):
    from slamlab.lab import check as student_check

    for rng in (0, lab.core.GRADING_RNG):
        res = lab.check(task_id, fn, rng=rng, quiet=True)
        assert res.passed, res.message
    res = student_check(task_id, fn, quiet=True)  # the feedback file the student's kernel has
    assert res.passed, res.message


def test_mistakes_fail():
    def multinomial(weights, n, r):  # ignores r: draws i.i.d.
        return np.random.default_rng(0).choice(len(weights), n, p=np.asarray(weights) / np.sum(weights))

    def no_squares(**kw):
        return motion_sample(**kw, squares=False)

    def no_skip(**kw):
        return likelihood_field(**kw, skip=False)

    def clamp_outside(**kw):
        return likelihood_field(**kw, outside=False)

    def averages_only_after(w_avg, w_slow, w_fast, alpha_slow, alpha_fast):  # p from the old averages
        p = 0.0 if w_slow == 0 else max(0.0, 1 - w_fast / w_slow)
        return np.array([w_slow + alpha_slow * (w_avg - w_slow), w_fast + alpha_fast * (w_avg - w_fast), p])

    _fails_both("08.low_variance", multinomial)
    assert all("case 1 of" in r.message for r in _fails_both("08.motion_sample", no_squares))
    assert all("(a beam at z_max is skipped)" in r.message for r in _fails_both("08.likelihood_field", no_skip))
    assert all("off the map" in r.message for r in _fails_both("08.likelihood_field", clamp_outside))
    _fails_both("08.augmented", averages_only_after)
    for rng in (0, lab.core.GRADING_RNG):
        res = lab.check("08.augmented", lambda **kw: augmented(**kw, guard=False), rng=rng, quiet=True)
        assert res.status in ("failed", "error")


def _library_wrappers():
    import slamlab as sl

    def motion(poses, odom_prev, odom_now, alpha, noise):
        from slamlab.localisation.models import motion_from_noise

        deltas = tuple(float(d) for d in sl.localisation.odometry_deltas(odom_prev, odom_now))
        return motion_from_noise(np.asarray(poses, float), deltas, np.asarray(alpha, float), np.asarray(noise, float))

    return {"08.low_variance": lambda weights, n, r: sl.localisation.low_variance_resample(weights, n, offset=r),
            "08.motion_sample": motion}


@pytest.mark.parametrize("task_id", ["08.low_variance", "08.motion_sample", "08.likelihood_field"])
def test_the_library_itself_is_refused(task_id):
    """The library's own function, wrapped to the task's signature, and the task's reference do not pass."""
    fns = [lab.task(task_id).reference] + ([_library_wrappers()[task_id]] if task_id in _library_wrappers() else [])
    for fn in fns:
        for res in _fails_both(task_id, fn):
            assert "called the library's" in res.message, res.message


def test_augmented_reference_is_written_out_and_a_library_call_is_refused():
    """Task 4's reference calls no library code (the library has no one-step update); any slamlab call is refused."""
    import slamlab as sl

    assert lab.check("08.augmented", lab.task("08.augmented").reference, quiet=True).passed

    def via_library(**kw):
        sl.localisation.check_alpha((0.1, 0.1, 0.1, 0.1))
        return augmented(**kw)

    for res in _fails_both("08.augmented", via_library):
        assert "called the library's" in res.message


# --- explorations: accepted ranges against independent computations ------------------------------------------


def _distinct_fraction_exact(M):
    """Mean and sd of the surviving fraction by enumerating every one of the M^M multinomial draws (small M)."""
    import itertools

    counts = np.array([len(set(draw)) for draw in itertools.product(range(M), repeat=M)], float) / M
    return counts.mean(), counts.std()


@pytest.mark.parametrize("M", [2, 3, 4, 5, 6])
def test_survivor_formula_and_sd_by_enumerating_every_draw(M):
    from slamlab_grading import tasks_localisation as tl

    mean, sd = _distinct_fraction_exact(M)
    assert tl.survivor_fraction(M) == pytest.approx(mean, rel=1e-12)
    assert tl.survivor_sd(M) == pytest.approx(sd, rel=1e-9)


def test_survivors_range_holds_for_single_runs_averages_and_the_formula_and_rejects_low_variance():
    t = lab.task("08.explore.survivors")
    lo, hi = t.accepted_range()
    M = 1000
    assert lo <= 1 - (1 - 1 / M) ** M <= hi
    rng = np.random.default_rng(11)
    singles = [np.unique(rng.choice(M, M)).size / M for _ in range(300)]  # numpy's sampler, not ours
    assert all(lo <= f <= hi for f in singles[:50])
    assert all(lo <= f <= hi for f in singles)
    assert lo <= np.mean(singles[:20]) <= hi
    assert lo <= np.mean(singles) <= hi
    for M_other in (500, 2000):  # the question fixes M: other particle counts also land in the range's width
        assert abs((1 - (1 - 1 / M_other) ** M_other) - (1 - (1 - 1 / M) ** M)) < 0.001
    # the low-variance sampler keeps every particle of equal weights (the typical wrong answer's 1.0)
    r = float(rng.uniform(0, 1 / M))
    assert np.unique(low_variance(np.full(M, 1.0), M, r)).size == M


def _first_injecting_length(alpha_slow, alpha_fast, drop, *, start_at_first=False):
    """Brute force with the test's own update: T steady steps of score 1, then one step scoring `drop`."""
    w_slow = w_fast = 0.0
    for T in range(1, 100000):
        if start_at_first and T == 1:  # ROS amcl: an average that is 0 takes the step's score
            w_slow = w_fast = 1.0
        else:
            w_slow, w_fast, _ = augmented(1.0, w_slow, w_fast, alpha_slow, alpha_fast)
        if augmented(drop, w_slow, w_fast, alpha_slow, alpha_fast)[2] > 0:
            return T
    raise AssertionError("no injection")


@pytest.mark.parametrize(("a_s", "a_f", "drop"), [(0.001, 0.1, 0.5), (0.05, 0.5, 0.5), (0.001, 0.1, 0.0),
                                                  (0.01, 0.2, 0.8)])
def test_warm_up_closed_form_equals_a_step_by_step_loop(a_s, a_f, drop):
    from slamlab_grading import tasks_localisation as tl

    assert tl.warm_up_steps(a_s, a_f, drop) == _first_injecting_length(a_s, a_f, drop)


def test_warm_up_range_and_the_steady_score_does_not_matter():
    t = lab.task("08.explore.warm_up")
    lo, hi = t.accepted_range()
    T = _first_injecting_length(0.001, 0.1, 0.5)
    assert lo == T
    assert hi == T + 1
    # any steady score: the condition is a ratio
    for s_bar in (1e-4, 0.3, 7.0):
        w_slow = w_fast = 0.0
        for _ in range(T - 1):
            w_slow, w_fast, _ = augmented(s_bar, w_slow, w_fast, 0.001, 0.1)
        assert augmented(s_bar / 2, w_slow, w_fast, 0.001, 0.1)[2] == 0.0
        w_slow, w_fast, _ = augmented(s_bar, w_slow, w_fast, 0.001, 0.1)
        assert augmented(s_bar / 2, w_slow, w_fast, 0.001, 0.1)[2] > 0.0
    # amcl's start (the typical wrong answer 1) injects at once
    assert _first_injecting_length(0.001, 0.1, 0.5, start_at_first=True) == 1


def test_exploration_answers_of_the_instructor_method():
    lo, _ = lab.task("08.explore.warm_up").accepted_range()
    assert lab.answer("08.explore.warm_up", _first_injecting_length(0.001, 0.1, 0.5), quiet=True).passed
    assert lab.answer("08.explore.warm_up", lo - 1, quiet=True).status == "failed"
    assert lab.answer("08.explore.survivors", 0.62, quiet=True).passed
    assert lab.answer("08.explore.survivors", 0.5, quiet=True).status == "failed"


def test_exploration_helpers_reject_bad_input():
    from slamlab_grading import tasks_localisation as tl

    with pytest.raises(ValueError, match="`M`"):
        tl.survivor_fraction(0)
    with pytest.raises(TypeError, match="`M`"):
        tl.survivor_sd(2.5)
    with pytest.raises(ValueError, match="`alpha_slow` must be smaller"):
        tl.warm_up_steps(0.2, 0.1)
    with pytest.raises(ValueError, match="`drop`"):
        tl.warm_up_steps(0.001, 0.1, 1.0)


# --- misconceptions rejected over 30 seeds or settings --------------------------------------------------------


def test_survivor_misconceptions_rejected_on_30_seeds():
    """The share lost (one minus a single run's surviving fraction, numpy's sampler, seeds 0-29) and the
    low-variance sampler's fraction (30 offsets) stay outside the accepted range, each with its hint."""
    t = lab.task("08.explore.survivors")
    lo, hi = t.accepted_range()
    M = 1000
    for seed in range(30):
        rng = np.random.default_rng(seed)
        survived = np.unique(rng.choice(M, M)).size / M
        assert lo <= survived <= hi
        lost = 1.0 - survived
        assert not lo <= lost <= hi
        assert "never drawn" in lab.answer("08.explore.survivors", lost, quiet=True).message
        lv = np.unique(low_variance(np.full(M, 1.0), M, float(rng.uniform(0, 1 / M)))).size / M
        assert not lo <= lv <= hi
        assert "low-variance" in lab.answer("08.explore.survivors", lv, quiet=True).message


SETTINGS = [(a_s, a_f, drop) for a_s in (0.001, 0.002, 0.005, 0.01, 0.02) for a_f in (0.05, 0.1, 0.2)
            for drop in (0.25, 0.5)]


@pytest.mark.parametrize(("a_s", "a_f", "drop"), SETTINGS)
def test_warm_up_misconceptions_rejected_on_30_settings(a_s, a_f, drop):
    """For 30 settings of (α_slow, α_fast, drop): the first injecting length by the test's loop, T, and [T, T + 1]
    (the question's range for its setting) never holds 1/α_slow (the time constant) or 1 (amcl's start)."""
    assert len(SETTINGS) == 30
    T = _first_injecting_length(a_s, a_f, drop)
    for wrong in (1.0 / a_s, 1.0):
        assert not T <= wrong <= T + 1


def test_warm_up_misconceptions_at_the_question_setting_get_their_hint():
    for wrong, hint in ((1000, "time constant"), (1, "amcl")):
        res = lab.answer("08.explore.warm_up", wrong, quiet=True)
        assert res.status == "failed"
        assert hint in res.message
