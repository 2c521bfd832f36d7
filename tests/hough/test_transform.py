"""Polar and classic Hough transforms (004 eq. (5)-(8)) against brute force, OpenCV and 004's example."""

import math

import cv2
import numpy as np
import pytest

import slamlab.hough as h


def brute_polar(phi, r, d_rho, d_theta, r_max):
    """The definition, one point and one θ at a time."""
    n_half = math.ceil(r_max / d_rho - 1e-9)
    n_theta = round(math.pi / d_theta)
    H = np.zeros((2 * n_half + 1, n_theta), dtype=int)
    for p, rr in zip(phi, r, strict=True):
        if not 0 < rr <= r_max:
            continue
        for k in range(n_theta):
            theta = -math.pi / 2 + k * d_theta
            rho = rr * math.cos(theta - p)
            H[math.floor(rho / d_rho + 0.5) + n_half, k] += 1
    return H


def test_polar_matches_definition():
    rng = np.random.default_rng(3)
    phi = rng.uniform(-math.pi, math.pi, 60)
    r = rng.uniform(0.1, 9.0, 60)
    acc = h.hough_polar(phi, r, delta_rho=0.37, delta_theta_rad=math.radians(2.0), r_max=9.5)
    assert np.array_equal(acc.H, brute_polar(phi, r, 0.37, math.radians(2.0), 9.5))
    assert acc.H.sum() == 60 * 90  # every point votes once per θ


def test_polar_axes_and_004_example():
    phi, r = h.line_scan(10.0, math.radians(45.0), r_max=16.0)
    acc = h.hough_polar(phi, r, r_max=16.0)
    assert acc.size_theta_rho == (180, 33)
    assert acc.rho[0] == -16.0
    assert acc.rho[-1] == 16.0
    assert np.degrees(acc.theta_rad[[0, -1]]).round(9).tolist() == [-90.0, 89.0]
    # every point of the line votes for (10, 45°)
    assert acc.H[list(acc.rho).index(10.0), 135] == phi.size


def test_classic_size_matches_matlab_hough():
    # Matlab's hough: nrho = 2·ceil(D/Δrho) + 1 with D the diagonal: 33×33 -> 93 (004's 180×93)
    acc = h.hough_classic(np.ones((33, 33), np.uint8))
    assert acc.size_theta_rho == (180, 93)
    acc2 = h.hough_classic(np.ones((10, 20), np.uint8), delta_rho=0.5)
    assert acc2.H.shape[0] == 2 * math.ceil(math.hypot(9, 19) / 0.5) + 1


def test_classic_equals_polar_on_lattice_points():
    # points on whole pixels: the classic transform about the corner, shifted by the centre, is the polar one
    rng = np.random.default_rng(5)
    xy = rng.integers(-12, 13, size=(40, 2)).astype(float)
    xy = xy[np.hypot(xy[:, 0], xy[:, 1]) > 0]
    phi, r = np.arctan2(xy[:, 1], xy[:, 0]), np.hypot(xy[:, 0], xy[:, 1])
    img, c = h.rasterise_scan(phi, r, r_max=float(r.max()))
    classic = h.hough_classic(img)
    rows, cols = np.nonzero(img)
    assert classic.H.sum() == rows.size * 180
    assert sorted(zip(cols - c, rows - c, strict=True)) == sorted({(int(a), int(b)) for a, b in xy})
    # one line through lattice points, found by both
    line_pts = np.array([[k, 5.0] for k in range(-10, 11)])
    phi, r = np.arctan2(line_pts[:, 1], line_pts[:, 0]), np.hypot(line_pts[:, 0], line_pts[:, 1])
    img, c = h.rasterise_scan(phi, r, r_max=16.0)
    pc = h.find_peaks(h.hough_classic(img), 15, max_lines=1)
    pp = h.find_peaks(h.hough_polar(phi, r, r_max=16.0), 15, max_lines=1)
    rc, tc = h.canonical_lines(*h.lines_about_centre(pc.rho, pc.theta_rad, c))
    rp, tp = h.canonical_lines(pp.rho, pp.theta_rad)
    assert np.allclose(np.abs(rp), 5.0)
    assert np.allclose(np.abs(tp), math.pi / 2)
    # the classic peak is read at image-corner resolution; about the centre it is within one bin
    assert abs(abs(float(rc[0])) - 5.0) <= 0.5
    assert abs(abs(float(tc[0])) - math.pi / 2) <= math.radians(1.0)


def test_strongest_line_agrees_with_opencv():
    rng = np.random.default_rng(11)
    for rho, theta_deg in ((20.0, 30.0), (35.0, -60.0), (12.0, 0.0)):
        phi, r = h.line_scan(rho, math.radians(theta_deg), r_max=60.0, delta_phi_rad=math.radians(0.25))
        r = r + rng.normal(0, 0.05, r.size)
        img, c = h.rasterise_scan(phi, r, r_max=60.0)
        ours = h.find_peaks(h.hough_polar(phi, r, r_max=60.0), 20, max_lines=1)
        lines = cv2.HoughLines(img, 1, math.pi / 180, 20)
        rho_cv, theta_cv = lines[0, 0]
        # OpenCV: origin at pixel (0, 0), rows grow with y as in rasterise_scan, θ in [0, π)
        rc, tc = h.canonical_lines(*h.lines_about_centre(np.array([rho_cv]), np.array([theta_cv]), c))
        d_rho, d_theta = h.line_difference(ours.rho, ours.theta_rad, rc, tc)
        assert abs(float(d_rho[0])) <= 1.5
        assert abs(math.degrees(float(d_theta[0]))) <= 1.5
        d_rho, d_theta = h.line_difference(ours.rho, ours.theta_rad, rho, math.radians(theta_deg))
        assert abs(float(d_rho[0])) <= 0.75
        assert abs(math.degrees(float(d_theta[0]))) <= 1.0


def test_lines_about_centre_round_trip():
    # the line x = 26 in pixels is x = 10 about the centre pixel 16
    rho, theta = h.lines_about_centre([26.0, 16 * math.sqrt(2) + 3.0], [0.0, math.pi / 4], 16)
    assert np.allclose(rho, [10.0, 3.0])
    assert np.allclose(theta, [0.0, math.pi / 4])


def test_cost_formulas():
    assert h.hough_cost(n_points=100) == 100 * 180
    assert h.hough_cost(n_points=100, delta_theta_rad=math.radians(0.5)) == 100 * 360
    assert h.hough_cost(r_max=16.0, delta_r=0.5) == (32**2) * 180


def test_theta_axis():
    assert h.theta_axis(math.radians(1.0)).size == 180
    with pytest.raises(ValueError, match="must divide 180 degrees; got 7"):
        h.theta_axis(math.radians(7.0))


def test_line_scan_is_exact():
    phi, r = h.line_scan(4.0, 0.3, r_max=20.0)
    x, y = r * np.cos(phi), r * np.sin(phi)
    assert np.allclose(x * math.cos(0.3) + y * math.sin(0.3), 4.0)
    assert r.max() <= 20.0


def test_zero_ranges_do_not_vote():
    acc = h.hough_polar([0.0, 1.0], [0.0, 2.0], r_max=3.0)
    assert acc.H.sum() == 180


@pytest.mark.parametrize(
    ("call", "exc", "match"),
    [
        (lambda: h.hough_polar([0.0, 1.0], [1.0]), ValueError, "same length; got 2 and 1"),
        (lambda: h.hough_polar([0.0], [np.nan]), ValueError, "`ranges` must be finite"),
        (lambda: h.hough_polar([0.0], [-1.0]), ValueError, "`ranges` must be >= 0"),
        (lambda: h.hough_polar([[0.0]], [[1.0]]), ValueError, "`bearings_rad` must be 1-dimensional"),
        (lambda: h.hough_polar([0.0], [1.0], delta_rho=0), ValueError, "`delta_rho` must be > 0"),
        (lambda: h.hough_polar(["a"], [1.0]), TypeError, "`bearings_rad` must be a numeric array"),
        (lambda: h.hough_classic(np.zeros((0, 3))), ValueError, "`image` must not be empty"),
        (lambda: h.hough_classic(np.zeros(5)), ValueError, r"`image` must have shape \(H, W\)"),
        (lambda: h.rasterise_scan([0.0], [1.0], cell=-1.0), ValueError, "`cell` must be > 0"),
        (lambda: h.hough_cost(), ValueError, "exactly one of `n_points`"),
        (lambda: h.line_scan(-1.0, 0.0, r_max=5.0), ValueError, "`rho` must be > 0"),
        (lambda: h.lines_about_centre([1.0], [0.0], -1), ValueError, "`centre_px` must be >= 0"),
    ],
)
def test_bad_input(call, exc, match):
    with pytest.raises(exc, match=match):
        call()


@pytest.mark.parametrize("n_points", [0, 1, 15, 20000])
def test_polar_blocks_do_not_change_votes(n_points):
    """Votes from blocked matrix products over θ rows (issue 17) equal the whole-array elementwise count."""
    rng = np.random.default_rng(n_points)
    phi = rng.uniform(-math.pi, math.pi, n_points)
    r = rng.uniform(0.0, 12.0, n_points)
    acc = h.hough_polar(phi, r, delta_rho=0.05, r_max=10.0)
    keep = (r > 0) & (r <= 10.0)
    x, y = r[keep] * np.cos(phi[keep]) / 0.05, r[keep] * np.sin(phi[keep]) / 0.05
    idx = np.multiply.outer(x, np.cos(acc.theta_rad)) + np.multiply.outer(y, np.sin(acc.theta_rad))
    idx += 200.5 + 401 * np.arange(180)
    H = np.bincount(idx.astype(np.intp).ravel(), minlength=401 * 180).reshape(180, 401).T
    assert np.array_equal(acc.H, H)
    assert acc.H.sum() == keep.sum() * 180
