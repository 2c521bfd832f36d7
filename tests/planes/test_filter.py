"""The plane particle filter (002): weights, resampling, motion, pairing, map merge, bad frames, a short flight."""

import numpy as np
import pytest

from slamlab.planes import (
    Frame,
    Plane,
    PlaneMap,
    PlaneSLAM,
    PlaneSLAMParams,
    VoxelStore,
    describe_plane,
    intensity_weights,
    mean_pose,
    pair_planes,
    predict_particles,
    systematic_resample,
)
from slamlab.planes.description import plane_frame


def test_intensity_weights_follow_002():
    sad = np.array([4.0, 1.0, 2.5, 4.0])
    w = intensity_weights(sad)
    star = sad.max() - sad                       # SAD* = max SAD - SAD_i, w = SAD* / sum SAD*
    np.testing.assert_allclose(w, star / star.sum())
    np.testing.assert_allclose(intensity_weights([np.nan, 1.0, 3.0]), [0.0, 1.0, 0.0])
    np.testing.assert_allclose(intensity_weights([2.0, 2.0]), [0.5, 0.5])


def test_resampler_is_the_shared_particle_toolbox():
    # the sampler itself is tested in tests/filters/test_particles.py (against PR Table 4.4's loop)
    from slamlab.filters.particles import low_variance_resample

    assert systematic_resample is low_variance_resample


def test_mean_pose_of_identical_particles_and_predict_without_noise():
    T = np.eye(4)
    T[:3, 3] = [1, 2, 3]
    X = np.repeat(T[None], 5, 0)
    np.testing.assert_allclose(mean_pose(X), T, atol=1e-12)
    U = np.eye(4)
    U[:3, 3] = [0.5, 0, 0]
    U[:3, :3] = [[0, -1, 0], [1, 0, 0], [0, 0, 1]]
    np.testing.assert_allclose(predict_particles(X, U, 0.0, 0.0, np.random.default_rng(0)), X @ U, atol=1e-12)


def test_pairing_picks_the_matching_map_plane():
    n_map = np.array([[1.0, 0, 0], [0, 1.0, 0], [1.0, 0, 0]])
    p_map = np.array([5.0, 2.0, 9.0])
    X = np.eye(4)[None].repeat(2, 0)
    X[1, 0, 3] = 4.0                              # particle 1 is 4 m further along x
    pairs = pair_planes(X, np.array([[1.0, 0, 0], [0, 1.0, 0]]), np.array([5.0, 2.0]), n_map, p_map,
                        angle_deg=10, dist_m=0.5)
    np.testing.assert_array_equal(pairs, [[0, 1], [2, 1]])


def _patch(x0, x1, y0, y1, z=0.0, intensity=100.0):
    g = np.stack(np.meshgrid(np.arange(x0, x1, 0.05), np.arange(y0, y1, 0.05)), -1).reshape(-1, 2)
    X = np.c_[g, np.full(len(g), z)]
    return describe_plane(X, np.full(len(X), intensity), [0, 0, 1.0], z, cell_m=0.25,
                          incidence_correction=False)


def test_map_merges_through_an_intermediate_plane():
    m = PlaneMap()
    m.add(_patch(0, 1, 0, 1))
    m.add(_patch(3, 4, 0, 1))                     # apart from the first: a second plane
    assert len(m) == 2
    absorbed = m.add(_patch(0.9, 3.1, 0, 1))      # touches both: all three become one
    assert absorbed == 2
    assert len(m) == 1
    pl = m.planes[0]
    assert pl.n_points == 400 + 400 + 44 * 20
    np.testing.assert_allclose(pl.mean_intensity, 100.0)
    m.add(_patch(0, 1, 0, 1, z=2.0))              # a parallel plane 2 m away: not merged
    assert len(m) == 2


def test_voxel_store_counts():
    s = VoxelStore(0.5)
    s.add([[0.1, 0.1, 0.1], [0.2, 0.2, 0.2]])
    s.add([[0.3, 0.1, 0.1], [1.2, 0, 0]])
    assert len(s) == 2
    assert sorted(s.counts.tolist()) == [1, 3]


def _room_frame(rng, planes, n=1500, noise=0.0):
    """A frame of points on the given ``(normal, p, (u, v))`` patches, with panel intensities."""
    pts, inten = [], []
    for nrm, p, (u, w) in planes:
        ab = rng.uniform(-1.5, 1.5, (n, 2))
        X = p * np.asarray(nrm) + ab[:, :1] * np.asarray(u) + ab[:, 1:] * np.asarray(w)
        pts.append(X + rng.normal(0, noise, X.shape))
        inten.append(np.where((np.floor(ab[:, 0]) + np.floor(ab[:, 1])) % 2 == 0, 200.0, 800.0))
    X = np.concatenate(pts)
    rays = X / np.linalg.norm(X, axis=1, keepdims=True)
    return Frame(X, np.concatenate(inten), rays, 0)


EX, EY, EZ = np.eye(3)
THREE = [(EX, 3.0, (EY, EZ)), (EY, 2.0, (EX, EZ)), (EZ, 1.5, (EX, EY))]


@pytest.fixture
def slam():
    s = PlaneSLAM(n_particles=50, rng=0, ransac_min_support=300, min_normal_rank=2)
    s.step(_room_frame(np.random.default_rng(1), THREE), np.eye(4))
    assert len(s.map) == 3
    return s


@pytest.mark.parametrize("case", ["no plane", "one plane", "parallel only", "nan points", "empty"])
def test_degenerate_frames_keep_the_prediction_and_are_counted(slam, case):
    rng = np.random.default_rng(2)
    if case == "no plane":
        frame = Frame(rng.uniform(-3, 3, (2000, 3)), np.ones(2000), np.tile(EX, (2000, 1)), 0)
    elif case == "one plane":
        frame = _room_frame(rng, THREE[:1])
    elif case == "parallel only":
        frame = _room_frame(rng, [THREE[0], (-EX, 3.0, (EY, EZ))])
    elif case == "nan points":
        frame = _room_frame(rng, THREE)
        frame.points[5] = np.nan
    else:
        frame = Frame(np.zeros((0, 3)), np.zeros(0), np.zeros((0, 3)), 0)
    rep = slam.step(frame, np.eye(4))
    assert not rep.corrected
    assert slam.n_kept_prediction == 1
    np.testing.assert_array_equal(slam.X, slam.X_predicted)


def test_a_good_frame_pulls_particles_back(slam):
    # the body moved +0.2 m in x but odometry says 0: the planes put the particles back near the truth
    frame = _room_frame(np.random.default_rng(3), [(EX, 2.8, (EY, EZ)), THREE[1], THREE[2]])
    rep = slam.step(frame, np.eye(4))
    assert rep.corrected
    assert slam.n_kept_prediction == 0
    assert slam.pose[0, 3] == pytest.approx(0.2, abs=0.01)


def test_bad_arguments():
    with pytest.raises(ValueError, match="n_particles"):
        PlaneSLAMParams(n_particles=0)
    with pytest.raises(TypeError, match="intensity_weights"):
        PlaneSLAMParams(intensity_weights=1)
    with pytest.raises(ValueError, match="min_normal_rank"):
        PlaneSLAMParams(min_normal_rank=4)
    with pytest.raises(TypeError, match="nope"):
        PlaneSLAM(nope=1)
    s = PlaneSLAM(n_particles=3)
    with pytest.raises(TypeError, match="frame"):
        s.step(np.zeros((10, 3)), np.eye(4))
    with pytest.raises(ValueError, match="odometry_increment"):
        s.step(Frame(np.zeros((0, 3)), np.zeros(0), np.zeros((0, 3)), 0), np.eye(3))
    with pytest.raises(ValueError, match="initial_pose"):
        PlaneSLAM(np.eye(3))


def test_plane_frame_is_orthonormal_on_the_plane():
    T = plane_frame([0.0, 0.6, 0.8], 2.0, [1.0, 1.0, 1.0])
    np.testing.assert_allclose(T[:3, :3].T @ T[:3, :3], np.eye(3), atol=1e-12)
    assert T[:3, 2] @ T[:3, 3] == pytest.approx(2.0)


def test_V_is_a_variance():
    # 002: "ε normally distributed with zero mean and a variance equal to V": the draws' std is sqrt(V)
    X = np.repeat(np.eye(4)[None], 20000, 0)
    out = predict_particles(X, np.eye(4), 0.04, 4.0, np.random.default_rng(1))
    assert np.std(out[:, :3, 3]) == pytest.approx(0.2, rel=0.02)
    from scipy.spatial.transform import Rotation

    rv = np.rad2deg(Rotation.from_matrix(out[:, :3, :3]).as_rotvec())
    assert np.std(rv) == pytest.approx(2.0, rel=0.02)
    assert PlaneSLAMParams().V_xyz_m2 == pytest.approx(0.03**2)
    with pytest.raises(ValueError, match="V_xyz_m2"):
        PlaneSLAMParams(V_xyz_m2=-1.0)
    with pytest.raises(TypeError, match="sigma_xyz_m"):
        PlaneSLAMParams.resolve(None, sigma_xyz_m=0.03)


def test_reconfigure_changes_the_next_prediction_and_refuses_fixed_fields():
    empty = Frame(np.zeros((0, 3)), np.zeros(0), np.zeros((0, 3)), 0)  # keeps the prediction: X moves by ε only
    s = PlaneSLAM(n_particles=4000, rng=0, V_xyz_m2=0.04)
    s.step(empty, np.eye(4))
    assert np.std(s.X[:, :3, 3]) == pytest.approx(0.2, rel=0.05)  # sqrt(V) of the first setting
    before = s.X[:, :3, 3].copy()
    assert s.reconfigure(V_xyz_m2=1e-4) is s.params
    assert s.params.V_xyz_m2 == 1e-4
    s.step(empty, np.eye(4))
    assert np.std(s.X[:, :3, 3] - before) == pytest.approx(0.01, rel=0.05)  # the new V: sqrt(1e-4)
    with pytest.raises(ValueError, match="'n_particles' cannot change"):
        s.reconfigure(n_particles=10)
    with pytest.raises(ValueError, match="V_xyz_m2"):
        s.reconfigure(V_xyz_m2=-1.0)
    with pytest.raises(TypeError, match="no field"):
        s.reconfigure(sigma_xyz_m=0.1)


def test_plane_from_cells_sums_the_entries_of_each_cell_in_key_order():
    ij = np.array([[2, -1], [0, 0], [2, -1], [-3, 5]])
    pl = Plane.from_cells(np.array([0, 0, 1.0]), 1.5, np.eye(4), 0.25, ij, [1, 2, 3, 4], [10.0, 20.0, 30.0, 40.0])
    assert pl.ij.tolist() == [[-3, 5], [0, 0], [2, -1]]          # ascending keys: i first, then j
    assert pl.counts.tolist() == [4, 2, 4]
    assert pl.counts.dtype == np.int64
    np.testing.assert_array_equal(pl.sums, [40.0, 20.0, 40.0])
    assert np.all(np.diff(pl.keys) > 0)
    assert pl.p == 1.5
    assert isinstance(pl.p, float)
