"""Issue 25: run_log_localisation(leave_out="used"): each mode's grid lacks exactly the scans it localises with."""

import numpy as np
import pytest

from slamlab.io import read_carmen
from slamlab.scans.logmap import log_counts
from slamlab.scans.occupancy import label_counts, occupancy_grid
from slamlab.studies import correlation as CS
from slamlab.studies.correlation._log_scan import leave_sets, mode_grids


def test_leave_sets_by_definition():
    # "used": mode k leaves out scans i-k+1 .. i and nothing else; "window": i-2 .. i+2 for every mode
    used = leave_sets(100, (1, 3), 2, 500, "used")
    assert {k: list(s) for k, s in used.items()} == {1: [100], 3: [98, 99, 100]}
    window = leave_sets(100, (1, 3), 2, 500, "window")
    assert {k: list(s) for k, s in window.items()} == {1: [98, 99, 100, 101, 102], 3: [98, 99, 100, 101, 102]}
    assert list(leave_sets(1, (1,), 2, 500)[1]) == [0, 1, 2, 3]  # clipped at the log's start


@pytest.mark.realdata
@pytest.mark.parametrize("hit_ratio", [0.25, 0.1])
def test_used_mode_grids_are_the_other_scans_grids(real_data, hit_ratio):
    # construction: the grid of mode k under "used" = the counts of every scan but i-k+1 .. i, labelled; built
    # here from the kept scans directly (counts add over scans), not as the whole log minus the left-out ones
    log = read_carmen(real_data / "carmen-radish-corrected" / "orebro-corrected.log.gz")
    _frame, scans_c, Pc, full = log_counts(log, cell_m=0.2, max_range_m=10.0)
    i = 150
    grids = mode_grids(leave_sets(i, (1, 3), 2, log.n_scans, "used"), full, scans_c, Pc, hit_ratio)
    for k, left in ((1, [i]), (3, [i - 2, i - 1, i])):
        keep = [j for j in range(log.n_scans) if j not in left]
        og = occupancy_grid([scans_c[j] for j in keep], Pc[keep], full.grid.shape)
        np.testing.assert_array_equal(grids[k], label_counts(og.hits, og.passes, hit_ratio=hit_ratio))
    assert not np.array_equal(grids[1], grids[3])  # scans i-2, i-1 drew cells: the two modes' grids differ
    # "window": one grid for every mode
    win = mode_grids(leave_sets(i, (1, 3), 2, log.n_scans, "window"), full, scans_c, Pc, hit_ratio)
    assert win[1] is win[3]


@pytest.mark.realdata
def test_used_localises_each_mode_on_its_own_grid(real_data):
    log = read_carmen(real_data / "carmen-radish-corrected" / "orebro-corrected.log.gz")
    idx, fast = (100, 150), {"delta_alpha_rad": np.radians(5.0), "progress": False}
    r = CS.run_log_localisation(log, idx, joined=(1, 3), leave_out="used", truth_check=True, **fast)
    assert r.leave_out == "used"
    assert r.exclude is None
    # mode 1 leaves out scan i only: the window of 0 scans around it gives the same grid and so the same search
    r1 = CS.run_log_localisation(log, idx, joined=(1,), exclude=0, **fast)
    np.testing.assert_array_equal(r.est_poses_m[0], r1.est_poses_m[0])
    np.testing.assert_array_equal(r.ambiguity[0], r1.ambiguity[0])
    # mode 3's grid does not depend on the other modes run beside it
    r3 = CS.run_log_localisation(log, idx, joined=(3,), leave_out="used", **fast)
    np.testing.assert_array_equal(r.est_poses_m[1], r3.est_poses_m[0])
    # the truth check runs per mode; only the mode's own scans are left out, so no mark is traced to a left-out
    # scan 1 or 2 steps away
    d = r.truth_check()
    assert len(d) == 4
    assert set(d["kind"]) <= {"ok", "score", "search", "grid"}
    for what in ("unex_obs", "unex_free", "conf_obs"):
        assert (d[f"{what}_1"] == 0).all()
        assert (d[f"{what}_2"] == 0).all()
    assert "each mode's own scans left out" in r.table()
    assert "each mode's own scans left out" in r.terms_table()
    s = CS.run_log_suite([log], 100, joined=(1,), leave_out="used", **fast)
    assert "each mode's own scans left out of each grid" in s.table()


@pytest.mark.realdata
def test_leave_out_bad_values(real_data):
    log = read_carmen(real_data / "carmen-radish-corrected" / "orebro-corrected.log.gz")
    with pytest.raises(ValueError, match="`leave_out` must be one of 'window', 'used'; got 'all'"):
        CS.run_log_localisation(log, (100,), leave_out="all")
    with pytest.raises(ValueError, match="`leave_out` must be one of"):
        CS.run_log_localisation(log, (100,), leave_out=None)
    with pytest.raises(ValueError, match=r"`exclude` is for leave_out='window'.*got exclude=2"):
        CS.run_log_localisation(log, (100,), leave_out="used", exclude=2)
    with pytest.raises(ValueError, match="`exclude` must be >= 2"):
        CS.run_log_localisation(log, (100,), joined=(3,), leave_out="window", exclude=1)


def test_log_points_name_a_scan_without_a_return():
    # the sweep's points carry the test scan and the scans joined before it; one without a return is named here,
    # before any worker runs
    from slamlab.scans import Scan
    from slamlab.studies.correlation._log_scan import log_points

    hit = Scan([0.0, 1.0], [3.0, 4.0], [True, True], max_range=10.0)
    miss = Scan([0.0, 1.0], [10.0, 10.0], [False, False], max_range=10.0)
    scans_c, Pc = [hit, miss, hit, hit], np.zeros((4, 3))
    (pt,) = log_points(np.array([3]), (1, 2), scans_c, Pc, np.zeros((1, 1, 3)))
    assert pt["index"] == 3
    assert pt["scans"] == [scans_c[3], scans_c[2]]
    np.testing.assert_array_equal(pt["rel"], np.zeros((2, 3)))
    with pytest.raises(ValueError, match="`scan 1` has no return"):
        log_points(np.array([2]), (1, 2), scans_c, Pc, np.zeros((1, 1, 3)))
