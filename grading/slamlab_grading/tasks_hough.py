"""Lab 07 (Hough SLAM, 004): the tasks and the library functions they are checked against."""

from __future__ import annotations

import math
from functools import cache

import numpy as np

from slamlab.hough import HoughAccumulator, find_peaks, hough_polar, pose_from_two_lines, transform_lines
from slamlab.lab.compare import allclose

from .core import Case, ExplorationTask, Task, WrongAnswer, register

#: Exploration 1's pose index on 004's path and the line (0-based, by votes) whose loss is asked for.
EXPLORE_POSE_INDEX = 20
EXPLORE_LINE = 2
#: Exploration 1's seed (the lab's SEED; the scan of Task 1's demo).
EXPLORE_SEED = 2010
#: Exploration 2: the run's seed (the lab's SEED) and H_min.
LOST_SEED = 2010
LOST_H_MIN = 40
#: The 30 seeds on which the tests check the explorations' misconceptions and independent counts.
CHECK_SEEDS = tuple(range(2010, 2040))


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
              "component along the line's normal before the turn; do not wrap the angle.", compare=allclose(1e-12, 1e-12),
              points=2))
register(Task("07.pose_from_two_lines", "Task 4, the pose change from two lines", _pose_reference, _pose_cases,
              "The rotation comes from one line's angle change and the translation from the two "
              "lines' distance changes; when the lines are nearly parallel, or the angle between "
              "them changed, no reliable pose exists, so say so rather than return a number.", compare=allclose(1e-9, 1e-9), points=3))


def _explore_accumulator():
    from .experiments import hough_scene_scan

    scan = hough_scene_scan(EXPLORE_POSE_INDEX, rng=EXPLORE_SEED)
    return hough_polar(scan.bearings_rad[scan.valid], scan.ranges[scan.valid], delta_rho=1.0,
                       delta_theta_rad=np.radians(1.0))


def _h_min_losing_line() -> float:
    acc = _explore_accumulator()
    for h in range(1, int(acc.H.max()) + 2):
        if len(find_peaks(acc, H_min=h)) <= EXPLORE_LINE:
            return float(h)
    return float("nan")


@cache
def independent_lost_count(seed: int = LOST_SEED, H_min: int = LOST_H_MIN) -> tuple[int, int]:
    """Exploration 2 independently: the steps of one run that cannot have a pose from lines (no slamlab.hough code).

    A pose change needs two lines seen in the step's scan and in its reference scan, and after a
    lost step the reference is the scan before; so a step is lost when its scan, or the scan before
    it, has fewer than two lines of at least H_min votes (:func:`independent_line_votes` on the
    run's own scans, :func:`~slamlab_grading.experiments.hough_run_scans`).

    Parameters
    ----------
    seed : int
        The run's seed.
    H_min : int
        Fewest votes of a line.

    Returns
    -------
    tuple of int
        ``(steps whose scan has < 2 lines, steps whose scan or the previous one has < 2 lines)``.
    """
    from .experiments import hough_run_scans

    n = np.array([independent_line_votes(s.bearings_rad[s.valid & (s.ranges > 0)],
                                         s.ranges[s.valid & (s.ranges > 0)], H_min=H_min, n_lines=2).size
                  for s in hough_run_scans(121, range_std_cells=0.1, rng=seed)])
    few = n < 2
    return int(few[1:].sum()), int((few[1:] | few[:-1]).sum())


def lost_range() -> tuple[float, float]:
    """Exploration 2's range: the independent count of the question's seed, ± 1 step.

    Returns
    -------
    tuple of float
        ``(lo, hi)`` lost steps.
    """
    n = independent_lost_count()[1]
    return float(n - 1), float(n + 1)


def _lost_steps() -> float:
    """The library's run of the question's seed: its lost steps."""
    from slamlab.studies.hough import run_sim_slam

    return float(run_sim_slam(121, range_std_cells=0.1, with_icp=False, H_min=LOST_H_MIN, rng=LOST_SEED,
                              progress=False).slam.lost.sum())


def independent_line_votes(bearings_rad, ranges, *, window: int = 3, H_min: int = 1,
                           n_lines: int | None = None, rho_offset: float = 0.5) -> np.ndarray:
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
    rho_offset : float
        Added to rho before flooring: 0.5 rounds to the nearest cell (Task 1), 0 floors (a misconception).

    Returns
    -------
    numpy.ndarray of int
        The lines' votes, strongest first.
    """
    b, r = np.asarray(bearings_rad, float), np.asarray(ranges, float)
    x, y = r * np.cos(b), r * np.sin(b)
    th = np.radians(np.arange(-90, 90))
    R = int(np.ceil(r.max())) + 1
    rho = np.floor(np.outer(x, np.cos(th)) + np.outer(y, np.sin(th)) + rho_offset).astype(int) + R
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


def _scene_points(seed: int):
    from .experiments import hough_scene_scan

    scan = hough_scene_scan(EXPLORE_POSE_INDEX, rng=seed)
    return scan.bearings_rad[scan.valid], scan.ranges[scan.valid]


@cache
def independent_h_min(seed: int = EXPLORE_SEED, *, window: int = 3, rho_offset: float = 0.5) -> float:
    """Exploration 1 independently: one vote above the third line's votes of :func:`independent_line_votes`.

    Parameters
    ----------
    seed : int
        The scan's seed (the question's is :data:`EXPLORE_SEED`).
    window : int
        The merging window (3: the question's; 0: no merging, a misconception).
    rho_offset : float
        0.5: nearest-cell rounding (the question's); 0: flooring (a misconception).

    Returns
    -------
    float
        The smallest H_min that leaves at most ``EXPLORE_LINE`` lines.
    """
    b, r = _scene_points(seed)
    votes = independent_line_votes(b, r, window=window, n_lines=EXPLORE_LINE + 1, rho_offset=rho_offset)
    return float(votes[EXPLORE_LINE] + 1)


register(ExplorationTask(
    "07.explore.h_min",
    "Exploration 1: the smallest H_min at which at most two lines of the scan at pose 20 remain (Task 1's "
    "accumulator with Δrho = 1 cell and Δθ = 1°, Task 2's peaks, peaks within 3 cells and 3° of a stronger one "
    "merged)",
    _h_min_losing_line,
    accepted=lambda: (independent_h_min(),) * 2,
    why="one integer, the third line's votes + 1, from an independent plain-numpy accumulator (1 cell × 1°, "
        "nearest-cell rounding as Task 1 fixes it) and peak finder (3×3 local maxima across the θ = ±90° seam, "
        "peaks within 3 cells / 3° of a stronger one merged, as the question fixes it); OpenCV's "
        "HoughLinesPointSet with the same merging and the library's accumulator and peak finder give the same "
        "number (tests/lab/test_check_hough.py). The question fixes the seed, the binning and the merging "
        "because each moves the answer: other seeds of the same scan give 22-25 (seeds 2010-2039), flooring rho "
        "gives 33, and the lab's Task 2 peaks without merging give 51-55 (a wall split into two maxima).",
    hint="H_min is the least number of votes a line needs; count the lines left after merging, as the question "
         "defines them, while H_min grows.",
    more="Look at the votes of the three strongest lines, and check that no two of them are the same wall.",
    points=2, unit="an H_min (a number of votes)", bounds=(1.0, math.inf), integer=True,
    answered_by=("slamlab.hough.find_peaks", "slamlab.hough.lines.find_peaks"),
    wrong=(WrongAnswer("a line counted twice", lambda: independent_h_min(window=0),
                       hint="that removes a peak that is not a third line: one wall can give two local maxima "
                            "(neighbouring cells, or both sides of the θ = ±90° seam), which the question merges "
                            "into one line."),
           WrongAnswer("rho floored into cells", lambda: independent_h_min(rho_offset=0.0),
                       hint="that looks like an accumulator whose votes go to the cell below rho, not the nearest "
                            "one: Task 1 rounds every vote to the nearest cell, and the question uses Task 1's "
                            "accumulator."))))
register(ExplorationTask(
    "07.explore.lost_steps",
    "Exploration 2: lost steps of 004's simulated Hough SLAM run (121 poses, seed 2010, range σ 0.1 cells, no "
    "ICP) with H_min = 40",
    _lost_steps, accepted=lost_range,
    why="the question's seed (2010) counted independently of the library's SLAM, ± 1 step: a pose change needs "
        "two lines seen in the step's scan and in its reference, and after a lost step the reference is the scan "
        "before, so a step is lost when its scan or the previous one has fewer than two lines of >= 40 votes, "
        "counted with Exploration 1's plain-numpy accumulator and peak finder on the run's own scans: 74, equal to "
        "the library's lost steps (the two agree on 29 of seeds 2010-2039; 2028: 74 against 75). ± 1 for a vote "
        "shifted on another machine: two scans of the run have a second line of exactly 40 votes (H_min 39 or 41 "
        "gives 72 or 75). The seed is fixed because it matters: seeds 2010-2039 give 71-75, and counting only "
        "the scans with fewer than two lines gives 69-73, so with any seed allowed the two could not be told "
        "apart.",
    hint="a step is lost when no pose can be computed from lines and the step falls back on odometry; count the "
         "lost steps of the whole run of the question's seed, with only H_min changed.",
    more="Count steps, not lines or a fraction of the run; a step needs usable lines in two scans.",
    points=2, unit="a number of steps", bounds=(0.0, 120.0), integer=True,
    answered_by=("slamlab.studies.hough.run_sim_slam", "slamlab.studies.hough.experiments.run_sim_slam"),
    wrong=(WrongAnswer("tracked steps", lambda: 120.0 - independent_lost_count()[1],
                       hint="that is the number of steps with a pose from lines: the question asks for the lost "
                            "ones."),)))
