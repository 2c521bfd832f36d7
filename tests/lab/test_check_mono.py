"""Lab 09 tasks: solutions written from 003 §4 / SVO pass, typical mistakes fail at the expected case."""

from __future__ import annotations

import math

import numpy as np
import pytest

from slamlab import lab


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


@pytest.mark.parametrize(("task_id", "fn"), [("09.update_seed", update_seed), ("09.depth_interval", depth_interval),
                                             ("09.linearity", linearity), ("09.tau", tau)])
def test_correct_solutions_pass(task_id, fn):
    res = lab.check(task_id, fn, quiet=True)
    assert res.passed, res.message


def test_mistakes_fail():
    def no_tau_in_marginal(mu, sigma2, a, b, x, tau2, rho_range):  # N(x | mu, sigma2) instead of sigma2 + tau2
        return update_seed(mu, sigma2 - 0.0, a, b, x, tau2, rho_range, outlier_density=1.0 / rho_range * 2)

    def no_floor(mu, sigma):  # forgets 003's rule: a negative far depth
        return 1 / (mu + 2 * sigma), 1 / (mu - 2 * sigma) if mu != 2 * sigma else 1e10

    def one_sigma(mu, sigma):  # SVO's 1 sigma band instead of 003's 2 sigma
        return 1 / (mu + sigma), 1 / max(mu - sigma, 1e-10)

    def signed_cos(mu, sigma2, d_m, cos_alpha):
        return 4 * math.sqrt(sigma2) / mu**2 * cos_alpha / d_m

    def no_minus_z(t, f, z, px_error_angle):  # returns z+ instead of tau = z+ - z
        return tau(t, f, z, px_error_angle) + z

    assert lab.check("09.update_seed", no_tau_in_marginal, quiet=True).status == "failed"
    assert "rho - 2 sigma < 0" in lab.check("09.depth_interval", no_floor, quiet=True).message
    assert "case 1 of 5" in lab.check("09.depth_interval", one_sigma, quiet=True).message
    assert "negative cos alpha" in lab.check("09.linearity", signed_cos, quiet=True).message
    assert "case 1 of 4" in lab.check("09.tau", no_minus_z, quiet=True).message


# --- explorations: accepted ranges against independent computations ------------------------------------------


def _half_converged_scalar(rate, seed, n_seeds=150, n_obs=40):
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


def test_doubling_range_holds_for_the_library_and_a_scalar_filter_on_coarse_and_fine_grids():
    import slamlab as sl

    lo, hi = lab.task("09.explore.doubling_rate").accepted_range()
    assert 0.3 < lo < hi < 0.7
    for seed, step in ((2019, 0.05), (5, 0.05), (8, 0.1), (2019, 0.02)):  # the library's study, another code
        rates = np.round(np.arange(0.0, 0.7 + step / 2, step), 10)
        k = np.array([41 if n is None else n for n in
                      sl.studies.mono.run_depth_filter_convergence(tuple(rates), n_obs=40, rng=seed).first_half()])
        assert lo <= rates[np.flatnonzero(k >= 2 * k[0])[0]] <= hi, (seed, step)
    rates = (0.0, 0.3, 0.35, 0.4, 0.45, 0.5, 0.55, 0.6)
    k = np.array([_half_converged_scalar(r, 3) for r in rates])
    assert lo <= rates[np.flatnonzero(k >= 2 * k[0])[0]] <= hi


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
    assert lo <= 9.1 <= hi  # a 0.1 m grid's answer
    assert not lo <= 0.1 * 0.2 / delta <= hi  # the small-angle estimate is off by more than the resolution


def test_exploration_answers_of_the_instructor_methods():
    assert lab.answer("09.explore.tau_depth", 9.1, quiet=True).passed
    assert lab.answer("09.explore.tau_depth", 9.3, quiet=True).status == "failed"
    assert lab.answer("09.explore.doubling_rate", 0.5, quiet=True).passed
    assert lab.answer("09.explore.doubling_rate", 0.3, quiet=True).status == "failed"


def test_exploration_helpers_reject_bad_input():
    from slamlab.lab import tasks_mono as tm

    with pytest.raises(ValueError, match="`rates`"):
        tm.half_converged_observations([0.2, 1.0])
    with pytest.raises(ValueError, match="`n_obs`"):
        tm.half_converged_observations([0.2], n_obs=0)
    with pytest.raises(ValueError, match="`step`"):
        tm.doubling_rate(1, step=0.0)
    with pytest.raises(ValueError, match="`z_m`"):
        tm.tau_relative_depth(-1.0)
    with pytest.raises(ValueError, match="`rel`"):
        tm.depth_for_relative_error(0.0)
