"""The defaults KITTI 01 informed (ours): their checks, their mechanisms on exact scenes, and the goal tables."""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pytest

from slamlab.geometry import rotation_xyz
from slamlab.geometry.se3 import se3_compose, se3_inverse
from slamlab.geometry.so3 import se3_exp, se3_log
from slamlab.mono import Initialiser, MonoParams, MonoSLAM, relative_pose_essential, relative_pose_homography
from slamlab.mono.mapping import MappingMixin
from slamlab.studies.mono import kitti_goal

K = np.array([[500.0, 0, 320], [0, 500.0, 240], [0, 0, 1]])


def test_the_new_fields_are_checked_by_name():
    with pytest.raises(ValueError, match="`init_plane_share_of` must be one of 'ransac', 'front'"):
        MonoParams(init_plane_share_of="all")
    with pytest.raises(ValueError, match="`reinit_scale` must be one of 'map', 'steps'"):
        MonoParams(reinit_scale="truth")
    with pytest.raises(ValueError, match="`reinit_velocity_frames`"):
        MonoParams(reinit_velocity_frames=0)
    with pytest.raises(TypeError, match="`init_velocity` must be True or False"):
        MonoParams(init_velocity=1)
    with pytest.raises(ValueError, match="`plane_share_of` must be one of"):
        Initialiser(K, lambda im: np.zeros((0, 2)), plane_share_of="inliers")


def _road_scene(rng):
    """A highway in miniature: 100 road points (the plane 1.5 m below the camera, 5-30 m ahead), 10 points
    off the road and 100 points 1 km ahead; the camera moves 1 m forward."""
    road = np.column_stack([rng.uniform(-6, 6, 100), np.full(100, 1.5), rng.uniform(5.0, 30.0, 100)])
    off = np.column_stack([rng.uniform(-6, 6, 10), rng.uniform(-3, 0, 10), rng.uniform(8.0, 15.0, 10)])
    far = np.column_stack([rng.uniform(-300, 300, 100), rng.uniform(-100, 0, 100), np.full(100, 1000.0)])
    X0 = np.vstack([road, off, far])
    R = rotation_xyz(0.002, -0.004, 0.001)
    X1 = X0 @ R.T + np.array([0.02, 0.0, -1.0])

    def proj(X):
        p = X @ K.T
        return p[:, :2] / p[:, 2:3]

    return proj(X0), proj(X1)


def test_the_5_point_ransac_count_keeps_the_far_points_that_recover_pose_drops():
    uv0, uv1 = _road_scene(np.random.default_rng(3))
    e = relative_pose_essential(uv0, uv1, K, ransac_px=1.0)
    h = relative_pose_homography(uv0, uv1, K, ransac_px=1.0)
    assert e.ok
    assert h.ok
    # every pair fits the epipolar geometry exactly, so RANSAC keeps all 210; cv2.recoverPose keeps only points
    # nearer than 50 baselines (1 m × 50): the 110 near ones
    assert e.n_ransac == 210
    assert e.inliers.sum() == 110
    assert h.n_ransac == h.inliers.sum()  # the homography's count has no cheirality cut
    # the homography mixes road and far points, and its pose is wrong where the 5-point's is right
    R_true = rotation_xyz(0.002, -0.004, 0.001)
    angle = lambda Ra: np.degrees(np.arccos(np.clip((np.trace(Ra.T @ R_true) - 1) / 2, -1, 1)))
    assert angle(e.R) < 0.1
    assert angle(h.R) > 5.0
    # against the 110 kept points the road's homography looks dominant (the 'front' count, share 0.9), against
    # the 210 RANSAC inliers it does not (the default)
    assert h.inliers.sum() >= 0.9 * e.inliers.sum()
    assert h.inliers.sum() < MonoParams().init_plane_share * e.n_ransac


def test_the_scale_of_a_new_map_is_the_median_depth_ratio_at_common_pixels():
    rng = np.random.default_rng(4)
    uv_old = rng.uniform(0, 600, (40, 2))
    z_old = rng.uniform(5, 50, 40)
    # 30 new points at old pixels (0.5 px off) with a third of the depth, 20 elsewhere
    uv_new = np.vstack([uv_old[:30] + 0.5, rng.uniform(700, 900, (20, 2))])
    X0 = np.column_stack([np.zeros((50, 2)), np.concatenate([z_old[:30] / 3.0, rng.uniform(1, 2, 20)])])
    res = SimpleNamespace(uv0=uv_new, X0=X0)
    r = {"anchor_uv": uv_old, "anchor_z": z_old}
    assert MappingMixin._map_scale(None, res, r) == pytest.approx(3.0, rel=1e-12)
    # fewer than 10 pixels in common: no scale from the map
    res_few = SimpleNamespace(uv0=np.vstack([uv_old[:9], rng.uniform(700, 900, (41, 2))]), X0=X0)
    assert MappingMixin._map_scale(None, res_few, r) is None


def test_the_first_tracked_frame_starts_from_the_first_maps_motion_per_frame():
    from slamlab.studies.mono.experiments import mono_sim, render_sequence, sequence_poses

    sim = mono_sim("tiny", rng=0)
    imgs, _ = render_sequence(sim, sequence_poses("strafe", 8), progress=False)
    for on in (True, False):
        slam = MonoSLAM(sim.rig.left.K, init_velocity=on)
        for img in imgs:
            slam.process(img)
            if slam.initialised:
                break
        kf0, kf1 = slam.keyframes[0], slam.keyframes[-1]
        n = kf1.frame - kf0.frame
        if not on:
            assert slam._T_cw_prev is None  # no velocity: the next frame starts at the last pose
            continue
        vel = se3_compose(slam._T_cw, se3_inverse(slam._T_cw_prev))
        expected = se3_exp(se3_log(se3_compose(kf1.T_cw, se3_inverse(kf0.T_cw))) / n)
        np.testing.assert_allclose(vel, expected, atol=1e-9)


def test_goal_tables_check_their_goal_and_name_bad_configurations():
    with pytest.raises(ValueError, match="`goal_correct_pct`"):
        kitti_goal.kitti_goal_table({}, goal_correct_pct=-1)
    with pytest.raises(ValueError, match="`goal_ate_pct`"):
        kitti_goal.kitti_goal_table({}, goal_ate_pct=0)
    assert "init_velocity" in kitti_goal.KITTI_GOAL_ABLATIONS["first tracked frame at the last pose"]
    # every row undoes a default: its value differs from the default's
    p = MonoParams()
    for ov in kitti_goal.KITTI_GOAL_ABLATIONS.values():
        assert any(getattr(p, k) != v for k, v in ov.items())
