"""Lab 08 (probabilistic localisation, 003 §2.2): the tasks and the library functions they are checked against."""

from __future__ import annotations

import numpy as np

from ..localisation import LikelihoodFieldModel, low_variance_resample, odometry_deltas, scan_beams
from ..localisation.mcl import _inject_probability
from ..localisation.models import motion_from_noise
from ..scans import Scan
from .core import Case, ExplorationTask, Task, allclose, register

#: Exploration settings: particle count, runs and steps of the global study; the kidnap run.
EXPLORE_GLOBAL = {"particle_counts": (500,), "n_runs": 20, "n_steps": 20}
EXPLORE_KIDNAP = {"n_particles": 1000, "kidnap_step": 25, "alpha_slow": 0.05, "alpha_fast": 0.5}


def _lv_reference(weights, n, r):
    return low_variance_resample(weights, n, offset=r)


def _lv_cases(rng):
    cases = []
    for k, n in ((5, 5), (12, 30), (40, 10)):
        w = rng.random(k) ** 2
        cases.append(Case(f"random, {k} particles -> {n}", {"weights": w, "n": n, "r": float(rng.uniform(0, 1 / n))}))
    cases.append(Case("weights not normalised (sum 7)", {"weights": np.array([1.0, 3.0, 3.0]), "n": 7, "r": 0.05}))
    cases.append(Case("zero weights are never drawn", {"weights": np.array([0.0, 0.5, 0.0, 0.5, 0.0]), "n": 4,
                                                      "r": 0.0}))
    cases.append(Case("r = 0 exactly on a slice boundary", {"weights": np.full(4, 0.25), "n": 4, "r": 0.0}))
    return cases


def _motion_reference(poses, odom_prev, odom_now, alpha, noise):
    deltas = tuple(float(d) for d in odometry_deltas(odom_prev, odom_now))
    return motion_from_noise(np.asarray(poses, float), deltas, np.asarray(alpha, float), np.asarray(noise, float))


def _motion_cases(rng):
    cases = []
    for n in (3, 8):
        P = np.column_stack([rng.uniform(-5, 5, n), rng.uniform(-5, 5, n), rng.uniform(-np.pi, np.pi, n)])
        a, b = rng.uniform(-3, 3, 3), rng.uniform(-3, 3, 3)
        cases.append(Case(f"random, {n} particles", {"poses": P, "odom_prev": a, "odom_now": b,
                                                    "alpha": rng.uniform(0, 0.2, 4),
                                                    "noise": rng.standard_normal((3, n))}))
    cases.append(Case("heading across ±π", {"poses": np.array([[0.0, 0.0, 3.1]]), "odom_prev": np.array([0, 0, 3.0]),
                                           "odom_now": np.array([-1.0, 0.2, -3.0]),
                                           "alpha": np.array([0.1, 0.01, 0.1, 0.01]), "noise": np.ones((3, 1))}))
    cases.append(Case("no noise: the odometry step itself", {"poses": np.array([[2.0, 1.0, 0.5]]),
                                                            "odom_prev": np.zeros(3),
                                                            "odom_now": np.array([1.0, 1.0, np.pi / 2]),
                                                            "alpha": np.zeros(4), "noise": np.ones((3, 1))}))
    cases.append(Case("turn in place: δtrans = 0, δrot1 = 0", {"poses": np.array([[0.0, 0.0, 0.0]]),
                                                              "odom_prev": np.zeros(3),
                                                              "odom_now": np.array([0.0, 0.0, 1.0]),
                                                              "alpha": np.array([0.1, 0.1, 0.1, 0.1]),
                                                              "noise": np.array([[0.5], [0.5], [0.5]])}))
    return cases


def _lf_reference(grid, pose, bearings_rad, ranges, z_hit, z_rand, z_max, sigma_hit, max_dist):
    m = LikelihoodFieldModel(grid, z_hit=z_hit, z_rand=z_rand, sigma_hit=sigma_hit, z_max=z_max, max_dist=max_dist)
    scan = Scan(bearings_rad, ranges, np.ones(len(ranges), bool), max_range=z_max)
    return float(m.log_likelihood(np.asarray(pose, float)[None], scan_beams(scan, keep_max=True))[0])


def _lf_grid(rng, h=30, w=40):
    g = np.zeros((h, w), np.int8)
    g[0], g[-1], g[:, 0], g[:, -1] = 1, 1, 1, 1
    g[rng.integers(2, h - 2, 6), rng.integers(2, w - 2, 6)] = 1
    return g


def _lf_cases(rng):
    cases = []
    for n in (5, 20):
        g = _lf_grid(rng)
        cases.append(Case(f"random room, {n} beams", {
            "grid": g, "pose": np.array([rng.uniform(5, 35), rng.uniform(5, 25), rng.uniform(-np.pi, np.pi)]),
            "bearings_rad": np.sort(rng.uniform(-np.pi, np.pi, n)), "ranges": rng.uniform(1.0, 12.0, n) + 0.123,
            "z_hit": 0.8, "z_rand": 0.2, "z_max": 30.0, "sigma_hit": 1.5, "max_dist": 6.0}))
    g = _lf_grid(rng)
    cases.append(Case("a beam at z_max is skipped", {
        "grid": g, "pose": np.array([20.0, 15.0, 0.3]), "bearings_rad": np.array([0.0, 1.0, 2.0]),
        "ranges": np.array([4.1, 30.0, 6.3]), "z_hit": 0.9, "z_rand": 0.1, "z_max": 30.0, "sigma_hit": 1.0,
        "max_dist": 5.0}))
    cases.append(Case("an end point off the map scores as max_dist", {
        "grid": g, "pose": np.array([3.2, 3.1, np.pi]), "bearings_rad": np.array([0.0, 0.4]),
        "ranges": np.array([10.2, 2.1]), "z_hit": 0.7, "z_rand": 0.3, "z_max": 30.0, "sigma_hit": 2.0,
        "max_dist": 4.0}))
    return cases


def _aug_reference(w_avg, w_slow, w_fast, alpha_slow, alpha_fast):
    s = w_slow + alpha_slow * (w_avg - w_slow)
    f = w_fast + alpha_fast * (w_avg - w_fast)
    return np.array([s, f, _inject_probability(s, f)])


def _aug_cases(rng):
    cases = [Case(f"random #{i}", {"w_avg": float(rng.uniform(0, 1)), "w_slow": float(rng.uniform(0.1, 1)),
                                   "w_fast": float(rng.uniform(0.1, 1)), "alpha_slow": 0.01, "alpha_fast": 0.3})
             for i in range(3)]
    cases.append(Case("first step: both averages start at 0 (003)", {"w_avg": 0.4, "w_slow": 0.0, "w_fast": 0.0,
                                                                    "alpha_slow": 0.001, "alpha_fast": 0.1}))
    cases.append(Case("w_fast above w_slow: no injection", {"w_avg": 0.9, "w_slow": 0.3, "w_fast": 0.5,
                                                           "alpha_slow": 0.01, "alpha_fast": 0.5}))
    cases.append(Case("injection off: α_slow = α_fast = 0", {"w_avg": 0.0, "w_slow": 0.0, "w_fast": 0.0,
                                                            "alpha_slow": 0.0, "alpha_fast": 0.0}))
    return cases


register(Task("08.low_variance", "Task 1, low-variance resampling", _lv_reference, _lv_cases,
              "normalise the weights, c = cumsum; for m = 0..n-1 the pointer u = r + m/n selects the first i with "
              "c[i] > u (np.searchsorted(c, u, side='right')); return the n indices.",
              compare=allclose(0.0, 0.0), points=2))
register(Task("08.motion_sample", "Task 2, the odometry motion model (sampling form)", _motion_reference,
              _motion_cases,
              "δrot1 = atan2(ȳ'-ȳ, x̄'-x̄) - θ̄ (0 when δtrans is tiny), δtrans = distance, δrot2 = θ̄'-θ̄-δrot1, "
              "angles wrapped; δ̂ = δ - sqrt(variance)·noise with the variances of PR Table 5.6; then move each "
              "particle and wrap its heading to [-π, π).", compare=allclose(rtol=1e-9, atol=1e-9), points=3))
register(Task("08.likelihood_field", "Task 3, log p(z | x) by the likelihood field", _lf_reference, _lf_cases,
              "d = scipy.ndimage.distance_transform_edt(grid != 1) capped at max_dist; end point of beam k at "
              "x + r_k cos(θ + α_k), y + r_k sin(θ + α_k); cell (row, col) = (floor(y + 0.5), floor(x + 0.5)); "
              "off the map d = max_dist; skip r_k >= z_max; sum log(z_hit N(d; 0, σ²) + z_rand / z_max).",
              compare=allclose(rtol=1e-5, atol=1e-6), points=3))
register(Task("08.augmented", "Task 4, w_slow, w_fast and the injection probability (003 eqs 2.9-2.11)",
              _aug_reference, _aug_cases,
              "update both averages first, then p = max(0, 1 - w_fast / w_slow), and p = 0 while w_slow is 0; "
              "return np.array([w_slow, w_fast, p]).", compare=allclose(rtol=1e-12, atol=1e-12), points=2))


def _global_success() -> float:
    from ..localisation import run_global_localisation

    g = run_global_localisation(rng=2026, **EXPLORE_GLOBAL)
    return float(g.summary()["success"].iloc[0])


def _kidnap_recovery() -> float:
    from ..localisation import demo_run

    _, res = demo_run(rng=2026, **EXPLORE_KIDNAP)
    k = res.converged_at(EXPLORE_KIDNAP["kidnap_step"])
    return float("nan") if k is None else float(k - EXPLORE_KIDNAP["kidnap_step"])


register(ExplorationTask(
    "08.explore.global_success",
    "Exploration 1: the success rate of global localisation with 500 particles (20 runs of 20 steps)",
    _global_success,
    hint="sl.localisation.run_global_localisation((500,), n_runs=20, n_steps=20, rng=SEED); "
         "read .summary()['success'].", atol=1e-9))
register(ExplorationTask(
    "08.explore.kidnap_recovery",
    "Exploration 2: steps after the kidnap until the estimate stays within 3 cells and 5°",
    _kidnap_recovery,
    hint="run, res = sl.localisation.demo_run(1000, kidnap_step=25, alpha_slow=0.05, alpha_fast=0.5, rng=SEED); "
         "res.converged_at(25) - 25."))
