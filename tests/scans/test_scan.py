"""The one Scan type and scan_to_points: construction checks, unit conversion, points against the closed form."""

import math

import numpy as np
import pytest

from slamlab.geometry import se2_transform
from slamlab.scans import Scan, scan_to_points


def test_points_closed_form_and_defaults():
    s = Scan([0.0, np.pi / 2, np.pi], [2.0, 3.0, 9.0], [True, True, False], unit="cell", max_range=9.0,
             pose=[1.0, 1.0, 0.0])
    np.testing.assert_allclose(s.points(), [[3.0, 1.0], [1.0, 4.0]], atol=1e-12)
    # another pose: a quarter turn
    np.testing.assert_allclose(s.points([0.0, 0.0, np.pi / 2]), [[0.0, 2.0], [-3.0, 0.0]], atol=1e-12)
    # no pose at all: the sensor frame; odom_pose when there is no pose
    bare = Scan([0.0], [2.0], [True])
    np.testing.assert_allclose(bare.points(), [[2.0, 0.0]])
    odo = Scan([0.0], [2.0], [True], odom_pose=[0.0, 1.0, 0.0])
    np.testing.assert_allclose(odo.points(), [[2.0, 1.0]])
    assert math.isnan(bare.time_s)
    assert bare.max_range == math.inf


def test_scan_to_points_is_polar_through_se2():
    rng = np.random.default_rng(1)
    b, r = rng.uniform(-np.pi, np.pi, 20), rng.uniform(0, 5, 20)
    pose = np.array([0.5, -1.0, 0.7])
    ref = se2_transform(pose, np.column_stack([r * np.cos(b), r * np.sin(b)]))
    np.testing.assert_allclose(scan_to_points(b, r, pose), ref, atol=1e-12)
    keep = r > 2
    np.testing.assert_allclose(scan_to_points(b, r, pose, keep), ref[keep], atol=1e-12)


def test_unit_conversion_round_trip():
    s = Scan([0.0, 1.0], [0.5, 4.0], [True, False], unit="m", max_range=4.0, odom_pose=[1.0, 2.0, 0.3],
             pose=[1.1, 2.1, 0.3], time_s=5.0)
    c = s.to_cells(0.1)
    assert c.unit == "cell"
    assert c.max_range == pytest.approx(40.0)
    np.testing.assert_allclose(c.ranges, [5.0, 40.0])
    np.testing.assert_allclose(c.pose, [11.0, 21.0, 0.3])
    np.testing.assert_allclose(c.odom_pose, [10.0, 20.0, 0.3])
    assert c.time_s == 5.0
    back = c.to_metres(0.1)
    np.testing.assert_allclose(back.ranges, s.ranges)
    np.testing.assert_allclose(back.points(), s.points())
    assert s.to_metres(0.1) is s
    assert c.to_cells(0.1) is c


def test_scan_is_read_only_and_copies():
    r = np.array([1.0, 2.0])
    s = Scan([0.0, 1.0], r, np.array([True, True]))
    r[0] = 9.0
    assert s.ranges[0] == 1.0
    with pytest.raises(ValueError, match="read-only"):
        s.ranges[0] = 3.0


def test_bad_input():
    with pytest.raises(ValueError, match="same length"):
        Scan([0.0, 1.0], [1.0], [True])
    with pytest.raises(ValueError, match="`valid` must be a bool array of shape"):
        Scan([0.0], [1.0], [1])
    with pytest.raises(ValueError, match="`ranges` must be >= 0"):
        Scan([0.0], [-1.0], [True])
    with pytest.raises(ValueError, match="`ranges` must be finite"):
        Scan([0.0], [np.nan], [False])
    with pytest.raises(ValueError, match="`unit` must be one of"):
        Scan([0.0], [1.0], [True], unit="mm")
    with pytest.raises(ValueError, match="`max_range` must be > 0"):
        Scan([0.0], [1.0], [True], max_range=0.0)
    with pytest.raises(ValueError, match="`pose` must have length 3"):
        Scan([0.0], [1.0], [True], pose=[1.0, 2.0])
    with pytest.raises(ValueError, match="`cell_m` must be > 0"):
        Scan([0.0], [1.0], [True], unit="m").to_cells(0.0)
    with pytest.raises(ValueError, match="same length"):
        scan_to_points([0.0, 1.0], [1.0])
    with pytest.raises(ValueError, match="`valid` must be a bool array"):
        scan_to_points([0.0], [1.0], None, [1])
