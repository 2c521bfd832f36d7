"""The stereo pipeline's public stages as the loop calls them, and one route per setting (issue 42, items 1 and 3)."""

from __future__ import annotations

import numpy as np
import pytest

from slamlab.features import Features
from slamlab.geometry import PinholeCamera, StereoRig
from slamlab.kdtree import ExactStore
from slamlab.sim.highway import HighwayScene, highway_path
from slamlab.stereo import (
    RenderParams,
    StereoParams,
    detect_features,
    detect_pair,
    match_in_window,
    match_to_landmarks,
    match_to_map,
)
from slamlab.stereo.landmark_filter import duplicate_mask, gated_update, in_view, landmark_observations
from slamlab.stereo.local_stages import check_features
from slamlab.stereo.map_stages import _window_match
from slamlab.stereo.noise_estimate import KeypointNoiseTracker, disparity_residuals_px
from slamlab.studies import stereo as S
from slamlab.studies.stereo import experiments as E


def _texture(seed=0, shape=(120, 160)):
    g = np.random.default_rng(seed)
    img = g.integers(0, 256, (shape[0] // 4, shape[1] // 4)).astype(np.uint8)
    return np.kron(img, np.ones((4, 4), np.uint8))


def test_detect_pair_is_detect_features_on_each_image_in_threads_or_not():
    left, right = _texture(0), _texture(1)
    for parallel in (True, False):
        fl, fr = detect_pair(left, right, detector="orb", n_features=200, parallel_detect=parallel)
        for f, img in ((fl, left), (fr, right)):
            ref = detect_features(img, detector="orb", n_features=200)
            np.testing.assert_array_equal(f.uv, ref.uv)
            np.testing.assert_array_equal(f.descriptors, ref.descriptors)


def test_check_features_names_the_argument():
    with pytest.raises(TypeError, match=r"`left_features` must be slamlab\.features\.Features"):
        check_features(np.zeros((3, 2)), "left_features")
    f = Features(np.zeros((1, 2)), np.ones(1), np.zeros(1), np.ones(1), np.zeros(1, int), None)
    with pytest.raises(ValueError, match="`right` must have descriptors"):
        check_features(f, "right")


def _twin_store():
    s = ExactStore()
    s.add(np.array([[0.0, 0.0], [0.0, 0.0], [5.0, 5.0]]), [0, 1, 2])  # 0 and 1: one descriptor twice
    X = np.array([[0.0, 0.0, 5.0], [0.01, 0.0, 5.0], [3.0, 0.0, 5.0]])  # 0 and 1: 1 cm apart
    return s, X


def test_match_to_map_uses_the_same_point_rule_in_use():
    s, X = _twin_store()
    D = np.array([[0.0, 0.1]])
    # ORB searches by window by default: two landmarks 3 cm apart count as one (StereoParams.twin_gap_m)
    assert match_to_map(D, s, positions=X, detector="orb").ids.tolist() == [0]
    assert match_to_map(D, s, positions=X, params=StereoParams(same_point_m=0.02)).ids.tolist() == [0]
    # 000's global search: no same-point rule, the ratio rule rejects the pair
    assert match_to_map(D, s, positions=X, detector="orb", map_search="global").ids.size == 0
    assert match_to_map(D, s, positions=X, detector="orb", same_point_m=0).ids.size == 0


def test_match_to_landmarks_is_the_store_search_on_those_landmarks():
    g = np.random.default_rng(3)
    desc = g.normal(size=(40, 8))
    ids = np.arange(100, 140)
    s = ExactStore()
    s.add(desc, ids)
    D = desc[[5, 9, 30]] + 0.01 * g.normal(size=(3, 8))
    D = np.vstack([D, g.normal(size=(2, 8))])
    a = match_to_map(D, s)
    b = match_to_landmarks(D, ids, desc)
    for name in ("local", "ids", "unmatched", "nearest"):
        np.testing.assert_array_equal(getattr(a, name), getattr(b, name))
    np.testing.assert_allclose(a.distance, b.distance, rtol=1e-5)  # the store keeps float32 descriptors
    assert b.ids[b.local < 3].tolist() == [105, 109, 130]
    with pytest.raises(ValueError, match=r"`landmark_descriptors` must have one row per landmark id \(40\); got 39"):
        match_to_landmarks(D, ids, desc[:39])


def test_match_in_window_projects_the_landmarks_and_matches_near_them():
    cam = PinholeCamera(640, 480, 500.0, 500.0, 320.0, 240.0)
    g = np.random.default_rng(5)
    n = 40
    desc = g.integers(0, 256, (n, 32), dtype=np.uint8)
    ids = np.arange(200, 200 + n)
    X = np.zeros((200 + n, 3))
    X[ids] = np.column_stack([np.linspace(-2, 2, n), np.zeros(n), np.full(n, 5.0)])
    uv_lm = cam.project(X[ids])
    pick = [3, 10, 20]
    D = desc[pick]
    uv = uv_lm[pick] + [2.0, 1.0]
    p = StereoParams(detector="orb", window_px=15.0)
    mm, n_pairs = match_in_window(D, uv, ids, desc, X, np.eye(4), cam, params=p)
    assert mm.ids.tolist() == [203, 210, 220]
    ref, n_ref = _window_match(D, uv, desc, uv_lm, ids, 15.0, p.map_ratio, p.window_max_hamming, X, p.twin_gap_m)
    assert n_pairs == n_ref
    for x, y in zip(mm, ref, strict=True):
        np.testing.assert_array_equal(x, y)
    # landmarks whose row lies outside the image by more than the window are no candidates
    T_wc = np.eye(4)
    T_wc[1, 3] = 1.0  # the camera 1 m lower: the landmarks project 100 px above the image
    assert match_in_window(D, uv, ids, desc, X, T_wc, cam, params=p)[1] == 0
    with pytest.raises(ValueError, match=r"`uv` must have shape \(3, 2\)"):
        match_in_window(D, uv[:2], ids, desc, X, np.eye(4), cam, params=p)
    with pytest.raises(TypeError, match="`camera` must be a PinholeCamera"):
        match_in_window(D, uv, ids, desc, X, np.eye(4), StereoRig.parallel(), params=p)
    with pytest.raises(ValueError, match=r"`positions` must have shape \(n, 3\)"):
        match_in_window(D, uv, ids, desc, X[:, :2], np.eye(4), cam, params=p)


def test_landmark_observations_covariance_routes():
    rig = StereoRig.parallel(baseline_m=0.5)
    pts = np.array([[0.5, 0.1, 6.0], [-1.0, 0.2, 9.0]])
    cov = np.tile(np.eye(3) * 1e-3, (2, 1, 1))
    Z, pose_var, Rz = landmark_observations(pts, cov, np.eye(4), np.eye(4), rig)
    np.testing.assert_array_equal(Z, pts)
    p = StereoParams()
    np.testing.assert_allclose(pose_var, p.pose_std_m**2 + (p.pose_std_rad * np.linalg.norm(pts, axis=1)) ** 2)
    np.testing.assert_allclose(Rz, cov + pose_var[:, None, None] * np.eye(3))
    # 'map': the stereo covariance at the landmark, not at the measured point
    X = pts * 1.1
    _, _, Rz_map = landmark_observations(pts, cov, np.eye(4), np.eye(4), rig, landmarks_map=X, update_cov_depth="map")
    _, _, Rz_true = landmark_observations(pts, cov, np.eye(4), np.eye(4), rig, true_cam=X, update_cov_depth="true")
    np.testing.assert_allclose(Rz_map, Rz_true)
    assert np.all(Rz_map[:, 2, 2] > Rz[:, 2, 2])  # deeper: larger depth variance
    with pytest.raises(ValueError, match="`landmarks_map` is needed with update_cov_depth='map'"):
        landmark_observations(pts, cov, np.eye(4), np.eye(4), rig, update_cov_depth="map")
    with pytest.raises(ValueError, match="`true_cam` is needed with update_cov_depth='true'"):
        landmark_observations(pts, cov, np.eye(4), np.eye(4), rig, update_cov_depth="true")


def test_gated_update_leaves_out_inconsistent_observations():
    X = np.zeros((2, 3))
    P = np.tile(np.eye(3) * 0.01, (2, 1, 1))
    Z = np.array([[0.01, 0.0, 0.0], [5.0, 0.0, 0.0]])  # the second: 50 sigma away
    ok, X_new, P_new = gated_update(X, P, Z, P.copy(), 0.0, 16.27)
    assert ok.tolist() == [True, False]
    np.testing.assert_allclose(X_new, [[0.005, 0.0, 0.0]])
    np.testing.assert_allclose(P_new[0], np.eye(3) * 0.005)
    assert gated_update(X, P, Z, P.copy(), 0.0, None)[0].tolist() == [True, True]


def test_duplicates_and_view_gate_on_arrays():
    X = np.array([[1.0, 0.0, 0.0], [9.0, 0.0, 0.0]])
    assert duplicate_mask(np.array([[1.02, 0, 0], [1.0, 0, 0]]), np.array([0, 1]), X, np.eye(4), 0.05).tolist() == [
        True, False]
    cam = PinholeCamera(100, 80, 50.0, 50.0, 50.0, 40.0)
    assert in_view(np.array([[4.0, 0, 5], [6.0, 0, 5]]), np.eye(4), cam, 10.0, 20.0).tolist() == [True, True]


def test_noise_tracker_and_disparity_residuals_check_their_arguments():
    with pytest.raises(TypeError, match="`params` must be a StereoParams"):
        KeypointNoiseTracker({"pixel_std": 0.5})
    rig = StereoRig.parallel()
    X = np.array([[0.0, 0.0, 5.0]])
    with pytest.raises(ValueError, match=r"`landmark_cov` must have shape \(1, 3, 3\)"):
        disparity_residuals_px(np.eye(4), X, np.zeros((2, 3, 3)), X, rig)
    with pytest.raises(TypeError, match="`rig` must be a StereoRig"):
        disparity_residuals_px(np.eye(4), X, np.zeros((1, 3, 3)), X, object())


# -- the studies: every field of `params` reaches the run or is refused by name ----------------------------


def test_disparity_errors_takes_its_detector_from_params(monkeypatch):
    seen = []
    monkeypatch.setattr(E, "disparity_error_table", lambda *a, params: seen.append(params) or "")
    E.disparity_errors(params=StereoParams(detector="sift"))
    E.disparity_errors()
    E.disparity_errors(params=StereoParams(detector="sift"), detector="surf")
    assert [p.detector for p in seen] == ["sift", "orb", "surf"]
    assert seen[1] == E.DISPARITY_PARAMS


def test_variants_refuse_a_second_route_for_a_field():
    poses = np.zeros((2, 3))
    with pytest.raises(ValueError, match=r"`policy` is set by this study itself \(`variants\['b'\]` sets it\)"):
        E.run_stereo_slam_variants(poses, {"a": {}, "b": {"policy": "all"}}, params=StereoParams(policy="all"))
    with pytest.raises(ValueError, match=r"`variants\['a'\]` is a StereoParams, which replaces `params`"):
        E.run_stereo_slam_variants(poses, {"a": StereoParams()}, params=StereoParams(ratio=0.7))
    with pytest.raises(ValueError, match=r"`detector` is set by this study itself \(`variants\['ORB, oldest'\]` sets it\)"):
        E.run_comparison("turn in place", params=StereoParams(detector="sift"))
    with pytest.raises(TypeError, match="has no field"):
        E.run_stereo_slam_variants(poses, {"a": {"typo": 1}}, params=StereoParams(policy="all"))


def test_variants_build_on_params(monkeypatch):
    seen = {}

    class FakeSLAM:
        def __init__(self, rig, T_body_left, *, params, store, rng):
            seen[len(seen)] = params
            raise RuntimeError("stop")

    monkeypatch.setattr(E, "StereoSLAM", FakeSLAM)
    with pytest.raises(RuntimeError, match="stop"):
        E.run_stereo_slam_variants(np.zeros((2, 3)), {"a": {"detector": "orb"}}, params=StereoParams(ratio=0.7))
    assert seen[0] == StereoParams(ratio=0.7, detector="orb")


def test_drift_study_refuses_a_render_that_sets_the_drift():
    with pytest.raises(ValueError, match=r"`render` sets 'drift_std_rad' = 0\.001, which run_drift_study varies itself"):
        S.run_drift_study((0.0,), render=RenderParams(drift_std_rad=1e-3))


def test_scale_ablation_refuses_a_field_a_setting_sets():
    with pytest.raises(ValueError, match=r"`weight_depth` is set by this study itself \(the setting 'w' of `variants` sets it\)"):
        S.run_scale_ablation(lambda rng: HighwayScene(rng=rng), highway_path(3), {"w": {"weight_depth": "map"}},
                             params=S.ABLATION_BASE.replace(weight_depth="measured"))
    with pytest.raises(ValueError, match="`pixel_std_obs` must be"):
        S.run_scale_ablation(lambda rng: HighwayScene(rng=rng), highway_path(3), {"w": {}}, pixel_std_obs=-1.0)


def test_run_experiment_is_the_turn_or_the_loop():
    with pytest.raises(ValueError, match="`experiment` must be one of"):
        S.run_experiment("spiral")
    assert set(S.EXPERIMENTS) == {"turn in place", "closed loop"}
    assert len(E.experiment_poses("closed loop")) == 57
    assert len(E.experiment_poses("turn in place")) == 37
