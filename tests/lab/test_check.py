"""slamlab.lab: a student's function is checked against the library on seeded and edge cases."""

from __future__ import annotations

import numpy as np
import pytest

from slamlab import lab

# --- independent solutions, written from 000 §1.2's equations (what a student should write) ---------


def kf_predict(x, P, F, Q):
    return F @ x, F @ P @ F.T + Q


def kf_update(x, P, z, H, R):
    y = z - H @ x
    S = H @ P @ H.T + R
    K = np.linalg.solve(S, H @ P).T  # P H^T S^-1 (S, P symmetric)
    return x + K @ y, (np.eye(len(x)) - K @ H) @ P


def joseph(P, K, H, R):
    A = np.eye(P.shape[0]) - K @ H
    return A @ P @ A.T + K @ R @ K.T


def sigma_weights(L, alpha, beta, kappa):
    c = alpha**2 * (L + kappa)  # L + lambda
    lam = c - L
    Ws = np.full(2 * L + 1, 1 / (2 * c))
    Wc = Ws.copy()
    Ws[0] = lam / c
    Wc[0] = lam / c + 1 - alpha**2 + beta
    return Ws, Wc, lam


def sigma_points(x, P, alpha, kappa):
    A = np.linalg.cholesky(alpha**2 * (len(x) + kappa) * P)
    return np.vstack([x, x + A.T, x - A.T])


@pytest.mark.parametrize(("task_id", "fn"), [("01.kf_predict", kf_predict), ("01.kf_update", kf_update),
                                             ("01.joseph", joseph), ("01.sigma_weights", sigma_weights),
                                             ("01.sigma_points", sigma_points)])
def test_correct_solutions_pass(task_id, fn, capsys):
    res = lab.check(task_id, fn)
    assert res.passed, res.message
    assert capsys.readouterr().out.startswith(f"{lab.task(task_id).title}: passed")


def test_a_wrong_solution_reports_the_first_failing_case_and_the_hint():
    res = lab.check("01.kf_predict", lambda x, P, F, Q: (F @ x, F @ P @ F + Q), quiet=True)  # F^T missing
    assert res.status == "failed"
    assert "case 2 of 4 (random, n=2) is wrong: item 1 of the returned tuple" in res.message
    assert "hint: The predicted covariance must stay symmetric" in res.message


def test_naive_weights_fail_only_where_000s_alpha_cancels():
    def naive(L, alpha, beta, kappa):  # L + lambda computed as a difference: loses digits at alpha = 1e-3
        lam = alpha**2 * (L + kappa) - L
        Ws = np.full(2 * L + 1, 1 / (2 * (L + lam)))
        Wc = Ws.copy()
        Ws[0] = lam / (L + lam)
        Wc[0] = Ws[0] + 1 - alpha**2 + beta
        return Ws, Wc, lam

    res = lab.check("01.sigma_weights", naive, quiet=True)
    assert res.status == "failed"
    assert "(000's defaults, L=5: alpha=1e-3, beta=2, kappa=0)" in res.message


def test_not_implemented_is_not_done_yet():
    def todo(x, P, F, Q):
        raise NotImplementedError

    res = lab.check("01.kf_predict", todo, quiet=True)
    assert (res.status, res.message) == ("not done yet", "Task 1, KF predict: not done yet.")


def test_student_exception_points_at_the_students_line_not_at_slamlab():
    def broken(x, P, F, Q):
        wrong = x @ np.ones((7, 7))  # the student's own line
        return wrong, P

    res = lab.check("01.kf_predict", broken, quiet=True)
    assert res.status == "error"
    assert "raised ValueError" in res.message
    assert "wrong = x @ np.ones((7, 7))" in res.message
    assert "slamlab" not in res.message.replace("sl.lab", "")
    assert "Traceback" not in res.message


def test_inputs_are_copied_between_cases():
    def mutating(x, P, F, Q):
        out = F @ x, F @ P @ F.T + Q
        P[:] = 0.0  # changes the caller's array: must not change the next case's reference
        return out

    assert lab.check("01.kf_predict", mutating, quiet=True).passed


def test_autograder_mode_raises_on_anything_but_a_pass(monkeypatch):
    monkeypatch.setenv("NBGRADER_EXECUTION", "autograde")
    assert lab.check("01.kf_predict", kf_predict, quiet=True).passed
    with pytest.raises(AssertionError, match="not done yet"):
        lab.check("01.kf_predict", lambda x, P, F, Q: (_ for _ in ()).throw(NotImplementedError), quiet=True)


def test_q_scale_range_is_filterpys_ekf_and_equals_the_library_run():
    import inspect

    from scipy.stats import chi2

    from slamlab.lab import tasks_filters as tf
    from slamlab.studies.filters import default_landmarks, run_stabilising_noise, run_unicycle_comparison

    d = {k: p.default for k, p in inspect.signature(run_unicycle_comparison).parameters.items()}
    assert (d["dt_s"], d["speed_mps"], d["turn_rate_degps"], d["v_std_mps"], d["omega_std_degps"], d["range_std_m"],
            d["bearing_std_deg"], d["init_pos_std_m"], d["init_heading_std_deg"]) == (
        0.5, 1.0, 11.46, 0.2, 10.0, 0.5, 10.0, 1.0, 90.0)  # the scenario tasks_filters simulates for filterpy
    np.testing.assert_array_equal(default_landmarks(), [[0.0, 5.0], [4.0, 8.0], [-4.0, 2.0]])
    mean, (lo, hi) = tf.q_scale_study_filterpy()
    res = run_stabilising_noise(scales=tf.EXPLORE_Q_SCALES, n_runs=30, n_steps=60, rng=2010, progress=False)
    np.testing.assert_allclose(mean, res.mean_nees, rtol=1e-8)  # filterpy's EKF == the library's, run for run
    np.testing.assert_allclose((lo, hi), res.nees_bounds, rtol=1e-12)
    inside = [s for s, m in zip(tf.EXPLORE_Q_SCALES, mean, strict=True) if lo <= m <= hi]
    t = lab.task("01.explore.q_scale")
    assert t.accepted_range() == (min(inside), min(inside))
    assert lab.answer("01.explore.q_scale", res.scales[(res.mean_nees >= lo) & (res.mean_nees <= hi)].min(),
                      quiet=True).passed
    below = max(s for s in tf.EXPLORE_Q_SCALES if s < min(inside))
    assert mean[tf.EXPLORE_Q_SCALES.index(below)] > hi  # the grid step below is over-confident
    for value, words in ((below, "last one that fails"), (tf.EXPLORE_Q_SCALES[int(np.argmin(abs(mean - 3)))],
                                                           "nearest the state dimension"),
                         (min(s for s, m in zip(tf.EXPLORE_Q_SCALES, mean, strict=True)
                              if chi2.ppf(0.025, 3) <= m <= chi2.ppf(0.975, 3)), "one run's NEES")):
        res_w = lab.answer("01.explore.q_scale", value, quiet=True)
        assert res_w.status == "failed"
        assert words in res_w.message
    assert lab.answer("01.explore.q_scale", None, quiet=True).status == "not done yet"
    assert lab.answer("01.explore.q_scale", "eight", quiet=True).status == "failed"


def test_task_lookup_errors():
    with pytest.raises(ValueError, match="`task_id` must be one of"):
        lab.check("99.nothing", kf_predict)
    with pytest.raises(TypeError, match=r"use sl\.lab\.answer"):
        lab.check("01.explore.q_scale", kf_predict)
    with pytest.raises(TypeError, match=r"use sl\.lab\.check"):
        lab.answer("01.kf_predict", 3)


def test_exploration_answer_given_as_a_function():
    def todo():
        raise NotImplementedError

    def broken():
        return 1 / 0

    assert lab.answer("01.explore.q_scale", todo, quiet=True).status == "not done yet"
    res = lab.answer("01.explore.q_scale", broken, quiet=True)
    assert res.status == "error"
    assert "return 1 / 0" in res.message


def test_answer_prints_the_number_to_the_decimals_its_tolerance_resolves():
    from slamlab.lab.core import _shown

    # a pipeline's 6th digit differs between machines; a check within 0.005 shows 3 decimals
    assert _shown(0.912438, 0.005) == "0.912"
    assert _shown(0.912439, 0.005) == "0.912"
    assert _shown(0.3456, 0.027) == "0.35"
    assert _shown(7.0, 0.0) == "7"  # exact answers (counts) as they are
    assert _shown(0.35, 1e-9) == "0.35"
