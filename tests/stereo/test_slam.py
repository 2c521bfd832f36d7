"""The StereoSLAM loop (000 §3.3-3.6) on a short seeded rendered run, with stated bounds."""

import numpy as np
import pytest

from slamlab.geometry import StereoRig, wrap_angle
from slamlab.kdtree import ExactStore
from slamlab.kdtree.stores import MultiKDTree, NonBaseBuffer
from slamlab.sim.arena import StereoArena, StereoSim
from slamlab.sim.stereo_paths import turn_in_place
from slamlab.stereo import STAGES, StereoParams, StereoSLAM
from slamlab.studies.stereo.experiments import StereoRunResult, run_stereo_slam, run_stereo_slam_variants


@pytest.fixture(scope="module")
def short_turn():
    # 8 frames of a turn in place, 5 deg per frame, in the 6x8 m arena
    poses = turn_in_place(np.deg2rad(5.0))[:8]
    return poses, run_stereo_slam(poses, name="turn in place", arena=StereoArena(texture_seed=0), rng=0)


def test_short_turn_tracks_the_ground_truth(short_turn):
    poses, res = short_turn
    assert isinstance(res, StereoRunResult)
    # bounds: 000 §3.7.1 quotes <= 15 cm and <= 5 deg over a whole turn; a short run must do better
    assert res.pos_err_m.max() < 0.10
    assert np.rad2deg(np.abs(res.yaw_err_rad)).max() < 2.0
    assert len(res.degenerate) == 0
    np.testing.assert_allclose(res.truth[:, 2], poses[:, 2] - poses[0, 2])
    assert res.counts["n_stereo"].min() > 300
    assert res.counts["n_inliers"][1:].min() > 100
    assert set(res.stage_time_s) == set(STAGES)
    assert res.fps > 0
    assert "turn in place" in res.table()
    assert "frames/s" in res.timing_table()


def test_run_is_deterministic(short_turn):
    poses, res = short_turn
    again = run_stereo_slam(poses[:4], name="turn in place", arena=StereoArena(texture_seed=0), rng=0)
    np.testing.assert_array_equal(again.estimate, res.estimate[:4])


def test_same_frame_twice_gives_identity_and_base_landmarks():
    sim = StereoSim(StereoArena(texture_seed=1), rng=0)
    slam = StereoSLAM(sim.rig, sim.T_body_left, params=StereoParams(), rng=0)
    pair = sim.render_pair([3.0, 4.0, 0.3])
    assert slam.process(*pair).status == "init"
    for _ in range(2):
        rec = slam.process(*pair)
        assert rec.status == "ok"
    np.testing.assert_allclose(slam.T, np.eye(4), atol=1e-9)
    # every landmark seen in three frames is now base (000 §3.4)
    assert rec.n_base == rec.n_inliers
    assert len(slam.landmark_map()) == rec.n_base
    # the default store is 000's: the multi kd-tree behind the non-base buffer (float descriptors)
    assert isinstance(slam.store, NonBaseBuffer)
    assert isinstance(slam.store.base, MultiKDTree)
    assert len(slam.store.base) == rec.n_base


def test_default_store_follows_the_descriptor_type():
    rig = StereoRig.parallel()
    assert isinstance(StereoSLAM(rig, detector="orb").store, ExactStore)  # Hamming: no kd-tree
    assert isinstance(StereoSLAM(rig, detector="sift").store.base, MultiKDTree)


def test_parallel_detection_gives_the_serial_result():
    rig = StereoRig.parallel(0.2, 384, 288)
    sim = StereoSim(StereoArena(texture_seed=1), rig, rng=0)
    pairs = [sim.render_pair([3.0, 4.0, yaw]) for yaw in (0.0, 0.05, 0.1)]
    runs = []
    for parallel in (True, False):
        slam = StereoSLAM(rig, sim.T_body_left, parallel_detect=parallel, rng=0)
        runs.append([slam.process(*p) for p in pairs] and slam)
    np.testing.assert_array_equal(runs[0].trajectory, runs[1].trajectory)
    assert runs[0].records == runs[1].records
    assert runs[0].records[-1].n_inliers > 20  # a real pose, not an empty run


def test_degenerate_frames_keep_the_pose_and_are_counted():
    rig = StereoRig.parallel(0.2, 192, 144)
    sim = StereoSim(StereoArena(texture_seed=1), rig, rng=0)
    slam = StereoSLAM(rig, sim.T_body_left, n_features=500, rng=0)
    slam.process(*sim.render_pair([3.0, 4.0, 0.0]))
    blank = np.zeros((144, 192), np.uint8)
    rec = slam.process(blank, blank)
    assert rec.status == "too_few_matches"
    # a view of a different part of the arena: few or no matches, the pose is kept
    rec2 = slam.process(*sim.render_pair([3.0, 4.0, np.pi]))
    assert rec2.status in ("too_few_matches", "ransac_failed")
    np.testing.assert_array_equal(slam.poses[1], slam.poses[0])
    np.testing.assert_array_equal(slam.poses[2], slam.poses[0])
    assert slam.degenerate_frames.tolist() == [1, 2]
    fresh = StereoSLAM(rig, sim.T_body_left, rng=0)
    assert fresh.process(blank, blank).status == "too_few_points"
    assert len(fresh.degenerate_frames) == 1


def test_policy_and_store_are_pluggable():
    rig = StereoRig.parallel(0.2, 384, 288)
    sim = StereoSim(StereoArena(texture_seed=1), rig, rng=0)
    created = []

    def factory():
        created.append(ExactStore())
        return created[-1]

    slam = StereoSLAM(rig, sim.T_body_left, store=factory, policy="all", n_features=500, rng=0)
    for yaw in (0.0, 0.05):
        slam.process(*sim.render_pair([3.0, 4.0, yaw]))
    assert slam.store is created[0]
    assert len(created[0]) > 0
    # a class is a factory too
    assert isinstance(StereoSLAM(rig, store=ExactStore).store, ExactStore)
    assert abs(float(wrap_angle(slam.planar_trajectory[-1, 2] - 0.05))) < np.deg2rad(1.0)


def test_bad_input():
    rig = StereoRig.parallel()
    with pytest.raises(TypeError, match="rig"):
        StereoSLAM(None)
    with pytest.raises(ValueError, match="detector"):
        StereoSLAM(rig, detector="surf-xyz")
    with pytest.raises(ValueError, match="policy"):
        StereoSLAM(rig, policy="newest")
    with pytest.raises(TypeError, match="LandmarkStore"):
        StereoSLAM(rig, store=object())
    with pytest.raises(TypeError, match="no field"):
        StereoSLAM(rig, n_points=5)
    with pytest.raises(ValueError, match="orb_levels"):
        StereoSLAM(rig, detector="orb", orb_levels=0)
    with pytest.raises(TypeError, match="`params` must be a StereoParams"):
        StereoSLAM(rig, params={"detector": "orb"})
    with pytest.raises(ValueError, match="T_body_left"):
        StereoSLAM(rig, np.eye(3))
    with pytest.raises(ValueError, match="poses"):
        run_stereo_slam(np.zeros((1, 3)))
    slam = StereoSLAM(rig)
    with pytest.raises(ValueError, match="images"):
        slam.process(np.zeros((4, 4, 4, 4)), np.zeros((4, 4)))
    h, w = rig.left.height_px, rig.left.width_px
    with pytest.raises(ValueError, match=rf"same shape; got \({h}, {w}\) and \({h}, {w - 1}\)"):
        slam.process(np.zeros((h, w), np.uint8), np.zeros((h, w - 1), np.uint8))
    with pytest.raises(ValueError, match=rf"must be {h}x{w} .* got 10x12"):
        slam.process(np.zeros((10, 12), np.uint8), np.zeros((10, 12), np.uint8))
    assert slam.frame == 0  # nothing was processed


def test_calibration_drift_costs_stereo_matches():
    from slamlab.studies.stereo import run_drift_study

    study = run_drift_study((0.0, 1e-3, 3e-3), n_frames=6, detector="orb", rng=0)
    none, mild, strong = study.runs
    # the right camera's random walk moves its image by ~1 px per mrad (f = 1055 px): the 2-px
    # epipolar band keeps fewer stereo matches the stronger the drift, in every frame
    assert np.all(mild.counts["n_stereo"] < none.counts["n_stereo"])
    assert np.all(strong.counts["n_stereo"] < 0.5 * none.counts["n_stereo"])
    assert len(none.degenerate) == 0
    assert none.pos_err_m.max() < 0.1
    assert len(strong.degenerate) > 0  # tracking lost
    assert "calibration drift" in study.table()
    with pytest.raises(ValueError, match="drift_std_rad"):
        run_drift_study((-1e-3,), n_frames=2)
    with pytest.raises(ValueError, match="experiment"):
        run_drift_study((0.0,), experiment="spiral")
    with pytest.raises(ValueError, match="size"):
        run_drift_study((0.0,), size="huge")


def test_drift_study_on_sweep_equals_the_sequential_loop_for_one_and_two_workers():
    from slamlab.stereo import RenderParams
    from slamlab.studies.stereo import run_drift_study, run_experiment

    levels = (0.0, 2e-3)
    # the study as it was: one run per level, in order, every level with the same seed
    ref = [run_experiment("turn in place", n_frames=3, detector="orb", render=RenderParams(drift_std_rad=d), rng=5) for d in levels]
    one = run_drift_study(levels, n_frames=3, detector="orb", rng=5, n_jobs=1, progress=False)
    two = run_drift_study(levels, n_frames=3, detector="orb", rng=5, n_jobs=2, progress=False)
    for study in (one, two):
        assert study.drift_std_rad == levels
        for r, s in zip(ref, study.runs, strict=True):
            np.testing.assert_array_equal(s.estimate, r.estimate)
            for k in r.counts:
                np.testing.assert_array_equal(s.counts[k], r.counts[k])
    assert one.table() == two.table()


def test_update_gate_keeps_inconsistent_observations_from_throwing_landmarks():
    # two stereo sightings 4 m away from viewpoints 10 deg apart: each ellipsoid is long along its ray
    # (depth sigma 5 cm, lateral 3 mm). A 20 cm sideways disagreement (a pose error) fused without a
    # gate moves the landmark far along the rays, much further than the disagreement itself
    def ray_cov(direction):
        r = np.asarray(direction, float) / np.linalg.norm(direction)
        return 0.003**2 * np.eye(3) + (0.05**2 - 0.003**2) * np.outer(r, r)

    P0 = ray_cov([1.0, 0.0, 0.0])[None]
    R1 = ray_cov([np.cos(0.17), np.sin(0.17), 0.0])[None]
    X0 = np.array([[4.0, 0.0, 0.0]])
    Z_bad = X0 + np.array([[0.0, 0.2, 0.0]])
    Z_good = X0 + np.array([[0.01, 0.002, 0.0]])
    from slamlab.filters.landmark import landmark_update

    X_fused, _ = landmark_update(X0, P0, Z_bad, R1)
    assert np.linalg.norm(X_fused - X0) > 0.5  # the failure the gate prevents (0.2 m in, > 0.5 m out)
    rig = StereoRig.parallel()
    for gate, expect in ((16.27, [False, True]), (None, [True, True])):
        slam = StereoSLAM(rig, update_gate=gate, pose_std_m=0.0, pose_std_rad=0.0, state_var=0.0)
        slam.X, slam.P = np.vstack([X0, X0]), np.concatenate([P0, P0])
        ok = slam.refine_landmarks(np.array([0, 1]), np.vstack([Z_bad, Z_good]), np.concatenate([R1, R1]))
        assert ok.tolist() == expect
        if gate is not None:
            np.testing.assert_array_equal(slam.X[0], X0[0])  # untouched
        assert np.linalg.norm(slam.X[1] - X0[0]) < 0.02  # a consistent sighting refines its landmark


def test_variants_on_shared_frames_equal_separate_runs(short_turn):
    from slamlab.studies.stereo import comparison_table, run_comparison, run_stereo_slam_variants

    poses, res = short_turn
    both = run_stereo_slam_variants(poses, {"a": {}, "b": {"policy": "all"}}, name="turn in place", arena=StereoArena(texture_seed=0), rng=0)
    np.testing.assert_array_equal(both["a"].estimate, res.estimate)
    alone = run_stereo_slam(poses, name="turn in place", arena=StereoArena(texture_seed=0), rng=0, policy="all")
    np.testing.assert_array_equal(both["b"].estimate, alone.estimate)
    cmp = run_comparison("turn in place", n_frames=3)
    assert [(r.detector, r.policy, r.n_frames) for r in cmp.values()] == [("surf", "oldest", 3), ("orb", "oldest", 3), ("orb", "all", 3)]
    table = comparison_table(cmp)
    assert "ORB, all" in table
    assert "heading error back at 0 deg" in table
    with pytest.raises(TypeError, match="variants"):
        run_stereo_slam_variants(poses, {})
    with pytest.raises(ValueError, match="policy"):
        run_comparison(variants={"x": {"policy": "newest"}}, n_frames=2)
    with pytest.raises(ValueError, match="experiment"):
        run_comparison("spiral")


def test_ill_conditioned_poses_are_not_trusted():
    # the rotation std of a normal frame is ~0.3-1.4 mrad: a limit of 1 urad rejects every pose, and a
    # rejected frame behaves like a RANSAC failure (pose kept, nothing added, counted as degenerate)
    rig = StereoRig.parallel(0.2, 384, 288)
    sim = StereoSim(StereoArena(texture_seed=1), rig, rng=0)
    pairs = [sim.render_pair([3.0, 4.0, yaw]) for yaw in (0.0, 0.05)]
    strict = StereoSLAM(rig, sim.T_body_left, max_rot_std_rad=1e-6, rng=0)
    loose = StereoSLAM(rig, sim.T_body_left, max_rot_std_rad=None, rng=0)
    for slam in (strict, loose):
        for p in pairs:
            slam.process(*p)
    assert strict.records[1].status == "ill_conditioned"
    assert strict.degenerate_frames.tolist() == [1]
    np.testing.assert_array_equal(strict.poses[1], strict.poses[0])
    assert strict.records[1].n_new == 0
    assert loose.records[1].status == "ok"
    assert abs(float(wrap_angle(loose.planar_trajectory[1, 2] - 0.05))) < np.deg2rad(1.0)
    with pytest.raises(ValueError, match="max_rot_std_rad"):
        StereoSLAM(rig, max_rot_std_rad=-1.0)


def test_params_are_one_frozen_object_shared_by_the_loop_and_the_runs():
    import dataclasses

    from slamlab.studies.stereo import run_experiment

    p = StereoParams()
    with pytest.raises(dataclasses.FrozenInstanceError):
        p.ratio = 0.5
    assert set(StereoParams.sources()) == set(StereoParams.field_names())
    assert all(src.startswith(("000 §", "ours")) for src in StereoParams.sources().values())
    rig = StereoRig.parallel()
    assert StereoSLAM(rig, detector="orb").params == StereoParams(detector="orb")
    res = run_experiment("turn in place", n_frames=2, params=StereoParams(detector="orb"), policy="all")
    assert res.params == StereoParams(detector="orb", policy="all")
    # the run's default equals the pipeline's default
    import inspect

    assert inspect.signature(run_experiment).parameters["params"].default is None


def test_colour_frames_follow_the_channel_order():
    cv2 = pytest.importorskip("cv2")
    rig = StereoRig.parallel(0.2, 192, 144)
    sim = StereoSim(StereoArena(texture_seed=1), rig, rng=0)
    left, right = sim.render_pair([3.0, 4.0, 0.0])
    rng = np.random.default_rng(0)
    # colour frames whose OpenCV grey version is the rendered frame +- a little
    tint = rng.integers(0, 30, (144, 192, 3)).astype(np.uint8)
    bgr_l = cv2.merge([left, cv2.subtract(left, tint[..., 1]), cv2.add(left, tint[..., 2])])
    bgr_r = cv2.merge([right, cv2.subtract(right, tint[..., 1]), cv2.add(right, tint[..., 2])])
    grey = StereoSLAM(rig, sim.T_body_left, detector="orb", n_features=300, rng=0)
    colour = StereoSLAM(rig, sim.T_body_left, detector="orb", n_features=300, channel_order="bgr", rng=0)
    rec_g = grey.process(cv2.cvtColor(bgr_l, cv2.COLOR_BGR2GRAY), cv2.cvtColor(bgr_r, cv2.COLOR_BGR2GRAY))
    rec_c = colour.process(bgr_l, bgr_r)
    assert rec_c == rec_g


def test_ours_vs_source_prints_the_runs_figures(short_turn):
    from slamlab.studies.stereo import ours_vs_source

    _, res = short_turn
    table = ours_vs_source(res, {"SURF, oldest": res, "again": res})
    row = next(line for line in table.splitlines() if line.strip().startswith("turn: max position error"))
    assert "<= 0.15" in row
    assert row.split()[-1] == f"{res.pos_err_m.max():.2f}"
    assert f"{res.pos_err_m.max():.2f} (again: {res.pos_err_m.max():.2f})" in table
    assert f"{100 * res.heading_error_ratio:.1f}" in table
    with pytest.raises(ValueError, match="`loops` is empty"):
        ours_vs_source(res, {})


@pytest.mark.parametrize("name", StereoParams.field_names())
def test_every_param_is_checked(name):
    import dataclasses

    default = getattr(StereoParams(), name)
    bad = {str: "no-such-choice", bool: "yes"}.get(type(default), -1.0)
    if name == "disparity_offset_px":
        bad = float("nan")  # an offset of either sign is valid (a disparity measured too small or too large)
    with pytest.raises((ValueError, TypeError), match=f"`{name}`"):
        StereoParams(**{name: bad})
    assert dataclasses.fields(StereoParams)  # frozen dataclass fields, each with a source
    assert StereoParams.sources()[name].startswith(("000 §", "ours"))


def test_duplicate_check_keeps_re_sighted_points_out_of_the_map():
    # a landmark whose sighting failed the ratio rule (two similar descriptors) is re-added unless the
    # duplicate check sees that its nearest landmark by descriptor already sits where the point is
    poses = turn_in_place(np.deg2rad(5.0))[:5]
    runs = run_stereo_slam_variants(poses, {"off": {"detector": "orb"}, "on": {"detector": "orb", "duplicate_gap_m": 0.1}},
                                    arena=StereoArena(texture_seed=0), rng=0, progress=False)
    off, on = runs["off"].counts, runs["on"].counts
    assert off["n_duplicates"].sum() == 0
    assert on["n_duplicates"][1:].min() > 0
    # every point the check holds back is one landmark fewer
    np.testing.assert_array_equal(on["n_new"][:2] + on["n_duplicates"][:2], off["n_new"][:2])
    assert on["n_new"][1:].sum() < off["n_new"][1:].sum()
    assert runs["on"].pos_err_m.max() < 0.1


def test_disparity_errors_table_shows_the_refinement_per_level():
    from slamlab.studies.stereo import disparity_errors

    table = disparity_errors()
    rows = [line.split() for line in table.splitlines()[3:]]
    assert len(rows) == 8  # ORB's 8 pyramid levels
    for _level, n, raw_med, _raw_far, ref_med, _ref_far, refined in rows:
        assert int(n) > 0
        assert float(ref_med) < float(raw_med)
        assert float(ref_med) <= 0.05  # against the renderer's depth (see test_stages)
        assert int(refined) >= 80


@pytest.mark.realdata
def test_kitti_comparison_prints_one_row_per_setting(real_data):
    from slamlab.studies.stereo import kitti_comparison

    table = kitti_comparison({"a": {"detector": "orb"}, "b": {"detector": "orb", "subpixel_stereo": False}},
                             real_data / "kitti-odometry-06-stereo", n_frames=3)
    assert "kitti-odometry-06-stereo, 3 frames" in table
    assert [line.split()[0] for line in table.splitlines()[3:]] == ["a", "b"]
    with pytest.raises(TypeError, match="variants"):
        kitti_comparison({})


@pytest.fixture(scope="module")
def orb_frames():
    sim = StereoSim(StereoArena(texture_seed=0), rng=0)
    poses = turn_in_place(np.deg2rad(5.0))[:6]
    return sim, poses, [sim.render_pair(p) for p in poses]


def test_window_search_tracks_with_a_fraction_of_the_descriptor_distances(orb_frames):
    sim, poses, pairs = orb_frames
    runs = {}
    for search in ("window", "global"):
        slam = StereoSLAM(sim.rig, sim.T_body_left, detector="orb", map_search=search, rng=0)
        slam.run(pairs)
        runs[search] = slam
    assert StereoParams(detector="orb").search == "window"
    assert StereoParams().search == "global"
    for slam in runs.values():
        est = slam.planar_trajectory
        truth = poses - poses[0]
        assert np.abs(wrap_angle(est[:, 2] - truth[:, 2])).max() < np.deg2rad(0.5)
        assert np.hypot(*est[:, :2].T).max() < 0.05  # a turn in place
        assert len(slam.degenerate_frames) == 0
    cw, cg = runs["window"].counts(), runs["global"].counts()
    assert not cw["window_fallback"].any()
    # global: every query against every stored landmark; window: the last frame's landmarks + the windows
    np.testing.assert_array_equal(cg["n_compared"][1:], cg["n_local"][1:] * cg["n_searched"][1:])
    # window search: the last frame's landmarks for every point, then a few landmarks per window
    per_window = (cw["n_compared"][1:] - cw["n_local"][1:] * cw["n_searched"][1:]) / cw["n_local"][1:]
    assert np.all(per_window < 0.03 * cw["n_landmarks"][:-1])  # a 15-px disc is 0.16 % of the image
    assert cw["n_compared"][-1] < 0.5 * cg["n_compared"][-1]
    assert cw["n_inliers"][1:].min() > 300


def test_map_does_not_grow_on_a_revisit(orb_frames):
    # the frames of a turn, back and forth three times: the window search with the twin rule finds the
    # landmarks of the first pass again instead of adding copies (000 §3.4: copies that are seen become base)
    sim, _, pairs = orb_frames
    frames = pairs + pairs[::-1] + pairs
    new = {}
    for label, over in (("window", {}), ("global", {"map_search": "global", "same_point_m": 0})):
        slam = StereoSLAM(sim.rig, sim.T_body_left, detector="orb", rng=0, **over)
        slam.run(frames)
        c = slam.counts()
        new[label] = c["n_new"][len(pairs):].sum()
        if label == "window":
            assert c["n_landmarks"][-1] <= c["n_landmarks"][len(pairs) - 1]
            # the same images right after they were mapped: (almost) every point is a landmark again
            assert c["n_new"][len(pairs)] < 0.01 * c["n_local"][len(pairs)]
    assert new["window"] < 0.8 * new["global"]


def test_a_search_that_gives_no_pose_falls_back_to_the_whole_map(orb_frames):
    sim, _, pairs = orb_frames
    # the view gate at a wrong last pose (turned around) finds nothing in view: the whole map is searched
    slam = StereoSLAM(sim.rig, sim.T_body_left, detector="orb", map_search="global", view_margin_deg=0.0, rng=0)
    slam.process(*pairs[0])
    slam.T = np.diag([-1.0, -1.0, 1.0, 1.0])
    rec = slam.process(*pairs[0])
    assert rec.gate_fallback
    assert rec.status == "ok"
    np.testing.assert_allclose(slam.T, np.eye(4), atol=1e-6)
    # the window search whose first pose fails (too few landmarks of the last frame) falls back the same way
    slam = StereoSLAM(sim.rig, sim.T_body_left, detector="orb", rng=0)
    slam.process(*pairs[0])
    slam._last_ids = np.arange(3)
    rec = slam.process(*pairs[0])
    assert rec.window_fallback
    assert rec.status == "ok"
    assert rec.n_searched == 3 + len(slam.store) - rec.n_new
    np.testing.assert_allclose(slam.T, np.eye(4), atol=1e-6)


def test_stage_times_in_wall_and_cpu_time(short_turn):
    poses, _ = short_turn
    sim = StereoSim(StereoArena(texture_seed=0), rng=0)
    slam = StereoSLAM(sim.rig, sim.T_body_left, detector="orb", rng=0)
    slam.run(sim.render_pair(p) for p in poses[:3])
    wall, cpu = slam.stage_times(), slam.stage_times(cpu=True)
    assert set(wall) == set(cpu) == set(STAGES)
    assert all(len(wall[s]) == 3 and np.all(cpu[s] >= 0) and np.all(wall[s] >= 0) for s in STAGES)
    assert sum(cpu[s].sum() for s in STAGES) > 0


def test_window_search_confirmed_by_too_few_windows_searches_globally(orb_frames):
    # window_min_share = 1: no frame has every point matched in its window, so every frame falls back
    sim, _poses, pairs = orb_frames
    slam = StereoSLAM(sim.rig, sim.T_body_left, detector="orb", window_min_share=1.0, rng=0)
    slam.run(pairs[:3])
    c = slam.counts()
    assert c["window_fallback"][1:].all()
    assert len(slam.degenerate_frames) == 0
    np.testing.assert_array_less(c["n_map_matches"][1:], c["n_local"][1:])
