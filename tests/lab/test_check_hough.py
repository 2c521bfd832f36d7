"""Lab 07 tasks: solutions written from 004's equations pass, typical mistakes fail at the expected case."""

from __future__ import annotations

import math

import numpy as np
import pytest

from slamlab import lab

# --- independent solutions (what a student should write) --------------------------------------------


def hough_votes(bearings_rad, ranges, delta_rho, delta_theta_rad, r_max, *, rounding=None):
    n_theta = round(math.pi / delta_theta_rad)
    theta = -math.pi / 2 + delta_theta_rad * np.arange(n_theta)
    n_half = math.ceil(r_max / delta_rho - 1e-9)
    H = np.zeros((2 * n_half + 1, n_theta), dtype=int)
    keep = (ranges > 0) & (ranges <= r_max)
    for phi, r in zip(bearings_rad[keep], ranges[keep], strict=True):
        rho = r * np.cos(theta - phi) / delta_rho
        i = np.floor(rho + n_half + 0.5).astype(int) if rounding is None else rounding(rho) + n_half
        H[i, np.arange(n_theta)] += 1
    return H


def find_peaks(H, rho, theta_rad, H_min, *, wrap=True):
    n_rho, n_theta = H.shape
    out = []
    for i in range(n_rho):
        for k in range(n_theta):
            if H[i, k] < H_min:
                continue
            best = True
            for di in (-1, 0, 1):
                for dk in (-1, 0, 1):
                    ii, kk = i + di, k + dk
                    if (di == 0 and dk == 0) or not 0 <= ii < n_rho:
                        continue
                    if kk < 0 or kk >= n_theta:
                        if not wrap:
                            continue
                        ii, kk = n_rho - 1 - ii, kk % n_theta
                    best &= H[i, k] >= H[ii, kk]
            if best:
                out.append((H[i, k], rho[i], theta_rad[k]))
    out.sort(key=lambda t: -t[0])
    return (np.array([o[1] for o in out]), np.array([o[2] for o in out]), np.array([o[0] for o in out], float))


def transform_lines(rho, theta_rad, pose):
    dx, dy, dphi = pose
    return rho - (dx * np.cos(theta_rad) + dy * np.sin(theta_rad)), theta_rad - dphi


def pose_from_two_lines(line_i1, line_i2, line_j1, line_j2, *, check_change=True):
    (r1, t1), (r2, t2) = line_i1, line_i2
    (s1, u1), (s2, u2) = line_j1, line_j2
    D = np.sin(t2 - t1)
    change = (t2 - t1) - (u2 - u1)
    change = (change + np.pi) % (2 * np.pi) - np.pi
    if abs(D) < np.sin(np.radians(20.0)) or (check_change and abs(change) > np.radians(2.0)):
        return np.full(3, np.nan)
    d1, d2 = r1 - s1, r2 - s2
    return np.array([(d1 * np.sin(t2) - d2 * np.sin(t1)) / D, (d2 * np.cos(t1) - d1 * np.cos(t2)) / D, t1 - u1])


def _fails_on(task_id, fn, label_start):
    """Whether ``fn`` disagrees with the reference on the (first) case whose label starts with ``label_start``."""
    t = lab.task(task_id)
    case = next(c for c in t.cases(np.random.default_rng(0)) if c.label.startswith(label_start))
    return (t.compare or lab.core.allclose())(t.reference(**case.kwargs), fn(**case.kwargs)) is not None


@pytest.mark.parametrize(("task_id", "fn"), [("07.hough_votes", hough_votes), ("07.find_peaks", find_peaks),
                                             ("07.transform_lines", transform_lines),
                                             ("07.pose_from_two_lines", pose_from_two_lines)])
def test_correct_solutions_pass(task_id, fn):
    res = lab.check(task_id, fn, quiet=True)
    assert res.passed, res.message


def test_hough_mistakes():
    def truncates(**kw):  # int() truncates towards zero instead of rounding to the nearest bin
        return hough_votes(**kw, rounding=lambda x: np.trunc(x).astype(int))

    def keeps_far_points(bearings_rad, ranges, delta_rho, delta_theta_rad, r_max):  # votes beyond r_max
        return hough_votes(bearings_rad, np.minimum(ranges, r_max), delta_rho, delta_theta_rad, r_max)

    assert "case 1 of 4" in lab.check("07.hough_votes", truncates, quiet=True).message
    assert "case 3 of 4 (zero ranges (no return) and ranges beyond r_max" in \
        lab.check("07.hough_votes", keeps_far_points, quiet=True).message


def test_find_peaks_mistakes():
    def no_wrap(**kw):  # θ = -90° and +90° - Δθ are not treated as neighbours
        return find_peaks(**kw, wrap=False)

    def unsorted(**kw):
        r, t, v = find_peaks(**kw)
        return r[::-1], t[::-1], v[::-1]

    assert lab.check("07.find_peaks", no_wrap, quiet=True).status == "failed"
    assert _fails_on("07.find_peaks", no_wrap, "θ wraps at ±90°")  # the edge case alone catches it too
    assert "case 1 of 4" in lab.check("07.find_peaks", unsorted, quiet=True).message


def test_transform_and_pose_mistakes():
    def wraps(rho, theta_rad, pose):  # wraps θ back into [-90°, 90°)
        r, t = transform_lines(rho, theta_rad, pose)
        k = np.floor((t + np.pi / 2) / np.pi)
        return np.where(k % 2 == 0, r, -r), t - k * np.pi

    def sign_flipped(rho, theta_rad, pose):  # rho_j = rho_i + (...)
        return rho + (pose[0] * np.cos(theta_rad) + pose[1] * np.sin(theta_rad)), theta_rad - pose[2]

    def no_angle_check(**kw):
        return pose_from_two_lines(**kw, check_change=False)

    assert lab.check("07.transform_lines", wraps, quiet=True).status == "failed"
    assert _fails_on("07.transform_lines", wraps, "θ leaves [-90°, 90°)")
    assert "case 1 of 4" in lab.check("07.transform_lines", sign_flipped, quiet=True).message
    assert "case 6 of 6 (the angle between the lines changed by 5°" in \
        lab.check("07.pose_from_two_lines", no_angle_check, quiet=True).message


def test_h_min_exploration_independent():
    """OpenCV's point-set Hough transform: the third distinct line's votes + 1 is the accepted H_min."""
    import cv2

    import slamlab as sl
    from slamlab.lab.tasks_hough import independent_h_min

    rf = sl.sim.Rangefinder(n_beams=360, max_range_cells=100.0, range_std_cells=0.1)
    scan = rf.scan(sl.sim.test_room_200(), sl.sim.path_004()[20], rng=2010)
    b, r = scan.bearings_rad[scan.valid], scan.ranges[scan.valid]
    pts = np.column_stack([r * np.cos(b), r * np.sin(b)]).astype(np.float32).reshape(-1, 1, 2)
    R = float(np.ceil(r.max()))
    found = cv2.HoughLinesPointSet(pts, 20, 1, -R, R, 1.0, 0.0, np.pi, np.radians(1.0)).reshape(-1, 3)
    lines = []  # (votes, rho, θ [deg] in [0, 180)), strongest first; a peak within 3 cells / 3° (also across
    for votes, rho, th in found:  # θ = 0/180°, where rho changes sign) of a stronger one is the same line
        t = np.degrees(th)
        if not any((abs(t - u) <= 3 and abs(rho - q) <= 3) or (abs(abs(t - u) - 180) <= 3 and abs(rho + q) <= 3)
                   for _, q, u in lines):
            lines.append((int(votes), rho, t))
    h = lines[2][0] + 1  # a peak needs H >= H_min: the third line goes one vote above its count
    assert h == independent_h_min()
    acc = sl.hough.hough_polar(b, r, delta_rho=1.0, delta_theta_rad=np.radians(1.0))
    assert len(sl.hough.find_peaks(acc, H_min=h)) == 2
    assert len(sl.hough.find_peaks(acc, H_min=h - 1)) == 3
    assert lab.answer("07.explore.h_min", h, quiet=True).passed
    raw = int(found[2, 0]) + 1  # the third raw maximum is the second line again
    for wrong, hint in ((h - 1, "still found"), (raw, "two local maxima")):
        res = lab.answer("07.explore.h_min", wrong, quiet=True)
        assert res.status == "failed"
        assert hint in res.message


def test_exploration_answers():
    """The library's run for the question's seed: its lost steps are the independent count, and accepted."""
    import slamlab as sl
    from slamlab.lab.tasks_hough import independent_lost_counts

    res = sl.studies.hough.run_sim_slam(121, range_std_cells=0.1, with_icp=False, H_min=40, rng=2010)
    assert int(res.slam.lost.sum()) == independent_lost_counts()[0][1]
    assert lab.answer("07.explore.lost_steps", int(res.slam.lost.sum()), quiet=True).passed
    assert lab.answer("07.explore.lost_steps", 0, quiet=True).status == "failed"


def test_lost_steps_exploration_range():
    """The accepted range: per seed, the steps whose scan or the previous one has fewer than two lines of >= 40
    votes by Exploration 1's plain-numpy line finder (no slamlab.hough code); the wrong answers stay outside."""
    from slamlab.lab.tasks_hough import LOST_SEEDS, independent_lost_counts

    counts = independent_lost_counts()
    assert len(counts) == len(LOST_SEEDS)
    assert all(0 < few < lost < 120 for few, lost in counts)  # the step after a scan without two lines is lost too
    lo, hi = min(n for _, n in counts), max(n for _, n in counts)
    assert lo < hi  # the seed matters: one seed's count is not the answer
    assert lab.task("07.explore.lost_steps").accepted_range() == (lo, hi)
    for n in range(lo, hi + 1):
        assert lab.answer("07.explore.lost_steps", n, quiet=True).passed
    few, lost = counts[0]
    for wrong, hint in ((lo - 1, "Hint"), (hi + 1, "Hint"), (120 - lost, "pose from lines"),
                        (lost / 120, "fraction"), (few, "fewer than two lines")):
        res = lab.answer("07.explore.lost_steps", wrong, quiet=True)
        assert res.status == "failed"
        assert hint in res.message
