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


def test_exploration_answers():
    import slamlab as sl

    c = sl.mono.run_depth_filter_convergence((0.4,), n_obs=40, rng=2019)
    k = int(np.flatnonzero(c.converged[0] >= 0.5)[0])
    assert lab.answer("09.explore.half_converged", k, quiet=True).passed
    assert not lab.answer("09.explore.half_converged", k + 3, quiet=True).passed
