"""The highway-like keypoint scene (issue 25): path, projections, repeated posts, argument checks."""

import numpy as np
import pytest

from slamlab.geometry.triangulation import triangulate_stereo
from slamlab.sim.highway import HIGHWAY_CONDITIONS, HighwayScene, highway_path


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
    with pytest.raises(ValueError, match="pyramid_levels"):
        HighwayScene(pyramid_levels=0)
    with pytest.raises(ValueError, match="pyramid_scale"):
        HighwayScene(pyramid_scale=1.0)
    with pytest.raises(ValueError, match="level_ref_m"):
        HighwayScene(level_ref_m=-1.0)
    with pytest.raises(ValueError, match="disparity_locking"):
        HighwayScene(disparity_locking=1.5)
    with pytest.raises(ValueError, match="disparity_bias_px"):
        HighwayScene(disparity_bias_px=np.inf)
    with pytest.raises(ValueError, match="n_oncoming"):
        HighwayScene(n_oncoming=-1)
    with pytest.raises(ValueError, match="n_ahead"):
        HighwayScene(n_ahead=-1)
    with pytest.raises(ValueError, match="vehicle_speed"):
        HighwayScene(vehicle_speed=-1.0)


def test_scene_options_off_leave_the_scene_and_keypoints_unchanged():
    """The options' defaults draw nothing: the plain scene (notebook 05 §7d) is the same with them spelled out."""
    a, b = HighwayScene(rng=0), HighwayScene(rng=0, **dict.fromkeys(("n_oncoming", "n_ahead"), 0), pyramid_levels=1)
    assert np.array_equal(a.points_m, b.points_m)
    assert np.array_equal(a.descriptors, b.descriptors)
    fa, fb = a.observe([3.0, 0, 0], rng=1), b.observe([3.0, 0, 0], rng=1)
    assert all(np.array_equal(x.uv, y.uv) for x, y in zip(fa, fb, strict=True))
    assert set(HIGHWAY_CONDITIONS) >= {"plain scene (0.5 px)", "6 oncoming vehicles"}


def test_disparity_options_and_pyramid_levels():
    pose = highway_path(3)[1]
    kw = {"pixel_std": 0.3, "detect_prob": 1.0, "descriptor_noise": 0.0}
    for opts, check in (({"disparity_locking": 1.0}, lambda d: np.abs(d - np.rint(d)).max() < 1e-9),
                        ({"disparity_bias_px": -0.2}, lambda d: True)):
        sc = HighwayScene(rng=0, **opts)
        fl, fr = sc.observe(pose, rng=1, **kw)
        # same landmark, same descriptor (no descriptor noise): pair left and right keypoints
        il, ir = np.argmax(fl.descriptors @ sc.descriptors.T, 1), np.argmax(fr.descriptors @ sc.descriptors.T, 1)
        pos = {k: j for j, k in enumerate(ir)}
        pairs = np.array([(i, pos[k]) for i, k in enumerate(il) if k in pos and sc.kind[k] != "post"])
        d = fl.uv[pairs[:, 0], 0] - fr.uv[pairs[:, 1], 0]
        assert check(d)
    # the disparity bias shifts the mean disparity error by the bias
    sc0, sc1 = HighwayScene(rng=0), HighwayScene(rng=0, disparity_bias_px=-0.2)
    d0 = [f.uv[:, 0].mean() for f in sc0.observe(pose, rng=1, **kw)]
    d1 = [f.uv[:, 0].mean() for f in sc1.observe(pose, rng=1, **kw)]
    assert d1[0] == d0[0]
    assert d1[1] > d0[1]
    # far keypoints come from coarse levels with level_ref_m; their octave is reported
    sc = HighwayScene(rng=0, pyramid_levels=8, level_ref_m=10.0)
    fl, _ = sc.observe(pose, rng=1, **kw)
    assert fl.octave.min() == 0
    assert fl.octave.max() == 7
    assert fl.scale_px.max() == pytest.approx(2.0 * 1.2**7)
    assert HighwayScene(rng=0, pyramid_levels=8).observe(pose, rng=1, **kw)[0].octave.max() > 0


def test_vehicles_move_along_the_road():
    sc = HighwayScene(rng=0, n_oncoming=2, n_ahead=1, vehicle_speed=0.5)
    car = sc.kind == "vehicle"
    assert car.sum() == 24
    assert len(sc.descriptors) == len(sc.points_m) == len(sc.velocity)
    moved = sc.points_at([10.0, 0.0, 0.0]) - sc.points_at([0.0, 0.0, 0.0])
    assert moved[~car].tolist() == np.zeros(((~car).sum(), 3)).tolist()
    assert sorted(set(np.round(moved[car, 0], 9))) == [-5.0, 5.0]
