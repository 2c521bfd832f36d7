"""slamlab.lab: a student's function is checked against the library on seeded and edge cases."""

from __future__ import annotations

import numpy as np
import pytest

import slamlab_grading as lab

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
    assert capsys.readouterr().out.startswith(f"graded: {lab.task(task_id).title}: passed")


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


#: The feedback file's cases (seed 0) and the grading's: a named mistake must fail on both.
SEEDS = (0, lab.core.GRADING_RNG)


def test_named_mistakes_fail_on_the_feedback_and_the_grading_cases():
    def no_transpose(x, P, F, Q):  # F P F + Q
        return F @ x, F @ P @ F + Q

    def no_process_noise(x, P, F, Q):
        return F @ x, F @ P @ F.T

    def no_measurement_noise(x, P, z, H, R):  # S = H P H^T: R forgotten
        S = H @ P @ H.T
        K = np.linalg.lstsq(S, H @ P, rcond=None)[0].T
        return x + K @ (z - H @ x), (np.eye(len(x)) - K @ H) @ P

    def short_form(P, K, H, R):  # (I - K H) P: right only for the optimal gain
        return (np.eye(P.shape[0]) - K @ H) @ P

    def rows_not_columns(x, P, alpha, kappa):  # the Cholesky factor's rows
        A = np.linalg.cholesky(alpha**2 * (len(x) + kappa) * P)
        return np.vstack([x, x + A, x - A])

    for rng in SEEDS:
        for task_id, fn, at in (("01.kf_predict", no_transpose, "(random, n=2)"),
                                ("01.kf_predict", no_process_noise, ""),
                                ("01.kf_update", no_measurement_noise, ""),
                                ("01.joseph", short_form, "(gain 1.5 x optimal, n=2)"),
                                ("01.sigma_points", rows_not_columns, "")):
            res = lab.check(task_id, fn, rng=rng, quiet=True)
            assert res.status == "failed", (task_id, fn.__name__, rng, res.message)
            assert at in res.message, (task_id, fn.__name__, rng, res.message)
    # not a lucky case: the gain 1.5 K_opt case (whatever its P) catches the short form, and every random case with
    # n >= 2 (a random F is never symmetric) catches the missing transpose
    edge = [c for c in lab.task("01.joseph").cases(np.random.default_rng(1)) if c.label.startswith("gain 1.5")]
    assert all(not np.allclose(short_form(**c.kwargs), joseph(**c.kwargs)) for c in edge)
    edge = [c for c in lab.task("01.kf_predict").cases(np.random.default_rng(1)) if c.label.startswith("random, n=2")]
    assert all(not np.allclose(no_transpose(**c.kwargs)[1], kf_predict(**c.kwargs)[1]) for c in edge)


def _library_calls():
    """The library's own functions wrapped to each task's signature (what the forbid check must catch)."""
    import slamlab as sl

    def update(x, P, z, H, R):
        u = sl.filters.kf_update(x, P, z, H, R)
        return u.x, u.P

    def joseph_after_a_library_call(P, K, H, R):  # no library function takes a given gain: any call counts
        sl.filters.sigma_weights(1, 1.0, 2.0, 0.0)
        return joseph(P, K, H, R)

    return {"01.kf_predict": lambda x, P, F, Q: sl.filters.kf_predict(x, P, F, Q),
            "01.kf_update": update,
            "01.joseph": joseph_after_a_library_call,
            "01.sigma_weights": lambda L, alpha, beta, kappa: sl.filters.sigma_weights(L, alpha, beta, kappa),
            "01.sigma_points": lambda x, P, alpha, kappa: sl.filters.sigma_points(x, P, alpha, kappa)}


@pytest.mark.parametrize("task_id", ["01.kf_predict", "01.kf_update", "01.joseph", "01.sigma_weights",
                                     "01.sigma_points"])
def test_the_librarys_own_function_is_refused(task_id):
    import slamlab as sl

    fn = _library_calls()[task_id]
    for res in (lab.check(task_id, fn, quiet=True), sl.lab.check(task_id, fn, quiet=True)):  # grading, feedback
        assert res.status == "failed", res.message
        assert "called the library's slamlab.filters." in res.message, res.message


# --- exploration 1: the median run's NEES with Q x 16 ---------------------------------------------------------


def test_typical_run_nees_filterpy_is_the_librarys_run_and_two_methods_pass():
    import inspect

    from slamlab.studies.filters import default_landmarks, run_unicycle_comparison
    from slamlab_grading import tasks_filters as tf

    d = {k: p.default for k, p in inspect.signature(run_unicycle_comparison).parameters.items()}
    assert (d["dt_s"], d["speed_mps"], d["turn_rate_degps"], d["v_std_mps"], d["omega_std_degps"], d["range_std_m"],
            d["bearing_std_deg"], d["init_pos_std_m"], d["init_heading_std_deg"]) == (
        0.5, 1.0, 11.46, 0.2, 10.0, 0.5, 10.0, 1.0, 90.0)  # the scenario tasks_filters simulates for filterpy
    np.testing.assert_array_equal(default_landmarks(), [[0.0, 5.0], [4.0, 8.0], [-4.0, 2.0]])
    seeds = range(2010, 2020)
    lib = [run_unicycle_comparison(1, 60, filters=("EKF",), stabilising_noise=16.0, rng=s, progress=False)
           .mean_nees[0] for s in seeds]
    np.testing.assert_allclose(tf.run_nees_filterpy(seeds).mean(axis=1), lib, rtol=1e-8)  # run for run
    t = lab.task("01.explore.q_scale")
    lo, hi = t.accepted_range()
    # method 1: the library's study, one run per seed 2010-2409 (the instructor's run); method 2: filterpy's EKF
    # on other seeds
    assert lo <= t.expected() <= hi
    other = float(np.median(tf.run_nees_filterpy(range(7000, 7400)).mean(axis=1)))
    assert lab.answer("01.explore.q_scale", other, quiet=True).passed
    res = lab.answer("01.explore.q_scale", 3.0, quiet=True)
    assert res.status == "failed"
    assert "true process noise" in res.message
    assert lab.answer("01.explore.q_scale", None, quiet=True).status == "not done yet"
    assert lab.answer("01.explore.q_scale", "eight", quiet=True).status == "failed"


def _wrap(a):
    return (a + np.pi) % (2 * np.pi) - np.pi


def batched_unicycle_nees(n_runs: int, scale: float, rng, n_steps: int = 60) -> np.ndarray:
    """NEES per run and step of the chapter's unicycle (000 §1.2.2's study) under an EKF written here, every run at
    once (numpy, batched 3x3 and 6x6 algebra; Joseph-form update, as filterpy's): independent of the library and
    of ``run_nees_filterpy``, with its own random stream."""
    lm = np.array([[0.0, 5.0], [4.0, 8.0], [-4.0, 2.0]])
    dt, v, om, sv, som = 0.5, 1.0, np.deg2rad(11.46), 0.2, np.deg2rad(10.0)
    r_std = np.tile([0.5, np.deg2rad(10.0)], 3)
    R = np.diag(r_std**2)
    P0 = np.diag([1.0, 1.0, np.deg2rad(90.0) ** 2])
    M = np.diag([sv**2, som**2])

    def move(x, vel, turn):
        return np.column_stack([x[:, 0] + vel * dt * np.cos(x[:, 2]), x[:, 1] + vel * dt * np.sin(x[:, 2]),
                                _wrap(x[:, 2] + turn * dt)])

    def hx(x):  # (N, 6): range and bearing to every landmark, interleaved
        d = lm[None] - x[:, None, :2]
        return np.stack([np.hypot(d[..., 0], d[..., 1]), _wrap(np.arctan2(d[..., 1], d[..., 0]) - x[:, None, 2])],
                        axis=-1).reshape(len(x), 6)

    def jac(x):
        d = lm[None] - x[:, None, :2]
        q = (d**2).sum(axis=-1)
        H = np.zeros((len(x), 6, 3))
        H[:, 0::2, 0], H[:, 0::2, 1] = -d[..., 0] / np.sqrt(q), -d[..., 1] / np.sqrt(q)
        H[:, 1::2, 0], H[:, 1::2, 1], H[:, 1::2, 2] = d[..., 1] / q, -d[..., 0] / q, -1.0
        return H

    x = np.zeros((n_runs, 3))
    xe = rng.normal(size=(n_runs, 3)) * np.sqrt(np.diag(P0))
    P = np.tile(P0, (n_runs, 1, 1))
    eye = np.eye(3)
    out = np.empty((n_runs, n_steps))
    for k in range(n_steps):
        x = move(x, v + sv * rng.normal(size=n_runs), om + som * rng.normal(size=n_runs))
        z = hx(x) + r_std * rng.normal(size=(n_runs, 6))
        th = xe[:, 2]
        F = np.tile(eye, (n_runs, 1, 1))
        F[:, 0, 2], F[:, 1, 2] = -v * dt * np.sin(th), v * dt * np.cos(th)
        V = np.zeros((n_runs, 3, 2))
        V[:, 0, 0], V[:, 1, 0], V[:, 2, 1] = dt * np.cos(th), dt * np.sin(th), dt
        xe = move(xe, v, om)
        P = F @ P @ F.transpose(0, 2, 1) + scale * V @ M @ V.transpose(0, 2, 1)
        H = jac(xe)
        y = z - hx(xe)
        y[:, 1::2] = _wrap(y[:, 1::2])
        S = H @ P @ H.transpose(0, 2, 1) + R
        K = np.linalg.solve(S, H @ P).transpose(0, 2, 1)  # P H^T S^-1 (S, P symmetric)
        xe = xe + (K @ y[..., None])[..., 0]
        xe[:, 2] = _wrap(xe[:, 2])
        A = eye - K @ H
        P = A @ P @ A.transpose(0, 2, 1) + K @ R @ K.transpose(0, 2, 1)
        e = x - xe
        e[:, 2] = _wrap(e[:, 2])
        out[:, k] = (e[:, None, :] @ np.linalg.solve(P, e[..., None]))[:, 0, 0]
    return out


def test_typical_run_nees_range_and_misconceptions_over_30_blocks_of_400_runs():
    """30 blocks of 400 runs, from an EKF batched here with streams of its own: every block's median run at scale 16
    lies in the accepted range, and the three misconceptions (scale 1, the pooled median of every step, the mean
    over runs) lie outside it on every block. (The range itself comes from filterpy's EKF on seeds 0-3999.)"""
    t = lab.task("01.explore.q_scale")
    lo, hi = t.accepted_range()
    n16 = batched_unicycle_nees(30 * 400, 16.0, np.random.default_rng(43))
    n1 = batched_unicycle_nees(30 * 400, 1.0, np.random.default_rng(44))
    for b in range(30):
        block16, block1 = n16[400 * b:400 * (b + 1)], n1[400 * b:400 * (b + 1)]
        assert lo <= np.median(block16.mean(axis=1)) <= hi, b
        for wrong in (np.median(block1.mean(axis=1)), np.median(block16), block16.mean()):
            assert not lo <= wrong <= hi, (b, wrong)
            assert lab.answer("01.explore.q_scale", float(wrong), quiet=True).status == "failed"


# --- exploration 2: the RMSE with a 0.25 m sensor --------------------------------------------------------------


def _cv_rmse(pos_std_m, n_runs, n_steps, seed):
    """The constant-velocity target tracked by a KF written here, one axis at a time, all runs at once."""
    rng = np.random.default_rng(seed)
    F = np.array([[1.0, 1.0], [0.0, 1.0]])
    Q = 0.2**2 * np.array([[1 / 3, 1 / 2], [1 / 2, 1.0]])
    L = np.linalg.cholesky(Q)
    se = 0.0
    for _axis in range(2):
        P = np.diag([pos_std_m**2, 1.0])
        x = np.array([0.0, 1.0]) + rng.normal(size=(n_runs, 2)) * [pos_std_m, 1.0]
        xe = np.tile([0.0, 1.0], (n_runs, 1))
        for _ in range(n_steps):
            x = x @ F.T + rng.normal(size=(n_runs, 2)) @ L.T
            z = x[:, 0] + pos_std_m * rng.normal(size=n_runs)
            xe, P = xe @ F.T, F @ P @ F.T + Q
            k = P[:, 0] / (P[0, 0] + pos_std_m**2)
            xe, P = xe + (z - xe[:, 0])[:, None] * k, P - np.outer(k, P[0])
            se += float(np.sum((xe[:, 0] - x[:, 0]) ** 2))
    return np.sqrt(se / (n_runs * n_steps))


def test_rmse_range_holds_on_30_seeds_and_rejects_each_misconception_on_each():
    lo, hi = lab.task("01.explore.rmse_quarter_metre").accepted_range()
    for seed in range(30):
        r, r1 = _cv_rmse(0.25, 50, 50, seed), _cv_rmse(1.0, 50, 50, seed)
        assert lo <= r <= hi, seed
        for wrong, label in ((r1, "the chapter's sensor"), (r / np.sqrt(2), "one axis only"),
                             (r**2, "mean squared error"), (100 * r, "centimetres")):
            assert not lo <= wrong <= hi, (seed, label)
            res = lab.answer("01.explore.rmse_quarter_metre", wrong, quiet=True)
            assert res.status == "failed"
            hint = next(w.hint for w in lab.task("01.explore.rmse_quarter_metre").wrong if w.label == label)
            assert hint in res.message, (seed, label, res.message)
    # longer runs and the steady state pass too (the range's two ends)
    assert lo <= _cv_rmse(0.25, 100, 200, 7) <= hi


def test_answer_prints_the_number_to_the_decimals_its_tolerance_resolves():
    from slamlab_grading.core import _shown

    # a pipeline's 6th digit differs between machines; a check within 0.005 shows 3 decimals
    assert _shown(0.912438, 0.005) == "0.912"
    assert _shown(0.912439, 0.005) == "0.912"
    assert _shown(0.3456, 0.027) == "0.35"
    assert _shown(7.0, 0.0) == "7"  # exact answers (counts) as they are
    assert _shown(0.35, 1e-9) == "0.35"
