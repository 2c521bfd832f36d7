"""Pinhole camera and stereo rig against OpenCV (000 §3.2-3.3)."""

import cv2
import numpy as np
import pytest

from slamlab.geometry import (
    PinholeCamera,
    StereoRig,
    backproject_points,
    focal_from_hfov,
    fundamental_matrix,
    project_points,
    rotation_xyz,
)


def test_focal_from_hfov_closed_form():
    f = focal_from_hfov(768, np.deg2rad(40.0))
    # the image half-width seen at the field-of-view edge: tan(20 deg) = 384 / f
    assert np.tan(np.deg2rad(20.0)) == pytest.approx(384.0 / f, rel=1e-12)
    assert 1054 < f < 1056


def test_project_matches_cv2_projectpoints():
    cam = PinholeCamera.from_hfov(768, 576, np.deg2rad(40.0))
    rng = np.random.default_rng(0)
    P = np.column_stack([rng.uniform(-1, 1, 50), rng.uniform(-1, 1, 50), rng.uniform(1, 8, 50)])
    ref, _ = cv2.projectPoints(P, np.zeros(3), np.zeros(3), cam.K, None)
    np.testing.assert_allclose(cam.project(P), ref[:, 0, :], atol=1e-9)


def test_backproject_inverts_project():
    cam = PinholeCamera.from_hfov(768, 576, np.deg2rad(40.0))
    P = np.array([[0.3, -0.2, 2.0], [-1.0, 0.5, 5.0]])
    d = cam.backproject(cam.project(P))
    np.testing.assert_allclose(d * P[:, 2:], P, atol=1e-12)


def test_pixel_rays_corners_span_the_field_of_view():
    cam = PinholeCamera.from_hfov(768, 576, np.deg2rad(40.0))
    rays = cam.pixel_rays()
    assert rays.shape == (576, 768, 3)
    # pixel edges (not centres) lie at +-tan(20 deg): centres are half a pixel inside
    assert rays[0, -1, 0] == pytest.approx(np.tan(np.deg2rad(20.0)) - 0.5 / cam.fx, rel=1e-12)
    np.testing.assert_allclose(rays[10, 20], cam.backproject([[20.0, 10.0]])[0])


def test_stereo_rig_projection_and_epipolar_constraint():
    rig = StereoRig(
        PinholeCamera.from_hfov(), PinholeCamera.from_hfov(), rotation_xyz(0.01, -0.02, 0.005), np.array([-0.2, 0.01, 0.0])
    )
    rng = np.random.default_rng(1)
    P = np.column_stack([rng.uniform(-1, 1, 30), rng.uniform(-0.5, 0.5, 30), rng.uniform(1.5, 8, 30)])
    uvl, uvr = rig.project(P)
    rvec, _ = cv2.Rodrigues(rig.R_rl)
    ref, _ = cv2.projectPoints(P, rvec, rig.t_rl, rig.right.K, None)
    np.testing.assert_allclose(uvr, ref[:, 0, :], atol=1e-9)
    xl = np.column_stack([uvl, np.ones(30)])
    xr = np.column_stack([uvr, np.ones(30)])
    F = rig.F
    F = F / np.linalg.norm(F)
    assert np.max(np.abs(np.einsum("ij,jk,ik->i", xr, F, xl))) < 1e-9
    # OpenCV's F from the same correspondences agrees up to scale
    F_cv, _ = cv2.findFundamentalMat(uvl, uvr, cv2.FM_8POINT)
    F_cv = F_cv / np.linalg.norm(F_cv)
    assert min(np.linalg.norm(F - F_cv), np.linalg.norm(F + F_cv)) < 1e-4


def test_parallel_rig_geometry():
    rig = StereoRig.parallel(0.25)
    assert rig.baseline_m == pytest.approx(0.25)
    uvl, uvr = rig.project([[0.0, 0.0, 5.0]])
    # disparity = f b / z
    assert uvl[0, 0] - uvr[0, 0] == pytest.approx(rig.left.fx * 0.25 / 5.0, rel=1e-12)
    assert uvl[0, 1] == pytest.approx(uvr[0, 1])


def test_fundamental_matrix_identity_rotation():
    K = np.eye(3)
    F = fundamental_matrix(K, K, np.eye(3), [-1.0, 0.0, 0.0])
    # pure x translation: epipolar lines are rows (y_r = y_l)
    assert np.array([0.1, 0.3, 1.0]) @ F @ np.array([0.4, 0.3, 1.0]) == pytest.approx(0.0)
    assert abs(np.array([0.1, 0.35, 1.0]) @ F @ np.array([0.4, 0.3, 1.0])) > 1e-3


@pytest.mark.parametrize(
    ("kwargs", "exc", "match"),
    [
        ({"width_px": 0, "hfov_rad": 0.5}, ValueError, "width_px"),
        ({"width_px": 768, "hfov_rad": 4.0}, ValueError, "hfov_rad"),
        ({"width_px": 768, "hfov_rad": -1.0}, ValueError, "hfov_rad"),
        ({"width_px": 7.5, "hfov_rad": 0.5}, TypeError, "width_px"),
    ],
)
def test_focal_bad_input(kwargs, exc, match):
    with pytest.raises(exc, match=match):
        focal_from_hfov(**kwargs)


def test_camera_bad_input():
    cam = PinholeCamera.from_hfov()
    with pytest.raises(ValueError, match="points_cam"):
        cam.project([[0.0, 0.0]])
    with pytest.raises(ValueError, match="in front of the camera"):
        cam.project([[0.0, 0.0, -1.0]])
    with pytest.raises(ValueError, match="finite"):
        cam.project([[0.0, np.nan, 1.0]])
    with pytest.raises(ValueError, match="uv"):
        cam.backproject([1.0, 2.0])
    with pytest.raises(ValueError, match="fx"):
        PinholeCamera(10, 10, -1.0, 1.0, 5.0, 5.0)
    with pytest.raises(ValueError, match="R_rl"):
        StereoRig(cam, cam, 2 * np.eye(3), np.zeros(3))
    with pytest.raises(TypeError, match="PinholeCamera"):
        StereoRig(cam, None, np.eye(3), np.zeros(3))
    with pytest.raises(ValueError, match="baseline_m"):
        StereoRig.parallel(0.0)
    with pytest.raises(ValueError, match="same shape"):
        StereoRig.parallel().rays([[1.0, 2.0]], [[1.0, 2.0], [3.0, 4.0]])


def test_project_points_matches_the_homogeneous_product_and_cv2():
    K = np.array([[500.0, 0.0, 320.0], [0.0, 480.0, 240.0], [0.0, 0.0, 1.0]])
    rng = np.random.default_rng(3)
    X = np.column_stack([rng.uniform(-2, 2, 40), rng.uniform(-2, 2, 40), rng.uniform(0.5, 9, 40)])
    h = X @ K.T  # independent reference: K X, then divide by the last coordinate
    np.testing.assert_allclose(project_points(K, X), h[:, :2] / h[:, 2:], rtol=1e-13)
    ref, _ = cv2.projectPoints(X, np.zeros(3), np.zeros(3), K, None)
    np.testing.assert_allclose(project_points(K, X), ref[:, 0, :], atol=1e-9)
    # the camera's method is this function
    cam = PinholeCamera(640, 480, 500.0, 480.0, 320.0, 240.0)
    assert np.array_equal(cam.project(X), project_points(cam.K, X))


def test_project_points_min_depth_clamps_z():
    K = np.diag([100.0, 100.0, 1.0])
    X = np.array([[1.0, -1.0, -2.0], [1.0, 1.0, 2.0]])
    np.testing.assert_array_equal(project_points(K, X, min_depth=0.5), [[200.0, -200.0], [50.0, 50.0]])


def test_project_points_bad_input():
    with pytest.raises(ValueError, match=r"`K` must have shape \(3, 3\); got \(2, 2\)"):
        project_points(np.eye(2), np.ones((3, 3)))
    with pytest.raises(ValueError, match=r"`X` must have shape \(N, 3\) or \(\.\.\., 3\); got \(3, 2\)"):
        project_points(np.eye(3), np.ones((3, 2)))


def test_project_points_is_batched_over_leading_axes():
    K = np.array([[500.0, 0.0, 320.0], [0.0, 480.0, 240.0], [0.0, 0.0, 1.0]])
    X = np.random.default_rng(0).uniform([-1, -1, 1], [1, 1, 5], (4, 5, 3))
    uv = project_points(K, X)
    assert uv.shape == (4, 5, 2)
    np.testing.assert_array_equal(uv.reshape(-1, 2), project_points(K, X.reshape(-1, 3)))  # same bits
    # independent reference: the homogeneous product K X, divided by its last row
    h = X @ K.T
    np.testing.assert_allclose(uv, h[..., :2] / h[..., 2:], rtol=1e-13)


def test_project_points_jacobian_matches_finite_differences():
    K = np.array([[500.0, 0.0, 320.0], [0.0, 480.0, 240.0], [0.0, 0.0, 1.0]])
    X = np.array([[0.3, -0.2, 2.0], [-1.0, 0.5, 5.0]])
    uv, J = project_points(K, X, jacobian=True)
    np.testing.assert_array_equal(uv, project_points(K, X))
    assert J.shape == (2, 2, 3)
    eps = 1e-6
    for k in range(3):
        d = np.zeros(3)
        d[k] = eps
        num = (project_points(K, X + d) - project_points(K, X - d)) / (2 * eps)
        np.testing.assert_allclose(J[:, :, k], num, rtol=1e-7, atol=1e-6)


def test_stereo_pixels_are_both_projections_with_their_jacobian():
    rig = StereoRig(PinholeCamera(640, 480, 500.0, 500.0, 320.0, 240.0), PinholeCamera(640, 480, 510.0, 505.0, 318.0, 242.0),
                    rotation_xyz(0.01, -0.02, 0.005), [-0.3, 0.01, 0.0])
    X = np.array([[0.3, -0.2, 4.0], [-1.0, 0.5, 9.0]])
    z, J = rig.stereo_pixels(X, jacobian=True)
    uv_l, uv_r = rig.project(X)
    np.testing.assert_allclose(z, np.hstack([uv_l, uv_r]), rtol=1e-14)
    np.testing.assert_array_equal(rig.stereo_pixels(X), z)
    eps = 1e-6
    for k in range(3):
        d = np.zeros(3)
        d[k] = eps
        num = (rig.stereo_pixels(X + d) - rig.stereo_pixels(X - d)) / (2 * eps)
        np.testing.assert_allclose(J[:, :, k], num, rtol=1e-6, atol=1e-5)
    with pytest.raises(ValueError, match=r"`points_left` must have shape \(N, 3\); got \(2, 2\)"):
        rig.stereo_pixels(np.ones((2, 2)))



def test_backproject_points_inverts_project_points():
    K = np.array([[500.0, 0.0, 320.0], [0.0, 480.0, 240.0], [0.0, 0.0, 1.0]])
    X = np.array([[0.3, -0.2, 2.0], [-1.0, 0.5, 5.0]])
    np.testing.assert_allclose(backproject_points(K, project_points(K, X)) * X[:, 2:], X, atol=1e-12)
    # independent reference: K^-1 [u, v, 1]
    uv = np.array([[10.0, 20.0], [600.0, 400.0]])
    np.testing.assert_allclose(backproject_points(K, uv), np.c_[uv, np.ones(2)] @ np.linalg.inv(K).T, atol=1e-15)
    with pytest.raises(ValueError, match=r"`uv` must have shape \(N, 2\); got \(2,\)"):
        backproject_points(K, np.zeros(2))
