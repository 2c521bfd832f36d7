"""Umeyama registration: exact recovery on synthetic data, proper rotations, scale, bad input."""

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from slamlab.geometry import RigidTransform, apply_transform, umeyama


@pytest.mark.parametrize("with_scale", [False, True])
def test_recovers_a_known_3d_transform(with_scale):
    rng = np.random.default_rng(0)
    R = Rotation.from_rotvec([0.3, -0.5, 1.1]).as_matrix()
    t = np.array([1.0, -2.0, 0.5])
    c = 1.7 if with_scale else 1.0
    src = rng.normal(size=(50, 3))
    T = umeyama(src, apply_transform(RigidTransform(R, t, c), src), with_scale=with_scale)
    np.testing.assert_allclose(T.R, R, atol=1e-12)
    np.testing.assert_allclose(T.t, t, atol=1e-12)
    assert T.c == pytest.approx(c, rel=1e-12)


def test_matches_scipy_align_vectors_on_noisy_data():
    rng = np.random.default_rng(1)
    R = Rotation.from_rotvec([0.1, 0.2, -0.3]).as_matrix()
    src = rng.normal(size=(200, 3))
    dst = src @ R.T + 0.01 * rng.normal(size=src.shape)
    T = umeyama(src, dst)
    ref, _ = Rotation.align_vectors(dst - dst.mean(0), src - src.mean(0))
    np.testing.assert_allclose(T.R, ref.as_matrix(), atol=1e-10)


def test_reflection_gives_proper_rotation():
    rng = np.random.default_rng(2)
    src = rng.normal(size=(20, 3))
    dst = src * np.array([1.0, 1.0, -1.0])  # a mirror image: no rotation maps it exactly
    T = umeyama(src, dst)
    assert np.linalg.det(T.R) == pytest.approx(1.0)


def test_bad_input():
    with pytest.raises(ValueError, match="`src` and `dst` must have the same shape"):
        umeyama(np.zeros((3, 3)), np.zeros((4, 3)))
    with pytest.raises(ValueError, match="`src` must have at least 3 points"):
        umeyama(np.zeros((2, 3)), np.zeros((2, 3)))
    with pytest.raises(ValueError, match="`src` must be finite"):
        umeyama(np.full((3, 2), np.nan), np.zeros((3, 2)))
    with pytest.raises(ValueError, match="`src` points must not all coincide"):
        umeyama(np.ones((4, 3)), np.ones((4, 3)), with_scale=True)


def test_unchecked_umeyama_is_the_checked_one_bit_for_bit():
    rng = np.random.default_rng(4)
    src = rng.normal(size=(6, 3))
    dst = src @ Rotation.from_rotvec([0.2, 0.1, -0.4]).as_matrix().T + 0.01 * rng.normal(size=(6, 3))
    w = rng.uniform(0.1, 1.0, 6)
    for with_scale in (False, True):
        a = umeyama(src, dst, with_scale=with_scale, weights=w)
        b = umeyama(src, dst, with_scale=with_scale, weights=w, check=False)
        np.testing.assert_array_equal(a.R, b.R)
        np.testing.assert_array_equal(a.t, b.t)
        assert a.c == b.c
    np.testing.assert_array_equal(umeyama(src, dst).R, umeyama(src, dst, check=False).R)
    with pytest.raises(ValueError, match="`src` must be finite; got 9 NaN"):
        umeyama(np.full((3, 3), np.nan), dst[:3])
