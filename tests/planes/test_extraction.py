"""Frame building and RANSAC plane extraction (002): against exact geometry and least-squares fits."""

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from slamlab.planes import build_frame, describe_plane, extract_planes, fit_plane_lsq, frame_transforms
from slamlab.planes.description import lookup_mean_intensity
from slamlab.sim import PlaneScanner, simulate_flight


def _pose(rv, t):
    T = np.eye(4)
    T[:3, :3] = Rotation.from_rotvec(rv).as_matrix()
    T[:3, 3] = t
    return T


def test_frame_transforms_are_inverse_of_last_times_each():
    rng = np.random.default_rng(0)
    O = np.stack([_pose(rng.normal(0, 0.5, 3), rng.normal(0, 2, 3)) for _ in range(5)])
    T = frame_transforms(O)
    for j in range(5):
        np.testing.assert_allclose(T[j], np.linalg.inv(O[-1]) @ O[j], atol=1e-12)
    np.testing.assert_allclose(T[-1], np.eye(4), atol=1e-12)


def test_noise_free_frame_points_lie_on_the_room_planes_seen_from_the_last_line():
    sc = PlaneScanner(sigma_range_m=0.0, sigma_intensity=0.0)
    f = simulate_flight(1.0, scanner=sc, odometry_noise=0.0, rng=0)
    fr = build_frame(f.body_points(), f.intensities, f.odometry, origin_m=sc.mount_m)
    assert len(fr) + fr.n_dropped == 40 * 1081
    assert len(fr) > 40000                                  # 002: "over 40 000 points"
    TN = f.poses[-1]
    x_m = fr.points @ TN[:3, :3].T + TN[:3, 3]
    k = f.plane_ids[f.plane_ids >= 0]
    np.testing.assert_allclose(np.einsum("ij,ij->i", f.room.normals[k], x_m), f.room.offsets[k], atol=1e-9)
    np.testing.assert_allclose(np.linalg.norm(fr.rays, axis=1), 1.0)


def test_nan_points_are_dropped_and_bad_shapes_named():
    P = np.zeros((2, 3, 3))
    P[0, 1] = np.nan
    fr = build_frame(P, np.ones((2, 3)), np.tile(np.eye(4), (2, 1, 1)))
    assert (len(fr), fr.n_dropped) == (5, 1)
    with pytest.raises(ValueError, match="points"):
        build_frame(np.zeros((2, 3)), np.ones((2, 3)), np.tile(np.eye(4), (2, 1, 1)))
    with pytest.raises(ValueError, match="intensities"):
        build_frame(P, np.ones((2, 4)), np.tile(np.eye(4), (2, 1, 1)))
    with pytest.raises(ValueError, match="odometry"):
        build_frame(P, np.ones((2, 3)), np.tile(np.eye(4), (3, 1, 1)))


def _box_scene(rng, noise=0.0, n=3000):
    """Three planes (two of them parallel) plus uniform clutter; returns points and the true labels."""
    planes = [(np.array([0.0, 0.0, 1.0]), 2.5), (np.array([1.0, 0.0, 0.0]), 4.0), (np.array([-1.0, 0, 0]), 3.0)]
    pts, lab = [], []
    for i, (nrm, p) in enumerate(planes):
        # in-plane axes; the patches stay > 0.5 m from the other planes (no points near an intersection)
        u, w = (np.eye(3)[[0, 1]] if i == 0 else np.eye(3)[[1, 2]])
        ab = rng.uniform(-2, 2, (n - 800 * i, 2))
        pts.append(p * nrm + ab[:, :1] * u + ab[:, 1:] * w + rng.normal(0, noise, (len(ab), 1)) * nrm)
        lab.append(np.full(len(ab), i))
    clutter = rng.uniform(-2.5, 2.5, (600, 3)) * [1, 1, 0.8]
    far = np.all([np.abs(clutter @ nrm - p) > 0.1 for nrm, p in planes], axis=0)
    clutter = clutter[far][:300]                    # clutter off every plane: the inlier sets are exact
    pts.append(clutter)
    lab.append(np.full(len(clutter), -1))
    return np.concatenate(pts), np.concatenate(lab), planes


def test_ransac_matches_least_squares_on_noise_free_planes():
    rng = np.random.default_rng(1)
    X, lab, truth = _box_scene(rng)
    found, leftover = extract_planes(X, tolerance_m=0.01, min_support=300, rng=2)
    assert len(found) == 3
    for (n, p, idx), i in zip(found, range(3), strict=True):
        # the biggest plane first; each equals the least-squares fit of its true points, and the truth
        n_ls, p_ls = fit_plane_lsq(X[lab == i])
        np.testing.assert_allclose(n, n_ls, atol=1e-9)
        assert p == pytest.approx(p_ls, abs=1e-9)
        np.testing.assert_allclose(n * np.sign(n @ truth[i][0]), truth[i][0], atol=1e-9)
        np.testing.assert_array_equal(np.sort(idx), np.flatnonzero(lab == i))
    np.testing.assert_array_equal(leftover, lab == -1)


def test_ransac_on_noisy_planes_is_its_own_inliers_least_squares_fit():
    rng = np.random.default_rng(3)
    X, _, _ = _box_scene(rng, noise=0.01)
    found, _ = extract_planes(X, tolerance_m=0.03, min_support=300, rng=4)
    for n, p, idx in found:
        n_ls, _ = fit_plane_lsq(X[idx])
        assert np.all(np.abs(X[idx] @ n - p) <= 0.03)
        assert abs(n @ n_ls) == pytest.approx(1.0, abs=1e-6)


def test_fit_plane_lsq_closed_form_and_errors():
    n, p = fit_plane_lsq([[1, 0, 0], [0, 1, 0], [0, 0, 1.0]])
    np.testing.assert_allclose(n, np.ones(3) / np.sqrt(3), atol=1e-12)
    assert p == pytest.approx(1 / np.sqrt(3))
    with pytest.raises(ValueError, match="collinear"):
        fit_plane_lsq([[0, 0, 0], [1, 1, 1], [2, 2, 2.0]])
    with pytest.raises(ValueError, match="points"):
        fit_plane_lsq([[0, 0, 0], [1, 1, 1]])
    with pytest.raises(ValueError, match="tolerance_m"):
        extract_planes(np.zeros((10, 3)), tolerance_m=-1)
    with pytest.raises(ValueError, match="points"):
        extract_planes(np.full((10, 3), np.nan))


def test_cell_grid_counts_and_sums_against_a_loop():
    rng = np.random.default_rng(5)
    ab = rng.uniform(0, 2, (500, 2))
    X = np.c_[ab, np.full(500, 1.0)]
    I = rng.uniform(0, 100, 500)
    pl = describe_plane(X, I, [0, 0, 1.0], 1.0, cell_m=0.5, incidence_correction=False)
    assert pl.counts.sum() == 500
    # every cell: count and sum of the points whose in-plane coordinates fall into it
    local = (X - pl.T[:3, 3]) @ pl.T[:3, :2]
    for (i, j), c, s in zip(pl.ij, pl.counts, pl.sums, strict=True):
        inside = (np.floor(local[:, 0] / 0.5) == i) & (np.floor(local[:, 1] / 0.5) == j)
        assert c == inside.sum()
        assert s == pytest.approx(I[inside].sum())
    np.testing.assert_allclose(lookup_mean_intensity(pl, X[:5]), [pl.mean_intensity[
        np.flatnonzero((pl.ij == np.floor(local[k] / 0.5)).all(1))[0]] for k in range(5)])
    assert np.isnan(lookup_mean_intensity(pl, [[50.0, 50.0, 1.0]])[0])


def test_incidence_correction_divides_by_cos():
    X = np.array([[0.1, 0.1, 1.0]])
    ray = np.array([[0.6, 0.0, 0.8]])
    pl = describe_plane(X, [40.0], [0, 0, 1.0], 1.0, rays=ray)
    assert pl.mean_intensity[0] == pytest.approx(50.0)
    with pytest.raises(ValueError, match="rays"):
        describe_plane(X, [40.0], [0, 0, 1.0], 1.0)
