"""Ch. 5 on every shared CARMEN log (issue 25): run_log_suite and its per-log tables."""

import numpy as np
import pytest

from slamlab.io import read_carmen
from slamlab.studies import correlation as CS


def test_log_suite_bad_input(tmp_path):
    with pytest.raises(TypeError, match="`paths` must be a list or tuple of logs"):
        CS.run_log_suite("intel-corrected.log.gz")
    with pytest.raises(ValueError, match="`paths` must hold at least one log"):
        CS.run_log_suite([])
    with pytest.raises(TypeError, match=r"`paths` must hold str, os\.PathLike or CarmenLog"):
        CS.run_log_suite([3])
    with pytest.raises(ValueError, match="`every`"):
        CS.run_log_suite([str(tmp_path / "x.log")], every=2)
    with pytest.raises(TypeError, match="`every`"):
        CS.run_log_suite([str(tmp_path / "x.log")], every=2.5)
    with pytest.raises(FileNotFoundError, match=r"no file at .*missing.log"):
        CS.run_log_suite([str(tmp_path / "missing.log")])
    assert len(CS.SHARED_CARMEN_LOGS) == 5


@pytest.mark.realdata
def test_log_suite_tables_and_bad_threshold(real_data):
    log = read_carmen(real_data / "carmen-radish-corrected" / "intel-corrected.log.gz")
    with pytest.raises(ValueError, match=r"`every` \(950\) leaves no scan of intel-corrected.log.gz"):
        CS.run_log_suite([log], every=950)
    r = CS.run_log_suite([log], every=500, joined=(1,), delta_alpha_rad=np.radians(5.0))
    assert r.names == ("intel",)
    assert r.rates().shape == (1, 1)
    assert r.results[0].scan_indices.tolist() == [500]
    assert "Every 500th scan of each log" in r.table()
    assert r.table().splitlines()[4].split()[:4] == ["intel", "1", "0", "1/1"]  # 1 scan, covered, localised
    assert "not covered: fewer than 50%" in r.table()
    assert "failures flagged (>= 0.8)" in r.ambiguity_table(0.8)
    assert r.ambiguity_table().splitlines()[-1].split()[:2] == ["all", "1"]
    assert "intel 1/1" in str(r)
    with pytest.raises(ValueError, match=r"`threshold` must lie in \[0, 1\]"):
        r.ambiguity_table(threshold=1.5)
    assert "failures flagged (<= 1.2)" in r.margin_table()
    assert r.results[0].margin.shape == (1, 1)
    with pytest.raises(ValueError, match="`threshold`"):
        r.margin_table(threshold=-1.0)
    with pytest.raises(ValueError, match=r"`hit_ratio` must lie in \[0, 1\]"):
        CS.run_log_localisation(log, (500,), hit_ratio=1.5)


@pytest.mark.realdata
def test_coverage_and_the_goal_counted_by_hand(real_data):
    # a real 3-scan run of one log, then coverage and errors set by hand so the counts are known
    import dataclasses

    log = read_carmen(real_data / "carmen-radish-corrected" / "seattle-corrected.log.gz")
    r = CS.run_log_localisation(log, (60, 120, 180), joined=(1, 3), delta_alpha_rad=np.radians(10.0), progress=False)
    assert r.coverage.shape == (3,) and np.all((r.coverage >= 0) & (r.coverage <= 1))
    assert r.pose_check["scan"].tolist() == [60, 120, 180]
    # scan 60 not covered (0.4 < 0.5); mode 1 right on 120 only, mode 3 right on 60, 120, 180
    err = np.array([[0.1, 0.1, 5.0], [0.1, 0.1, 0.1]])
    r = dataclasses.replace(r, coverage=np.array([0.4, 0.9, 0.5]), err_pos_m=err, err_heading_rad=np.zeros((2, 3)))
    assert r.covered.tolist() == [False, True, True]
    s = CS.LogSuiteResult((r,), 60)
    np.testing.assert_allclose(s.rates(), [[0.5, 1.0]])     # over scans 120 and 180 only
    row = s.table().splitlines()[4].split()
    assert row[:6] == ["seattle", "3", "1", "1/2", "50.0%", "0.100"]
    g = s.meets_goal()
    assert g["pooled"] == (0.5, 1.0) and g["lowest"] == (0.5, 1.0) and not g["met"]
    assert CS.LogSuiteResult((r,), 60).meets_goal(single=0.5, joined=0.9, per_log=0.5)["met"]
    goal = s.goal_table().splitlines()
    assert goal[3].split()[-3:] == ["no", "2/3", "(66.7%)"]   # mode 1 over all 3 scans: 60 and 120 right
    cov = s.coverage_table().splitlines()
    assert cov[-1].split() == ["seattle", "60", "0.40", "yes", "yes"]
    with pytest.raises(ValueError, match=r"`single` must lie in \[0, 1\]"):
        s.meets_goal(single=1.5)
    with pytest.raises(ValueError, match=r"`min_coverage` must lie in \[0, 1\]"):
        CS.run_log_localisation(log, (60,), min_coverage=2.0)


@pytest.mark.realdata
def test_joined_odometry_noise_is_drawn_per_step_of_the_log(real_data):
    # the noise belongs to the log's steps, not to a scan's place in the list: scan 75 joined with the 2 scans
    # before it gets the same odometry, so the same answer, alone or among other scans, with or without votes
    log = read_carmen(real_data / "carmen-radish-corrected" / "seattle-corrected.log.gz")
    fast = {"joined": (3,), "delta_alpha_rad": np.radians(5.0), "progress": False}
    alone = CS.run_log_localisation(log, (75,), **fast)
    among = CS.run_log_localisation(log, (50, 75, 76, 225), **fast)
    np.testing.assert_array_equal(among.est_poses_m[:, 1], alone.est_poses_m[:, 0])
    np.testing.assert_array_equal(among.ambiguity[:, 1], alone.ambiguity[:, 0])
    # the noise does matter: another seed draws other steps, and (here) another answer for at least one scan
    other = CS.run_log_localisation(log, (50, 75, 76, 225), rng=5, **fast)
    assert not np.array_equal(other.est_poses_m, among.est_poses_m)


@pytest.mark.realdata
def test_more_confident_keeps_the_answer_with_the_larger_margin(real_data):
    # a real two-mode run, then margins and errors set by hand so the choice and the counts are known
    import dataclasses

    log = read_carmen(real_data / "carmen-radish-corrected" / "seattle-corrected.log.gz")
    r = CS.run_log_localisation(log, (75, 150, 225), joined=(1, 3), delta_alpha_rad=np.radians(10.0),
                               progress=False)
    margin = np.array([[2.0, 0.5, 1.0], [1.0, 3.0, 1.0]])       # scan 75: mode 1 leads; 150: mode 3; 225: a tie
    err = np.array([[0.1, 0.1, 5.0], [5.0, 5.0, 0.1]])          # mode 1 right on 75, 150; mode 3 right on 225
    r = dataclasses.replace(r, margin=margin, err_pos_m=err, err_heading_rad=np.zeros((2, 3)))
    assert CS.more_confident(r).tolist() == [1, 3, 3]            # a tie keeps the second mode
    assert CS.more_confident(r, (3, 1)).tolist() == [1, 3, 1]    # ... whichever is second
    s = CS.LogSuiteResult((r,), 75)
    row = s.confident_table().splitlines()[3].split()
    # kept: mode 1 on 75 (right), mode 3 on 150 (wrong), mode 3 on 225 (right): 2/3; mode 1 alone 2/3, mode 3 1/3
    assert row == ["seattle", "3", "2/3", "1/3", "2/3", "1"]
    assert s.confident_table().splitlines()[-1].split()[:5] == ["all", "3", "2/3", "1/3", "2/3"]
    with pytest.raises(ValueError, match=r"`modes` must be two distinct modes of the run \(1, 3\); got \(1, 2\)"):
        CS.more_confident(r, (1, 2))
    with pytest.raises(ValueError, match="`modes` must be two distinct modes"):
        s.confident_table((3, 3))
    with pytest.raises(TypeError, match="`result` must be a LogLocalisationResult; got dict"):
        CS.more_confident({})
    with pytest.raises(ValueError, match="carries no margins"):
        CS.more_confident(dataclasses.replace(r, margin=None))
