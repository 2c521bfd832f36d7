"""CARMEN log reader: synthetic logs with known content, then the real Radish and MbICP logs."""

import gzip

import numpy as np
import pytest
from scipy.spatial import cKDTree

from slamlab.data import find_data
from slamlab.io import flaser_angles, open_text, read_carmen
from slamlab.scans import Scan

LOG = """# a comment
PARAM robot_frontlaser_offset 0.0 nohost 0
ODOM 0.5 0.25 0.1 0 0 0 12.5 pippo 12.5
FLASER 3 1.0 2.0 NaN 1.5 -2.0 0.5 1.6 -2.1 0.4 13.0 pippo 13.0
NEFF 15
FLASER 3 4.0 0.0 3.0 1.0 2.0 3.0 1.0 2.0 3.0 14.0 pippo 14.0
ROBOTLASER1 whatever
"""


def test_open_text_tells_gzip_by_its_bytes_not_its_name(tmp_path):
    plain, packed = tmp_path / "log.gz", tmp_path / "log.txt"  # names that lie about the content
    plain.write_text(LOG, encoding="ascii")
    packed.write_bytes(gzip.compress(LOG.encode("ascii")))
    for path in (plain, packed):
        with open_text(path) as fh:
            assert fh.read() == LOG


@pytest.mark.parametrize("compress", [False, True])
def test_synthetic_log(tmp_path, compress):
    path = tmp_path / ("x.log.gz" if compress else "x.log")
    if compress:
        with gzip.open(path, "wt") as fh:
            fh.write(LOG)
    else:
        path.write_text(LOG)
    L = read_carmen(path)
    assert (L.n_scans, L.n_beams) == (2, 3)
    np.testing.assert_array_equal(L.ranges_m[1], [4.0, 0.0, 3.0])
    assert np.isnan(L.ranges_m[0, 2])
    # the log marks invalid readings with NaN (the MbICP convention): the limit is the largest
    # reading rounded up to the next whole metre (4.0 -> 5 m), so 4.0 is a return; 0 and NaN are not
    assert L.max_range_m == 5.0
    assert L.valid.tolist() == [[True, True, False], [True, False, True]]
    # without NaN (the Radish convention) the largest reading is the sensor's "no return" value
    nonan = tmp_path / "nonan.log"
    nonan.write_text(LOG.replace("NaN", "2.5"))
    L2 = read_carmen(nonan)
    assert L2.max_range_m == 4.0
    assert L2.valid.tolist() == [[True, True, True], [False, False, True]]
    np.testing.assert_array_equal(L.poses[0], [1.5, -2.0, 0.5])
    np.testing.assert_array_equal(L.odom_poses[0], [1.6, -2.1, 0.4])
    np.testing.assert_array_equal(L.timestamps_s, [13.0, 14.0])
    np.testing.assert_array_equal(L.odom, [[0.5, 0.25, 0.1, 12.5]])
    assert L.params == {"robot_frontlaser_offset": "0.0"}
    assert L.skipped == {"NEFF": 1, "ROBOTLASER1": 1}
    # 3 beams over 180°: -90, 0, +90; beam 0 of scan 0 (1 m, at -90° + heading 0.5 rad)
    s0 = L.scan(0)
    assert isinstance(s0, Scan)
    assert (s0.unit, s0.max_range, s0.time_s) == ("m", 5.0, 13.0)
    np.testing.assert_array_equal(s0.pose, [1.5, -2.0, 0.5])
    np.testing.assert_array_equal(s0.odom_pose, [1.6, -2.1, 0.4])
    pts = s0.points()
    np.testing.assert_allclose(pts[0], [1.5 + np.cos(0.5 - np.pi / 2), -2.0 + np.sin(0.5 - np.pi / 2)])
    c = s0.to_cells(0.5)
    np.testing.assert_allclose(c.ranges, [2.0, 4.0, 10.0])  # the NaN beam: no return at the 5 m limit
    assert c.valid.tolist() == [True, True, False]
    np.testing.assert_allclose(c.pose, [3.0, -4.0, 0.5])
    assert [s.time_s for s in L.scans()] == [13.0, 14.0]
    assert L.name == path.name
    assert "2 scans x 3 beams" in str(L)
    # an explicit max range keeps the 4 m reading
    assert read_carmen(path, max_range_m=10.0).valid[1, 0]


def test_flaser_angles_layouts():
    a = flaser_angles(361)
    np.testing.assert_allclose(np.diff(a), np.radians(0.5))
    assert a[0] == pytest.approx(-np.pi / 2)
    assert a[-1] == pytest.approx(np.pi / 2)
    b = flaser_angles(180)
    np.testing.assert_allclose(np.degrees(b[[0, -1]]), [-90, 89])


def test_bad_input(tmp_path):
    with pytest.raises(FileNotFoundError, match=r"`path`: no file at .*missing.log"):
        read_carmen(tmp_path / "missing.log")
    with pytest.raises(TypeError, match=r"`path` must be a str or os.PathLike"):
        read_carmen(3)
    (tmp_path / "empty.log").write_text("ODOM 0 0 0 0 0 0 1 h 1\n")
    with pytest.raises(ValueError, match="no FLASER message"):
        read_carmen(tmp_path / "empty.log")
    (tmp_path / "short.log").write_text("FLASER 5 1 2 3\n")
    with pytest.raises(ValueError, match="line 1: malformed FLASER"):
        read_carmen(tmp_path / "short.log")
    (tmp_path / "mixed.log").write_text("FLASER 2 1 2 0 0 0 0 0 0\nFLASER 3 1 2 3 0 0 0 0 0 0\n")
    with pytest.raises(ValueError, match=r"line 2: .*beam count 3 differs"):
        read_carmen(tmp_path / "mixed.log")
    (tmp_path / "bad.log").write_text("ODOM 0 0 0\nFLASER 2 1 x 0 0 0 0 0 0\n")
    with pytest.raises(ValueError, match=r"bad.log, line 2: malformed FLASER message: could not convert .*'x'"):
        read_carmen(str(tmp_path / "bad.log"))
    (tmp_path / "odom.log").write_text("FLASER 2 1 2 0 0 0 0 0 0\nODOM 0 y 0\n")
    with pytest.raises(ValueError, match=r"odom.log, line 2: malformed ODOM message"):
        read_carmen(tmp_path / "odom.log")
    with pytest.raises(ValueError, match="`max_range_m` must be > 0"):
        read_carmen(tmp_path / "bad.log", max_range_m=0)
    with pytest.raises(ValueError, match="`n_beams` must be >= 2"):
        flaser_angles(1)


def _consecutive_overlap(L, step=5):
    """Median nearest-neighbour distance [m] between scan i and i+1 drawn at their stored poses."""
    med = []
    for i in range(0, L.n_scans - 1, step):
        a, b = L.scan(i).points(), L.scan(i + 1).points()
        a = a[np.hypot(*(a - L.poses[i, :2]).T) < 8]
        b = b[np.hypot(*(b - L.poses[i + 1, :2]).T) < 8]
        if len(a) > 50 and len(b) > 50:
            med.append(np.median(cKDTree(a).query(b)[0]))
    return np.array(med)


@pytest.mark.realdata
def test_intel_corrected_log():
    path = find_data("carmen-radish-corrected/intel-corrected.log.gz")
    L = read_carmen(path)
    with gzip.open(path, "rt") as fh:
        kinds = [ln.split(maxsplit=1)[0] for ln in fh if ln.strip()]
    assert L.n_scans == kinds.count("FLASER") == 910
    assert L.odom.shape == (kinds.count("ODOM"), 4) == (14541, 4)
    assert L.n_beams == 180
    assert L.max_range_m == pytest.approx(81.83)
    # corrected logs repeat the corrected pose as odometry
    np.testing.assert_allclose(L.poses, L.odom_poses, atol=1e-9)
    # SLAM-corrected poses + the beam layout make consecutive scans overlap to a few cm;
    # a mirrored beam order or a wrong angle offset gives decimetres to metres
    med = _consecutive_overlap(L)
    assert np.median(med) < 0.05
    mirrored = L.__class__(**{**L.__dict__, "ranges_m": L.ranges_m[:, ::-1], "valid": L.valid[:, ::-1]})
    assert np.median(_consecutive_overlap(mirrored)) > 3 * np.median(med)


@pytest.mark.realdata
def test_mbicp_sick_log():
    L = read_carmen(find_data("mbicp-laserazos-sick/laserazosSM3.log"))
    assert (L.n_scans, L.n_beams) == (778, 361)
    # PROVENANCE: beam i at -π/2 + i·π/(n-1), valid when 0 < r < 8 m (the source's reader)
    np.testing.assert_allclose(L.bearings_rad, -np.pi / 2 + np.arange(361) * np.pi / 360)
    assert L.max_range_m == 8.0
    R = L.ranges_m
    with np.errstate(invalid="ignore"):
        np.testing.assert_array_equal(L.valid, np.isfinite(R) & (R > 0) & (R < 8.0))
    s = L.scan(5)
    assert s.unit == "m"
    assert s.max_range == 8.0
    assert s.valid.sum() == L.valid[5].sum()
    nan_frac = np.isnan(L.ranges_m).mean()
    assert 0.06 < nan_frac < 0.075  # PROVENANCE: about 6.8 %
    ok = L.ranges_m[L.valid]
    assert ok.min() >= 0.33
    assert ok.max() < 8.0
    np.testing.assert_array_equal(L.poses, L.odom_poses)
    assert np.all(np.isnan(L.timestamps_s))
    assert L.odom.shape == (0, 4)
    # raw odometry: ~62 m of travel (PROVENANCE)
    travel = np.hypot(*np.diff(L.poses[:, :2], axis=0).T).sum()
    assert 55 < travel < 70
    med = _consecutive_overlap(L, step=3)
    assert np.median(med) < 0.1


@pytest.mark.realdata
@pytest.mark.parametrize("name", ["csail", "fhw", "orebro", "seattle"])
def test_other_radish_logs_read(name):
    L = read_carmen(find_data(f"carmen-radish-corrected/{name}-corrected.log.gz"))
    expected = {"csail": (406, 361), "fhw": (488, 180), "orebro": (237, 181), "seattle": (241, 361)}[name]
    assert (L.n_scans, L.n_beams) == expected
    assert L.valid.mean() > 0.8
