"""The disparity offset of a rig estimated from two frames' stereo pixels (ours; KITTI 01's 7 % long path)."""

import numpy as np
import pytest

from slamlab.geometry import StereoRig
from slamlab.stereo import StereoParams
from slamlab.stereo.disparity_offset import DisparityOffsetTracker, disparity_offset_step
from slamlab.studies.stereo import KITTI_PARAMS

RIG = StereoRig.parallel(0.54, 1241, 376, hfov_rad=2 * np.arctan(620.5 / 718.0))  # KITTI-like: f = 718 px


def _uvd(points, bias_px):
    """(u, v, d) of left-camera points with every disparity measured ``bias_px`` too small."""
    c = RIG.left
    fb = c.fx * RIG.baseline_m
    return np.c_[c.fx * points[:, 0] / points[:, 2] + c.cx, c.fy * points[:, 1] / points[:, 2] + c.cy,
                 fb / points[:, 2] - bias_px]


def _scene(rng, n=150):
    # a highway-like cloud 8-60 m ahead; the camera moves 1 m forward and turns 0.5 deg
    X = rng.uniform([-15, -2, 8], [15, 2, 60], (n, 3))
    a = np.deg2rad(0.5)
    T = np.eye(4)
    T[:3, :3] = [[np.cos(a), 0, np.sin(a)], [0, 1, 0], [-np.sin(a), 0, np.cos(a)]]
    T[:3, 3] = [0.0, 0.0, -1.0]
    return X, T, X @ T[:3, :3].T + T[:3, 3]


@pytest.mark.parametrize("bias_px", [0.0, 1.0, -0.5])
def test_a_known_offset_and_the_motion_are_recovered_from_exact_pixels(bias_px):
    X, T, Xc = _scene(np.random.default_rng(0))
    T0 = T.copy()
    T0[2, 3] = -0.9  # a start 10 % short, as a biased disparity gives
    d, var, T_fit = disparity_offset_step(_uvd(X, bias_px), _uvd(Xc, bias_px), T0, RIG)
    assert d == pytest.approx(bias_px, abs=1e-6)
    np.testing.assert_allclose(T_fit, T, atol=1e-6)
    assert var >= 0


def test_noisy_pixels_give_the_offset_within_its_standard_deviation():
    rng = np.random.default_rng(1)
    X, T, Xc = _scene(rng, n=300)
    noise = 0.3  # px, each coordinate of both frames
    A = _uvd(X, 1.0) + rng.normal(0, noise, (len(X), 3))
    B = _uvd(Xc, 1.0) + rng.normal(0, noise, (len(X), 3))
    d, var, _ = disparity_offset_step(A, B, T, RIG)
    assert 0 < np.sqrt(var) < 0.5
    assert abs(d - 1.0) <= 4 * np.sqrt(var) + 0.1  # the previous frame's noise biases it up a little (1/d convex)


def test_the_tracker_averages_frame_pairs_and_sets_the_parameter():
    rng = np.random.default_rng(2)
    p = StereoParams(disparity_offset_estimate=True)
    tr = DisparityOffsetTracker(p)
    assert tr.offset_px == 0.0
    X = rng.uniform([-15, -2, 8], [15, 2, 60], (120, 3))
    ids = np.arange(120)
    T_wl = np.eye(4)
    for _ in range(4):
        uvd = _uvd(X - T_wl[:3, 3], 0.8) + rng.normal(0, 0.05, (len(X), 3))
        tr.observe(ids, uvd, T_wl, RIG)  # the camera moves 1 m forward per frame
        T_wl = T_wl.copy()
        T_wl[2, 3] += 1.0
    assert len(tr.history) == 3
    d, var = np.array(tr.history).T
    assert tr.offset_px == pytest.approx(np.sum(d / var) / np.sum(1 / var))  # the information-weighted mean
    assert tr.offset_px == pytest.approx(0.8, abs=0.1)


def test_a_fixed_offset_is_added_to_every_disparity():
    # a point at 10 m measured with its disparity 1 px too small: the offset moves it back to 10 m
    from slamlab.features.base import Features
    from slamlab.stereo import StereoMatches, triangulate_local

    c = RIG.left
    d_true = c.fx * RIG.baseline_m / 10.0
    def one(u):
        return Features(np.array([[u, c.cy]]), np.ones(1), np.zeros(1), np.ones(1), np.zeros(1, int),
                        np.zeros((1, 64), np.float32))

    left, right = one(c.cx), one(c.cx - d_true + 1.0)
    m = StereoMatches(np.array([0]), np.array([0]), np.array([0.0]))
    z = [triangulate_local(RIG, left, right, m, max_depth_m=100.0, **kw).points[0, 2]
         for kw in ({}, {"disparity_offset_px": 1.0}, {"extra_offset_px": 1.0},
                    {"disparity_offset_px": 0.5, "extra_offset_px": 0.5})]
    assert z[0] == pytest.approx(10.0 * d_true / (d_true - 1.0))
    assert z[1:] == pytest.approx([10.0, 10.0, 10.0])
    with pytest.raises(TypeError, match="extra_offset_px"):
        triangulate_local(RIG, left, right, m, extra_offset_px="1")


def test_kitti_params_estimate_the_offset():
    assert KITTI_PARAMS.disparity_offset_estimate is True
    assert KITTI_PARAMS.refine_min_seen == 1


def test_bad_input_names_the_argument():
    X, T, Xc = _scene(np.random.default_rng(0), n=10)
    with pytest.raises(ValueError, match="uvd_prev"):
        disparity_offset_step(_uvd(X, 0)[:, :2], _uvd(Xc, 0)[:, :2], T, RIG)
    with pytest.raises(ValueError, match="uvd_prev"):
        disparity_offset_step(_uvd(X, 0)[:2], _uvd(Xc, 0)[:2], T, RIG)
    with pytest.raises(ValueError, match="T_cur_prev"):
        disparity_offset_step(_uvd(X, 0), _uvd(Xc, 0), np.eye(3), RIG)
    with pytest.raises(TypeError, match="rig"):
        disparity_offset_step(_uvd(X, 0), _uvd(Xc, 0), T, "rig")
    with pytest.raises(TypeError, match="params"):
        DisparityOffsetTracker("params")
    with pytest.raises(TypeError, match="disparity_offset_px"):
        StereoParams(disparity_offset_px=float("nan"))
    with pytest.raises(TypeError, match="disparity_offset_estimate"):
        StereoParams(disparity_offset_estimate=1)
