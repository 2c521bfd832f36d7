"""Lab 09 tasks: solutions written from 003 §4 / SVO pass, typical mistakes fail at the expected case."""

from __future__ import annotations

import math

import numpy as np
import pytest

import slamlab_grading as lab
from slamlab_grading import core


def update_seed(mu, sigma2, a, b, x, tau2, rho_range, *, outlier_density=None):
    s_tot2 = sigma2 + tau2
    C1 = a / (a + b) * math.exp(-0.5 * (x - mu) ** 2 / s_tot2) / math.sqrt(2 * math.pi * s_tot2)
    C2 = b / (a + b) * (1.0 / rho_range if outlier_density is None else outlier_density)
    C1, C2 = C1 / (C1 + C2), C2 / (C1 + C2)
    s2 = 1 / (1 / sigma2 + 1 / tau2)
    m = s2 * (mu / sigma2 + x / tau2)
    mu_new = C1 * m + C2 * mu
    var = C1 * (s2 + m * m) + C2 * (sigma2 + mu * mu) - mu_new**2
    f = C1 * (a + 1) / (a + b + 1) + C2 * a / (a + b + 1)
    e = (C1 * (a + 1) * (a + 2) + C2 * a * (a + 1)) / ((a + b + 1) * (a + b + 2))
    a_new = (e - f) / (f - e / f)
    return mu_new, var, a_new, a_new * (1 - f) / f


def depth_interval(mu, sigma):
    lo = mu - 2 * sigma
    return 1 / (mu + 2 * sigma), 1 / (lo if lo > 0 else 1e-10)


def linearity(mu, sigma2, d_m, cos_alpha):
    return 4 * math.sqrt(sigma2) / mu**2 * abs(cos_alpha) / d_m


def tau(t, f, z, px_error_angle):
    t, f = np.asarray(t, float), np.asarray(f, float)
    a = f * z - t
    alpha = math.acos(f @ t / np.linalg.norm(t))
    beta = math.acos(a @ -t / (np.linalg.norm(t) * np.linalg.norm(a)))
    bp = beta + px_error_angle
    return np.linalg.norm(t) * math.sin(bp) / math.sin(math.pi - alpha - bp) - z


TASKS = [("09.update_seed", update_seed), ("09.depth_interval", depth_interval), ("09.linearity", linearity),
         ("09.tau", tau)]


@pytest.mark.parametrize(("task_id", "fn"), TASKS)
@pytest.mark.parametrize("rng", [0, None], ids=["feedback cases", "grading cases"])
def test_correct_solutions_pass(task_id, fn, rng):
    res = lab.check(task_id, fn, quiet=True) if rng is None else lab.check(task_id, fn, rng=rng, quiet=True)
    assert res.passed, res.message


def _library_wrapped():
    from slamlab.mono import depth_filter as df

    def update(mu, sigma2, a, b, x, tau2, rho_range):
        return tuple(float(z) for z in df.update_seeds(mu, sigma2, a, b, x, tau2, rho_range))

    def interval(mu, sigma):
        lo, hi = df.depth_interval(np.array([mu]), np.array([sigma]))
        return float(lo[0]), float(hi[0])

    def lin(mu, sigma2, d_m, cos_alpha):
        return float(df.linearity_index(mu, sigma2, d_m, cos_alpha))

    def tau_lib(t, f, z, px_error_angle):
        return float(df.compute_tau(np.asarray(t), np.asarray(f)[None], np.array([z]), px_error_angle)[0])

    return {"09.update_seed": update, "09.depth_interval": interval, "09.linearity": lin, "09.tau": tau_lib}


@pytest.mark.parametrize("task_id", [t for t, _ in TASKS])
def test_the_librarys_own_function_fails(task_id):
    res = lab.check(task_id, _library_wrapped()[task_id], quiet=True)
    assert res.status == "failed", res.message
    assert "called the library's slamlab.mono" in res.message, res.message


def _no_tau_in_marginal(mu, sigma2, a, b, x, tau2, rho_range):  # N(x | mu, sigma2): the measurement noise forgotten
    s2 = sigma2
    C1 = a / (a + b) * math.exp(-0.5 * (x - mu) ** 2 / s2) / math.sqrt(2 * math.pi * s2)
    C2 = b / (a + b) / rho_range
    C1, C2 = C1 / (C1 + C2), C2 / (C1 + C2)
    return _mix(mu, sigma2, a, b, x, tau2, C1, C2)


def _no_uniform_density(mu, sigma2, a, b, x, tau2, rho_range):  # C2 = b / (a + b): the 1 / rho_range forgotten
    return update_seed(mu, sigma2, a, b, x, tau2, rho_range, outlier_density=1.0)


def _mix(mu, sigma2, a, b, x, tau2, C1, C2):
    s2 = 1 / (1 / sigma2 + 1 / tau2)
    m = s2 * (mu / sigma2 + x / tau2)
    mu_new = C1 * m + C2 * mu
    var = C1 * (s2 + m * m) + C2 * (sigma2 + mu * mu) - mu_new**2
    f = C1 * (a + 1) / (a + b + 1) + C2 * a / (a + b + 1)
    e = (C1 * (a + 1) * (a + 2) + C2 * a * (a + 1)) / ((a + b + 1) * (a + b + 2))
    a_new = (e - f) / (f - e / f)
    return mu_new, var, a_new, a_new * (1 - f) / f


def _no_floor(mu, sigma):  # forgets 003's rule: a negative far depth
    return 1 / (mu + 2 * sigma), 1 / (mu - 2 * sigma) if mu != 2 * sigma else 1e10


def _one_sigma(mu, sigma):  # SVO's 1 sigma band instead of 003's 2 sigma
    return 1 / (mu + sigma), 1 / max(mu - sigma, 1e-10)


def _signed_cos(mu, sigma2, d_m, cos_alpha):
    return 4 * math.sqrt(sigma2) / mu**2 * cos_alpha / d_m


def _depth_std_not_squared(mu, sigma2, d_m, cos_alpha):  # sigma_rho / rho instead of / rho^2
    return 4 * math.sqrt(sigma2) / mu * abs(cos_alpha) / d_m


def _no_minus_z(t, f, z, px_error_angle):  # returns z+ instead of tau = z+ - z
    return tau(t, f, z, px_error_angle) + z


MISTAKES = [("09.update_seed", _no_tau_in_marginal, None), ("09.update_seed", _no_uniform_density, None),
            ("09.depth_interval", _no_floor, "rho - 2 sigma < 0"), ("09.depth_interval", _one_sigma, None),
            ("09.linearity", _signed_cos, "negative cos alpha"), ("09.linearity", _depth_std_not_squared, None),
            ("09.tau", _no_minus_z, None)]


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


def _half_converged_scalar(rate, seed, n_seeds=500, n_obs=40):
    """The study with this file's own scalar update (a third implementation): observations to half converged."""
    rng = np.random.default_rng(seed)
    rho = rng.uniform(0.2, 2.0, n_seeds)
    seeds = [(float(rho.mean()), 4.0 / 36, 10.0, 10.0) for _ in range(n_seeds)]
    for k in range(n_obs + 1):
        if np.mean([math.sqrt(s[1]) < 2.0 / 200 for s in seeds]) >= 0.5:
            return k
        out = rng.random(n_seeds) < rate
        x = np.where(out, rng.uniform(0.0, 2.0, n_seeds), rho + rng.normal(0.0, 0.01, n_seeds))
        seeds = [update_seed(*s, float(xi), 1e-4, 2.0) for s, xi in zip(seeds, x, strict=True)]
    return n_obs + 1


def test_outlier_rate_range_holds_on_30_seeds_and_rejects_the_misconceptions_on_each():
    from slamlab_grading import tasks_mono as tm

    t = lab.task("09.explore.tripling_rate")
    lo, hi = t.accepted_range()
    labels = {w.label for w in t.wrong}
    assert labels == {"a percentage", "the inlier rate"}
    for seed in range(2000, 2030):  # 30 runs of the vectorised filter of tasks_mono on the question's 0.05 grid
        r = tm.factor_rate(seed)
        assert lo <= r <= hi, seed
        for wrong, label in ((1.0 - r, "the inlier rate"), (100.0 * r, "a percentage")):
            assert not lo <= wrong <= hi, (seed, label)
            assert t.misconception(wrong).label == label, (seed, label)
            assert lab.answer("09.explore.tripling_rate", wrong, quiet=True).status == "failed"


def test_outlier_rate_range_holds_for_the_library_a_scalar_filter_and_a_finer_grid():
    import slamlab as sl

    lo, hi = lab.task("09.explore.tripling_rate").accepted_range()
    rates = np.round(np.arange(0.0, 0.8, 0.05), 2)
    for seed in (2019, 5, 8):  # the library's study (another code, another stream)
        k = np.array([41 if n is None else n for n in
                      sl.studies.mono.run_depth_filter_convergence(tuple(rates), n_obs=40, rng=seed).first_half()])
        assert lo <= rates[np.flatnonzero(k >= 3 * k[0])[0]] <= hi, seed
    sub = (0.0, 0.5, 0.55, 0.6, 0.65, 0.7)  # this file's scalar update, one seed at a time
    k = np.array([_half_converged_scalar(r, 3) for r in sub])
    assert lo <= sub[np.flatnonzero(k >= 3 * k[0])[0]] <= hi
    from slamlab_grading import tasks_mono as tm

    for seed in range(3):  # a finer grid than the question's
        assert lo <= tm.factor_rate(seed, step=0.01) <= hi, seed


def test_tau_depth_range_from_this_files_tau_the_library_and_a_disparity():
    from slamlab.mono import compute_tau

    lo, hi = lab.task("09.explore.tau_depth").accepted_range()
    delta = 2 * math.atan(0.5 / 500)
    t, f = np.array([0.2, 0.0, 0.0]), np.array([0.0, 0.0, 1.0])
    z = np.arange(5.0, 12.0, 0.001)
    rel = np.array([tau(t, f, zi, delta) for zi in z]) / z  # this file's law-of-sines solution
    assert lo <= z[np.argmax(rel > 0.1)] <= hi
    rel_lib = compute_tau(t, np.tile(f, (z.size, 1)), z, delta) / z
    assert lo <= z[np.argmax(rel_lib > 0.1)] <= hi
    assert lo <= 500 * 0.2 / 11 <= hi  # rectified pair: z' = f b / (d - 1) is 10 % deeper when d = 11 px
    assert lo <= 9.1 <= hi
    assert lo <= 9.0 <= hi
    assert not lo <= 0.1 * 0.2 / delta <= hi  # the small-angle estimate is off by more than the resolution


def test_tau_depth_misconceptions_are_rejected_on_30_settings():
    """The question's design holds beyond its one setting: for 30 baselines and focal lengths the exact depth
    (this file's tau, scanned) is more than the resolution away from both misconceptions."""
    from slamlab_grading import tasks_mono as tm

    for b, f_px in zip(np.linspace(0.1, 0.4, 30), np.tile([400.0, 500.0, 600.0, 800.0, 1000.0], 6), strict=True):
        delta = 2 * math.atan(0.5 / f_px)
        exact = tm.depth_for_relative_error(0.1, baseline_m=b, f_px=f_px)
        z = np.arange(0.95 * exact, 1.05 * exact, 1e-3)
        rel = np.array([tau(np.array([b, 0, 0.0]), np.array([0, 0, 1.0]), zi, delta) for zi in z]) / z
        assert abs(z[np.argmax(rel > 0.1)] - exact) < 2e-3
        first_order = 0.1 * b / delta
        zs = np.linspace(1e-3, exact, 4000)
        absolute = zs[np.argmax(np.array([tm.tau_relative_depth(zi, baseline_m=b, f_px=f_px) * zi
                                          for zi in zs]) > 0.1)]
        for wrong in (first_order, absolute):
            assert abs(wrong - exact) > 0.1, (b, f_px, wrong, exact)
    t = lab.task("09.explore.tau_depth")
    for w in t.wrong:
        assert lab.answer("09.explore.tau_depth", float(w.value()), quiet=True).status == "failed"
        assert t.misconception(float(w.value())) is w


def test_exploration_answers_of_the_instructor_methods():
    assert lab.answer("09.explore.tau_depth", 9.1, quiet=True).passed
    assert lab.answer("09.explore.tau_depth", 9.3, quiet=True).status == "failed"
    assert lab.answer("09.explore.tripling_rate", 0.65, quiet=True).passed
    assert lab.answer("09.explore.tripling_rate", 0.6, quiet=True).passed
    for neighbour in (0.55, 0.7, 0.5):
        assert lab.answer("09.explore.tripling_rate", neighbour, quiet=True).status == "failed"


def test_student_visible_text_states_no_answer():
    """The feedback file's question and the exploration's prose hold no accepted number."""
    import re
    from pathlib import Path

    import nbformat

    root = Path(__file__).resolve().parents[2]
    fb = (root / "slamlab" / "lab" / "feedback" / "09.json").read_text()
    words = " ".join(re.findall(r'"(?:question|title|hint|unit)":"([^"]*)"', fb))  # what the student reads
    nb = nbformat.read(root / "notebooks" / "labs" / "09_monocular_mapping_lab.ipynb", as_version=4)
    prose = "\n".join(c.source for c in nb.cells if not c.metadata.get("nbgrader", {}).get("solution", False))
    for needle in ("0.6", "0.65", "9.1", "9.09", "9.087", "run_depth_filter_convergence", "compute_tau", "tau_table"):
        assert needle not in prose, needle
    for needle in ("0.6", "9.1", "9.09"):
        assert needle not in words, needle


def test_exploration_helpers_reject_bad_input():
    from slamlab_grading import tasks_mono as tm

    with pytest.raises(ValueError, match="`rates`"):
        tm.half_converged_observations([0.2, 1.0])
    with pytest.raises(ValueError, match="`n_obs`"):
        tm.half_converged_observations([0.2], n_obs=0)
    with pytest.raises(ValueError, match="`step`"):
        tm.factor_rate(1, step=0.0)
    with pytest.raises(ValueError, match="`z_m`"):
        tm.tau_relative_depth(-1.0)
    with pytest.raises(ValueError, match="`rel`"):
        tm.depth_for_relative_error(0.0)
