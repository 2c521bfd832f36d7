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
    assert "intel      1     1/1" in r.table()
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
def test_intel_meets_the_issue_25_goals_at_every_25th_scan(real_data):
    """Issue 25's goal on the Intel log at the goal's size (every 25th scan, 36 scans) with the real-log defaults.

    csail and fhw meet the goal too (docs/benchmarks.md) but cost 60-85 s each; orebro and seattle do not yet.
    """
    log = read_carmen(real_data / "carmen-radish-corrected" / "intel-corrected.log.gz")
    r = CS.run_log_suite([log], 25, joined=(1, 3))
    ok = r.results[0].success
    assert ok.shape == (2, 36)
    # the goal: >= 75 % from a single scan, >= 90 % with 3 joined scans
    assert ok[0].mean() >= 0.75
    assert ok[1].mean() >= 0.90


def _goal_rates(real_data, name: str, every: int):
    """Single-scan and 3-scan success rates of every ``every``-th scan of a shared log with the real-log defaults.

    ``ambiguity=False``: the rival search only scores the estimate's rivals, it never moves the estimate (the
    peak search runs before it), so the success counts are the defaults' at about 3/4 of the time.
    """
    log = read_carmen(real_data / "carmen-radish-corrected" / f"{name}-corrected.log.gz")
    ok = CS.run_log_suite([log], every, joined=(1, 3), ambiguity=False).results[0].success
    return ok.mean(axis=1)


#: (log, every n-th scan): csail at the goal's set; fhw on a cheaper subset, every 50th scan (9 scans, half of the
#: goal's every 25th; the whole set costs about 30 s); orebro and seattle miss the goal, strict xfails that fail
#: loudly the day it is met
_GOAL_LOGS = [
    pytest.param("csail", 25, id="csail-every-25th"),
    pytest.param("fhw", 50, id="fhw-every-50th"),
    pytest.param("orebro", 25, id="orebro-every-25th", marks=pytest.mark.xfail(
        strict=True, reason="issue 25: orebro misses the goal (4/9 single, 7/9 with 3 scans; orebro 50 and 200 are "
                            "score failures: the map they see was drawn only by scans the ±2 leave-out removes, "
                            "docs/benchmarks.md): passes the day it is met")),
    pytest.param("seattle", 25, id="seattle-every-25th", marks=pytest.mark.xfail(
        strict=True, reason="issue 25: seattle misses the 3-scan goal (7/9 with 3 scans; seattle 75 is a score "
                            "failure in every term, with either leave-out, docs/benchmarks.md): passes the day it is met")),
]


@pytest.mark.realdata
@pytest.mark.parametrize(("name", "every"), _GOAL_LOGS)
def test_log_meets_the_issue_25_goals(real_data, name, every):
    """Issue 25's goal on each shared log but intel (above). Bounds from the goal: >= 75 % single, >= 90 % with 3
    joined scans."""
    single, three = _goal_rates(real_data, name, every)
    assert single >= 0.75
    assert three >= 0.90


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
