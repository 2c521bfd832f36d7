"""Per-frame stages of the stereo pipeline (000 §3.3-3.5) on rendered frames and exact data."""

import cv2
import numpy as np
import pytest

from slamlab.features import Features
from slamlab.geometry import rotation_xyz, se3_from_planar
from slamlab.kdtree import ExactStore, LandmarkStore
from slamlab.sim.arena import StereoArena, StereoSim
from slamlab.stereo import (
    StereoMatches,
    StereoParams,
    detect_features,
    estimate_pose,
    is_rectified,
    match_to_map,
    select_oldest,
    stereo_match,
    subpixel_disparity,
    triangulate_local,
)

POSE = np.array([3.0, 4.0, 1.2])


def detect(image, detector="surf", n_features=2000):
    return detect_features(image, detector=detector, n_features=n_features)


def _features(uv, descriptors):
    n = len(uv)
    return Features(np.asarray(uv, float), np.ones(n), np.zeros(n), np.ones(n), np.zeros(n, int), descriptors)


@pytest.fixture(scope="module")
def frame():
    arena = StereoArena(texture_seed=2)
    sim = StereoSim(arena, rng=0)
    left, right = sim.render_pair(POSE)
    T = se3_from_planar(*POSE) @ sim.T_body_left
    _, _, pts = arena.cast(sim.rig.left, T)
    return sim, left, right, T, pts


def test_detect_orb_and_sift(frame):
    _, left, *_ = frame
    f = detect(left, "orb", 1500)
    assert 1000 < len(f.uv) <= 1500
    assert f.descriptors.shape == (len(f.uv), 32)
    assert f.is_binary
    ref = cv2.ORB_create(nfeatures=1500, fastThreshold=12).detect(left, None)
    np.testing.assert_allclose(f.uv, [k.pt for k in ref])
    s = detect(left, "sift", 500)
    assert s.descriptors.dtype == np.float32
    assert s.descriptors.shape[1] == 128
    # a float image in [0, 1] gives the same keypoints as its uint8 version
    g = detect(left / 255.0, "orb", 1500)
    np.testing.assert_allclose(g.uv, f.uv)


# SURF's large-scale blobs straddle depth edges (fence top against the floor behind), so a few more of
# its points miss the surface pixel they are compared with (measured 0.94 against ORB's 0.996)
@pytest.mark.parametrize(("detector", "n_min", "within"), [("orb", 500, 0.95), ("surf", 300, 0.90)])
def test_stereo_matches_and_triangulation_against_the_renderer(frame, detector, n_min, within):
    sim, left, right, T, pts = frame
    fl, fr = detect(left, detector), detect(right, detector)
    sm = stereo_match(fl, fr, sim.rig)
    assert len(sm.left) > n_min
    assert len(np.unique(sm.right)) == len(sm.right)
    # epipolar check: the rig is rectified, so matched rows agree within the tolerance
    assert np.abs(fl.uv[sm.left, 1] - fr.uv[sm.right, 1]).max() <= 2.0 + 1e-9
    cloud = triangulate_local(sim.rig, fl, fr, sm)
    uv = np.rint(fl.uv[cloud.left]).astype(int)
    truth_world = pts[uv[:, 1], uv[:, 0]]
    ok = np.isfinite(truth_world[:, 0])
    truth_cam = (truth_world[ok] - T[:3, 3]) @ T[:3, :3]
    err = np.linalg.norm(cloud.points[ok] - truth_cam, axis=1)
    sigma = np.sqrt(np.trace(cloud.cov[ok], axis1=1, axis2=2))
    # ORB keypoints are quantised on its pyramid, SURF's on its scale-space grid:
    # allow 4 sigma (+1 cm for the pixel rounding above)
    assert np.mean(err < 4 * sigma + 0.01) > within
    assert cloud.points[:, 2].min() >= 0.3
    assert cloud.points[:, 2].max() <= 10.0


def test_stereo_match_ratio_rule_on_synthetic_descriptors():
    from slamlab.geometry import StereoRig

    rig = StereoRig.parallel(0.2)
    uv_l = np.array([[100.0, 50.0], [200.0, 80.0], [300.0, 120.0]])
    uv_r = np.array([[90.0, 50.0], [190.0, 80.5], [150.0, 80.0], [290.0, 300.0]])
    dl = np.array([[0] * 32, [255] * 32, [15] * 32], np.uint8)
    dr = np.array([[0] * 32, [255] * 32, [255] * 32, [15] * 32], np.uint8)
    sm = stereo_match(_features(uv_l, dl), _features(uv_r, dr), rig)
    # 0 <-> 0 (unique on its row); 1 has two near-equal candidates on its row -> rejected by the ratio;
    # 2's descriptor twin lies far off its epipolar line -> no match
    assert sm.left.tolist() == [0]
    assert sm.right.tolist() == [0]


def test_exact_store_matches_numpy_brute_force():
    rng = np.random.default_rng(0)
    D = rng.integers(0, 256, (500, 32), dtype=np.uint8)
    Q = rng.integers(0, 256, (50, 32), dtype=np.uint8)
    s = ExactStore()
    s.add(D, np.arange(1000, 1500))
    dist, ids = s.query(Q, k=2)
    bits = np.unpackbits(Q[:, None, :] ^ D[None, :, :], axis=2).sum(axis=2)
    ref = np.sort(bits, axis=1)[:, :2]
    np.testing.assert_array_equal(dist, ref)
    np.testing.assert_array_equal(bits[np.arange(50), ids[:, 0] - 1000], ref[:, 0])
    Df = rng.normal(size=(300, 64)).astype(np.float32)
    Qf = rng.normal(size=(20, 64)).astype(np.float32)
    s = ExactStore()
    s.add(Df, np.arange(300))
    dist, ids = s.query(Qf)
    full = np.linalg.norm(Qf[:, None] - Df[None], axis=2)
    np.testing.assert_allclose(dist, np.sort(full, axis=1)[:, :2], rtol=1e-5)
    assert isinstance(s, LandmarkStore)


def test_exact_store_base_rule():
    s = ExactStore(base_seen_times=3, max_non_base_time=7)
    X = np.eye(4, dtype=np.float32)
    s.add(X[:2], [0, 1])
    for it in range(10):
        if it in (1, 2):
            s.observe([0])  # id 0 seen 3 times within 7 frames -> base
        s.end_iteration()
        if it == 6:
            assert sorted(s.ids.tolist()) == [0, 1]
        if it == 7:
            assert s.ids.tolist() == [0]  # id 1 timed out
            assert s.dropped_ids.tolist() == [1]
    assert s.is_base.tolist() == [True]
    d, i = s.query(X[:1], k=3)
    assert i.tolist() == [[0, -1, -1]]
    assert np.isinf(d[0, 1:]).all()


def test_match_to_map_one_local_per_landmark():
    s = ExactStore()
    s.add(np.array([[0.0, 0.0], [10.0, 0.0]]), [5, 6])
    m = match_to_map(np.array([[0.1, 0.0], [0.2, 0.0], [9.0, 0.0], [5.0, 0.0]]), s)
    assert m.local.tolist() == [0, 2]
    assert m.ids.tolist() == [5, 6]
    assert m.unmatched.tolist() == [3]  # 1 lost landmark 5 to 0; 3 is ambiguous (ratio 1)


def _pose_data(n=150, outliers=0.3, seed=0):
    rng = np.random.default_rng(seed)
    P = np.column_stack([rng.uniform(1, 6, n), rng.uniform(-2, 2, n), rng.uniform(0, 0.5, n)])
    T = se3_from_planar(0.4, -0.3, 0.25)
    T[:3, :3] = T[:3, :3] @ rotation_xyz(0.01, -0.005, 0.0)
    Q = P @ T[:3, :3].T + T[:3, 3] + rng.normal(0, 0.005, P.shape)
    bad = rng.random(n) < outliers
    Q[bad] += rng.uniform(-2, 2, (bad.sum(), 3))
    return P, Q, T, bad


@pytest.mark.parametrize("policy", ["oldest", "all"])
def test_estimate_pose_with_outliers(policy):
    P, Q, T, bad = _pose_data()
    first = np.random.default_rng(1).integers(0, 10, len(P))
    est = estimate_pose(P, Q, first, policy=policy, rng=0)
    assert est.converged
    np.testing.assert_allclose(est.T, T, atol=0.02)
    assert np.mean(est.inliers == ~bad) > 0.97
    if policy == "oldest":
        used_first = np.sort(first[~bad])[: est.n_used]
        assert used_first.max() <= np.sort(first[~bad])[39]


def test_estimate_pose_failure_and_bad_input():
    rng = np.random.default_rng(0)
    est = estimate_pose(rng.uniform(0, 5, (30, 3)), rng.uniform(0, 5, (30, 3)), threshold_m=0.01, rng=0)
    assert not est.converged
    np.testing.assert_array_equal(est.T, np.eye(4))
    with pytest.raises(ValueError, match="at least 3 matches"):
        estimate_pose(np.zeros((2, 3)), np.zeros((2, 3)))
    with pytest.raises(ValueError, match="policy"):
        estimate_pose(np.zeros((5, 3)), np.zeros((5, 3)), policy="newest")
    with pytest.raises(ValueError, match="first_seen"):
        estimate_pose(np.ones((5, 3)), np.ones((5, 3)), [1, 2])
    with pytest.raises(ValueError, match="shape"):
        estimate_pose(np.ones((5, 2)), np.ones((5, 2)))


def test_select_oldest_takes_ties():
    assert select_oldest([3, 3, 3, 1], 2).tolist() == [0, 1, 2, 3]
    assert select_oldest([4, 2], 5).tolist() == [0, 1]
    with pytest.raises(ValueError, match="n_min"):
        select_oldest([1, 2], 0)


def test_stage_bad_input(frame):
    sim, left, *_ = frame
    with pytest.raises(ValueError, match="detector"):
        detect(left, "surf-xyz")
    with pytest.raises(TypeError, match="no field"):
        detect_features(left, n_points=5)
    with pytest.raises(ValueError, match="must not be empty"):
        detect(np.zeros((0, 0)))
    with pytest.raises(ValueError, match="image"):
        detect(np.zeros((4, 4, 4, 4)))
    f = detect(left, n_features=100)
    with pytest.raises(TypeError, match="rig"):
        stereo_match(f, f, None)
    with pytest.raises(TypeError, match="Features"):
        stereo_match(f, "x", sim.rig)
    with pytest.raises(ValueError, match="ratio"):
        stereo_match(f, f, sim.rig, ratio=1.5)
    with pytest.raises(TypeError, match="StereoMatches"):
        triangulate_local(sim.rig, f, f, None)
    empty = StereoMatches(np.empty(0, int), np.empty(0, int), np.empty(0))
    assert len(triangulate_local(sim.rig, f, f, empty).points) == 0
    with pytest.raises(ValueError, match="descriptors"):
        match_to_map(np.zeros(3), ExactStore())
    with pytest.raises(TypeError, match="LandmarkStore"):
        match_to_map(np.zeros((2, 3)), object())
    s = ExactStore()
    s.add(np.zeros((2, 4), np.uint8), [0, 1])
    with pytest.raises(ValueError, match=r"must have shape \(N, 4\) to match the store"):
        s.query(np.zeros((1, 5), np.uint8))
    with pytest.raises(TypeError, match="must be uint8"):
        s.query(np.zeros((1, 4), np.float32))
    with pytest.raises(ValueError, match="ids"):
        s.add(np.zeros((2, 4), np.uint8), [0])


def test_surf_from_the_features_chapter(frame):
    pytest.importorskip("slamlab.features")
    _, left, *_ = frame
    f = detect(left, "surf", 300)
    assert 0 < len(f.uv) <= 300
    assert f.descriptors.shape == (len(f.uv), 64)
    assert not f.is_binary


def test_oldest_policy_follows_the_old_landmarks_when_the_map_drifted():
    # 000 §3.5: 100 landmarks from frame 0 (exact) and 300 from frame 40, placed with a drifted pose
    # (1 deg, 5 cm). "all" follows the recent majority; "oldest" follows the old landmarks.
    rng = np.random.default_rng(5)
    P = np.column_stack([rng.uniform(2, 5, 400), rng.uniform(-1.5, 1.5, 400), rng.uniform(-0.4, 0.1, 400)])
    T = se3_from_planar(0.3, 0.1, 0.4)
    drift = se3_from_planar(0.05, 0.0, np.deg2rad(1.0))
    first = np.r_[np.zeros(100, int), np.full(300, 40)]
    Q = P @ T[:3, :3].T + T[:3, 3]
    Td = drift @ T
    Q[100:] = P[100:] @ Td[:3, :3].T + Td[:3, 3]
    Q += rng.normal(0, 0.003, Q.shape)
    est_all = estimate_pose(P, Q, first, policy="all", threshold_m=0.04, rng=0)
    est_old = estimate_pose(P, Q, first, policy="oldest", oldest_fraction=0.2, threshold_m=0.04, rng=0)
    np.testing.assert_allclose(est_all.T, Td, atol=0.01)
    np.testing.assert_allclose(est_old.T, T, atol=0.01)
    assert est_old.inliers[:100].mean() > 0.95


def _reference_stereo_match(fl, fr, rig, ratio=0.8, tol=2.0):
    """OpenCV's masked 2-NN (cv2.BFMatcher.knnMatch) with the same ratio rule and right-uniqueness."""
    xl = np.column_stack([fl.uv, np.ones(len(fl.uv))])
    lines = xl @ rig.F.T
    lines /= np.hypot(lines[:, 0], lines[:, 1])[:, None]
    mask = (np.abs(lines[:, :2] @ fr.uv.T + lines[:, 2:3]) <= tol).astype(np.uint8)
    norm = cv2.NORM_HAMMING if fl.is_binary else cv2.NORM_L2
    best = {}
    for m in cv2.BFMatcher(norm).knnMatch(fl.descriptors, fr.descriptors, k=2, mask=mask):
        if m and m[0].distance < ratio * (m[1].distance if len(m) > 1 else np.inf):
            q, t, d = m[0].queryIdx, m[0].trainIdx, m[0].distance
            if t not in best or d < best[t][1]:
                best[t] = (q, d)
    pairs = sorted((q, t) for t, (q, _) in best.items())
    return [p[0] for p in pairs], [p[1] for p in pairs]


@pytest.mark.parametrize("detector", ["orb", "surf"])
@pytest.mark.parametrize("rig_kind", ["rectified", "drifted", "vertical"])
def test_stereo_match_equals_opencv_masked_knn(frame, detector, rig_kind):
    from scipy.spatial.transform import Rotation

    from slamlab.geometry import StereoRig

    sim, left, right, *_ = frame
    fl, fr = detect(left, detector), detect(right, detector)
    rig = sim.rig
    if rig_kind == "drifted":  # epipolar lines slanted: the row-sorted candidate search still applies
        rig = StereoRig(rig.left, rig.right, Rotation.from_rotvec([0.0, 0.0, 0.01]).as_matrix() @ rig.R_rl, rig.t_rl)
    elif rig_kind == "vertical":  # baseline along the columns: vertical lines, every pair is tested
        rig = StereoRig(rig.left, rig.right, rig.R_rl, np.array([0.0, -0.2, 0.0]))
    sm = stereo_match(fl, fr, rig)
    ref_l, ref_r = _reference_stereo_match(fl, fr, rig)
    assert len(ref_l) > 0
    assert sm.left.tolist() == ref_l
    assert sm.right.tolist() == ref_r


def test_pose_std_matches_monte_carlo_of_the_fit():
    # isotropic point noise: the least-squares (Umeyama) pose scatter must equal pose_std's prediction
    from scipy.spatial.transform import Rotation

    from slamlab.geometry.registration import umeyama
    from slamlab.stereo.stages import pose_std

    rng = np.random.default_rng(3)
    P = rng.uniform([-2, -1, 2], [2, 1, 6], (25, 3))
    sigma = 0.02
    pred = pose_std(P, np.tile(np.eye(3) * sigma**2, (len(P), 1, 1)))
    c = P.mean(axis=0)
    est = []
    for _ in range(3000):
        T = umeyama(P, P + rng.normal(0, sigma, P.shape))
        est.append(np.r_[Rotation.from_matrix(T.R).as_rotvec(), T.R @ c + T.t - c])
    mc = np.std(est, axis=0)
    np.testing.assert_allclose(mc, pred, rtol=0.06)  # 3000 draws: std known to ~1.3 %


def test_pose_std_sees_the_wall_ambiguity():
    # a wall straight ahead, stereo-like covariance (depth sigma 20x the lateral one): yaw and
    # sideways translation are poorly determined; adding near points at other depths fixes it
    from slamlab.stereo.stages import pose_std

    rng = np.random.default_rng(0)
    wall = np.column_stack([rng.uniform(-1.3, 1.3, 60), rng.uniform(-0.2, 0.5, 60), np.full(60, 5.0)])
    near = np.column_stack([rng.uniform(-0.8, 0.8, 60), rng.uniform(-0.4, 0.3, 60), rng.uniform(1.0, 3.0, 60)])
    cov = np.diag([0.003**2, 0.003**2, 0.06**2])
    s_wall = pose_std(wall, np.tile(cov, (60, 1, 1)), center=np.zeros(3))
    both = np.vstack([wall, near])
    s_both = pose_std(both, np.tile(cov, (120, 1, 1)), center=np.zeros(3))
    assert s_wall[1] > 3 * s_both[1]  # yaw (about the camera's vertical axis)
    assert s_wall[3] > 3 * s_both[3]  # sideways translation
    with pytest.raises(ValueError, match="cov_map"):
        pose_std(wall, np.eye(3))


def test_oldest_policy_grows_an_ill_conditioned_oldest_set():
    # 000 §3.5 wants "a sufficiently large number" of the oldest landmarks. Here the oldest 60 form a
    # wall 5 m ahead with stereo-like noise (depth sigma 6 cm, lateral 3 mm): alone they leave yaw and
    # sideways translation nearly interchangeable. With the covariances, estimate_pose adds the next
    # oldest (60 near points) until the pose is determined, and the error drops by an order of magnitude
    def ray_cov(p, dep):
        r = p / np.linalg.norm(p)
        return 0.003**2 * np.eye(3) + (dep**2 - 0.003**2) * np.outer(r, r)

    err = {True: [], False: []}
    for seed in range(8):
        rng = np.random.default_rng(seed)
        wall = np.column_stack([rng.uniform(-1.3, 1.3, 60), rng.uniform(-0.2, 0.5, 60), np.full(60, 5.0)])
        near = np.column_stack([rng.uniform(-0.8, 0.8, 60), rng.uniform(-0.4, 0.3, 60), rng.uniform(1.0, 3.0, 60)])
        M = np.vstack([wall, near])  # map points; the true pose is the identity
        covs = np.array([ray_cov(p, 0.06 if i < 60 else 0.01) for i, p in enumerate(M)])
        L = M + np.array([rng.multivariate_normal(np.zeros(3), c) for c in covs])
        first_seen = np.r_[np.zeros(60, int), np.full(60, 10)]
        for use_cov in (True, False):
            e = estimate_pose(L, M, first_seen, depth_m=L[:, 2], cov=covs if use_cov else None, policy="oldest", rng=seed)
            yaw = np.arctan2(e.T[0, 2], e.T[2, 2])
            err[use_cov].append((abs(yaw), np.linalg.norm(e.T[:3, 3]), e.n_used))
    with_cov, without = np.array(err[True]), np.array(err[False])
    assert np.all(without[:, 2] == 60)  # the wall alone
    assert np.all(with_cov[:, 2] > 60)  # grown by the next-oldest
    assert with_cov[:, 0].mean() < 0.2 * without[:, 0].mean()  # measured 0.55 vs 8.0 mrad (20 seeds)
    assert with_cov[:, 1].mean() < 0.2 * without[:, 1].mean()  # measured 2 mm vs 20 cm
    with pytest.raises(ValueError, match="cov"):
        estimate_pose(L, M, first_seen, cov=covs[:5])


def test_exact_store_query_among_and_candidates_in_match_to_map():
    rng = np.random.default_rng(1)
    D = rng.integers(0, 256, (400, 32), dtype=np.uint8)
    Q = D[:30] ^ np.uint8(1)  # one bit away from landmarks 0..29
    s = ExactStore()
    s.add(D, np.arange(100, 500))
    among = np.arange(100, 500, 2)  # even ids only
    dist, ids = s.query_among(Q, among, k=2)
    bits = np.unpackbits(Q[:, None, :] ^ D[None, ::2, :], axis=2).sum(axis=2)  # the even rows
    np.testing.assert_array_equal(dist, np.sort(bits, axis=1)[:, :2])
    assert np.isin(ids, among).all()
    # match_to_map: the exact store searches only the candidates ...
    mm = match_to_map(Q, s, candidates=among)
    assert set(mm.ids.tolist()) <= set(among.tolist())
    assert sorted(mm.ids.tolist()) == list(range(100, 130, 2))  # the even twins match, the odd ones find none
    # ... and so does every other store (query_among is part of the interface, exact for all)
    from slamlab.kdtree import make_store

    Df = rng.normal(size=(400, 16)).astype(np.float32)
    Qf = Df[:30] + np.float32(0.01)
    for name in ("rebuild", "multi", "brute", "flann"):
        st = make_store(name, n1=50, q=2.0)
        st.add(Df, np.arange(100, 500))
        st.end_iteration()
        d_f, i_f = st.query_among(Qf, among, k=2)
        full = np.linalg.norm(Qf[:, None] - Df[None, ::2], axis=2)
        np.testing.assert_allclose(d_f, np.sort(full, axis=1)[:, :2], rtol=1e-5)
        assert np.isin(i_f, among).all()


def test_view_gate_keeps_the_landmarks_in_front():
    from slamlab.geometry import StereoRig
    from slamlab.stereo import StereoSLAM

    slam = StereoSLAM(StereoRig.parallel(), np.eye(4), params=StereoParams(max_depth_m=10.0))
    # camera frame: x right, z forward (T_body_left = I); 40 deg field of view -> +-20 deg
    slam.X = np.array([[0.0, 0.0, 3.0], [3.0 * np.tan(np.deg2rad(25)), 0, 3.0], [0.0, 0.0, -3.0], [0.0, 0.0, 16.0]])
    slam.alive = np.ones(4, bool)
    assert slam.landmarks_in_view(0.0).tolist() == [0]
    assert slam.landmarks_in_view(10.0).tolist() == [0, 1]  # 25 deg < 20 + 10
    assert slam.landmarks_in_view(10.0, T_body=np.diag([-1.0, 1.0, -1.0, 1.0])).tolist() == [2]  # turned around


def _smooth_texture(shape, shift_px=0.0, seed=0):
    """A band-limited texture (sum of sines) sampled at columns ``u + shift_px``: exact sub-pixel shifts."""
    rng = np.random.default_rng(seed)
    v, u = np.indices(shape, dtype=float)
    img = np.zeros(shape)
    for _ in range(12):
        ku, kv, ph = rng.uniform(0.05, 0.35), rng.uniform(0.05, 0.35), rng.uniform(0, 2 * np.pi)
        img += np.sin(ku * (u + shift_px) + kv * v + ph)
    return np.clip(np.rint(127.5 + 10.0 * img), 0, 255).astype(np.uint8)


def test_subpixel_disparity_recovers_an_exact_shift():
    d_true = 9.37  # the right image shows column u + d of the left one at column u
    left = _smooth_texture((60, 120))
    right = _smooth_texture((60, 120), shift_px=d_true)
    uvl = np.array([[40.3, 20.0], [70.0, 31.0], [90.6, 44.0]])
    # keypoint-like inputs off by up to 1.6 px (a coarse pyramid level)
    uvr = uvl - [[d_true + 1.6, 0.0], [d_true - 1.2, 0.0], [d_true + 0.4, 0.0]]
    out_l, out_r, ok = subpixel_disparity(left, right, uvl, uvr)
    assert ok.all()
    np.testing.assert_array_equal(out_l, uvl)  # the left keypoints stay
    np.testing.assert_array_equal(out_r[:, 1], uvl[:, 1])  # same row
    # a V fitted to three costs is biased towards whole pixels ("pixel locking", up to ~0.1 px on a smooth
    # texture) where the keypoints were off by up to 1.6 px
    np.testing.assert_allclose(uvl[:, 0] - out_r[:, 0], d_true, atol=0.1)
    # near the border, or a best cost at the end of the search window: not refined
    _, _, ok = subpixel_disparity(left, right, [[3.0, 20.0], [60.0, 30.0]], [[-6.0, 20.0], [60.0 - d_true - 6.0, 30.0]])
    assert ok.tolist() == [False, False]


def test_subpixel_disparity_makes_orb_depths_agree_with_the_renderer(frame):
    sim, left, right, T, pts = frame
    assert is_rectified(sim.rig)
    fl, fr = detect(left, "orb"), detect(right, "orb")
    sm = stereo_match(fl, fr, sim.rig)
    f, b = sim.rig.left.fx, sim.rig.baseline_m

    def disparity_errors(uvl, uvr):
        uv = np.rint(uvl).astype(int)
        z = ((pts[uv[:, 1], uv[:, 0]] - T[:3, 3]) @ T[:3, :3])[:, 2]
        ok = np.isfinite(z)
        return (uvl[ok, 0] - uvr[ok, 0]) - f * b / z[ok]

    raw = disparity_errors(fl.uv[sm.left], fr.uv[sm.right])
    uvl, uvr, ok = subpixel_disparity(left, right, fl.uv[sm.left], fr.uv[sm.right])
    ref = disparity_errors(uvl[ok], uvr[ok])
    assert ok.mean() > 0.9
    # ORB's pyramid keypoints: median |error| measured 0.2 px (coarse levels up to 1.2^7 / 2 px);
    # refined against the renderer's depth, 0.05 px or better in the median, and far fewer beyond 1 px
    assert np.median(np.abs(ref)) < 0.5 * np.median(np.abs(raw))
    assert np.median(np.abs(ref)) < 0.05
    assert np.mean(np.abs(ref) > 1.0) < 0.5 * np.mean(np.abs(raw) > 1.0)
    # the pipeline's triangulation with the images refines the same way and keeps the confirmed matches
    cloud = triangulate_local(sim.rig, fl, fr, sm, images=(left, right), detector="orb")
    assert set(cloud.left) <= set(sm.left[ok])
    assert len(cloud.left) > len(triangulate_local(sim.rig, fl, fr, sm).left) * 0.8
    # SURF's keypoints are interpolated: by default its matches are not refined
    assert len(triangulate_local(sim.rig, fl, fr, sm, images=(left, right)).left) == len(
        triangulate_local(sim.rig, fl, fr, sm).left)
    with pytest.raises(TypeError, match="images"):
        triangulate_local(sim.rig, fl, fr, sm, images=left)


def test_subpixel_disparity_bad_input():
    img = np.zeros((20, 30), np.uint8)
    with pytest.raises(ValueError, match="uv_left"):
        subpixel_disparity(img, img, np.zeros((2, 3)), np.zeros((2, 3)))
    with pytest.raises(ValueError, match="same shape"):
        subpixel_disparity(img, np.zeros((21, 30), np.uint8), np.zeros((1, 2)), np.zeros((1, 2)))
    with pytest.raises(ValueError, match="half_px"):
        subpixel_disparity(img, img, np.zeros((1, 2)), np.zeros((1, 2)), half_px=0)
    from slamlab.geometry import StereoRig

    rig = StereoRig.parallel()
    assert is_rectified(rig)
    assert not is_rectified(StereoRig(rig.left, rig.right, rotation_xyz(0.0, 0.01, 0.0), rig.t_rl))


def test_radius_pairs_are_every_pair_within_the_radius():
    from slamlab.stereo.map_stages import _radius_pairs

    rng = np.random.default_rng(3)
    uq = rng.uniform(-30, 800, (300, 2))
    ut = rng.uniform(0, 780, (900, 2))
    for radius in (4.0, 15.0, 60.0):
        qi, ti = _radius_pairs(uq, ut, radius)
        d = np.linalg.norm(uq[:, None] - ut[None], axis=2)
        expected = set(zip(*np.nonzero(d <= radius), strict=True))
        assert set(zip(qi.tolist(), ti.tolist(), strict=True)) == {(int(a), int(b)) for a, b in expected}
        assert np.all(np.diff(qi) >= 0)  # grouped by query
    qi, ti = _radius_pairs(np.array([[0.0, 0.0]]), np.array([[100.0, 100.0]]), 5.0)
    assert qi.size == ti.size == 0


def test_two_nearest_per_query():
    from slamlab.stereo._pairs import two_nearest

    q, t1, d1, d2, t2 = two_nearest(np.array([0, 0, 0, 2, 3, 3]), np.array([5, 6, 7, 8, 9, 10]),
                                     np.array([3.0, 1.0, 2.0, 4.0, 1.0, 1.0]))
    assert q.tolist() == [0, 2, 3]
    assert t1.tolist() == [6, 8, 9]
    assert t2.tolist() == [7, -1, 10]
    assert d1.tolist() == [1.0, 4.0, 1.0]
    assert d2.tolist() == [2.0, np.inf, 1.0]


def test_window_match_searches_only_near_the_projections():
    from slamlab.stereo.map_stages import _window_match

    rng = np.random.default_rng(5)
    n = 60
    desc = rng.integers(0, 256, (n, 32), dtype=np.uint8)
    ids = np.arange(1000, 1000 + n)
    uv_lm = np.column_stack([np.arange(n) * 12.0, np.full(n, 100.0)])  # 12 px apart on one row
    X = np.zeros((1000 + n, 3))
    X[ids, 0] = np.arange(n) * 0.1  # landmarks 10 cm apart
    flip = np.zeros(32, np.uint8)
    flip[:3] = 1  # 3 bits
    D = desc[[3, 10, 20]] ^ flip
    uv = uv_lm[[3, 10, 20]] + [2.0, 1.0]
    uv[2] += [200.0, 0.0]  # the third point's landmark projects 200 px away: outside its window
    mm, n_pairs = _window_match(D, uv, desc, uv_lm, ids, 15.0, 0.8, 64)
    assert dict(zip(mm.local.tolist(), mm.ids.tolist(), strict=True)) == {0: 1003, 1: 1010}
    assert mm.unmatched.tolist() == [2]
    # pairs: every landmark within 15 px of each point (brute force)
    assert n_pairs == int((np.linalg.norm(uv[:, None] - uv_lm[None], axis=2) <= 15.0).sum())
    # a window candidate farther than the Hamming bound is no match
    mm, _ = _window_match(D[:1] ^ np.uint8(0x0F), uv[:1], desc, uv_lm, ids, 15.0, 0.8, 64)  # 4 x 32 bits more
    assert mm.local.size == 0
    # twins: two landmarks with the same descriptor in one window fail the ratio rule unless they are one place
    desc2 = desc.copy()
    desc2[4] = desc2[3]
    mm, _ = _window_match(D[:1], uv[:1], desc2, uv_lm, ids, 15.0, 0.8, 64, X, None)
    assert mm.local.size == 0
    assert mm.unmatched.tolist() == [0]
    X2 = X.copy()
    X2[1004] = X2[1003] + [0.01, 0.0, 0.0]  # 1 cm apart: the same point added twice
    mm, _ = _window_match(D[:1], uv[:1], desc2, uv_lm, ids, 15.0, 0.8, 64, X2, 0.03)
    assert mm.ids.tolist() == [1003]
    mm, _ = _window_match(D[:1], uv[:1], desc2, uv_lm, ids, 15.0, 0.8, 64, X, 0.03)  # 10 cm apart: two points
    assert mm.local.size == 0
