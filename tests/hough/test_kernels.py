"""The compiled Hough kernels (issue 25) give the numpy path's results bit for bit."""

import math
from fractions import Fraction

import numpy as np
import pytest

import slamlab.hough as h
from slamlab import sim
from slamlab.hough import _kernels
from slamlab.hough.lines import _greedy_keep


def both(monkeypatch, fn, *args, **kwargs):
    """``fn(*args, **kwargs)`` on the numpy path (SLAMLAB_NO_NUMBA=1) and on the compiled one."""
    monkeypatch.setenv("SLAMLAB_NO_NUMBA", "1")
    ref = fn(*args, **kwargs)
    monkeypatch.delenv("SLAMLAB_NO_NUMBA")
    return ref, fn(*args, **kwargs)


def assert_same_lines(a, b):
    for name in ("rho", "theta_rad", "votes"):
        x, y = getattr(a, name), getattr(b, name)
        assert x.dtype == y.dtype
        assert np.array_equal(x, y), name


def sim_scans(n_scans=3, cell_m=0.05, rng=0):
    """Scans of the test room at 5 cm cells, 1081 beams over 270°, 1 cm noise (as bench_hough.py)."""
    room = sim.test_room_200()
    rng = np.random.default_rng(rng)
    rf = sim.Rangefinder(n_beams=1081, fov_rad=math.radians(270.0), max_range_cells=600.0, range_std_cells=0.2,
                         quantum_cells=0.0)
    out = []
    for p in sim.random_free_poses(room, n_scans, margin_cells=5, rng=rng):
        s = rf.scan(room, p, rng)
        out.append((s.bearings_rad[s.valid], s.ranges[s.valid] * cell_m))
    return out


def random_scan(rng, n):
    """Random bearings and ranges with zero ranges (no return) and ranges beyond any r_max used."""
    phi = rng.uniform(-math.pi, math.pi, n)
    r = rng.uniform(0.0, 12.0, n)
    r[rng.random(n) < 0.1] = 0.0
    return phi, r


@pytest.mark.parametrize("seed", range(4))
def test_votes_equal_the_numpy_path_on_random_scans(monkeypatch, seed):
    rng = np.random.default_rng(seed)
    for n in (0, 1, 17, 1081, 9000, 17000):  # 17000: one θ row per block in the numpy path
        phi, r = random_scan(rng, n)
        d_rho = float(rng.choice([0.01, 0.05, 0.37, 1.0]))
        d_theta = math.radians(float(rng.choice([0.5, 1.0, 3.0])))
        r_max = float(rng.uniform(1.0, 11.0))
        ref, got = both(monkeypatch, h.hough_polar, phi, r, delta_rho=d_rho, delta_theta_rad=d_theta, r_max=r_max)
        assert got.H.dtype == ref.H.dtype
        assert got.H.strides == ref.H.strides
        assert np.array_equal(got.H, ref.H)


def test_votes_equal_on_sim_scans_and_bin_edges(monkeypatch):
    cases = [(*s, 0.05, 10.0) for s in sim_scans()]
    cases.append((*h.line_scan(10.0, math.radians(45.0), r_max=16.0), 1.0, 16.0))  # 004's example
    # lattice points: rho = x cos θ + y sin θ falls on half-bins (bin edges) at θ = 0° and ±90°
    xy = np.stack(np.meshgrid(np.arange(-8, 9) * 0.25, np.arange(-8, 9) * 0.25), -1).reshape(-1, 2)
    cases.append((np.arctan2(xy[:, 1], xy[:, 0]), np.hypot(xy[:, 0], xy[:, 1]), 0.5, 2.0))
    cases.append((np.arctan2(xy[:, 1], xy[:, 0]), np.hypot(xy[:, 0], xy[:, 1]), 0.5, 2.8))  # r_max cuts
    for phi, r, d_rho, r_max in cases:
        ref, got = both(monkeypatch, h.hough_polar, phi, r, delta_rho=d_rho, r_max=r_max)
        assert np.array_equal(got.H, ref.H)


def test_votes_reproduce_the_fused_multiply_add_of_the_numpy_path(monkeypatch):
    """A point whose bin differs between ``c·x + s·y`` rounded twice and the numpy path's matmul (one fma)."""
    theta = h.theta_axis(math.radians(1.0))
    k = 120  # θ = 30°; with 5000 points the numpy path's blocks are 3 θ rows, so θ_120's offset is n_half + 0.5
    c, s = float(np.cos(theta[k])), float(np.sin(theta[k]))
    n_half = 20

    def search():
        for phi0 in np.linspace(0.5, 0.9, 2001).tolist():
            r0 = 5.5 / math.cos(theta[k] - phi0)  # rho_i(θ_k) = 5.5: on the edge of bins 5 and 6
            for step in range(-12, 13):
                r = r0 + step * 2.0**-50
                x, y = float(np.float64(r) * np.cos(phi0)), float(np.float64(r) * np.sin(phi0))
                fused = float(Fraction(s) * Fraction(y) + Fraction(c * x)) + (n_half + 0.5)
                if int(fused) != int(c * x + s * y + (n_half + 0.5)):
                    return phi0, r
        return None

    found = search()
    assert found is not None  # the test is meaningful: the two roundings give different bins
    phi, r = np.full(5000, 0.1), np.full(5000, 1.0)
    phi[0], r[0] = found
    ref, got = both(monkeypatch, h.hough_polar, phi, r, r_max=float(n_half))
    assert np.array_equal(got.H, ref.H)


def test_bad_ranges_raise_on_both_paths(monkeypatch):
    for bad in (np.nan, np.inf, -1.0):
        for env in ("1", "0"):
            monkeypatch.setenv("SLAMLAB_NO_NUMBA", env)
            with pytest.raises(ValueError, match="`ranges` must be"):
                h.hough_polar([0.0, 1.0], [1.0, bad])


def test_peaks_equal_the_numpy_path(monkeypatch):
    phi_sq = np.linspace(-0.75 * np.pi, 0.75 * np.pi, 1081)
    r_sq = 5.0 / np.maximum(np.abs(np.cos(phi_sq)), np.abs(np.sin(phi_sq)))  # notebook 07's square room
    scans = [(*s, 0.05, 10.0) for s in sim_scans()] + [(phi_sq, r_sq, 0.05, 30.0), (phi_sq, r_sq, 0.5, 30.0)]
    scans.append((*h.line_scan(4.0, -math.pi / 2, r_max=12.0, delta_phi_rad=math.radians(0.5)), 1.0, 12.0))  # wrap
    rng = np.random.default_rng(7)
    scans.append((*random_scan(rng, 3000), 0.2, 12.0))  # noise: many local maxima (over the 600 cap at H_min 2)
    options = [{}, {"max_lines": 3}, {"suppress_rho": 0.0, "suppress_theta_rad": 0.0},
               {"suppress_rho": 0.5, "suppress_theta_rad": math.radians(10.0), "max_lines": 5}]
    for phi, r, d_rho, r_max in scans:
        acc = h.hough_polar(phi, r, delta_rho=d_rho, r_max=r_max)
        for H_min in (2, 20, 60):
            for kw in options:
                ref, got = both(monkeypatch, h.find_peaks, acc, H_min, **kw)
                assert_same_lines(got, ref)


def test_peaks_equal_on_handmade_accumulators(monkeypatch):
    """Flat tops, ties, maxima on the rho ends and across the θ seam, a non-contiguous H (dtype intp)."""
    theta = h.theta_axis(math.radians(1.0))
    rng = np.random.default_rng(3)
    for trial in range(20):
        H = np.zeros((21, 180), dtype=np.intp)
        for _ in range(int(rng.integers(1, 12))):
            i, k = int(rng.integers(0, 21)), int(rng.integers(0, 180))
            H[max(0, i - 1): i + 2, k: k + int(rng.integers(1, 4))] = int(rng.integers(10, 40))
        H[[0, 20], [179, 0]] = 25  # seam and rho ends
        if trial % 2:
            H = np.ascontiguousarray(H.T).T  # θ-major, as hough_polar gives it
        acc = h.HoughAccumulator(H, np.arange(-10.0, 11.0), theta)
        for kw in ({}, {"max_lines": 2}, {"suppress_rho": 0.0, "suppress_theta_rad": 0.0}):
            ref, got = both(monkeypatch, h.find_peaks, acc, 10, **kw)
            assert_same_lines(got, ref)


def test_greedy_keep_kernel_equals_numpy(monkeypatch):
    rng = np.random.default_rng(11)
    monkeypatch.setenv("SLAMLAB_NO_NUMBA", "1")
    for _ in range(30):
        n = int(rng.integers(0, 40))
        theta = rng.choice([-math.pi / 2, math.pi / 2 - 0.01, 0.0, 1.0], n) + rng.normal(0, 0.02, n)
        rho = rng.choice([-3.0, 3.0, 0.0], n) + rng.normal(0, 0.1, n)
        for s_rho, s_theta in ((0.15, 0.05), (0.0, 0.0), (1.0, 0.5)):
            assert np.array_equal(_kernels.greedy_keep(rho, theta, s_rho, s_theta),
                                  _greedy_keep(rho, theta, s_rho, s_theta))
