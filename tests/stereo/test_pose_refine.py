"""The stereo reprojection pose refinement and the landmark filter in pixels (issue 25's options; default off)."""

import numpy as np
import pytest

from slamlab.geometry import StereoRig, se3_from_planar
from slamlab.geometry.camera import PinholeCamera
from slamlab.geometry.registration import umeyama
from slamlab.stereo import StereoParams, StereoSLAM
from slamlab.stereo.pose_stages import refine_pose_stereo


def _kitti_like_rig():
    cam = PinholeCamera(1226, 370, 718.856, 718.856, 607.19, 185.22)
    return StereoRig(cam, cam, np.eye(3), np.array([-0.537, 0.0, 0.0]))


def _triangulate(rig, z_px):
    """Left-camera points of stereo pixels (u_l, v_l, u_r) of a rectified rig (the textbook formula)."""
    c = rig.left
    d = z_px[:, 0] - z_px[:, 2]
    z = c.fx * rig.baseline_m / d
    return np.column_stack([(z_px[:, 0] - c.cx) * z / c.fx, (z_px[:, 1] - c.cy) * z / c.fy, z])


def test_refinement_recovers_the_exact_pose_from_noise_free_points():
    """Construction: landmarks = the true pose applied to the local points; the refinement converges to it."""
    rig = _kitti_like_rig()
    g = np.random.default_rng(3)
    P = np.column_stack([g.uniform(-8, 8, 60), g.uniform(-2, 2, 60), g.uniform(4, 40, 60)])
    T_bl = se3_from_planar(0.0, 0.0, 0.0, 1.65)
    T = se3_from_planar(1.0, 0.05, 0.02) @ se3_from_planar(0.0, 0.0, 0.0, 0.03)
    X = (P @ T_bl[:3, :3].T + T_bl[:3, 3]) @ T[:3, :3].T + T[:3, 3]
    T0 = se3_from_planar(0.8, 0.0, 0.0)  # 0.2 m and 1 degree off
    T_est = refine_pose_stereo(T0, X, P, rig, T_bl, iters=10)
    assert np.allclose(T_est, T, atol=1e-9)


def test_refinement_is_unbiased_where_the_depth_weighted_3d_fit_is_not():
    """Noisy stereo points (0.5 px on u_l, v_l, u_r), exact landmarks, 1 m forward, 300 trials.

    The independent reason: with exact landmarks and Gaussian pixel noise, Gauss-Newton on the pixel error
    is the maximum-likelihood estimate, unbiased to first order; its mean forward error must lie within 3
    standard errors of 0. The 3-D fit with the pipeline's weights at the *measured* depth weights each point
    by its own noisy depth; its mean error must be larger than the refinement's.
    """
    rig = _kitti_like_rig()
    g = np.random.default_rng(0)
    T = np.eye(4)
    T[2, 3] = 1.0  # 1 m along the camera's optical axis
    err_fit, err_ref = [], []
    for _ in range(300):
        Pt = np.column_stack([g.uniform(-10, 10, 80), g.uniform(-1.5, 2, 80), np.exp(g.uniform(np.log(5), np.log(40), 80))])
        X = Pt @ T[:3, :3].T + T[:3, 3]  # landmarks in the map = the first camera frame
        z_px = rig.stereo_pixels(Pt)[:, :3] + 0.5 * g.standard_normal((80, 3))
        P = _triangulate(rig, z_px)
        w = 1.0 / np.maximum(1.0, (P[:, 2] / 3.0) ** 2) ** 2
        fit = umeyama(P, X, weights=w)
        T_fit = np.eye(4)
        T_fit[:3, :3], T_fit[:3, 3] = fit.R, fit.t
        T_ref = refine_pose_stereo(T_fit, X, P, rig)
        err_fit.append(T_fit[2, 3] - 1.0)  # the camera's z axis is forward
        err_ref.append(T_ref[2, 3] - 1.0)
    err_fit, err_ref = np.array(err_fit), np.array(err_ref)
    se = err_ref.std(ddof=1) / np.sqrt(err_ref.size)
    assert abs(err_ref.mean()) <= 3 * se
    assert abs(err_fit.mean()) > abs(err_ref.mean())
    assert err_ref.std() < err_fit.std()  # and more precise: the error is modelled along the ray


def test_refinement_bad_input():
    rig = _kitti_like_rig()
    P = np.array([[0.0, 0, 5], [1, 0, 6], [0, 1, 7], [1, 1, 8]])
    with pytest.raises(ValueError, match="landmarks_map"):
        refine_pose_stereo(np.eye(4), P[:3], P, rig)
    with pytest.raises(ValueError, match="at least 3"):
        refine_pose_stereo(np.eye(4), P[:2], P[:2], rig)
    with pytest.raises(ValueError, match="points_left"):
        refine_pose_stereo(np.eye(4), P, P * [1, 1, -1], rig)
    with pytest.raises(TypeError, match="rig"):
        refine_pose_stereo(np.eye(4), P, P, None)
    with pytest.raises(ValueError, match="iters"):
        refine_pose_stereo(np.eye(4), P, P, rig, iters=0)
    with pytest.raises(ValueError, match="huber_px"):
        refine_pose_stereo(np.eye(4), P, P, rig, huber_px=0.0)
    with pytest.raises(ValueError, match="T_body"):
        refine_pose_stereo(np.eye(3), P, P, rig)


@pytest.mark.parametrize(("field", "value"), [("pose_refine", "ba"), ("filter_space", "uvd"),
                                              ("reobserve_depth_factor", 0.5), ("refine_min_seen", 0),
                                              ("refine_iters", 0), ("refine_huber_px", -1.0),
                                              ("init_cov_depth", "map"), ("weight_depth", "oracle")])
def test_new_params_are_checked(field, value):
    with pytest.raises(ValueError, match=field):
        StereoParams(**{field: value})


def test_pixel_filter_averages_disparities_not_depths():
    """One landmark and one observation on the same ray with equal pixel covariances (σ² I in (u_l, v_l, u_r)):
    the Kalman update with equal covariances is the mean, so the fused disparity is the mean of the two
    disparities and the depth f b / mean(d) (the xyz filter would average nearer to the smaller depth)."""
    rig = _kitti_like_rig()
    slam = StereoSLAM(rig, params=StereoParams(filter_space="pixels", state_var=0.0, update_gate=None))
    c = rig.left
    z1, z2, sigma = 30.0, 20.0, slam.params.pixel_std
    X1 = np.array([[2.0 * z1 / c.fx, 1.0 * z1 / c.fy, z1]])  # pixel (cx + 2, cy + 1)
    J = rig.stereo_pixels(X1, jacobian=True)[1][:, :3]
    Ji = np.linalg.inv(J[0])
    slam.X, slam.P = X1.copy(), (sigma**2 * Ji @ Ji.T)[None]
    obs = np.array([[2.0 * z2 / c.fx, 1.0 * z2 / c.fy, z2]])
    ok = slam._refine_landmarks_in_pixels(np.array([0]), obs, np.eye(4), np.zeros(1))
    assert ok.tolist() == [True]
    fb = c.fx * rig.baseline_m
    assert slam.X[0, 2] == pytest.approx(fb / ((fb / z1 + fb / z2) / 2), rel=1e-9)
    assert slam.X[0, 0] == pytest.approx(2.0 * slam.X[0, 2] / c.fx, rel=1e-9)


def test_the_oracle_depth_needs_the_truth():
    from slamlab.sim.highway import HighwayScene, highway_path

    sc = HighwayScene(rng=0)
    slam = StereoSLAM(sc.rig, sc.T_body_left, params=StereoParams(weight_depth="true"), rng=0)
    with pytest.raises(ValueError, match="truth_left_cam_m"):
        slam.process_features(*sc.observe(highway_path(2)[0], rng=1))
    assert sc.last_observed is not None
    assert len(sc.last_observed[0]) > 100


def test_second_sighting_replaces_the_first_triangulation():
    """drop_first_sighting: a landmark seen twice holds one observation's covariance, not two fused ones.

    Construction: the Kalman fusion of two observations has a smaller covariance than either; with the option
    the second sighting replaces the first, so the landmarks seen twice keep a larger covariance (trace).
    """
    from slamlab.sim.highway import HighwayScene, highway_path

    tr = {}
    for drop in (False, True):
        sc = HighwayScene(rng=0)
        slam = StereoSLAM(sc.rig, sc.T_body_left, params=StereoParams(max_depth_m=40.0, drop_first_sighting=drop), rng=0)
        g = np.random.default_rng(1)
        for pose in highway_path(2):
            slam.process_features(*sc.observe(pose, pixel_std=0.5, rng=g))
        twice = np.flatnonzero(slam.n_seen == 2)
        assert twice.size > 50
        tr[drop] = np.trace(slam.P[twice], axis1=1, axis2=2)
    assert np.median(tr[True]) > 1.5 * np.median(tr[False])
    with pytest.raises(TypeError, match="drop_first_sighting"):
        StereoParams(drop_first_sighting=1)
