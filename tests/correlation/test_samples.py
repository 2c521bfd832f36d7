"""Issue 42: the samples a scan marks (ScanSamples), the search on them (localise_samples), the score and the marks at
any pose (pose_scores, pose_marks), and the stamps that localise correlates (scan_stamps)."""

import numpy as np
import pytest

from slamlab import correlation as C
from slamlab import sim as S
from slamlab.correlation.algorithm import localise_samples
from slamlab.correlation.samples import ScanSamples, joined_samples, scan_samples
from slamlab.correlation.scoring import pose_marks, pose_scores
from slamlab.correlation.settings import check_score_norm
from slamlab.scans import Scan, grid_to_values


def _scan(pose=(60.0, 40.0, 0.5), n_beams=90, max_range=40.0):
    return S.Rangefinder(n_beams=n_beams, max_range_cells=max_range).scan(S.test_room_200(), list(pose))


def test_scan_samples_by_definition():
    s = Scan([0.0, np.pi / 2], [2.0, 9.0], [True, False], max_range=9.0)
    smp = scan_samples(s, delta_l_cells=0.5, hit_offset_cells=0.5, step_cells=0.5)
    # free: t < 2 - 0.5 along the beam with a return; the miss is skipped (use_misses False)
    assert smp.free.round(12).tolist() == [[0.0, 0.0], [0.5, 0.0], [1.0, 0.0]]
    # obstacle: from l - Δl + 0.01 to l + Δl + hit_offset, every step_cells or less
    np.testing.assert_allclose(smp.obs[:, 0], np.linspace(1.51, 3.0, 4))
    assert (smp.free_value, smp.obs_value, smp.n_scans) == (-1.0, 1.0, 1)
    assert smp.reach_cells == 3.0
    assert smp.origin == 5
    with_misses = scan_samples(s, use_misses=True, free_mark_weight=0.5, a_c=-2.0)
    assert with_misses.free_value == -1.0  # a_c · free_mark_weight
    assert with_misses.free[:, 1].max() > 8.0  # the miss is sampled over its range
    assert with_misses.reach_cells == 9.5  # the miss's range plus the obstacle offset


def test_scan_samples_bad_input():
    with pytest.raises(TypeError, match=r"`scan` must be a slamlab\.scans\.Scan; got list"):
        scan_samples([1.0])
    with pytest.raises(ValueError, match="`scan` must be in cell units"):
        scan_samples(Scan([0.0], [1.0], [True], unit="m"))
    with pytest.raises(ValueError, match="`scan` has no return"):
        scan_samples(Scan([0.0], [5.0], [False], max_range=5.0))
    with pytest.raises(TypeError, match="LocaliseParams has no field"):
        scan_samples(_scan(), step=0.5)


def test_joined_samples_use_only_the_relative_poses():
    scans = [_scan((60.0, 40.0, 0.5)), _scan((64.0, 41.0, 0.6))]
    world = np.array([[60.0, 40.0, 0.5], [64.0, 41.0, 0.6]])
    moved = np.array([[10.0, -3.0, 2.0], [0.0, 0.0, 0.0]])  # the same two poses seen from another frame
    from slamlab.geometry.se2 import se2_compose, se2_relative

    other = se2_compose(moved[0], world)
    a, b = joined_samples(scans, world), joined_samples(scans, other)
    np.testing.assert_allclose(a.free, b.free, atol=1e-9)
    np.testing.assert_allclose(a.obs, b.obs, atol=1e-9)
    assert a.n_scans == 2
    # poses already relative to the first scan (first row exactly zero) are used as given
    rel = se2_relative(world[0], world)
    c = joined_samples(scans, rel)
    np.testing.assert_array_equal(c.free, a.free)
    np.testing.assert_array_equal(c.obs, a.obs)
    # one scan at the zero pose: the single scan's samples (the half-size by the farthest sample)
    one, single = joined_samples(scans[:1], np.zeros((1, 3))), scan_samples(scans[0])
    np.testing.assert_array_equal(one.free, single.free)
    np.testing.assert_array_equal(one.obs, single.obs)
    assert one.reach_cells == pytest.approx(np.sqrt(np.max(np.sum(single.obs ** 2, axis=1))))
    with pytest.raises(ValueError, match="`odom_poses` must have 2 rows"):
        joined_samples(scans, world[:1])


def test_localise_is_scan_samples_then_localise_samples():
    M = S.test_room_200()
    s = _scan()
    kw = {"delta_alpha_rad": np.radians(5.0), "wall_balance": True}
    a = C.localise(M, s, **kw)
    b = localise_samples(grid_to_values(M), scan_samples(s, **kw))
    assert (a.row, a.col, a.heading_index, a.score, a.rival_score) == (b.row, b.col, b.heading_index, b.score,
                                                                       b.rival_score)
    np.testing.assert_array_equal(a.best_per_heading, b.best_per_heading)


def test_localise_samples_bad_input():
    Mv = grid_to_values(S.test_room_200())
    smp = scan_samples(_scan(), delta_alpha_rad=np.radians(30.0))
    with pytest.raises(TypeError, match="`samples` must be a ScanSamples"):
        localise_samples(Mv, _scan())
    with pytest.raises(ValueError, match="`M_values` must not be empty"):
        localise_samples(np.zeros((0, 3)), smp)
    with pytest.raises(ValueError, match="`window_rad` needs `prior_heading_rad`"):
        localise_samples(Mv, smp, window_rad=0.1)
    with pytest.raises(ValueError, match="`refine` does not support `score_norm='explored'`"):
        localise_samples(Mv, smp, refine=2, score_norm="explored")
    with pytest.raises(ValueError, match="`refine` must be"):
        localise_samples(Mv, smp, refine=-1)
    with pytest.raises(ValueError, match="`refine_heading_rad` must be >= 0"):
        localise_samples(Mv, smp, refine=1, refine_heading_rad=-0.1)
    with pytest.raises(TypeError, match="`params` must be a LocaliseParams; got dict"):
        check_score_norm("none", 0.8, {})


def test_pose_marks_add_up_to_pose_scores():
    M = S.test_room_200()
    Mv = grid_to_values(M)
    smp = joined_samples([_scan(), _scan((62.0, 40.0, 0.5))], [[60.0, 40.0, 0.5], [62.0, 40.0, 0.5]],
                         wall_balance=True)
    poses = np.array([[60.0, 40.0, 0.5], [61.3, 39.6, 0.52], [np.nan, 1.0, 0.0], [1e6, 0.0, 0.0]])
    scores = pose_scores(Mv, smp, poses)
    marks = pose_marks(Mv, smp, poses)
    for sc, mk in zip(scores[:2], marks[:2], strict=True):
        assert sc == float(np.dot(mk.stamp, mk.map))
        assert len(set(zip(mk.row.tolist(), mk.col.tolist(), strict=True))) == mk.row.size  # each cell once
        assert set(np.unique(mk.stamp[~mk.is_obs]).tolist()) == {smp.free_value}
    assert np.isnan(scores[2:]).all()
    assert marks[2:] == [None, None]
    assert pose_scores(Mv, smp, poses[0]).shape == (1,)  # one pose as a (3,) row


def test_pose_scores_bad_input():
    Mv = grid_to_values(S.test_room_200())
    smp = scan_samples(_scan())
    with pytest.raises(ValueError, match=r"`poses` must have shape \(m, 3\)"):
        pose_scores(Mv, smp, [[1.0, 2.0]])
    with pytest.raises(TypeError, match="`poses` must be numbers"):
        pose_marks(Mv, smp, [["a", "b", "c"]])
    with pytest.raises(TypeError, match="`samples` must be a ScanSamples"):
        pose_scores(Mv, (smp.free, smp.obs), [[1.0, 2.0, 0.0]])
    with pytest.raises(ValueError, match="`M_values`"):
        pose_scores(np.full((3, 3), np.nan), smp, [[1.0, 2.0, 0.0]])


def test_scan_stamps_are_the_stamps_localise_correlates():
    # with wall_balance the obstacle marks carry their weights in the stamps too: the best of the stamps' score
    # maps (the definition) is localise's score
    M = S.test_room_200()[20:100, 0:90]
    scan = S.Rangefinder(n_beams=90, max_range_cells=60.0).scan(M, [40.0, 30.0, np.radians(33.0)])
    hs = C.heading_candidates(np.radians(10.0))
    kw = {"wall_balance": True, "dtype": "float64"}
    T, o = C.scan_stamps(scan, hs, **kw)
    smp = scan_samples(scan, **kw)
    assert not np.all(np.isin(T, (-1.0, 0.0, 1.0)))  # weighted obstacle marks
    assert set(np.unique(T[T > 0])) <= set(np.unique(smp.obs_value))
    D = C.score_maps(grid_to_values(M), T, o, method="direct")
    loc = C.localise(M, scan, delta_alpha_rad=np.radians(10.0), ambiguity=False, **kw)
    assert np.isclose(loc.score, D.max())
    assert isinstance(smp, ScanSamples)
