"""Lab 07 (Hough SLAM, 004): the tasks and the library functions they are checked against."""

from __future__ import annotations

from functools import lru_cache

import numpy as np

from ..hough import HoughAccumulator, find_peaks, hough_polar, pose_from_two_lines, transform_lines
from .core import Case, ExplorationTask, Task, WrongAnswer, allclose, register

#: Exploration 1's pose index on 004's path and the line (0-based, by votes) whose loss is asked for.
EXPLORE_POSE_INDEX = 20
EXPLORE_LINE = 2


def _hough_reference(bearings_rad, ranges, delta_rho, delta_theta_rad, r_max):
    return hough_polar(bearings_rad, ranges, delta_rho=delta_rho, delta_theta_rad=delta_theta_rad, r_max=r_max).H


def _wall_scan(rng, n, rho, theta, r_max):
    """Points of the line (rho, theta) seen from the origin, with a little noise along the normal."""
    t = rng.uniform(-r_max / 2, r_max / 2, n)
    x = rho * np.cos(theta) - t * np.sin(theta)
    y = rho * np.sin(theta) + t * np.cos(theta)
    x, y = x + rng.normal(0, 0.05, n) * np.cos(theta), y + rng.normal(0, 0.05, n) * np.sin(theta)
    return np.arctan2(y, x), np.hypot(x, y)


def _hough_cases(rng):
    cases = []
    for n, d_rho, d_theta in ((30, 1.0, 1.0), (50, 0.5, 5.0)):
        b1, r1 = _wall_scan(rng, n // 2, 6.0, np.radians(30.0), 16.0)
        b2, r2 = _wall_scan(rng, n - n // 2, -4.0, np.radians(-70.0), 16.0)
        cases.append(Case(f"two walls, {n} points, Δrho = {d_rho}, Δθ = {d_theta}°",
                          {"bearings_rad": np.concatenate([b1, b2]), "ranges": np.concatenate([r1, r2]),
                           "delta_rho": d_rho, "delta_theta_rad": float(np.radians(d_theta)), "r_max": 16.0}))
    b = rng.uniform(-np.pi, np.pi, 12)
    r = rng.uniform(1.0, 14.0, 12)
    r[[2, 5]] = 0.0
    r[[7, 9]] = 20.0
    cases.append(Case("zero ranges (no return) and ranges beyond r_max do not vote",
                      {"bearings_rad": b, "ranges": r, "delta_rho": 1.0, "delta_theta_rad": float(np.radians(45.0)),
                       "r_max": 15.0}))
    cases.append(Case("an empty scan: an accumulator of zeros", {"bearings_rad": np.empty(0), "ranges": np.empty(0),
                                                                "delta_rho": 1.0,
                                                                "delta_theta_rad": float(np.radians(10.0)),
                                                                "r_max": 5.0}))
    return cases


def _peaks_reference(H, rho, theta_rad, H_min):
    acc = HoughAccumulator(H, rho, theta_rad, float(rho[1] - rho[0]), float(theta_rad[1] - theta_rad[0]))
    lines = find_peaks(acc, H_min, suppress_rho=0.0, suppress_theta_rad=0.0)
    return lines.rho, lines.theta_rad, lines.votes.astype(float)


def _accumulator(rng, n_half, n_theta):
    n_rho = 2 * n_half + 1
    H = rng.permutation(n_rho * n_theta).reshape(n_rho, n_theta)  # distinct counts: no flat tops
    return {"H": H, "rho": np.arange(-n_half, n_half + 1, dtype=float),
            "theta_rad": -np.pi / 2 + np.pi / n_theta * np.arange(n_theta)}


def _peaks_cases(rng):
    cases = []
    for n_half, n_theta, frac in ((4, 12, 0.5), (6, 18, 0.7)):
        acc = _accumulator(rng, n_half, n_theta)
        h_min = int(frac * acc["H"].size)
        cases.append(Case(f"random {2 * n_half + 1}x{n_theta} accumulator, H_min = {h_min}", {**acc, "H_min": h_min}))
    # θ wraps: the column before -90° is +90° - Δθ with rho flipped
    acc = _accumulator(rng, 3, 6)
    H = acc["H"]
    H[2, 0] = 100  # a peak at (rho = -1, θ = -90°) ...
    H[4, 5] = 101  # ... beaten across the wrap by (rho = +1, θ = +60°), its neighbour (-rho, θ + 180° - Δθ)
    H[0, 2] = 99  # a peak on the rho edge: only the cells that exist are compared
    cases.append(Case("θ wraps at ±90° with rho flipped; a peak on the rho edge", {**acc, "H": H, "H_min": 30}))
    acc = _accumulator(rng, 2, 4)
    cases.append(Case("H_min above every count: no line, empty arrays", {**acc, "H_min": 1000}))
    return cases


def _transform_cases(rng):
    cases = []
    for n in (1, 5):
        cases.append(Case(f"random, {n} lines", {"rho": rng.uniform(-10, 10, n), "theta_rad": rng.uniform(-1.5, 1.5, n),
                                                 "pose": rng.normal(0, 2, 3)}))
    cases.append(Case("θ leaves [-90°, 90°): keep it continuous, do not wrap",
                      {"rho": np.array([4.0, -3.0]), "theta_rad": np.radians([-85.0, 88.0]),
                       "pose": np.array([0.5, -1.0, np.radians(10.0)])}))
    cases.append(Case("no lines", {"rho": np.empty(0), "theta_rad": np.empty(0), "pose": np.array([1.0, 2.0, 0.3])}))
    return cases


def _pose_reference(line_i1, line_i2, line_j1, line_j2):
    try:
        return pose_from_two_lines(line_i1, line_i2, line_j1, line_j2)
    except ValueError:
        return np.full(3, np.nan)


def _pose_case(label, li, pose, tj_shift=(0.0, 0.0)):
    rj, tj = transform_lines(li[:, 0], li[:, 1], pose)
    tj = tj + np.asarray(tj_shift)
    return Case(label, {"line_i1": li[0], "line_i2": li[1], "line_j1": np.array([rj[0], tj[0]]),
                        "line_j2": np.array([rj[1], tj[1]])})


def _pose_cases(rng):
    cases = []
    for k in range(2):
        t1 = rng.uniform(-1.5, 1.5)
        li = np.array([[rng.uniform(-10, 10), t1], [rng.uniform(-10, 10), t1 + rng.uniform(0.5, 2.6)]])
        cases.append(_pose_case(f"random pose {k + 1}", li, np.array([*rng.normal(0, 1.5, 2), rng.normal(0, 0.2)])))
    cases.append(_pose_case("lines near θ = ±90°, turning past -90°", np.array([[6.0, np.radians(-87.0)],
                                                                               [2.0, np.radians(10.0)]]),
                            np.array([0.3, 0.8, np.radians(6.0)])))
    cases.append(_pose_case("parallel lines: no pose, (nan, nan, nan)", np.array([[6.0, 0.4], [-2.0, 0.4]]),
                            np.array([0.5, 0.5, 0.1])))
    cases.append(_pose_case("lines only 10° apart (< 20°): (nan, nan, nan)", np.array([[6.0, 0.4], [-2.0, 0.575]]),
                            np.array([0.5, 0.5, 0.1])))
    cases.append(_pose_case("the angle between the lines changed by 5° (> 2°): (nan, nan, nan)",
                            np.array([[6.0, 0.4], [-2.0, 1.9]]), np.array([0.5, 0.5, 0.1]),
                            (0.0, np.radians(5.0))))
    return cases


register(Task("07.hough_votes", "Task 1, the polar Hough accumulator", _hough_reference, _hough_cases,
              "Check the θ range (half a turn), the number of rho cells on each side of zero, "
              "rounding to the nearest cell, and which points vote (the range must be positive "
              "and within the maximum).",
              compare=allclose(0.0, 0.0), points=3))
register(Task("07.find_peaks", "Task 2, peaks above H_min", _peaks_reference, _peaks_cases,
              "A peak needs at least H_min votes and no more-voted neighbour; at the θ = ±90° "
              "seam the neighbouring column has rho of opposite sign. Return the peaks strongest "
              "first.", compare=allclose(1e-12, 1e-12),
              points=3))
register(Task("07.transform_lines", "Task 3, lines seen from the next pose",
              lambda rho, theta_rad, pose: transform_lines(rho, theta_rad, pose), _transform_cases,
              "A line's angle shifts by the rotation, and its distance by the translation's "
              "component along the line's normal before the turn; do not wrap the angle.", compare=allclose(1e-12, 1e-12)))
register(Task("07.pose_from_two_lines", "Task 4, the pose change from two lines", _pose_reference, _pose_cases,
              "The rotation comes from one line's angle change and the translation from the two "
              "lines' distance changes; when the lines are nearly parallel, or the angle between "
              "them changed, no reliable pose exists, so say so rather than return a number.", compare=allclose(1e-9, 1e-9), points=3))


def _explore_accumulator():
    from .experiments import hough_scene_scan

    scan = hough_scene_scan(EXPLORE_POSE_INDEX, rng=2010)
    return hough_polar(scan.bearings_rad[scan.valid], scan.ranges[scan.valid], delta_rho=1.0,
                       delta_theta_rad=np.radians(1.0))


def _h_min_losing_line() -> float:
    acc = _explore_accumulator()
    for h in range(1, int(acc.H.max()) + 2):
        if len(find_peaks(acc, H_min=h)) <= EXPLORE_LINE:
            return float(h)
    return float("nan")


#: Exploration 2: the seeds whose runs span the accepted range of lost steps, and H_min.
LOST_SEEDS = tuple(range(2010, 2016))
LOST_H_MIN = 40


@lru_cache(maxsize=1)
def lost_runs() -> tuple:
    """Exploration 2's run (121 poses, σ = 0.1 cell, no ICP, H_min = 40) for each seed of :data:`LOST_SEEDS`.

    Returns
    -------
    tuple of numpy.ndarray
        Each run's ``lost`` flags, shape (121,).
    """
    from ..studies.hough import run_sim_slam

    return tuple(run_sim_slam(121, range_std_cells=0.1, with_icp=False, H_min=LOST_H_MIN, rng=seed,
                              progress=False).slam.lost for seed in LOST_SEEDS)


def _lost_steps() -> float:
    return float(lost_runs()[0].sum())


@lru_cache(maxsize=1)
def independent_lost_counts() -> tuple[tuple[int, int], ...]:
    """Exploration 2 independently: per seed, the steps that cannot have a pose from lines (no slamlab.hough code).

    A pose change needs two lines seen in the step's scan and in its reference scan, and after a
    lost step the reference is the scan before; so a step is lost when its scan, or the scan before
    it, has fewer than two lines of at least H_min votes (:func:`independent_line_votes` on the
    run's own scans, :func:`~slamlab.lab.experiments.hough_run_scans`).

    Returns
    -------
    tuple of tuple of int
        Per seed of :data:`LOST_SEEDS`: ``(steps whose scan has < 2 lines, steps whose scan or the
        previous one has < 2 lines)``.
    """
    from .experiments import hough_run_scans

    out = []
    for seed in LOST_SEEDS:
        n = np.array([independent_line_votes(s.bearings_rad[s.valid & (s.ranges > 0)],
                                             s.ranges[s.valid & (s.ranges > 0)], H_min=LOST_H_MIN).size
                      for s in hough_run_scans(121, range_std_cells=0.1, rng=seed)])
        few = n < 2
        out.append((int(few[1:].sum()), int((few[1:] | few[:-1]).sum())))
    return tuple(out)


def lost_over_seeds() -> tuple[float, float]:
    """Exploration 2's range: fewest and most lost steps over :data:`LOST_SEEDS` by :func:`independent_lost_counts`.

    Returns
    -------
    tuple of float
        ``(lo, hi)`` lost steps.
    """
    n = [hi for _, hi in independent_lost_counts()]
    return float(min(n)), float(max(n))


def _seeded_lost() -> float:
    """The independent count for the question's seed (the first of :data:`LOST_SEEDS`)."""
    return float(independent_lost_counts()[0][1])


def independent_line_votes(bearings_rad, ranges, *, window: int = 3, H_min: int = 1,
                           n_lines: int | None = None) -> np.ndarray:
    """Votes of the scan's lines, strongest first, from a plain numpy accumulator (no slamlab.hough code).

    Every point ``(x, y)`` votes once per 1° θ in [-90°, 90°) for ``rho = x cos θ + y sin θ``
    rounded to the nearest cell; a line is a cell no 3×3 neighbour beats (θ = -90° borders θ = 89°
    with rho negated), and going down by votes a line within ``window`` cells and degrees of a
    stronger one (across the seam too) is the same line (004 §Hough SLAM; the independent check
    of Exploration 1). Only lines of at least ``H_min`` votes are returned: whether a line merges
    depends only on stronger ones, so the count above ``H_min`` is the same as without it (and
    fast: a scan has thousands of weak maxima).

    Parameters
    ----------
    bearings_rad, ranges : array_like, shape (n,)
        The valid beams' directions [rad] and ranges [cells].
    window : int
        Suppression window, in rho cells and degrees.
    H_min : int
        Fewest votes of a returned line.
    n_lines : int, optional
        Stop after the ``n_lines`` strongest lines (exact too: a line depends only on stronger ones).

    Returns
    -------
    numpy.ndarray of int
        The lines' votes, strongest first.
    """
    b, r = np.asarray(bearings_rad, float), np.asarray(ranges, float)
    x, y = r * np.cos(b), r * np.sin(b)
    th = np.radians(np.arange(-90, 90))
    R = int(np.ceil(r.max()))
    rho = np.floor(np.outer(x, np.cos(th)) + np.outer(y, np.sin(th)) + 0.5).astype(int) + R
    H = np.zeros((2 * R + 1, th.size), int)
    np.add.at(H, (rho, np.broadcast_to(np.arange(th.size), rho.shape)), 1)
    Hp = np.full((H.shape[0] + 2, H.shape[1] + 2), -1)
    Hp[1:-1, 1:-1], Hp[1:-1, 0], Hp[1:-1, -1] = H, H[::-1, -1], H[::-1, 0]  # the seam: (rho, -90°) ~ (-rho, 90°)
    n0, n1 = H.shape
    nb = np.max([Hp[1 + i:1 + i + n0, 1 + j:1 + j + n1] for i in (-1, 0, 1) for j in (-1, 0, 1) if i or j], axis=0)
    h0 = max(int(H_min), 1)
    cand = np.argwhere((nb <= H) & (h0 <= H))
    kept: list[tuple[int, int, int]] = []
    for i, j in cand[np.argsort(-H[cand[:, 0], cand[:, 1]], kind="stable")]:
        p, t = int(i) - R, int(j) - 90
        if not any((abs(t - u) <= window and abs(p - q) <= window)
                   or (abs(abs(t - u) - 180) <= window and abs(p + q) <= window) for q, u, _ in kept):
            kept.append((p, t, int(H[i, j])))
            if n_lines is not None and len(kept) >= n_lines:
                break
    return np.array([v for _, _, v in kept], dtype=int)


@lru_cache(maxsize=1)
def independent_h_min() -> float:
    """Exploration 1 independently: one vote above the third line's votes of :func:`independent_line_votes`.

    Returns
    -------
    float
        The smallest H_min that leaves at most ``EXPLORE_LINE`` lines.
    """
    from .experiments import hough_scene_scan

    scan = hough_scene_scan(EXPLORE_POSE_INDEX, rng=2010)
    return float(independent_line_votes(scan.bearings_rad[scan.valid], scan.ranges[scan.valid],
                                        n_lines=EXPLORE_LINE + 1)[EXPLORE_LINE] + 1)


def _raw_third_peak_h_min() -> float:
    """The misconception: the third local maximum before merging duplicates, plus one."""
    from .experiments import hough_scene_scan

    scan = hough_scene_scan(EXPLORE_POSE_INDEX, rng=2010)
    votes = independent_line_votes(scan.bearings_rad[scan.valid], scan.ranges[scan.valid], window=0,
                                   n_lines=EXPLORE_LINE + 1)
    return float(votes[EXPLORE_LINE] + 1)


register(ExplorationTask(
    "07.explore.h_min",
    "Exploration 1: the smallest H_min at which the third line of the scan at pose 20 is lost",
    _h_min_losing_line,
    accepted=lambda: (independent_h_min(),) * 2,
    why="one integer from an independent plain-numpy accumulator (1 cell × 1°, nearest-cell rounding) and peak "
        "finder (3×3 local maxima across the θ = ±90° seam, duplicates within 3 cells / 3° merged into the "
        "stronger line): the third line's votes + 1. Votes are integers and a peak needs H ≥ H_min, so the third "
        "line is kept up to its vote count and lost one above it; the reference accumulator differs from the "
        "library's by one vote in a few cells (rounding of half-cell ties), none of them the third line's peak.",
    hint="H_min is the least number of votes a peak needs; the third line (by votes) disappears once H_min exceeds "
         "what it got. The question asks for the first H_min with at most two lines left.",
    more="Look at the votes of the strongest peaks and at how the peak finder compares them with H_min.",
    wrong=(WrongAnswer("the last H_min keeping three lines", lambda: independent_h_min() - 1.0,
                       hint="at that H_min the third line is still found: it is the last value that keeps it, not "
                            "the first that loses it."),
           WrongAnswer("a line counted twice", _raw_third_peak_h_min,
                       hint="that removes a peak that is not a third line: one line can give two local maxima "
                            "(neighbouring cells, or both sides of the θ = ±90° seam), which the peak finder merges."))))
register(ExplorationTask(
    "07.explore.lost_steps",
    "Exploration 2: lost steps of Hough SLAM on 004's path with H_min = 40",
    _lost_steps, accepted=lost_over_seeds,
    why="the fewest to the most lost steps over six seeds (2010-2015), each counted independently of the "
        "library's SLAM: a pose change needs two lines seen in the step's scan and in its reference, and after a "
        "lost step the reference is the scan before, so a step is lost when its scan or the previous one has fewer "
        "than two lines of >= 40 votes, counted with the plain-numpy accumulator and peak finder of Exploration 1 "
        "on the run's own scans. The count equals the library's lost steps for every seed (72-75; the scans alone "
        "without two lines give 70-72); the noise and odometry are random, so a run with another seed lands "
        "in this range.",
    hint="a step is lost when no pose can be computed from lines and the step falls back on odometry; count the "
         "lost steps of the whole run with only H_min changed.",
    more="Count steps, not lines or a fraction of the run; a step needs usable lines in two scans.",
    wrong=(WrongAnswer("tracked steps", lambda: 120.0 - _seeded_lost(),
                       hint="that is the number of steps with a pose from lines: the question asks for the lost "
                            "ones."),
           WrongAnswer("a fraction", lambda: _seeded_lost() / 120.0, atol=0.01,
                       hint="that looks like a fraction of the run: the question asks for a count of steps."),
           WrongAnswer("scans without two lines", lambda: float(independent_lost_counts()[0][0]),
                       hint="that looks like the scans with fewer than two lines: a step also fails when the "
                            "scan before it had too few, as both scans must share two lines."))))
