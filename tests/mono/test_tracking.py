"""Epipolar search (003 §4.2), direct alignment and pose refinement (003 §4.4), the loop's bad input."""

from __future__ import annotations

import numpy as np
import pytest

from slamlab.geometry import rotation_xyz, se3_exp
from slamlab.geometry.se3 import se3_inverse
from slamlab.mono import MonoParams, MonoSLAM
from slamlab.mono.align import build_pyramid, refine_pose, sparse_align
from slamlab.mono.epipolar import epipolar_segments, extract_patches, search_epipolar, zncc

K = np.array([[300.0, 0, 160], [0, 300.0, 120], [0, 0, 1]])


def _T(R, t):
    T = np.eye(4)
    T[:3, :3], T[:3, 3] = R, t
    return T


def test_epipolar_segment_contains_the_true_projection():
    rng = np.random.default_rng(0)
    T_cur_ref = _T(rotation_xyz(0.01, -0.03, 0.02), [0.3, 0.05, -0.02])
    f = np.column_stack([rng.uniform(-0.3, 0.3, (50, 2)), np.ones(50)])
    f /= np.linalg.norm(f, axis=1, keepdims=True)
    z = rng.uniform(1.0, 5.0, 50)
    mu, sigma = 1 / z + rng.normal(0, 0.02, 50), np.full(50, 0.05)
    a, b, ok = epipolar_segments(K, T_cur_ref, f, mu, sigma)
    X = f * z[:, None] @ T_cur_ref[:3, :3].T + T_cur_ref[:3, 3]
    p = X[:, :2] / X[:, 2:3] * 300 + [160, 120]
    assert ok.all()
    inside = np.abs(1 / z - mu) < 2 * sigma
    # on the line through a and b, and between them when the depth is inside the band
    d = b - a
    cross = d[:, 0] * (p - a)[:, 1] - d[:, 1] * (p - a)[:, 0]
    np.testing.assert_allclose(cross / np.linalg.norm(d, axis=1), 0, atol=1e-8)
    tpar = np.sum((p - a) * d, axis=1) / np.sum(d * d, axis=1)
    assert np.all((tpar[inside] >= 0) & (tpar[inside] <= 1))


def test_epipolar_far_end_at_vanishing_point_when_band_reaches_zero():
    T = _T(np.eye(3), [0.2, 0, 0])
    _, b, _ = epipolar_segments(K, T, [[0, 0, 1.0]], np.array([0.1]), np.array([0.2]))
    np.testing.assert_allclose(b, [[160, 120]], atol=1e-6)  # rho - 2 sigma <= 0: infinity


def test_search_finds_the_corner_and_triangulates_its_depth():
    rng = np.random.default_rng(1)
    img = rng.integers(0, 255, (240, 320)).astype(np.uint8)
    T_cur_ref = _T(rotation_xyz(0.0, 0.02, 0.0), [0.25, 0.0, 0.03])
    corners = np.array([[100.0, 80], [200, 150], [250, 60], [60, 200]])
    z_cur = np.array([2.0, 3.0, 4.0, 2.5])
    Xc = np.column_stack([(corners - [160, 120]) / 300 * z_cur[:, None], z_cur])
    T_ref_cur = se3_inverse(T_cur_ref)
    Xr = Xc @ T_ref_cur[:3, :3].T + T_ref_cur[:3, 3]
    f = Xr / np.linalg.norm(Xr, axis=1, keepdims=True)
    depth_true = np.linalg.norm(Xr, axis=1)
    # distractor corners off the lines, and the seed patches equal to the true corners' patches
    all_c = np.vstack([corners, rng.uniform(20, 220, (200, 2)).round()])
    ref_p = extract_patches(img, corners, 9)
    mu = 1 / depth_true * 1.1
    m = search_epipolar(K, T_cur_ref, f, mu, np.full(4, 0.1 * mu.max()), ref_p, img, all_c, patch_px=9)
    assert m.found.all()
    np.testing.assert_allclose(m.uv, corners)
    np.testing.assert_allclose(m.score, 1.0, atol=1e-9)
    np.testing.assert_allclose(m.depth_m, depth_true, rtol=1e-9)


def test_zncc_is_invariant_to_gain_and_offset():
    rng = np.random.default_rng(2)
    A = rng.normal(size=(3, 81))
    np.testing.assert_allclose(np.diag(zncc(A, 2.5 * A + 7)), 1.0)
    assert zncc(A, np.ones((1, 81)))[0, 0] == 0.0  # a flat patch scores 0


def test_refine_pose_exact_and_with_outliers():
    rng = np.random.default_rng(3)
    X = np.column_stack([rng.uniform(-2, 2, (80, 2)), rng.uniform(2, 6, 80)])
    T_true = _T(rotation_xyz(0.02, -0.01, 0.03), [0.1, -0.05, 0.2])
    Xc = X @ T_true[:3, :3].T + T_true[:3, 3]
    uv = Xc[:, :2] / Xc[:, 2:3] * 300 + [160, 120]
    T0 = se3_exp([0.02, 0.01, -0.03, 0.01, 0.0, -0.01]) @ T_true
    T, err, ok = refine_pose(K, X, uv, T0)
    assert ok
    np.testing.assert_allclose(T, T_true, atol=1e-7)
    uv_bad = uv.copy()
    uv_bad[:8] += 40.0  # 10 % gross outliers
    T, err, ok = refine_pose(K, X, uv_bad, T0, reject_px=None)
    assert np.abs(T[:3, 3] - T_true[:3, 3]).max() > 1e-4  # the Huber loss alone leans on them
    T, err, ok = refine_pose(K, X, uv_bad, T0)  # the second pass on the points below 3 px is exact
    np.testing.assert_allclose(T, T_true, atol=1e-7)
    assert (err[:8] > 30).all()


def test_sparse_align_recovers_motion_on_a_rendered_pair():
    from slamlab.studies.mono.experiments import mono_sim, render_sequence

    sim = mono_sim("small", noise_std=0.0)
    (A, B), (Ta, Tb) = render_sequence(sim, [[3.0, 2.5, -np.pi / 2], [3.02, 2.5, -np.pi / 2 + 0.004]], progress=False)
    _, t, _ = sim.arena.cast(sim.rig.left, Ta)
    from slamlab.features.opencv import fast_cv

    uv = fast_cv(A, threshold=20).uv  # textured points, as the pipeline uses
    uv = uv[(uv[:, 0] > 10) & (uv[:, 0] < 310) & (uv[:, 1] > 10) & (uv[:, 1] < 230)][::3]
    z = t[uv[:, 1].astype(int), uv[:, 0].astype(int)]
    uv, z = uv[np.isfinite(z)], z[np.isfinite(z)]
    Kc = sim.rig.left.K
    X = np.column_stack([(uv - Kc[:2, 2]) / Kc[0, 0] * z[:, None], z])
    T_true = se3_inverse(Tb) @ Ta
    r = sparse_align(build_pyramid(A, 3), build_pyramid(B, 3), Kc, X, np.eye(4))
    assert r.ok
    np.testing.assert_allclose(r.T_cur_ref[:3, 3], T_true[:3, 3], atol=2e-3)  # 3 cm step, 2 mm
    dR = r.T_cur_ref[:3, :3] @ T_true[:3, :3].T
    assert np.degrees(np.arccos(np.clip((np.trace(dR) - 1) / 2, -1, 1))) < 0.05


def test_monoslam_bad_input_is_counted_never_nan():
    slam = MonoSLAM(K)
    for _ in range(3):
        rec = slam.process(np.zeros((240, 320), np.uint8))
        assert rec["status"] == "too_few_corners"
        assert np.all(np.isfinite(rec["T_wc"]))
    assert slam.counts["init_too_few_corners"] == 3
    assert not slam.tracked.any()
    with pytest.raises(ValueError, match=r"must have shape \(H, W\)"):
        slam.process(np.zeros((240, 320, 3), np.uint8))


def test_params_are_checked():
    with pytest.raises(ValueError, match="align_min_level"):
        MonoParams(align_min_level=3, align_max_level=2)
    with pytest.raises(ValueError, match="motion_model"):
        MonoParams(motion_model="teleport")
    with pytest.raises(TypeError, match="no field"):
        MonoParams.resolve(None, max_keyframe=3)
