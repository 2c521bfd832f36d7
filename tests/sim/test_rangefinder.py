"""Scanning rangefinder and odometry against closed-form references (its ray caster: tests/scans/test_raycast.py)."""

import numpy as np
import pytest

from slamlab.geometry import wrap_angle
from slamlab.sim import grid as G
from slamlab.sim import rangefinder as R


def test_beam_angles_layouts():
    np.testing.assert_allclose(R.beam_angles(360), np.radians(np.arange(360)))
    a = R.beam_angles(181, np.pi)
    assert a[0] == pytest.approx(-np.pi / 2)
    assert a[-1] == pytest.approx(np.pi / 2)
    np.testing.assert_allclose(np.diff(a), np.radians(1.0))


def test_noise_and_quantisation():
    g = G.make_grid(201, 201, G.OBSTACLE)
    g[1:200, 1:200] = G.FREE
    rf = R.Rangefinder(n_beams=4000, max_range_cells=300, range_std_cells=0.5, quantum_cells=0.1)
    s = rf.scan(g, [100.0, 100.0, 0.0], rng=1)
    exact, _ = R.cast_rays(g, [100.0, 100.0, 0.0], rf.angles_rad, 300)
    err = s.ranges - exact
    assert abs(err.std() - 0.5) < 0.03
    assert abs(err.mean()) < 0.03
    assert np.allclose(s.ranges * 10, np.round(s.ranges * 10), atol=1e-9)
    # seeded: same scan twice
    assert np.array_equal(s.ranges, rf.scan(g, [100.0, 100.0, 0.0], rng=1).ranges)
    # noise-free, unquantised = exact
    s0 = R.Rangefinder(n_beams=4000, max_range_cells=300, quantum_cells=0).scan(g, [100.0, 100.0, 0.0])
    assert np.array_equal(s0.ranges, exact)


def test_scan_points_land_on_obstacles():
    M = G.measurement_room_200()
    s = R.Rangefinder(n_beams=720, max_range_cells=150, quantum_cells=0).scan(M, [70.0, 30.0, 0.4])
    pts = s.points()
    # step 1e-6 beyond the face: inside the obstacle cell
    th = 0.4 + s.bearings_rad[s.valid]
    inner = pts + 1e-6 * np.column_stack([np.cos(th), np.sin(th)])
    rc = G.world_to_cell(inner)
    assert np.all(M[rc[:, 0], rc[:, 1]] == G.OBSTACLE)


def test_scan_is_the_shared_scan_type():
    from slamlab.scans import Scan

    s = R.Rangefinder(n_beams=8, max_range_cells=50).scan(G.test_room_200(), [70.0, 30.0, 0.4])
    assert isinstance(s, Scan)
    assert (s.unit, s.max_range) == ("cell", 50.0)
    np.testing.assert_array_equal(s.pose, [70.0, 30.0, 0.4])
    assert np.all(s.ranges[~s.valid] == 50.0)  # no return: the range limit


def test_odometry_increments_are_se2_relative_poses():
    from slamlab.geometry import se2_relative

    rng = np.random.default_rng(5)
    P = np.column_stack([rng.uniform(0, 100, (30, 2)), rng.uniform(-np.pi, np.pi, 30)])
    odo = R.simulate_odometry(P)
    for k in range(29):
        np.testing.assert_allclose(odo.true_increments[k], se2_relative(P[k], P[k + 1]), atol=1e-12)
    np.testing.assert_allclose(odo.poses[:, :2], P[:, :2], atol=1e-9)
    np.testing.assert_allclose(wrap_angle(odo.poses[:, 2] - P[:, 2]), 0, atol=1e-9)


def test_odometry_drift_closed_form():
    # straight line of 50 unit steps: a heading drift of k rad/cell turns the path on an arc
    P = np.column_stack([np.arange(51.0), np.zeros(51), np.zeros(51)])
    k = 0.002
    odo = R.simulate_odometry(P, drift_rad_per_cell=k)
    assert odo.poses[-1, 2] == pytest.approx(50 * k)
    # each step is taken along the previous heading: y_n = Σ_{j<n} sin(j k)
    assert odo.poses[-1, 1] == pytest.approx(np.sin(np.arange(50) * k).sum())
    # noise-free, drift-free odometry reproduces the path
    np.testing.assert_allclose(R.simulate_odometry(P).poses, P, atol=1e-12)
    noisy = R.simulate_odometry(P, trans_std_frac=0.05, rot_std_rad=0.01, rng=4)
    assert np.std(noisy.increments[:, 0] - 1.0) == pytest.approx(0.05, rel=0.4)


def test_simulate_scans_uses_one_stream():
    M = G.test_room_200()
    rf = R.Rangefinder(n_beams=90, range_std_cells=0.3)
    a = R.simulate_scans(M, [[70, 30, 0], [70, 30, 0]], rf, rng=7)
    assert not np.array_equal(a[0].ranges, a[1].ranges)  # independent noise per scan
    b = R.simulate_scans(M, [[70, 30, 0], [70, 30, 0]], rf, rng=7)
    assert np.array_equal(a[1].ranges, b[1].ranges)
    assert "90 beams" in str(a[0])


def test_bad_input():
    g = G.make_grid(5, 5)
    with pytest.raises(ValueError, match="`poses` must have length 3"):
        R.cast_rays(g, [1, 2], [0.0], 5)
    with pytest.raises(ValueError, match="`poses` must be finite"):
        R.cast_rays(g, [1, np.nan, 0], [0.0], 5)
    with pytest.raises(ValueError, match="`max_range` must be > 0"):
        R.cast_rays(g, [1, 1, 0], [0.0], 0)
    with pytest.raises(ValueError, match="`fov_rad` must be <= 2π"):
        R.beam_angles(10, 7.0)
    with pytest.raises(ValueError, match="`n_beams` must be >= 1"):
        R.Rangefinder(n_beams=0)
    with pytest.raises(ValueError, match="`range_std_cells` must be >= 0"):
        R.Rangefinder(range_std_cells=-1)
    with pytest.raises(ValueError, match="`poses` must have shape \\(n, 3\\)"):
        R.simulate_odometry([[0, 0]])
    with pytest.raises(TypeError, match="`scale_error` must be a finite real"):
        R.simulate_odometry([[0, 0, 0], [1, 0, 0]], scale_error="x")
    with pytest.raises(TypeError, match="`rangefinder` must be a Rangefinder"):
        R.simulate_scans(g, [[1, 1, 0]], rangefinder=3)
    with pytest.raises(TypeError, match="`rng` must be a numpy Generator"):
        R.Rangefinder().scan(g, [1, 1, 0], rng="seed")


def test_aperture_returns_the_nearest_echo_in_the_cone():
    # a wall at column 20 straight ahead (17.5 cells from x = 2: the ray enters the cell's face at 19.5) and a post
    # at (row 7, col 12) off the axis: seen from (2, 10) its nearest face is 9.5 cells ahead and about 2.5 to 3.5
    # cells to the side, 14.7°-19.6° off the beam: a 20° cone misses it (its centre ray is the nearest echo of the
    # wall), a 45° cone returns it
    g = np.zeros((21, 21), dtype=np.int8)
    g[:, 20] = 1
    g[7, 12] = 1
    kw = {"n_beams": 1, "fov_rad": 0.1, "max_range_cells": 30, "quantum_cells": 0.0}
    assert R.Rangefinder(**kw).scan(g, [2.0, 10.0, 0.0]).ranges[0] == pytest.approx(17.5)
    assert R.Rangefinder(**kw, aperture_rad=np.radians(20), aperture_rays=21).scan(g, [2.0, 10.0, 0.0]).ranges[0] \
        == pytest.approx(17.5)
    wide = R.Rangefinder(**kw, aperture_rad=np.radians(45), aperture_rays=46).scan(g, [2.0, 10.0, 0.0])
    # the nearest ray to hit the post travels at least 9.5 cells (its face x = 11.5) and at most ~10.1
    assert 9.5 <= wide.ranges[0] <= np.hypot(9.5, 3.5) and wide.valid[0]
    with pytest.raises(ValueError, match="`aperture_rad` must be below π"):
        R.Rangefinder(aperture_rad=4.0)
    with pytest.raises(ValueError, match="`aperture_rad`"):
        R.Rangefinder(aperture_rad=-0.1)
    with pytest.raises(ValueError, match="`aperture_rays`"):
        R.Rangefinder(aperture_rays=1)
