"""KITTI_PARAMS on both shared KITTI sets, SURF and ORB: one set of defaults, no per-scene switch (real data).

Bounds from the goal, not from our output: the path length within 1.5 % of the truth and the ATE at most 1 % of the
path, on KITTI 06 (51 frames, 59.9 m, the set the defaults were tuned on) and KITTI 01 (the highway, frames 0-50,
51.8 m, about 1 m per frame: the set that informed the disparity-offset estimate and ``refine_min_seen``).
"""

import pytest

from slamlab.studies.stereo import KITTI_GOAL, run_kitti

CASES = [
    ("kitti-odometry-06-stereo-51", "surf", 59.9),
    ("kitti-odometry-06-stereo-51", "orb", 59.9),
    pytest.param("kitti-odometry-01-stereo", "surf", 51.8, marks=pytest.mark.xfail(
        strict=True, reason="SURF on KITTI 01 misses the goal: few inliers (about 45 a frame) leave the "
                            "disparity offset estimate noisy; path 1.04, ATE 1.8 % of the path with seed 2010")),
    ("kitti-odometry-01-stereo", "orb", 51.8),
]


def test_the_goal_is_the_brief_s():
    assert KITTI_GOAL == {"path_tolerance": 0.015, "ate_share": 0.01}


@pytest.mark.realdata
@pytest.mark.parametrize(("name", "detector", "path_m"), CASES)
def test_one_set_of_defaults_keeps_both_scenes_within_the_goal(real_data, name, detector, path_m):
    res = run_kitti(real_data / name, detector=detector, rng=0, progress=False)
    assert len(res.truth) == 51
    assert res.path_length_m == pytest.approx(path_m, abs=0.1)
    assert abs(res.length_ratio - 1) <= 0.015
    assert res.ate_m <= 0.01 * res.path_length_m


def test_bad_input_names_the_argument():
    from slamlab.studies.stereo import kitti_ablation_table, kitti_set_runs, kitti_sets_table

    with pytest.raises(TypeError, match="variants"):
        kitti_set_runs({})
    with pytest.raises(TypeError, match="detectors"):
        kitti_set_runs({"defaults": {}}, detectors="orb")
    with pytest.raises(TypeError, match="sets"):
        kitti_set_runs({"defaults": {}}, sets="kitti-odometry-01-stereo")
    with pytest.raises(TypeError, match="runs"):
        kitti_ablation_table({})
    with pytest.raises(ValueError, match="runs"):
        kitti_sets_table({})
