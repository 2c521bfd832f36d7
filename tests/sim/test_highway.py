"""The highway-like keypoint scene (issue 25): path, projections, repeated posts, argument checks."""

import numpy as np
import pytest

from slamlab.geometry.triangulation import triangulate_stereo
from slamlab.sim.highway import HighwayScene, highway_path


def test_highway_path_steps_and_curve():
    p = highway_path(11, step_m=1.0, curvature_per_m=0.002)
    steps = np.linalg.norm(np.diff(p[:, :2], axis=0), axis=1)
    assert steps == pytest.approx(1.0, abs=1e-5)  # chords of a 500 m radius: 1 m to 1e-6
    assert p[-1, 2] == pytest.approx(0.02)
    assert highway_path(3, curvature_per_m=0.0)[:, 1].tolist() == [0.0, 0.0, 0.0]


def test_noise_free_keypoints_triangulate_to_the_landmarks():
    sc = HighwayScene(rng=0)
    pose = highway_path(5)[3]
    fl, fr = sc.observe(pose, pixel_std=0.0, detect_prob=1.0, descriptor_noise=0.0, rng=1)
    # the same landmark in both images has the same descriptor: pair them, then triangulate
    d_l = {tuple(np.round(d, 6)): i for i, d in enumerate(fl.descriptors)}
    pairs = np.array([(d_l[k], j) for j, d in enumerate(fr.descriptors) if (k := tuple(np.round(d, 6))) in d_l])
    assert len(pairs) > 100
    assert fl.uv[pairs[:, 0], 1] == pytest.approx(fr.uv[pairs[:, 1], 1])  # rectified: same row
    tri = triangulate_stereo(sc.rig, fl.uv[pairs[:, 0]], fr.uv[pairs[:, 1]])
    T_wl = sc.ground_truth_se3(pose) @ sc.T_body_left
    world = tri.points @ T_wl[:3, :3].T + T_wl[:3, 3]
    # every triangulated point is one of the scene's landmarks
    gap = np.min(np.linalg.norm(world[:, None, :] - sc.points_m[None, :, :], axis=2), axis=1)
    assert gap.max() < 1e-6 * 300


def test_posts_repeat_and_far_points_dominate():
    sc = HighwayScene(rng=0)
    posts = sc.descriptors[sc.kind == "post"]
    # the posts share a few looks: each post's nearest other post is far closer than two random landmarks
    d = np.linalg.norm(posts[:30, None] - posts[None, :30], axis=2) + 10 * np.eye(30)
    assert d.min(axis=1).max() < 0.5
    far = sc.points_m[sc.kind == "far"]
    assert np.median(far[:, 0]) > 40.0


def test_highway_arguments_are_checked():
    with pytest.raises(ValueError, match="n_frames"):
        highway_path(1)
    with pytest.raises(ValueError, match="curvature_per_m"):
        highway_path(3, curvature_per_m=np.nan)
    with pytest.raises(ValueError, match="post_spacing_m"):
        HighwayScene(post_spacing_m=0.0)
    with pytest.raises(ValueError, match="detect_prob"):
        HighwayScene(rng=0).observe([0, 0, 0], detect_prob=1.5)
    with pytest.raises(ValueError, match="pose"):
        HighwayScene(rng=0).observe([0, 0])
