"""Issue 25: run_log_localisation(votes=True): do the single-scan localisations of scans i, i-1, i-2 agree with
each answer?"""

import numpy as np
import pytest

from slamlab.geometry.se2 import se2_compose
from slamlab.io import read_carmen
from slamlab.studies import correlation as CS
from slamlab.studies.correlation._log_scan import count_votes, leave_sets, vote_leave


def test_vote_leave_by_definition():
    # the voters' grid lacks the largest mode's scans and the voters i-2 .. i: with the ±2 window, the window
    window = leave_sets(100, (1, 3), 2, 500, "window")
    assert vote_leave(100, window) == tuple(range(98, 103))
    assert vote_leave(100, leave_sets(100, (1,), 0, 500, "window")) == (98, 99, 100)
    assert vote_leave(100, leave_sets(100, (1,), 2, 500, "used")) == (98, 99, 100)
    assert vote_leave(100, leave_sets(100, (1, 3), 2, 500, "used")) == (98, 99, 100)
    assert vote_leave(100, leave_sets(100, (1, 5), 2, 500, "used")) == (96, 97, 98, 99, 100)


def test_votes_count_agreeing_voters_by_geometry():
    # scan i at P; scans i-1, i-2 at P ⊕ rel[1], P ⊕ rel[2]: a voter at exactly that pose carries back to P
    P = np.array([40.0, 25.0, 0.3])
    rel = np.array([[0.0, 0.0, 0.0], [-5.0, 1.0, -0.1], [-9.0, 3.0, -0.25]])
    v0 = P.copy()                                       # carries to P
    v1 = se2_compose(P, rel[1]) + np.array([1.5, 0.0, 0.0])       # a 1.5-cell shift of the voter shifts its carried pose so
    # turned by 6°: its carried heading is 6° off, its carried position 2·|rel[2]|·sin 3° ≈ 0.99 cell off
    v2 = se2_compose(P, rel[2]) + np.array([0.0, 0.0, np.radians(6.0)])
    far = P + np.array([3.0, 0, 0])                     # 3 cells from v0, 1.5 from v1, and 6° from v2
    turned = P + np.radians([0.0, 0.0, 4.0])            # 4° from v0 and v1, 2° and ≈ 1 cell from v2
    out = count_votes([v0, v1, v2], rel, {1: P, 3: far, 2: turned})
    assert out == {"vote1": 2, "vote3": 1, "vote2": 3}
    # a wrapped heading still agrees: 359.5° against -0.5°
    Q = np.array([10.0, 10.0, np.radians(-0.5)])
    assert count_votes([Q + np.array([0, 0, 2 * np.pi])], rel[:1], {1: Q}) == {"vote1": 1}


@pytest.mark.realdata
def test_votes_leave_the_answers_unchanged_and_count_the_answer_itself(real_data):
    log = read_carmen(real_data / "carmen-radish-corrected" / "seattle-corrected.log.gz")
    idx, fast = (75, 150, 225), {"delta_alpha_rad": np.radians(5.0), "progress": False}
    for joined in ((1, 3), (2,)):
        r0 = CS.run_log_localisation(log, idx, joined=joined, **fast)
        r = CS.run_log_localisation(log, idx, joined=joined, votes=True, **fast)
        # the voters use the log's per-step odometry noise: every answer is the one without votes
        np.testing.assert_array_equal(r.est_poses_m, r0.est_poses_m)
        np.testing.assert_array_equal(r.ambiguity, r0.ambiguity)
        assert r0.votes is None
        assert r.votes.shape == (len(joined), len(idx))
        assert r.votes.dtype.kind == "i"
        assert ((r.votes >= 0) & (r.votes <= 3)).all()
        np.testing.assert_array_equal(r.flagged(), r.votes < 2)
        assert not r.flagged(0).any()
    # mode 1 on the ±2 window: voter i is scan i alone on the same grid, i.e. the answer itself, so >= 1 vote
    r_1 = CS.run_log_localisation(log, idx, joined=(1,), votes=True, **fast)
    assert r_1.votes.min() >= 1
    np.testing.assert_array_equal(r_1.votes, CS.run_log_localisation(log, idx, joined=(1, 3), votes=True,
                                                                    **fast).votes[:1])
    s = CS.run_log_suite([log], 75, joined=(1,), votes=True, **fast)
    assert "failures flagged (< 2 votes)" in s.votes_table()
    assert "flagged when fewer than 3 agree" in s.votes_table(3)
    assert s.votes_table().splitlines()[-1].split()[:3] == ["all", "1", "scan"]


@pytest.mark.realdata
def test_votes_bad_input(real_data):
    log = read_carmen(real_data / "carmen-radish-corrected" / "seattle-corrected.log.gz")
    with pytest.raises(TypeError, match="`votes` must be a bool; got str"):
        CS.run_log_localisation(log, (75,), votes="yes")
    with pytest.raises(ValueError, match=r"`scan_indices` must lie in \[2, .*join.* or vote"):
        CS.run_log_localisation(log, (1,), votes=True)
    r = CS.run_log_localisation(log, (75,), delta_alpha_rad=np.radians(10.0), progress=False)
    with pytest.raises(ValueError, match=r"no votes: run run_log_localisation\(\.\.\., votes=True\)"):
        r.flagged()
    with pytest.raises(ValueError, match="no votes"):
        CS.run_log_suite([log], 75, joined=(1,), delta_alpha_rad=np.radians(10.0), progress=False).votes_table()
    rv = CS.run_log_localisation(log, (75,), delta_alpha_rad=np.radians(10.0), votes=True, progress=False)
    with pytest.raises(ValueError, match=r"`min_votes` must lie in 0\.\.3; got 4"):
        rv.flagged(4)
    with pytest.raises(ValueError, match="`min_votes`"):
        rv.flagged(-1)
    with pytest.raises(TypeError, match="`min_votes`"):
        rv.flagged(1.5)
