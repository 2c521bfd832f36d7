"""004's remarks on the sensor and the stamp, measured: the beam aperture (004 §7) and trimming T_n (004 §6)."""

import numpy as np
import pytest

from slamlab.scans import Scan
from slamlab.studies import correlation as CS


def test_a_wide_cone_shortens_beams_and_loses_poses():
    r = CS.run_aperture_study((0.0, 10.0, 30.0), 4, progress=False)
    # the cone's nearest echo is never farther than its centre ray: no shortfall for a thin ray, more for wider cones
    assert r.range_error_cells[0] == 0.0
    assert 0.0 < r.range_error_cells[1] < r.range_error_cells[2]
    assert r.err_pos_cells.shape == (3, 4)
    # 004 §7: a thin ray (a laser) localises Table 1's poses; a 30° cone (an ultrasonic sensor) localises fewer
    assert r.success[0].all()
    assert r.success[2].sum() < r.success[0].sum()
    t = r.table().splitlines()
    assert t[4].split()[:3] == ["0", "0.00", "4/4"]
    with pytest.raises(ValueError, match=r"`apertures_deg` must be a non-empty list of angles in \[0, 180\)"):
        CS.run_aperture_study((0.0, 180.0))
    with pytest.raises(ValueError, match="`n_poses`"):
        CS.run_aperture_study((0.0,), 0)


def test_trim_scan_keeps_the_shortest_returns():
    s = Scan(np.arange(6.0), [5.0, 1.0, 4.0, 2.0, 3.0, 9.0], [True, True, True, True, True, False], unit="cell")
    assert CS.trim_scan(s, 1.0) is s
    assert CS.trim_scan(s, 0.6).valid.tolist() == [False, True, False, True, True, False]  # 3 of 5 returns
    assert CS.trim_scan(s, 0.2).valid.tolist() == [False, True, False, False, False, False]
    with pytest.raises(ValueError, match=r"`quantile` must lie in \(0, 1\]"):
        CS.trim_scan(s, 1.5)
    with pytest.raises(ValueError, match="`quantile`"):
        CS.trim_scan(s, 0.0)
    with pytest.raises(TypeError, match="`scan` must be a Scan"):
        CS.trim_scan(np.ones(3), 0.5)


def test_trimmed_stamps_are_smaller():
    r = CS.run_stamp_trim_study((1.0, 0.5), 3)
    # S = 2 (l_max + 2) with l_max the longest kept beam: half the returns, a smaller stamp on every scan
    assert np.all(r.stamp_side[1] < r.stamp_side[0])
    assert r.success[0].all()
    assert "took" in r.timing()
    assert r.table().splitlines()[4].split()[2] == "1.00"
    with pytest.raises(ValueError, match=r"`quantiles` must be a non-empty list of shares in \(0, 1\]"):
        CS.run_stamp_trim_study((1.0, 0.0))
