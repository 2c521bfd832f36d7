"""The maps of MCL on real logs (log_maps): a stretch's map leaves the stretch and ``leave_margin`` scans on either
side out (= a recount of the other scans), its coverage, the runs on it (run_log_mcl, run_log_protocol), the tuned and
untuned logs pooled apart in the protocol's table, and bad input."""

import numpy as np
import pandas as pd
import pytest

from slamlab import scans as SC
from slamlab.io import CarmenLog
from slamlab.sim import grid as G
from slamlab.sim.rangefinder import Rangefinder
from slamlab.studies import localisation as LS
from slamlab.studies.localisation.log_protocol import LogProtocolResult

CELL_M = 0.1  # the simulated room's cell size: the log is metric


@pytest.fixture(scope="module")
def room_log():
    """A CARMEN log of 16 scans of 181 beams over 180° (CARMEN's layout) at random free places of the test room
    (metric, 0.1 m cells)."""
    room = G.test_room_200()
    rng = np.random.default_rng(4)
    xy = [rng.uniform(40, 160, 2) for _ in range(200)]
    P = np.array([[x, y, rng.uniform(-np.pi, np.pi)] for x, y in xy if room[int(y + 0.5), int(x + 0.5)] == G.FREE][:16])
    rf = Rangefinder(n_beams=181, fov_rad=np.pi, max_range_cells=80, quantum_cells=0)
    scans = [rf.scan(room, p).to_metres(CELL_M) for p in P]
    n = len(scans)
    ranges = np.array([np.where(s.valid, s.ranges, np.nan) for s in scans])
    poses = np.column_stack([P[:, :2] * CELL_M, P[:, 2]])
    return CarmenLog(path="room.log", ranges_m=ranges, valid=np.isfinite(ranges), poses=poses, odom_poses=poses,
                     timestamps_s=np.arange(n, dtype=float), odom=np.zeros((0, 4)), max_range_m=10.0)


def _recount(scans_c, Pc, shape, leave):
    keep = [j for j in range(len(scans_c)) if j not in set(leave)]
    return SC.occupancy_grid([scans_c[j] for j in keep], Pc[keep], shape).grid


def test_a_stretch_map_is_a_recount_without_the_stretch_and_its_margin(room_log):
    frame, scans_c, Pc, counts = SC.log_counts(room_log, cell_m=0.2, max_range_m=6.0)
    grid, left = LS.stretch_map(counts, scans_c, Pc, [6, 7, 8], "stretch", 2)
    assert left == range(4, 11)  # 6..8 and 2 scans on either side
    np.testing.assert_array_equal(grid, _recount(scans_c, Pc, frame.shape, range(4, 11)))
    grid0, left0 = LS.stretch_map(counts, scans_c, Pc, np.arange(0, 3), leave_margin=3)  # clipped at the log's start
    assert left0 == range(6)
    np.testing.assert_array_equal(grid0, _recount(scans_c, Pc, frame.shape, range(6)))
    full, none = LS.stretch_map(counts, scans_c, Pc, [6, 7, 8], "none")
    assert none == range(0)
    np.testing.assert_array_equal(full, counts.grid)
    assert not np.array_equal(grid, full)  # the left-out scans drew part of the full map


def test_the_map_does_not_know_the_stretch_as_well_as_the_full_map(room_log):
    """Scans from scattered places: on the full map the end points of scans 3 and 4 are on walls they drew (coverage
    above 0.9; grazing beams of other scans can mark a wall cell free, so not every scan of the room is); on the
    map without them only the walls other scans also saw are."""
    _, scans_c, Pc, counts = SC.log_counts(room_log, cell_m=0.2, max_range_m=6.0)
    idx = [3, 4]
    full, _ = LS.stretch_map(counts, scans_c, Pc, idx, "none")
    out, _ = LS.stretch_map(counts, scans_c, Pc, idx, leave_margin=0)
    c_full, c_out = LS.stretch_coverage(full, scans_c, Pc, idx), LS.stretch_coverage(out, scans_c, Pc, idx)
    assert c_full > 0.9
    assert c_out < c_full - 0.05
    by_hand = np.mean([SC.map_coverage(out, scans_c[i], Pc[i], radius_cells=1) for i in idx])
    assert c_out == pytest.approx(by_hand)


def test_run_log_mcl_runs_on_the_stretch_map(room_log):
    r = LS.run_log_mcl(room_log, start=5, n_scans=3, n_particles_track=30, n_particles_global=40, rng=0)
    frame, scans_c, Pc, counts = SC.log_counts(room_log, cell_m=0.1, max_range_m=10.0)
    np.testing.assert_array_equal(r.grid, _recount(scans_c, Pc, frame.shape, range(3, 10)))
    assert (r.map_leave_out, r.leave_margin) == ("stretch", 2)
    assert r.coverage == pytest.approx(LS.stretch_coverage(r.grid, scans_c, Pc, [5, 6, 7]))
    assert r.row()["coverage"] == r.coverage
    assert "coverage" in str(r)
    assert "without the stretch ±2 scans" in str(r)
    a = LS.run_log_mcl(room_log, start=5, n_scans=3, n_particles_track=30, n_particles_global=40, rng=0,
                       map_leave_out="none")
    np.testing.assert_array_equal(a.grid, counts.grid)
    assert a.coverage > r.coverage
    assert "coverage" in LS.logs_table([r, a])


def test_leave_out_bad_input(room_log):
    with pytest.raises(ValueError, match="`map_leave_out` must be one of 'stretch', 'none'; got 'all'"):
        LS.run_log_mcl(room_log, n_scans=3, map_leave_out="all")
    with pytest.raises(ValueError, match="`leave_margin` must be >= 0; got -1"):
        LS.run_log_mcl(room_log, n_scans=3, leave_margin=-1)
    with pytest.raises(TypeError, match="`leave_margin` must be an integer; got float"):
        LS.run_log_mcl(room_log, n_scans=3, leave_margin=1.5)
    with pytest.raises(ValueError, match="`leave_margin` leaves every scan of the log out of the map"):
        LS.run_log_mcl(room_log, start=2, n_scans=12, leave_margin=2)
    with pytest.raises(ValueError, match="`map_leave_out` must be one of"):
        LS.run_log_protocol(room_log.path, map_leave_out=None)
    with pytest.raises(ValueError, match="`leave_margin` must be >= 0"):
        LS.run_log_protocol(room_log.path, leave_margin=-2)
    _, scans_c, Pc, counts = SC.log_counts(room_log, cell_m=0.2, max_range_m=6.0)
    with pytest.raises(ValueError, match="`map_leave_out` must be one of"):
        LS.stretch_map(counts, scans_c, Pc, [1], "stretches")


def test_tuned_logs_are_the_ones_the_global_settings_name():
    assert set(LS.TUNED_LOGS) == {"fhw", "intel", "orebro"}
    assert set(LS.TUNED_LOGS) < set(LS.CARMEN_LOGS)
    doc = " ".join(LS.global_log_settings.__doc__.split())
    assert "tuned on fhw, intel and orebro" in doc
    assert "not on csail and seattle" in doc
    from slamlab.studies.localisation.log_maps import is_tuned_log

    assert is_tuned_log("intel")
    assert is_tuned_log("/data/carmen-radish-corrected/orebro-corrected.log.gz")
    assert not is_tuned_log("csail")
    assert not is_tuned_log("/data/seattle-corrected.log.gz")
    assert not is_tuned_log("mine.log")


def _result(success: dict, counts=(100, 400)) -> LogProtocolResult:
    """A protocol result made by hand: two stretches per log, ``success[log] = (per count: (run 0, run 1))``."""
    rows = []
    for log, per_count in success.items():
        for n, runs in zip(counts, per_count, strict=True):
            for k, ok in enumerate(runs):
                rows.append({"name": f"{log}-corrected.log.gz", "tuned": LS.TUNED_LOGS.count(log) > 0, "start": 10 * k,
                             "left_out": 7, "coverage": 0.5 + 0.1 * k, "success": ok, "within_tracking_bound": ok,
                             "converged_step": 2 if ok else -1, "err_after_m": 0.1 if ok else np.nan,
                             "final_err_m": 0.1 if ok else 3.0, "final_err_deg": 1.0, "time_per_step_s": 0.01,
                             "track_success": 1.0 if n == max(counts) else np.nan,
                             "track_within_tracking_bound": 1.0 if n == max(counts) else np.nan, "n_particles": n})
    return LogProtocolResult(pd.DataFrame(rows), 2, 5, LS.log_params(0.1, "global"), 0.1, 50)


def test_the_table_pools_tuned_and_untuned_logs_apart():
    res = _result({"intel": ((True, False), (True, True)), "fhw": ((False, False), (True, False)),
                   "csail": ((True, True), (False, False))})
    # by hand: tuned = intel + fhw: 1 of 4 with 100 particles, 3 of 4 with 400; untuned = csail: 2/2, 0/2
    assert res.success(100, tuned=True) == 0.25
    assert res.success(400, tuned=True) == 0.75
    assert res.success(100, tuned=False) == 1.0
    assert res.success(400, tuned=False) == 0.0
    assert res.success(400) == pytest.approx(3 / 6)
    assert res.coverage(tuned=False) == pytest.approx(0.55)
    lines = res.table().splitlines()
    labels = [ln.split()[0] for ln in lines if ln.split() and ln.split()[0] in ("intel", "fhw", "csail", "tuned",
                                                                                 "untuned", "all")]
    # the tuned logs and their pooled rows, then the untuned ones and theirs, then every log
    assert labels == ["intel", "intel", "fhw", "fhw", "tuned", "tuned", "csail", "csail", "untuned", "untuned",
                      "all", "all"]
    row = next(ln for ln in lines if ln.startswith("  tuned logs") and " 400 " in ln).split()
    assert row[3:5] == ["0.75", "0.75"]  # success (3 cells / 5°) and within 0.2 m / 2°
    assert max(len(ln) for ln in lines) <= 110
    assert "untuned 0.00" in str(res)
    assert "0.60" in res.stretches_table()  # each stretch's coverage
