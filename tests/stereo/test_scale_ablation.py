"""The scale ablation on the simulated highway (issue 25), and StereoSLAM.process_features."""

import numpy as np
import pytest

from slamlab.sim.highway import HIGHWAY_CONDITIONS, HighwayScene, highway_path
from slamlab.stereo import StereoSLAM
from slamlab.studies.stereo import KITTI_PARAMS, run_scale_ablation
from slamlab.studies.stereo.scale_ablation import PROPOSED_FIX, run_condition_ablation


def _scene(rng):
    return HighwayScene(rng=rng)


def test_highway_ablation_base_and_the_measured_depth_weights():
    """The ablation's base (KITTI_PARAMS of stop 36, ``ABLATION_BASE``) on the highway-like scene: path length within
    1 % of the truth (its displacement is not: see the PROPOSED_FIX tests below).

    One seed, 21 frames (20 m), keypoint noise 0.5 px. Also without keypoint noise the path is exact, and the
    two measured-depth weights alone bias the scale in opposite directions (the ablation's finding).
    """
    variants = {"defaults": {}, "no keypoint noise": {"pixel_std_obs": 0.0},
                "pose weight at the measured depth": {"weight_depth": "measured"},
                "filter covariance at the measured depth": {"update_cov_depth": "measured"}}
    a = run_scale_ablation(_scene, highway_path(21), variants, n_seeds=1, rng=0)
    ratio = a.path_ratio[:, 0]
    assert abs(ratio[0] - 1) <= 0.01
    assert abs(ratio[1] - 1) <= 0.002
    assert ratio[2] > ratio[0] > ratio[3]
    assert a.n_degenerate.sum() == 0
    assert "no keypoint noise" in a.table()
    assert "keypoint noise 0.5 px" in a.table()
    assert a.step_mean_se().shape == (4, 2)
    assert "4 settings x 1 seeds" in str(a)


def test_process_features_runs_the_stages_after_detection():
    sc = HighwayScene(rng=0)
    slam = StereoSLAM(sc.rig, sc.T_body_left, params=KITTI_PARAMS, rng=0)
    g = np.random.default_rng(0)
    for pose in highway_path(3):
        rec = slam.process_features(*sc.observe(pose, rng=g))
    assert rec.status == "ok"
    assert rec.n_inliers > 30
    assert np.linalg.norm(slam.trajectory[-1, :3, 3]) == pytest.approx(2.0, abs=0.1)
    with pytest.raises(TypeError, match=r"`left_features` must be slamlab\.features\.Features"):
        slam.process_features(np.zeros((3, 2)), None)


def test_scale_ablation_arguments_are_checked():
    with pytest.raises(TypeError, match="scene_factory"):
        run_scale_ablation(None, highway_path(3))
    with pytest.raises(ValueError, match="poses"):
        run_scale_ablation(_scene, np.zeros((2, 3)))
    with pytest.raises(TypeError, match="variants"):
        run_scale_ablation(_scene, highway_path(3), {})
    with pytest.raises(ValueError, match="n_seeds"):
        run_scale_ablation(_scene, highway_path(3), n_seeds=0)
    with pytest.raises(ValueError, match="pixel_std_obs"):
        run_scale_ablation(_scene, highway_path(3), {"x": {"pixel_std_obs": -1.0}})
    with pytest.raises(ValueError, match="weight_depth"):
        run_scale_ablation(_scene, highway_path(3), {"x": {"weight_depth": "guess"}})


def test_moving_vehicles_bias_the_scale_with_the_expected_signs():
    """Oncoming vehicles make us seem faster, vehicles moving with us slower (issue 25's scene conditions).

    One seed, 21 frames, KITTI_PARAMS; the same seed for every condition.
    """
    labels = ("plain scene (0.5 px)", "6 oncoming vehicles", "4 vehicles ahead, our speed")
    conds = {lab: ((lambda rng, kw=HIGHWAY_CONDITIONS[lab][0]: HighwayScene(rng=rng, **kw)), HIGHWAY_CONDITIONS[lab][1])
             for lab in labels}
    res = run_condition_ablation(conds, highway_path(21), {"KITTI_PARAMS": {}}, n_seeds=1, rng=0)
    plain, oncoming, ahead = (a.path_ratio[0, 0] for a in res.results)
    assert oncoming > plain + 0.005
    assert ahead < plain - 0.005
    assert "6 oncoming vehicles" in res.table()
    assert "end est./true" in res.table()
    assert "end est./true" in res.results[0].table(end=True)
    assert "end est./true" not in res.results[0].table()  # the default table keeps its columns; end=True adds one
    assert res.results[0].end_ratio[0, 0] == pytest.approx(plain, abs=0.05)  # no jitter to speak of at 0.5 px
    assert "3 conditions" in str(res)
    with pytest.raises(TypeError, match="conditions"):
        run_condition_ablation({}, highway_path(3))
    with pytest.raises(TypeError, match="conditions"):
        run_condition_ablation({"x": _scene}, highway_path(3))


def test_proposed_fix_keeps_path_and_displacement_within_one_percent():
    """Issue 25's goal (within 1 %) for both the path length and the displacement (end ratio) with PROPOSED_FIX.

    Bound from the goal. One seed, 21 frames, 0.5 px; the same scene with KITTI_PARAMS and the pose-weight
    oracle runs alongside, and the refined pose jitters less (step ratio spread) than the 3-D fit's.
    """
    variants = {"defaults": {}, "fix": PROPOSED_FIX, "oracle": {"weight_depth": "true"}}
    a = run_scale_ablation(_scene, highway_path(21), variants, n_seeds=1, rng=0)
    assert abs(a.path_ratio[1, 0] - 1) <= 0.01
    assert abs(a.end_ratio[1, 0] - 1) <= 0.01
    assert a.step_ratios[1].std() < a.step_ratios[0].std()
    assert np.isfinite(a.end_ratio[2, 0])
    assert a.n_degenerate.sum() == 0


@pytest.mark.xfail(strict=True, reason="KITTI_PARAMS' disparity-offset estimate takes each frame pair's previous "
                                      "pixels as exact, which biases the offset up on this exact rig: path 0.990 "
                                      "(the bound is 1 %); see slamlab/stereo/disparity_offset.py")
def test_kitti_params_meet_the_highway_goal_in_path_and_displacement():
    """Today's KITTI_PARAMS themselves (PROPOSED_FIX adopted, stop 37), not an override of the ablation's base: the
    path and the displacement within 1 % on the simulated highway (bound from issue 25's goal; one seed, 21 frames)."""
    from slamlab.studies.stereo import KITTI_PARAMS

    a = run_scale_ablation(_scene, highway_path(21), {"KITTI_PARAMS": {}}, params=KITTI_PARAMS, n_seeds=1, rng=0)
    assert abs(a.path_ratio[0, 0] - 1) <= 0.01
    assert abs(a.end_ratio[0, 0] - 1) <= 0.01
