"""Lab 08 (probabilistic localisation, 003 §2.2): the tasks and the library functions they are checked against."""

from __future__ import annotations

import math

import numpy as np

from slamlab._validate import check_int, check_positive, check_probability
from slamlab.lab.compare import allclose
from slamlab.localisation import LikelihoodFieldModel, low_variance_resample, odometry_deltas, scan_beams
from slamlab.localisation.models import motion_from_noise
from slamlab.scans import Scan

from .core import Case, ExplorationTask, Task, WrongAnswer, register


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
    p_inject = max(0.0, 1.0 - f / s) if s > 0 else 0.0  # PR Table 8.3, written out: the reference stays independent
    return np.array([s, f, p_inject])


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
              "all n pointers share the one offset r and are 1/n apart, so the draw is deterministic: compare your "
              "indices with the case's weights by hand. A pointer that lands exactly on a boundary of the cumulative "
              "weights belongs to the particle whose slice starts there, and the weights need not sum to 1.",
              compare=allclose(0.0, 0.0), points=2))
register(Task("08.motion_sample", "Task 2, the odometry motion model (sampling form)", _motion_reference,
              _motion_cases,
              "the noise perturbs the three motion parts read from the odometry (two rotations and a translation), "
              "not the particles' coordinates; each part's spread grows with the size of the motion (PR Table 5.6). "
              "Check the turn on the spot (no translation) and the headings near ±π.",
              compare=allclose(rtol=1e-9, atol=1e-9), points=3))
register(Task("08.likelihood_field", "Task 3, log p(z | x) by the likelihood field", _lf_reference, _lf_cases,
              "the field holds the distance to the nearest obstacle cell, capped at max_dist; an end point is "
              "rounded to the nearest cell, one off the map counts as max_dist, and a beam at the range limit "
              "carries no information about a wall. Sum the logs of the mixture, not the log of a sum.",
              compare=allclose(rtol=1e-5, atol=1e-6), points=3))
register(Task("08.augmented", "Task 4, w_slow, w_fast and the injection probability (003 eqs 2.9-2.11)",
              _aug_reference, _aug_cases,
              "the injection probability is computed from the averages after this step's update, not before; and "
              "while the slow average is still 0 the ratio is undefined: no particle is injected.",
              compare=allclose(rtol=1e-12, atol=1e-12), points=2))

# --- explorations -----------------------------------------------------------------------------------------

#: Exploration 1: the particle count; Exploration 2: 003's averages, the steady score and the kidnap's drop.
EXPLORE_M = 1000
EXPLORE_ALPHAS = (0.001, 0.1)
EXPLORE_DROP = 0.5


def survivor_fraction(M: int = EXPLORE_M) -> float:
    """Expected fraction of M equally weighted particles drawn at least once by M multinomial draws.

    Parameters
    ----------
    M : int
        Particle count (and draws).

    Returns
    -------
    float
        ``1 - (1 - 1/M)**M`` (each particle is missed by all M draws with probability ``(1 - 1/M)**M``).
    """
    M = check_int(M, "M", minimum=1)
    return float(1.0 - (1.0 - 1.0 / M) ** M)


def survivor_sd(M: int = EXPLORE_M) -> float:
    """Standard deviation of the surviving fraction of one multinomial resampling of M equal weights.

    Parameters
    ----------
    M : int
        Particle count (and draws).

    Returns
    -------
    float
        From the occupancy problem: Var(distinct) = M (M-1) (1-2/M)^M + M (1-1/M)^M - M² (1-1/M)^{2M}.
    """
    M = check_int(M, "M", minimum=1)
    q1, q2 = (1.0 - 1.0 / M) ** M, (1.0 - 2.0 / M) ** M
    var = M * (M - 1) * q2 + M * q1 - (M * q1) ** 2
    return float(np.sqrt(var) / M)


def warm_up_steps(alpha_slow: float = EXPLORE_ALPHAS[0], alpha_fast: float = EXPLORE_ALPHAS[1],
                  drop: float = EXPLORE_DROP) -> int:
    """Fewest steady steps before a kidnap after which 003's averages (started at 0) inject (003 eqs 2.9-2.11).

    Closed form: after T steps of a steady score 1 the averages are ``1 - (1 - α)^T``; the kidnap step scores
    ``drop`` and injects when the updated w_fast falls below the updated w_slow. T is the first integer for which
    it does, found from the logarithm and confirmed on the integers around it.

    Parameters
    ----------
    alpha_slow, alpha_fast : float
        The averages' rates, 0 < alpha_slow < alpha_fast < 1.
    drop : float
        The kidnap step's score as a fraction of the steady score, 0 <= drop < 1.

    Returns
    -------
    int
        The number of steady steps T.
    """
    alpha_slow, alpha_fast = check_probability(alpha_slow, "alpha_slow"), check_probability(alpha_fast, "alpha_fast")
    if not alpha_slow < alpha_fast:
        raise ValueError(f"`alpha_slow` must be smaller than `alpha_fast`; got {alpha_slow} and {alpha_fast}")
    drop = check_positive(drop, "drop", allow_zero=True)
    if not drop < 1:
        raise ValueError(f"`drop` must be in [0, 1); got {drop}")

    def injects(T):
        s, f = 1.0 - (1.0 - alpha_slow) ** T, 1.0 - (1.0 - alpha_fast) ** T
        return f + alpha_fast * (drop - f) < s + alpha_slow * (drop - s)

    # with w_fast ~ 1 the condition is w_slow (1 - α_slow) + α_slow drop > 1 - α_fast (1 - drop)
    target = (1.0 - alpha_fast * (1.0 - drop) - alpha_slow * drop) / (1.0 - alpha_slow)
    T = max(1, int(np.floor(np.log1p(-target) / np.log1p(-alpha_slow))) - 2)
    while not injects(T):
        T += 1
    return T


register(ExplorationTask(
    "08.explore.survivors",
    f"Exploration 1: the fraction of {EXPLORE_M} equally weighted particles that survive one multinomial resampling",
    survivor_fraction,
    accepted=lambda: (survivor_fraction() - 4 * survivor_sd(), survivor_fraction() + 4 * survivor_sd()),
    why=f"the closed form 1 - (1 - 1/M)^M = {survivor_fraction():.4f} (each particle is missed by every one of the M "
        f"draws with probability (1 - 1/M)^M) ± 4 standard deviations of a single resampling "
        f"({survivor_sd():.4f}, the occupancy problem's variance): one run, an average of many runs and the "
        f"formula itself all pass (300 single runs of numpy's sampler all fall inside). The misconceptions stay "
        f"outside on 30 seeds: one minus a single run's fraction (the share lost) and the low-variance sampler's 1 "
        f"for 30 offsets.",
    hint="count the particles that appear at least once among the drawn indices and divide by M; the weights are "
         "all equal, so any loss is the sampler's doing, not the weights'.",
    more="Multinomial resampling draws M times independently with replacement: some particles are drawn twice, "
         "others never.",
    points=2, unit="a fraction of the particles", bounds=(0.0, 1.0), integer=False,
    # no slamlab function computes the multinomial fraction; the library's resampler is what the question leaves
    # unnamed (the student compares with the Task 1 sampler)
    answered_by=("slamlab.localisation.low_variance_resample", "slamlab.filters.particles.low_variance_resample"),
    wrong=(WrongAnswer("the low-variance sampler", lambda: 1.0,
                       hint="that is what the low-variance sampler gives with equal weights (one pointer per slice); "
                            "the question asks for independent, multinomial draws."),
           WrongAnswer("the fraction lost", lambda: 1.0 - survivor_fraction(), atol=0.05,
                       hint="that is the share of particles that are never drawn; the question asks for the share "
                            "that survives."))))


register(ExplorationTask(
    "08.explore.warm_up",
    f"Exploration 2: steady steps before a kidnap that halves the score can inject, with (α_slow, α_fast) = "
    f"{EXPLORE_ALPHAS} and 003's averages starting at 0",
    lambda: float(warm_up_steps()),
    accepted=lambda: (float(warm_up_steps()), float(warm_up_steps()) + 1.0),
    why=f"the closed form of the two averages after T steady steps, 1 - (1 - α)^T, gives T = {warm_up_steps()} "
        f"(a step-by-step loop over Task 4's update gives the same); T + 1 is accepted too: it counts the kidnap "
        f"step itself. Any steady score gives the same T (the condition is a ratio). Not a knife-edge: one step "
        f"before, p = 1 - w_fast/w_slow is -1.5e-5 and at T it is +3.8e-5, far above rounding (1e-16), so every "
        f"correct loop or formula finds the same integer. Misconceptions: 1/α_slow and amcl's 1 lie outside "
        f"[T, T + 1] on the 30 settings the tests try (α_slow 0.001-0.02, α_fast 0.05-0.2, drop 0.25 or 0.5); "
        f"T - 1 is not named (its hint would place the answer).",
    hint="both averages start at 0 and climb towards the steady score at their own rates; the kidnap step injects "
         "only when, after its update, the fast average lies below the slow one. Find the first steady length for "
         "which that happens.",
    more="Loop over the steady length (or solve for it): run Task 4's update for that many steps, then one step at "
         "half the score, and look at the injection probability.",
    points=2, unit="a number of steady steps", bounds=(0.0, math.inf), integer=True,
    # no slamlab function computes T; the averages' update lives in the library's MCL step, which the question
    # leaves unnamed (Task 4 is the route)
    answered_by=("slamlab.localisation.mcl_step", "slamlab.localisation.MCL"),
    wrong=(WrongAnswer("the slow average's time constant", lambda: 1.0 / EXPLORE_ALPHAS[0],
                       hint="that is the slow average's time constant, a rule of thumb; after that many steps it has "
                            "reached only about two thirds of the steady score, which is not enough here."),
           WrongAnswer("amcl's initialisation", lambda: 1.0,
                       hint="that is true when both averages start at the first step's score, as ROS's amcl does; "
                            "003 starts them at 0."))))
