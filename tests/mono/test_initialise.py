"""Two-view initialisation (003 §4.3.1): homography / essential on exact synthetic scenes."""

from __future__ import annotations

import numpy as np
import pytest

from slamlab.geometry import rotation_xyz
from slamlab.mono import Initialiser, relative_pose_essential, relative_pose_homography, track_lk

K = np.array([[500.0, 0, 320], [0, 500.0, 240], [0, 0, 1]])


def _project(X):
    p = X @ K.T
    return p[:, :2] / p[:, 2:3]


def _scene(planar, rng, n=200):
    if planar:  # a tilted plane about 4 m ahead
        xy = rng.uniform(-2, 2, (n, 2))
        X0 = np.column_stack([xy, 4.0 + 0.3 * xy[:, 0] - 0.2 * xy[:, 1]])
    else:
        X0 = np.column_stack([rng.uniform(-2, 2, (n, 2)), rng.uniform(2.5, 8.0, n)])
    R = rotation_xyz(0.02, -0.05, 0.01)
    t = np.array([0.4, -0.05, 0.1])
    X1 = X0 @ R.T + t
    return _project(X0), _project(X1), R, t / np.linalg.norm(t)


def _angle_deg(R1, R2):
    return np.degrees(np.arccos(np.clip((np.trace(R1.T @ R2) - 1) / 2, -1, 1)))


def test_planar_scene_homography_recovers_pose():
    uv0, uv1, R, t = _scene(True, np.random.default_rng(0))
    pose = relative_pose_homography(uv0, uv1, K, ransac_px=0.5)
    assert pose.ok
    assert pose.inliers.all()
    assert _angle_deg(pose.R, R) < 1e-3
    assert np.degrees(np.arccos(np.clip(pose.t @ t, -1, 1))) < 1e-2
    assert pose.n_front == 200


def test_planar_scene_essential_is_ambiguous():
    # a plane is a critical surface of the 5-point method: two poses explain the matches
    # (Longuet-Higgins 1986). Over eight scenes the method returns poses that satisfy every match's epipolar
    # constraint, and at least one of them is not the true pose (which satisfies them too, by construction).
    def skew(v):
        return np.array([[0, -v[2], v[1]], [v[2], 0, -v[0]], [-v[1], v[0], 0]])

    wrong = 0
    for seed in range(8):
        uv0, uv1, R, t = _scene(True, np.random.default_rng(seed))
        e = relative_pose_essential(uv0, uv1, K, ransac_px=0.5)
        assert e.ok
        h0 = np.column_stack([uv0, np.ones(len(uv0))]) @ np.linalg.inv(K).T
        h1 = np.column_stack([uv1, np.ones(len(uv1))]) @ np.linalg.inv(K).T
        # the returned pose explains all 200 matches (normalised coordinates; 1e-5 is 0.005 px at f = 500 px)
        assert np.abs(np.einsum("ij,jk,ik->i", h1, skew(e.t) @ e.R, h0)).max() < 1e-5
        wrong += _angle_deg(e.R, R) > 1.0 or np.degrees(np.arccos(np.clip(e.t @ t, -1, 1))) > 1.0
    assert wrong >= 1  # and it is not always the true one: the matches cannot tell the two apart


def test_non_planar_scene_essential_exact_homography_not():
    uv0, uv1, R, t = _scene(False, np.random.default_rng(1))
    e = relative_pose_essential(uv0, uv1, K, ransac_px=0.5)
    assert e.ok
    assert _angle_deg(e.R, R) < 1e-3
    assert np.degrees(np.arccos(np.clip(e.t @ t, -1, 1))) < 1e-2
    h = relative_pose_homography(uv0, uv1, K, ransac_px=0.5)
    # no single plane explains a deep scene: the homography keeps few inliers
    assert h.inliers.mean() < 0.5


def test_degenerate_inputs_are_reported_not_raised():
    assert relative_pose_homography(np.zeros((3, 2)), np.zeros((3, 2)), K).reason == "too_few_points"
    same = np.random.default_rng(2).uniform(0, 600, (50, 2))
    p = relative_pose_homography(same, same, K)  # identical views: H = I, no translation
    assert not p.ok
    assert np.all(np.isfinite(p.R))
    with pytest.raises(ValueError, match="`uv0` and `uv1`"):
        relative_pose_essential(np.zeros((5, 2)), np.zeros((6, 2)), K)


def _blob_image(shift_px, rng_seed=3, size=(240, 320)):
    rng = np.random.default_rng(rng_seed)
    img = np.full(size, 60, np.float64)
    yy, xx = np.mgrid[0 : size[0], 0 : size[1]]
    for _ in range(150):
        cy, cx = rng.uniform(-20, size[0] + 20), rng.uniform(-20, size[1] + 40)
        img += rng.uniform(60, 150) * np.exp(-((yy - cy) ** 2 + (xx - cx - shift_px) ** 2) / (2 * 3.0**2))
    return np.clip(img, 0, 255).astype(np.uint8)


def test_lk_tracks_a_known_shift():
    a, b = _blob_image(0.0), _blob_image(3.0)
    import cv2

    uv = cv2.goodFeaturesToTrack(a, 100, 0.01, 8).reshape(-1, 2).astype(float)
    uv = uv[(uv[:, 0] > 20) & (uv[:, 0] < 280)]
    uv1, ok = track_lk(a, b, uv)
    assert ok.mean() > 0.9
    np.testing.assert_allclose(np.median(uv1[ok] - uv[ok], axis=0), [3.0, 0.0], atol=0.05)


def test_initialiser_reports_too_few_corners_and_restarts():
    def det(img):
        import cv2

        return cv2.goodFeaturesToTrack(img, 500, 0.01, 5).reshape(-1, 2) if img.std() > 0 else np.zeros((0, 2))

    ini = Initialiser(K, det, min_disparity_px=10.0)
    assert ini.add_frame(np.zeros((240, 320), np.uint8)) == "too_few_corners"
    assert ini.add_frame(_blob_image(0.0)) == "first_frame"
    assert ini.add_frame(_blob_image(2.0)) == "tracking"  # 2 px < 10 px
    assert ini.add_frame(np.full((240, 320), 60, np.uint8)) == "restart"  # all tracks lost
    assert ini.counts["too_few_corners"] >= 1
    with pytest.raises(ValueError, match="method"):
        Initialiser(K, det, method="eight-point")
