"""Reader for the Mines URG-04LX log with wheel ticks (mines-urg04lx-odometry)."""

import math

import numpy as np
import pytest

import slamlab.hough as h
from slamlab.data import find_data
from slamlab.geometry import se2_compose, se2_integrate
from slamlab.io.urg04lx import (
    read_urg04lx_log,
    urg04lx_bearings,
    urg04lx_odometry,
    urg04lx_sensor_increments,
)
from slamlab.scans import Scan


def write_log(path, n=3):
    rows = []
    for k in range(n):
        fields = [1000000 + 100000 * k, 14500, 100 * k, 120 * k] + [0] * 20
        ranges = [1000 + k] * 682
        ranges[0] = 0  # no return
        ranges[1] = 7  # an error code
        ranges[2] = 5000  # beyond 4 m
        rows.append(" ".join(str(x) for x in fields + ranges + [0]))
    path.write_text("\n".join(rows) + "\n")


def test_reader_on_a_synthetic_file(tmp_path):
    p = tmp_path / "tiny.dat"
    write_log(p)
    log = read_urg04lx_log(p)
    assert len(log) == 3
    assert log.ranges_m.shape == (3, 682)
    assert np.isnan(log.ranges_m[:, :3]).all()
    assert log.ranges_m[2, 5] == pytest.approx(1.002)
    assert np.allclose(log.time_s, [0.0, 0.1, 0.2])
    assert log.ticks[2].tolist() == [200, 240]
    s = log.scan(1)
    assert isinstance(s, Scan)
    assert s.valid[:3].tolist() == [False, False, False]
    assert (s.ranges[0], s.max_range, s.unit) == (4.0, 4.0, "m")  # no return: the range limit
    assert s.time_s == pytest.approx(0.1)
    np.testing.assert_allclose(s.odom_pose, log.odometry_poses()[1])
    assert [x.time_s for x in log.scans()] == pytest.approx([0.0, 0.1, 0.2])
    assert log.name == "tiny.dat"
    assert "tiny.dat: 3 scans" in str(log)


def test_reader_errors(tmp_path):
    with pytest.raises(FileNotFoundError, match=r"`path`: no file at .*missing.dat"):
        read_urg04lx_log(tmp_path / "missing.dat")
    bad = tmp_path / "bad.dat"
    bad.write_text("1 2 3\n")
    with pytest.raises(ValueError, match="line 1: expected 707 numbers; got 3"):
        read_urg04lx_log(bad)
    p = tmp_path / "token.dat"
    write_log(p)
    lines = p.read_text().splitlines()
    fields = lines[1].split()
    fields[30] = "12a4"
    lines[1] = " ".join(fields)
    p.write_text("\n".join(lines) + "\n")
    with pytest.raises(ValueError, match=r"token.dat line 2: field 30 is not a number: '12a4'"):
        read_urg04lx_log(str(p))
    empty = tmp_path / "empty.dat"
    empty.write_text("\n")
    with pytest.raises(ValueError, match="no scans"):
        read_urg04lx_log(empty)
    with pytest.raises(ValueError, match=r"`ticks` must have shape \(n, 2\)"):
        urg04lx_odometry(np.zeros((3, 3)))
    with pytest.raises(ValueError, match="`max_range_m` must be > 0"):
        read_urg04lx_log(bad, max_range_m=0)


def test_odometry_kinematics():
    R, b = 0.077, 0.165
    # straight: one revolution of both wheels = 2πR
    u = urg04lx_odometry([[0, 0], [2000, 2000]])
    assert np.allclose(u, [[2 * math.pi * R, 0.0, 0.0]])
    # spin in place: wheels opposite, the centre stays, Δθ = 2·(2πR/4)/(2b)
    u = urg04lx_odometry([[0, 0], [-500, 500]])
    assert np.allclose(u[0, :2], 0.0)
    assert u[0, 2] == pytest.approx(2 * (2 * math.pi * R / 4) / (2 * b))
    # an arc: integrating many small steps lands on the circle of the exact arc
    n = 1000
    ticks = np.column_stack([np.arange(n + 1) * 2, np.arange(n + 1) * 3])
    pose = se2_integrate((0, 0, 0), urg04lx_odometry(ticks))[-1]
    dl, dr = 2 * n * 2 * math.pi * R / 2000, 3 * n * 2 * math.pi * R / 2000
    th = (dr - dl) / (2 * b)
    radius = (dl + dr) / 2 / th
    assert pose[2] == pytest.approx(th)
    # the midpoint rule steps along chords of length d instead of 2·r·sin(dθ/2): error O(n·dθ²·d)
    assert pose[:2] == pytest.approx([radius * math.sin(th), radius * (1 - math.cos(th))], abs=1e-6)


def test_sensor_increments_match_composition():
    rng = np.random.default_rng(2)
    U = rng.normal(0, 0.1, (5, 3))
    off = 0.145
    got = urg04lx_sensor_increments(U, offset_m=off)
    for u, g in zip(U, got, strict=True):
        # o⁻¹ ⊕ u ⊕ o with o = (off, 0, 0)
        expected = se2_compose(se2_compose((-off, 0.0, 0.0), u), (off, 0.0, 0.0))
        assert np.allclose(g[:2], expected[:2])
        assert g[2] == pytest.approx(u[2])
    # closed form: a quarter turn in place moves a sensor 1 m ahead by (-1, 1)
    np.testing.assert_allclose(urg04lx_sensor_increments([[0.0, 0.0, np.pi / 2]], offset_m=1.0),
                               [[-1.0, 1.0, np.pi / 2]], atol=1e-12)


def test_bearings():
    b = urg04lx_bearings()
    assert b.size == 682
    assert math.degrees(b[-1] - b[0]) == pytest.approx(240.0)


@pytest.mark.realdata
def test_real_log_matches_provenance():
    log = read_urg04lx_log(find_data("mines-urg04lx-odometry/exp2.dat"))
    assert len(log) == 641
    assert log.time_s[-1] == pytest.approx(63.2, abs=0.1)
    assert np.nanmin(log.ranges_m) >= 0.02
    assert np.nanmax(log.ranges_m) <= 4.0
    step = np.median(np.diff(log.time_s))
    assert 0.09 < step < 0.11  # ~10 Hz


@pytest.mark.realdata
def test_real_log_rotation_sense_agrees_with_icp():
    # the beam order (counter-clockwise) and the odometry's turn sign must agree with scan matching
    log = read_urg04lx_log(find_data("mines-urg04lx-odometry/exp2.dat"))
    U = urg04lx_odometry(log.ticks)
    turns = np.argsort(-np.abs(U[:, 2]))[:8]
    agree = 0
    for k in turns:
        pts = []
        for j in (k, k + 1):
            pts.append(log.scan(int(j)).points([0.0, 0.0, 0.0]))
        res = h.icp(pts[1], pts[0], max_dist=0.3)
        agree += np.sign(res.pose[2]) == np.sign(U[k, 2])
    assert agree >= 6
