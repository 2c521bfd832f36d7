"""Midpoint triangulation (000 §3.3) against cv2.triangulatePoints and exact geometry."""

import cv2
import numpy as np
import pytest

from slamlab.geometry import StereoRig, rotation_xyz, triangulate_midpoint, triangulate_stereo
from slamlab.geometry.camera import PinholeCamera


def _projection_matrices(rig):
    P1 = rig.left.K @ np.hstack([np.eye(3), np.zeros((3, 1))])
    P2 = rig.right.K @ np.hstack([rig.R_rl, rig.t_rl[:, None]])
    return P1, P2


def _cv_triangulate(rig, uvl, uvr):
    P1, P2 = _projection_matrices(rig)
    X = cv2.triangulatePoints(P1, P2, uvl.T.astype(np.float64), uvr.T.astype(np.float64))
    return (X[:3] / X[3]).T


@pytest.fixture
def rig():
    cam = PinholeCamera.from_hfov()
    return StereoRig(cam, cam, rotation_xyz(0.02, 0.01, -0.01), np.array([-0.2, 0.005, 0.01]))


def _points(n, rng):
    return np.column_stack([rng.uniform(-1.5, 1.5, n), rng.uniform(-0.5, 0.5, n), rng.uniform(1.0, 8.0, n)])


def test_exact_data_recovers_points_and_matches_opencv(rig):
    P = _points(200, np.random.default_rng(0))
    uvl, uvr = rig.project(P)
    tri = triangulate_stereo(rig, uvl, uvr)
    np.testing.assert_allclose(tri.points, P, atol=1e-9)
    np.testing.assert_allclose(tri.points, _cv_triangulate(rig, uvl, uvr), atol=1e-7)
    assert tri.valid.all()
    assert tri.gap_m.max() < 1e-9


def test_noisy_pixels_agree_with_opencv_to_within_the_depth_error(rig):
    rng = np.random.default_rng(1)
    P = _points(500, rng)
    uvl, uvr = rig.project(P)
    uvl = uvl + rng.normal(0, 0.5, uvl.shape)
    uvr = uvr + rng.normal(0, 0.5, uvr.shape)
    ours = triangulate_stereo(rig, uvl, uvr).points
    ref = _cv_triangulate(rig, uvl, uvr)
    # stereo depth error sigma_z = z^2 sigma_d / (f b); the two estimators differ by far less
    sigma_z = P[:, 2] ** 2 * 0.7 / (rig.left.fx * 0.2)
    diff = np.linalg.norm(ours - ref, axis=1)
    assert np.all(diff < sigma_z)
    assert np.median(diff / sigma_z) < 0.05
    # and both are equally accurate against the truth
    rms = [np.sqrt(np.mean(np.sum((X - P) ** 2, axis=1))) for X in (ours, ref)]
    assert rms[0] == pytest.approx(rms[1], rel=0.05)
    assert np.all(np.linalg.norm(ours - P, axis=1) < 5 * sigma_z + 1e-3)


def test_midpoint_is_on_the_common_perpendicular():
    rng = np.random.default_rng(2)
    c1, c2 = rng.normal(size=(40, 3)), rng.normal(size=(40, 3))
    d1, d2 = rng.normal(size=(40, 3)), rng.normal(size=(40, 3))
    tri = triangulate_midpoint(c1, d1, c2, d2)
    p1 = c1 + tri.s[:, None] * d1
    p2 = c2 + tri.t[:, None] * d2
    seg = p1 - p2
    # the connecting segment is orthogonal to both rays
    assert np.max(np.abs(np.einsum("ij,ij->i", seg, d1))) < 1e-9
    assert np.max(np.abs(np.einsum("ij,ij->i", seg, d2))) < 1e-9
    np.testing.assert_allclose(tri.gap_m, np.linalg.norm(seg, axis=1))
    # closed form for the gap of two skew lines: |w . (d1 x d2)| / |d1 x d2|
    n = np.cross(d1, d2)
    gap = np.abs(np.einsum("ij,ij->i", c1 - c2, n)) / np.linalg.norm(n, axis=1)
    np.testing.assert_allclose(tri.gap_m, gap, rtol=1e-9, atol=1e-12)


def test_parallel_and_behind_rays_are_invalid():
    tri = triangulate_midpoint(
        [0.0, 0.0, 0.0], [[0.0, 0.0, 1.0], [0.1, 0.0, 1.0]], [1.0, 0.0, 0.0], [[0.0, 0.0, 1.0], [0.5, 0.0, 1.0]]
    )
    assert tri.valid.tolist() == [False, False]  # parallel; crossing behind the cameras
    assert np.all(np.isfinite(tri.points))


def test_bad_input():
    with pytest.raises(ValueError, match="d1"):
        triangulate_midpoint(np.zeros(3), np.ones((2, 2)), np.zeros(3), np.ones((2, 3)))
    with pytest.raises(ValueError, match="same number of rows"):
        triangulate_midpoint(np.zeros(3), np.ones((2, 3)), np.zeros(3), np.ones((3, 3)))
    with pytest.raises(ValueError, match="zero-length"):
        triangulate_midpoint(np.zeros(3), np.zeros((1, 3)), np.ones(3), np.ones((1, 3)))
    with pytest.raises(ValueError, match="finite"):
        triangulate_midpoint(np.zeros(3), [[np.nan, 0.0, 1.0]], np.ones(3), np.ones((1, 3)))
    with pytest.raises(TypeError, match="c1"):
        triangulate_midpoint(None, np.ones((1, 3)), np.ones(3), np.ones((1, 3)))
