"""StereoSLAM on the 20 real KITTI frames (sequence 06, 000000-000019): ATE and RPE against the ground truth."""

import cv2
import numpy as np
import pytest

from slamlab.evaluation import Trajectory, ate, rpe
from slamlab.geometry import PinholeCamera, StereoRig
from slamlab.stereo import StereoSLAM


@pytest.mark.realdata
def test_kitti_06_first_20_frames(real_data):
    d = real_data / "kitti-odometry-06-stereo"
    P = np.loadtxt(d / "calib.txt").reshape(2, 3, 4)  # P0, P1 of the rectified pair (PROVENANCE.md)
    fx, cx, cy = P[0][0, 0], P[0][0, 2], P[0][1, 2]
    baseline_m = -P[1][0, 3] / fx
    assert baseline_m == pytest.approx(0.537, abs=1e-3)
    cam = PinholeCamera(1226, 370, fx, fx, cx, cy)
    rig = StereoRig(cam, cam, np.eye(3), np.array([-baseline_m, 0.0, 0.0]))
    gt = np.loadtxt(d / "poses.txt").reshape(-1, 3, 4)  # left-camera poses in the frame-0 camera frame
    slam = StereoSLAM(rig, np.eye(4), max_depth_m=40.0, rng=0)  # map frame = the first left camera frame
    for i in range(20):
        left = cv2.imread(str(d / "image_0" / f"{i:06d}.png"), cv2.IMREAD_GRAYSCALE)
        right = cv2.imread(str(d / "image_1" / f"{i:06d}.png"), cv2.IMREAD_GRAYSCALE)
        slam.process(left, right)
    est = slam.trajectory
    t = np.arange(20) * 0.1  # about 10 Hz
    ref = Trajectory(gt[:, :, 3], gt[:, :, :3], t)
    ours = Trajectory(est[:, :3, 3], est[:, :3, :3], t)
    assert len(slam.degenerate_frames) == 0
    # stated bounds (the car drives 22.7 m), about twice what we measured with the defaults (our SURF,
    # multi kd-tree, oldest-landmark policy; seed 0): ATE 0.18 m unaligned / 0.10 m after SE(3),
    # RPE 0.14 m per frame, final error 0.10 m (0.45 %)
    assert ate(ref, ours, align="none").rmse < 0.35
    assert ate(ref, ours, align="se3").rmse < 0.2
    assert rpe(ref, ours, delta=1).rmse < 0.3
    final_err = np.linalg.norm(est[-1, :3, 3] - gt[-1, :, 3])
    assert final_err < 0.03 * np.linalg.norm(gt[-1, :, 3])


@pytest.mark.realdata
def test_run_kitti_matches_the_manual_loop(real_data):
    from slamlab.studies.stereo import run_kitti

    res = run_kitti(real_data / "kitti-odometry-06-stereo")
    assert res.n_degenerate == 0
    assert res.path_length_m == pytest.approx(22.7, abs=0.1)
    assert res.ate_se3_m < 0.2
    assert res.final_error_m < 0.03 * res.path_length_m
    assert res.name == "kitti-odometry-06-stereo"  # the folder's name
    assert "kitti-odometry-06-stereo, frames 0-19" in res.table()


@pytest.mark.realdata
def test_orb_on_kitti_keeps_the_scale(real_data):
    """ORB with KITTI_PARAMS (refined disparities, one pyramid level): issue 17's 1 % scale goal.

    Measured (seed 0): path length 1.0066 x and start-to-end 1.0040 x the truth, ATE 0.26 m, final 0.28 m;
    with OpenCV's 8 levels 1.019 / 1.015 (the per-frame step lengths spread twice as much). With issue 25's
    KITTI_PARAMS (window search, weights at the landmark's depth): 1.0042 / 1.0029, ATE 0.175 m. Bounds:
    1.5 % on the scale (the 19 steps' standard error is ~0.6 %), ATE and final error about 1.5x measured.
    """
    from slamlab.studies.stereo import run_kitti

    res = run_kitti(real_data / "kitti-odometry-06-stereo", detector="orb", progress=False)
    assert res.n_degenerate == 0
    assert abs(res.length_ratio - 1) < 0.015
    assert abs(res.end_distance_ratio - 1) < 0.015
    assert res.ate_m < 0.4
    assert res.final_error_m < 0.45
    assert res.step_ratios.shape == (19,)
    assert abs(res.step_ratios.mean() - 1) < 0.015
