"""Lab 09 (monocular mapping, 003 §4): the tasks and the library functions they are checked against."""

from __future__ import annotations

import functools

import numpy as np

from .._validate import as_finite_array, as_rng, check_int, check_positive
from ..mono import depth_filter as df
from .core import Case, ExplorationTask, Task, WrongAnswer, allclose, register


def _update_reference(mu, sigma2, a, b, x, tau2, rho_range):
    return tuple(float(z) for z in df.update_seeds(mu, sigma2, a, b, x, tau2, rho_range))


def _update_cases(rng):
    cases = []
    for _ in range(3):
        mu = float(rng.uniform(0.2, 1.5))
        cases.append(Case("random seed, an inlier-like measurement",
                          {"mu": mu, "sigma2": float(rng.uniform(1e-4, 0.05)), "a": float(rng.uniform(2, 30)),
                           "b": float(rng.uniform(2, 30)), "x": mu + float(rng.normal(0, 0.02)),
                           "tau2": float(rng.uniform(1e-5, 1e-3)), "rho_range": 2.0}))
    cases.append(Case("a measurement far from the mean: mostly an outlier",
                      {"mu": 0.5, "sigma2": 1e-4, "a": 10.0, "b": 10.0, "x": 1.8, "tau2": 1e-4, "rho_range": 2.0}))
    cases.append(Case("SVO's fresh seed (a = b = 10, sigma^2 = rho_range^2 / 36)",
                      {"mu": 0.25, "sigma2": 4.0 / 36, "a": 10.0, "b": 10.0, "x": 0.3, "tau2": 1e-3, "rho_range": 2.0}))
    return cases


def _interval_reference(mu, sigma):
    lo, hi = df.depth_interval(np.array([mu]), np.array([sigma]))
    return (float(lo[0]), float(hi[0]))


def _interval_cases(rng):
    cases = [Case("random", {"mu": float(rng.uniform(0.3, 1.0)), "sigma": float(rng.uniform(0.01, 0.1))}) for _ in range(3)]
    cases.append(Case("rho - 2 sigma exactly 0: 003's 1e-10", {"mu": 0.2, "sigma": 0.1}))
    cases.append(Case("rho - 2 sigma < 0: the far end at 1 / 1e-10", {"mu": 0.1, "sigma": 0.3}))
    return cases


def _linearity_reference(mu, sigma2, d_m, cos_alpha):
    return float(df.linearity_index(mu, sigma2, d_m, cos_alpha))


def _linearity_cases(rng):
    cases = [Case("random", {"mu": float(rng.uniform(0.2, 1.0)), "sigma2": float(rng.uniform(1e-6, 1e-3)),
                             "d_m": float(rng.uniform(1, 6)), "cos_alpha": float(rng.uniform(0.9, 1.0))})
             for _ in range(3)]
    cases.append(Case("negative cos alpha (|cos|)", {"mu": 0.5, "sigma2": 1e-4, "d_m": 2.0, "cos_alpha": -0.99}))
    return cases


def _tau_reference(t, f, z, px_error_angle):
    return float(df.compute_tau(np.asarray(t), np.asarray(f)[None], np.array([z]), px_error_angle)[0])


def _tau_cases(rng):
    cases = []
    for _ in range(3):
        f = np.array([rng.uniform(-0.3, 0.3), rng.uniform(-0.2, 0.2), 1.0])
        cases.append(Case("random", {"t": rng.uniform(-0.3, 0.3, 3), "f": f / np.linalg.norm(f),
                                     "z": float(rng.uniform(1, 8)), "px_error_angle": 2 * np.arctan(0.5 / 500)}))
    cases.append(Case("sideways baseline, point straight ahead", {"t": np.array([0.5, 0.0, 0.0]), "f": np.array([0.0, 0.0, 1.0]),
                                                                  "z": 4.0, "px_error_angle": 0.002}))
    return cases


register(Task("09.update_seed", "Task 1, the Gaussian x Beta update of one seed", _update_reference, _update_cases,
              "the inlier weight is the measurement's likelihood under the prior widened by the measurement noise, the "
              "outlier weight the uniform density over the inverse-depth range, both times their prior share; normalise "
              "them before mixing. A far measurement should barely move the mean and lower the inlier ratio.",
              compare=allclose(rtol=1e-9, atol=1e-12), points=3))
register(Task("09.depth_interval", "Task 2, 003's depth band", _interval_reference, _interval_cases,
              "the near end of the band comes from the larger inverse depth; when the smaller inverse depth is not "
              "positive, 003 replaces it by a tiny positive number, so the far end becomes huge, never negative.",
              compare=allclose(rtol=1e-12, atol=0.0)))
register(Task("09.linearity", "Task 3, 003's convergence test L", _linearity_reference, _linearity_cases,
              "the depth std follows from the inverse-depth std through the derivative of 1/ρ (it grows with the depth "
              "squared); the parallax enters through the size of its cosine, whatever its sign.",
              compare=allclose(rtol=1e-12, atol=0.0)))
register(Task("09.tau", "Task 4, SVO's measurement noise tau", _tau_reference, _tau_cases,
              "τ is a difference of depths, not the widened depth itself; the angles are those of the triangle formed by "
              "the two cameras and the point, and the pixel's angle widens the angle at the current camera.",
              compare=allclose(rtol=1e-9, atol=1e-12)))


# --- explorations -----------------------------------------------------------------------------------------

#: Exploration 1: the study's settings (run_depth_filter_convergence's defaults), the seeds of the independent
#: runs and the grid of outlier rates they scan.
EXPLORE_TAU = 0.01
EXPLORE_DEPTH_MIN_M = 0.5
EXPLORE_RUN_SEEDS = (1, 2, 3, 4)
EXPLORE_RATE_STEP = 0.01
#: Exploration 2: the baseline (sideways), the focal length and the relative depth error.
EXPLORE_BASELINE_M = 0.2
EXPLORE_F_PX = 500.0
EXPLORE_REL_ERROR = 0.1


def half_converged_observations(rates, *, n_seeds: int = 500, n_obs: int = 40, tau: float = EXPLORE_TAU,
                                depth_min_m: float = EXPLORE_DEPTH_MIN_M, rng=None) -> np.ndarray:
    """Observations until half of the seeds pass SVO's test, per outlier rate, by a filter written here.

    Written from the equations of Task 1 (Vogiatzis & Hernández's moment matching; 003 §4.1.1) and SVO's start
    (a = b = 10, σ² = ρ_range²/36, μ the mean inverse depth), vectorised over rates and seeds; it calls nothing of
    ``slamlab.mono``. Inliers are ``N(ρ_true, τ²)``, outliers ``U(0, ρ_range)``; SVO's test is σ < ρ_range/200.

    Parameters
    ----------
    rates : array_like, shape (R,)
        Outlier rates in [0, 1).
    n_seeds, n_obs : int
        Seeds per rate; the most observations tried.
    tau : float
        Inlier noise std, 1/m.
    depth_min_m : float
        Nearest depth, m (ρ_range = 1/depth_min_m).
    rng : numpy.random.Generator, int or None
        Randomness.

    Returns
    -------
    numpy.ndarray, shape (R,)
        The first observation count with at least half of the seeds converged (``n_obs + 1`` if never).
    """
    rng = as_rng(rng)
    r = as_finite_array(rates, "rates", ndim=1)[:, None]
    if r.size == 0 or np.any((r < 0) | (r >= 1)):
        raise ValueError(f"`rates` must be outlier rates in [0, 1); got {np.ravel(r)}")
    n_seeds, n_obs = check_int(n_seeds, "n_seeds", minimum=1), check_int(n_obs, "n_obs", minimum=1)
    tau, depth_min_m = check_positive(tau, "tau"), check_positive(depth_min_m, "depth_min_m")
    rho_range = 1.0 / depth_min_m
    rho = rng.uniform(0.2, rho_range, n_seeds)[None, :]
    mu = np.full((r.shape[0], n_seeds), rho.mean())
    s2 = np.full_like(mu, rho_range**2 / 36)
    a, b = np.full_like(mu, 10.0), np.full_like(mu, 10.0)
    out = np.full(r.shape[0], n_obs + 1)
    for k in range(n_obs + 1):
        done = (np.mean(np.sqrt(s2) < rho_range / 200, axis=1) >= 0.5) & (out > n_obs)
        out[done] = k
        if k == n_obs:
            break
        outlier = rng.random(mu.shape) < r
        x = np.where(outlier, rng.uniform(0.0, rho_range, mu.shape), rho + rng.normal(0.0, tau, mu.shape))
        var = s2 + tau**2
        c1 = a / (a + b) * np.exp(-0.5 * (x - mu) ** 2 / var) / np.sqrt(2 * np.pi * var)
        c2 = b / (a + b) / rho_range
        c1, c2 = c1 / (c1 + c2), c2 / (c1 + c2)
        s2n = 1.0 / (1.0 / s2 + 1.0 / tau**2)
        m = s2n * (mu / s2 + x / tau**2)
        mu_new = c1 * m + c2 * mu
        s2 = c1 * (s2n + m * m) + c2 * (s2 + mu * mu) - mu_new**2
        f = c1 * (a + 1) / (a + b + 1) + c2 * a / (a + b + 1)
        e = (c1 * (a + 1) * (a + 2) + c2 * a * (a + 1)) / ((a + b + 1) * (a + b + 2))
        a = (e - f) / (f - e / f)
        b = a * (1 - f) / f
        mu = mu_new
    return out


def doubling_rate(rng, *, step: float = EXPLORE_RATE_STEP) -> float:
    """The smallest outlier rate (on a grid of ``step``) needing at least twice the outlier-free observations.

    Parameters
    ----------
    rng : numpy.random.Generator, int or None
        The independent run's stream (:func:`half_converged_observations`).
    step : float
        Grid step of the outlier rate.

    Returns
    -------
    float
        The rate.
    """
    step = check_positive(step, "step")
    rates = np.round(np.arange(0.0, 0.9 + step / 2, step), 10)
    k = half_converged_observations(rates, rng=rng)
    return float(rates[np.flatnonzero(k >= 2 * k[0])[0]])


@functools.lru_cache(maxsize=1)
def _doubling_range() -> tuple[float, float]:
    found = [doubling_rate(s) for s in EXPLORE_RUN_SEEDS]
    return min(found) - 0.02, max(found) + 0.05


def tau_relative_depth(z_m: float, *, baseline_m: float = EXPLORE_BASELINE_M, f_px: float = EXPLORE_F_PX) -> float:
    """SVO's τ/z for a point straight ahead and a sideways baseline, in closed form (the triangle of Task 4).

    With α = 90°, β = atan(z/b) and one pixel of angle error δ = 2 atan(1/(2f)), z⁺ = b tan(β + δ).

    Parameters
    ----------
    z_m : float
        Depth, m.
    baseline_m, f_px : float
        Sideways baseline, m; focal length, px.

    Returns
    -------
    float
        τ / z.
    """
    z_m, baseline_m, f_px = check_positive(z_m, "z_m"), check_positive(baseline_m, "baseline_m"), \
        check_positive(f_px, "f_px")
    delta = 2.0 * np.arctan(0.5 / f_px)
    beta = np.arctan2(z_m, baseline_m)
    return float((baseline_m * np.tan(beta + delta) - z_m) / z_m)


def depth_for_relative_error(rel: float = EXPLORE_REL_ERROR, **kw) -> float:
    """The depth (m) at which SVO's τ reaches ``rel`` of the depth (bisection on :func:`tau_relative_depth`).

    Parameters
    ----------
    rel : float
        The relative error τ/z.
    **kw
        ``baseline_m``, ``f_px`` of :func:`tau_relative_depth`.

    Returns
    -------
    float
        The depth, m.
    """
    rel = check_positive(rel, "rel")
    b, f = kw.get("baseline_m", EXPLORE_BASELINE_M), kw.get("f_px", EXPLORE_F_PX)
    lo, hi = 1e-6 * b, 0.999 * b / np.tan(2.0 * np.arctan(0.5 / f))  # beyond hi the pixel's ray never meets the point's
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if tau_relative_depth(mid, **kw) < rel else (lo, mid)
    return 0.5 * (lo + hi)


def _first_order_depth() -> float:
    return EXPLORE_REL_ERROR * EXPLORE_BASELINE_M / (2.0 * np.arctan(0.5 / EXPLORE_F_PX))


def _depth_for_absolute_error() -> float:
    lo, hi = 1e-3, depth_for_relative_error(0.999)  # tau rises monotonically with the depth up to there
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if tau_relative_depth(mid) * mid < EXPLORE_REL_ERROR else (lo, mid)
    return 0.5 * (lo + hi)


register(ExplorationTask(
    "09.explore.doubling_rate",
    "Exploration 1: the outlier rate at which the depth filter needs twice the observations of an outlier-free one "
    "until half of the seeds pass SVO's test",
    lambda: float(np.mean(_doubling_range())),
    accepted=_doubling_range,
    why="a depth filter written from Task 1's equations (not slamlab.mono's), run with four seeds on a 0.01 grid of "
        "rates, 500 seeds per rate: the smallest rate of each run with at least twice the outlier-free count; "
        "accepted from 0.02 below the least to 0.05 above the largest, so coarser grids (0.05, 0.1) that land on "
        "the first grid value at or above the crossing pass too.",
    hint="first measure the outlier-free count (the observations until half of the seeds pass SVO's test), then "
         "raise the outlier rate until that count has at least doubled; answer with the rate as a fraction.",
    more="Scan the rate on a grid and print the count per rate: the answer is the first rate whose count is at "
         "least twice the first row's, not the last one below it.",
    wrong=(WrongAnswer("a percentage", lambda: 100.0 * float(np.mean(_doubling_range())), atol=6.0,
                       hint="that looks like a percentage; give the outlier rate as a fraction between 0 and 1."),
           WrongAnswer("the inlier rate", lambda: 1.0 - float(np.mean(_doubling_range())), atol=0.03,
                       hint="that is the share of inliers at the answer; the question asks for the outlier rate."))))
register(ExplorationTask(
    "09.explore.tau_depth",
    f"Exploration 2: the depth [m] beyond which one pixel of error changes the depth by more than "
    f"{EXPLORE_REL_ERROR:.0%} ({EXPLORE_BASELINE_M} m sideways baseline, f = {EXPLORE_F_PX:.0f} px)",
    depth_for_relative_error,
    accepted=lambda: (depth_for_relative_error() - 0.1, depth_for_relative_error() + 0.1),
    why=f"the closed form of Task 4's triangle for a point straight ahead, τ = b tan(atan(z/b) + δ) - z, solved for "
        f"τ/z = {EXPLORE_REL_ERROR} by bisection: {depth_for_relative_error():.3f} m (a rectified pair's disparity "
        f"f b / z losing one pixel gives the same to 1 mm); ± 0.1 m, the resolution the question asks for.",
    hint="τ from Task 4 is the change of the depth caused by one pixel of angle error; divide it by the depth and "
         "find where that ratio crosses the threshold, scanning the depth finely enough.",
    more="The ratio grows with the depth because the parallax angle shrinks while the pixel's angle stays the same.",
    wrong=(WrongAnswer("the first-order estimate", _first_order_depth, atol=0.1,
                       hint="that is the small-angle (first-order) estimate of the depth error; here the pixel's "
                            "angle is a tenth of the parallax angle, not small enough: use the exact triangle."),
           WrongAnswer("an absolute error", _depth_for_absolute_error, atol=0.1,
                       hint="at that depth τ is a tenth of a metre, an absolute error; the question asks for a "
                            "tenth of the depth."))))
