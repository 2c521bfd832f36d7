"""Peaks, line equivalence, refit, association, line history, pose from lines (004 §Hough SLAM)."""

import math

import numpy as np
import pytest

import slamlab.hough as h
from slamlab.hough.pose import weighted_median


def room_scan(pose, walls=((5.0, 0.0), (4.0, math.pi / 2), (6.0, math.pi), (3.0, -math.pi / 2)), n=720):
    """Exact ranges from ``pose`` (x, y, φ) to a rectangular room given by world lines (rho, θ)."""
    x, y, p = pose
    phi = -math.pi + 2 * math.pi * np.arange(n) / n
    best = np.full(n, np.inf)
    for rho, th in walls:
        # world line seen from the pose: rho_s = rho - (x cos th + y sin th), θ_s = th - p
        rs, ts = rho - (x * math.cos(th) + y * math.sin(th)), th - p
        c = np.cos(phi - ts)
        with np.errstate(divide="ignore"):
            r = np.where(np.abs(c) > 1e-12, rs / np.where(np.abs(c) > 1e-12, c, 1.0), np.inf)
        best = np.minimum(best, np.where(r > 0, r, np.inf))
    return phi, best


def test_find_peaks_finds_the_four_walls():
    phi, r = room_scan((0.5, -0.3, 0.2))
    lines = h.find_peaks(h.hough_polar(phi, r, delta_rho=0.1), 30)
    assert len(lines) == 4
    fine = h.refine_lines(lines, phi, r, band=0.1)
    truth = h.transform_lines(np.array([5.0, 4.0, 6.0, 3.0]), np.array([0, math.pi / 2, math.pi, -math.pi / 2]),
                              (0.5, -0.3, 0.2))
    for rho, th in zip(*truth, strict=True):
        d_rho, d_theta = h.line_difference(fine.rho, fine.theta_rad, rho, th)
        best = np.argmin(np.abs(d_rho) + np.abs(d_theta))
        # exact up to the few corner points of the perpendicular walls inside the 0.1 band
        assert abs(d_rho[best]) < 1e-3
        assert abs(d_theta[best]) < 1e-3


def test_peaks_wrap_around_theta():
    # a line at θ = -90° (y = -4) gives a plateau across the ±90° seam: one line, not two
    phi, r = h.line_scan(4.0, -math.pi / 2, r_max=12.0, delta_phi_rad=math.radians(0.5))
    lines = h.find_peaks(h.hough_polar(phi, r, r_max=12.0), 100)
    assert len(lines) == 1
    d_rho, d_theta = h.line_difference(lines.rho, lines.theta_rad, 4.0, -math.pi / 2)
    assert abs(float(d_rho[0])) <= 0.5
    assert abs(float(d_theta[0])) <= math.radians(1.0)


def test_suppression_keeps_the_line_with_more_points():
    acc = h.HoughAccumulator(np.zeros((21, 180), int), np.arange(-10.0, 11.0), h.theta_axis(math.radians(1.0)))
    acc.H[15, 90] = 50  # (5, 0°)
    acc.H[17, 92] = 40  # (7, 2°): a false neighbour within 3 bins
    acc.H[5, 100] = 30  # (-5, 10°): a separate line
    lines = h.find_peaks(acc, 10)
    assert lines.votes.tolist() == [50, 30]
    assert h.find_peaks(acc, 10, suppress_rho=1.0, suppress_theta_rad=0.01).votes.tolist() == [50, 40, 30]
    assert len(h.find_peaks(acc, 60)) == 0
    assert len(h.find_peaks(acc, 10, max_lines=1)) == 1


def test_refine_matches_svd_total_least_squares():
    rng = np.random.default_rng(7)
    phi = np.radians(np.arange(-30.0, 31.0, 0.5))
    r = 6.0 / np.cos(phi - 0.1) + rng.normal(0, 0.02, phi.size)
    rough = h.Lines(np.array([6.0]), np.array([0.1]), np.array([phi.size]))
    fine = h.refine_lines(rough, phi, r, band=0.5)
    pts = np.column_stack([r * np.cos(phi), r * np.sin(phi)])
    centred = pts - pts.mean(axis=0)
    normal = np.linalg.svd(centred)[2][-1]
    normal *= np.sign(normal[0])
    assert abs(fine.theta_rad[0] - math.atan2(normal[1], normal[0])) < 1e-9
    assert abs(fine.rho[0] - pts.mean(axis=0) @ normal) < 1e-9


def test_refine_max_gap_keeps_the_longest_segment():
    # two collinear segments far apart: only the longer one is fitted
    phi1 = np.radians(np.arange(-20.0, 21.0))
    r1 = 5.0 / np.cos(phi1)
    phi2 = np.radians(np.arange(60.0, 66.0))
    r2 = (5.0 + 0.3) / np.cos(phi2)  # a second, slightly offset wall far along
    phi, r = np.concatenate([phi1, phi2]), np.concatenate([r1, r2])
    rough = h.Lines(np.array([5.0]), np.array([0.0]), np.array([47]))
    fine = h.refine_lines(rough, phi, r, band=0.5, max_gap=1.0)
    assert int(fine.votes[0]) == phi1.size
    assert abs(fine.rho[0] - 5.0) < 1e-9


def test_line_equivalence():
    r, t = h.canonical_lines(np.array([3.0, 3.0]), np.array([math.radians(100.0), math.radians(-100.0)]))
    assert np.allclose(r, [-3.0, -3.0])
    assert np.allclose(np.degrees(t), [-80.0, 80.0])
    d_rho, d_theta = h.line_difference(3.0, math.radians(89.0), -3.0, math.radians(-90.0))
    assert abs(float(d_rho)) < 1e-12
    assert abs(math.degrees(float(d_theta)) + 1.0) < 1e-9


def test_transform_lines_against_moved_points():
    rng = np.random.default_rng(1)
    for _ in range(20):
        rho, th = rng.uniform(-5, 5), rng.uniform(-math.pi, math.pi)
        pose = rng.uniform([-2, -2, -1], [2, 2, 1])
        s = rng.uniform(-10, 10, 5)
        pts_i = np.column_stack([rho * math.cos(th) - s * math.sin(th), rho * math.sin(th) + s * math.cos(th)])
        c, sn = math.cos(pose[2]), math.sin(pose[2])
        pts_j = (pts_i - pose[:2]) @ np.array([[c, -sn], [sn, c]])  # the same points seen from the pose
        rj, tj = h.transform_lines(rho, th, pose)
        assert np.allclose(pts_j @ [math.cos(tj), math.sin(tj)], rj)


@pytest.mark.parametrize("seed", range(10))
def test_pose_from_two_lines_exact(seed):
    rng = np.random.default_rng(seed)
    pose = rng.uniform([-1, -1, -0.5], [1, 1, 0.5])
    ri, ti = rng.uniform(-6, 6, 2), np.array([rng.uniform(-1, 1), 0.0])
    ti[1] = ti[0] + rng.uniform(0.6, 2.5)
    rj, tj = h.transform_lines(ri, ti, pose)
    got = h.pose_from_two_lines((ri[0], ti[0]), (ri[1], ti[1]), (rj[0], tj[0]), (rj[1], tj[1]))
    assert np.allclose(got, pose, atol=1e-12)
    # the same lines written as (-rho, θ ± π) in scan j: align them to scan i first
    rjf, tjf = h.canonical_lines(-rj, tj + math.pi)
    rja, tja = h.align_lines(rjf, tjf, ti + pose[2] * 0 - pose[2])
    got2 = h.pose_from_two_lines((ri[0], ti[0]), (ri[1], ti[1]), (rja[0], tja[0]), (rja[1], tja[1]))
    assert np.allclose(got2, pose, atol=1e-12)


def test_pose_from_lines_least_squares_rejects_an_outlier():
    pose = np.array([0.4, -0.3, 0.05])
    ri = np.array([5.0, 3.0, -2.0, 4.0, -6.0])
    ti = np.array([0.0, 1.6, 0.02, -1.5, 0.8])
    rj, tj = h.transform_lines(ri, ti, pose)
    rj[4] += 0.8  # a line that moved on its own (a door, a person)
    pc = h.pose_from_lines(ri, ti, rj, tj, method="least_squares", rho_tol=0.1)
    assert pc.ok
    assert np.allclose(pc.pose, pose, atol=1e-9)
    assert 4 not in pc.used.tolist()
    two = h.pose_from_lines(ri[:4], ti[:4], rj[:4], tj[:4], method="two_lines")
    assert np.allclose(two.pose, pose, atol=1e-9)


def test_pose_from_lines_reports_failure():
    pc = h.pose_from_lines([1.0, 2.0], [0.0, 0.05], [1.0, 2.0], [0.0, 0.05])
    assert not pc.ok
    assert "no pair" in pc.message


def test_association_follows_a_move_and_uses_parallel_distances():
    old = h.Lines(np.array([1.0, 2.0, 3.0]), np.array([0.0, 0.0, math.pi / 2]), np.ones(3, int))
    # the robot moves 0.5 along x: lines at 1, 2 move to 0.5, 1.5; the peak displacement alone
    # cannot tell 1.5 <- 2 (move 0.5) from 1.5 <- 1 (move 0.5 the other way) ...
    new = h.Lines(np.array([0.5, 1.5, 3.0]), np.array([0.0, 0.0, math.pi / 2]), np.ones(3, int))
    P = h.association_probability(new, old, a=1.0)
    assert P.shape == (3, 3)
    assert np.all((P >= 0) & (P <= 1))
    assert h.associate_lines(P).tolist() == [0, 1, 2]
    # ... with the parallel-distance term the right pairing scores higher than the swapped one
    assert P[1, 1] > 0.5


def test_association_handles_flipped_representation():
    old = h.Lines(np.array([2.0, 5.0]), np.array([math.radians(89.5), math.radians(89.5)]), np.ones(2, int))
    new = h.Lines(np.array([-2.1, -5.1]), np.array([math.radians(-90.0), math.radians(-90.0)]), np.ones(2, int))
    assert h.associate_lines(h.association_probability(new, old, a=0.5)).tolist() == [0, 1]


def test_weighted_median_is_where_half_the_weight_is_reached():
    assert weighted_median([0.3, 0.1, 0.2], [1.0, 1.0, 5.0]) == 0.2
    assert weighted_median([0.3, 0.1, 0.2], [1.0, 1.0, 1.0]) == 0.2
    assert weighted_median([5.0], [2.0]) == 5.0
    with pytest.raises(ValueError, match="`x` and `weights` must have one non-zero length"):
        weighted_median([1.0, 2.0], [1.0])
    with pytest.raises(ValueError, match="`weights` must be >= 0 with a positive sum"):
        weighted_median([1.0, 2.0], [1.0, -1.0])


def test_line_history_matrix():
    hist = h.LineHistory()
    ids0 = hist.add_scan(h.Lines(np.array([1.0, 2.0]), np.array([0.0, 1.5]), np.array([5, 6])), [-1, -1])
    ids1 = hist.add_scan(h.Lines(np.array([0.9, 7.0]), np.array([0.01, 0.5]), np.array([5, 9])), [0, -1])
    assert ids0.tolist() == [0, 1]
    assert ids1.tolist() == [0, 2]
    assert hist.seen.tolist() == [[True, True, False], [True, False, True]]
    assert np.isnan(hist.rho[1, 1])
    assert hist.rho[1, 0] == 0.9
    with pytest.raises(ValueError, match="`match_ids` must be < 3"):
        hist.add_scan(h.Lines(np.array([1.0]), np.array([0.0]), np.array([5])), [7])
    with pytest.raises(ValueError, match="one entry per line"):
        hist.add_scan(h.Lines(np.array([1.0]), np.array([0.0]), np.array([5])), [0, 1])


@pytest.mark.parametrize(
    ("call", "exc", "match"),
    [
        (lambda: h.find_peaks(np.zeros((3, 3)), 1), TypeError, "`acc` must be a HoughAccumulator"),
        (lambda: h.find_peaks(h.hough_polar([0.0], [1.0]), 0), ValueError, "`H_min` must be >= 1"),
        (lambda: h.pose_from_two_lines((1, 0), (2, 0.1), (1, 0), (2, 0.1)), ValueError, "at least 20.0 degrees"),
        (lambda: h.pose_from_two_lines((1, 0), (2, 1.5), (1, 0), (2, 1.0)), ValueError, "must not change"),
        (lambda: h.pose_from_two_lines((1, 0, 3), (2, 1.5), (1, 0), (2, 1.0)), ValueError, r"\(rho, θ\) pairs"),
        (lambda: h.pose_from_lines([1.0], [0.0], [1.0, 2.0], [0.0, 1.0]), ValueError, "must have one length"),
        (lambda: h.pose_from_lines([1.0], [0.0], [1.0], [0.0], method="x"), ValueError, "`method` must be one of"),
        (lambda: h.association_probability([1.0], h.Lines(np.ones(1), np.ones(1), np.ones(1)), a=1.0), TypeError,
         "`new` must be Lines"),
        (lambda: h.association_probability(h.Lines(np.ones(1), np.ones(1), np.ones(1)),
                                           h.Lines(np.ones(1), np.ones(1), np.ones(1)), a=0.0), ValueError,
         "`a` must be > 0"),
        (lambda: h.associate_lines(np.ones(3)), ValueError, "`P` must be 2-dimensional"),
        (lambda: h.refine_lines(h.Lines(np.ones(1), np.ones(1), np.ones(1)), [0.0], [1.0, 2.0]), ValueError,
         "same length"),
        (lambda: h.transform_lines([1.0], [0.0], (1.0, 2.0)), ValueError, "`pose` must"),
    ],
)
def test_bad_input(call, exc, match):
    with pytest.raises(exc, match=match):
        call()


@pytest.mark.parametrize("seed", range(5))
def test_peak_grouping_partition_equals_scipy_connected_components(seed):
    """The flat-top grouping of find_peaks (issue 17: no sparse matrix) = scipy's undirected components."""
    from scipy.sparse import csr_matrix
    from scipy.sparse.csgraph import connected_components

    from slamlab.hough.lines import _components

    rng = np.random.default_rng(seed)
    m = int(rng.integers(1, 60))
    adj = rng.random((m, m)) < 2.0 / m  # sparse and not symmetric
    np.fill_diagonal(adj, True)
    ours = _components(adj)
    _, ref = connected_components(csr_matrix(adj), directed=False)
    # the same partition: labels map one to one
    pairs = set(zip(ours.tolist(), ref.tolist(), strict=True))
    assert len(pairs) == len(set(ours.tolist())) == len(set(ref.tolist()))
    assert ours.max() == len(set(ours.tolist())) - 1
