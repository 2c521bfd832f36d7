"""StereoSLAM with KITTI_PARAMS on the 51-frame KITTI 06 set (59.9 m): issue 25's stereo goal for SURF and ORB.

Bounds from the goal, not from our output: path length within 1 % of the truth and ATE at most 1 % of
the path, with the same defaults for both detectors (the detector changed only), and for RANSAC seeds 0-2: a goal
met with one seed only is not met (stop 36's SURF missed it with seed 1).
"""

import numpy as np
import pytest

from slamlab.studies.stereo import run_kitti


@pytest.mark.realdata
@pytest.mark.parametrize("seed", [0, 1, 2])
@pytest.mark.parametrize("detector", ["surf", "orb"])
def test_kitti_06_51_frames_keeps_the_scale(real_data, detector, seed):
    res = run_kitti(real_data / "kitti-odometry-06-stereo-51", detector=detector, rng=seed, progress=False)
    assert len(res.truth) == 51
    assert res.path_length_m == pytest.approx(59.9, abs=0.1)
    assert res.n_degenerate == 0
    assert abs(res.length_ratio - 1) <= 0.01
    assert abs(res.end_distance_ratio - 1) <= 0.01  # the displacement too, which pose jitter does not lengthen
    assert res.ate_m <= 0.01 * res.path_length_m
    assert res.step_ratios.shape == (50,)
    assert np.isfinite(res.step_ratios).all()
