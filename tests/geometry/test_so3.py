"""SO(3)/SE(3) hat, exp and log against scipy's Rotation and the matrix exponential."""

import numpy as np
import pytest
from scipy.linalg import expm, logm
from scipy.spatial.transform import Rotation

from slamlab.geometry import hat, rotation_angle, se3_exp, se3_log, so3_exp, so3_log, vee


def _rotvecs(seed=0):
    """Random rotation vectors plus the awkward ones: zero, tiny, small, near π and π."""
    rng = np.random.default_rng(seed)
    axis = rng.normal(size=(9, 3))
    axis /= np.linalg.norm(axis, axis=1, keepdims=True)
    angles = np.array([0.0, 1e-12, 1e-7, 1e-4, 0.3, 2.0, np.pi - 1e-3, np.pi - 1e-9, np.pi])
    return np.concatenate([rng.normal(scale=1.0, size=(40, 3)), axis * angles[:, None]])


def test_hat_is_the_cross_product_and_vee_inverts_it():
    rng = np.random.default_rng(1)
    w, x = rng.normal(size=(20, 3)), rng.normal(size=(20, 3))
    np.testing.assert_allclose(np.einsum("nij,nj->ni", hat(w), x), np.cross(w, x), atol=1e-14)
    np.testing.assert_array_equal(vee(hat(w)), w)
    np.testing.assert_array_equal(hat(w[0]), hat(w)[0])
    assert hat(w.reshape(4, 5, 3)).shape == (4, 5, 3, 3)


def test_so3_exp_matches_scipy():
    w = _rotvecs()
    np.testing.assert_allclose(so3_exp(w), Rotation.from_rotvec(w).as_matrix(), atol=1e-14)


def test_so3_log_matches_scipy_and_inverts_exp():
    w = _rotvecs()
    R = Rotation.from_rotvec(w).as_matrix()
    got = so3_log(R)
    np.testing.assert_allclose(so3_exp(got), R, atol=1e-13)
    # away from π the vector is unique: scipy's must agree; at π either sign is the rotation
    ok = np.linalg.norm(w, axis=1) < np.pi - 1e-6
    np.testing.assert_allclose(got[ok], Rotation.from_matrix(R[ok]).as_rotvec(), atol=1e-12)
    assert np.all(np.linalg.norm(got, axis=1) <= np.pi + 1e-12)


def test_so3_log_near_pi_is_accurate():
    # sin θ vanishes at π: the axis comes from the symmetric part, not from R - Rᵀ
    n = np.array([1.0, 2.0, -2.0]) / 3.0
    for theta in (np.pi - 1e-6, np.pi - 1e-10):
        np.testing.assert_allclose(so3_log(Rotation.from_rotvec(theta * n).as_matrix()), theta * n, atol=1e-9)


def test_se3_exp_matches_the_matrix_exponential():
    rng = np.random.default_rng(2)
    for w in _rotvecs(3)[::3]:
        xi = np.r_[rng.normal(size=3), w]
        A = np.zeros((4, 4))
        A[:3, :3], A[:3, 3] = hat(xi[3:]), xi[:3]
        np.testing.assert_allclose(se3_exp(xi), expm(A), atol=1e-12)


def test_se3_log_inverts_exp_and_matches_logm():
    rng = np.random.default_rng(4)
    w = _rotvecs(5)
    w = w[np.linalg.norm(w, axis=1) < np.pi - 1e-6]
    xi = np.c_[rng.normal(size=(len(w), 3)), w]
    np.testing.assert_allclose(se3_log(se3_exp(xi)), xi, atol=1e-10)
    T = se3_exp(xi[7])
    L = np.real(logm(T))
    np.testing.assert_allclose(se3_log(T), np.r_[L[:3, 3], vee(L[:3, :3])], atol=1e-10)
    T_pi = se3_exp(np.r_[0.5, -1.0, 2.0, 0.0, 0.0, np.pi])
    np.testing.assert_allclose(se3_exp(se3_log(T_pi)), T_pi, atol=1e-12)


def test_batched_is_the_same_bits_as_one_at_a_time():
    rng = np.random.default_rng(6)
    xi = np.c_[rng.normal(size=(30, 3)), _rotvecs(7)[:30]]
    batch = se3_exp(xi)
    for k in range(len(xi)):
        assert np.array_equal(se3_exp(xi[k]), batch[k])
    assert np.array_equal(so3_exp(xi[:, 3:].reshape(5, 6, 3)).reshape(30, 3, 3), batch[:, :3, :3])


@pytest.mark.parametrize(
    ("fn", "arg", "match"),
    [
        (hat, np.zeros(4), r"`w` must have shape \(3,\) or \(\.\.\., 3\); got \(4,\)"),
        (vee, np.zeros(3), r"`S` must have shape \(3, 3\)"),
        (so3_exp, np.zeros((2, 2)), r"`w` must have shape"),
        (so3_log, np.eye(4), r"`R` must have shape \(3, 3\) or \(\.\.\., 3, 3\); got \(4, 4\)"),
        (se3_exp, np.zeros(3), r"`xi` must have shape \(6,\) or \(\.\.\., 6\); got \(3,\)"),
        (se3_log, np.eye(3), r"`T` must have shape \(4, 4\)"),
    ],
)
def test_bad_shapes_name_the_argument(fn, arg, match):
    with pytest.raises(ValueError, match=match):
        fn(arg)


def test_rotation_angle_matches_scipy_and_is_batched():
    w = _rotvecs(3)
    R = so3_exp(w)
    angle = rotation_angle(R)
    assert angle.shape == (len(w),)
    np.testing.assert_allclose(angle, np.linalg.norm(Rotation.from_matrix(R).as_rotvec(), axis=1), atol=1e-12)
    np.testing.assert_array_equal(rotation_angle(R.reshape(7, 7, 3, 3)), angle.reshape(7, 7))
    assert rotation_angle(R[5]) == angle[5]


def test_rotation_angle_keeps_its_digits_where_arccos_loses_them():
    # 1e-9 rad: arccos((tr R - 1) / 2) rounds the cosine to 1 and returns 0 (or ~1e-8); atan2 keeps the angle
    small = so3_exp([0.0, 0.0, 1e-9])
    assert abs(rotation_angle(small) - 1e-9) < 1e-20
    assert np.arccos(np.clip((np.trace(small) - 1) / 2, -1, 1)) == 0.0
    np.testing.assert_allclose(rotation_angle(so3_exp([np.pi - 1e-6, 0.0, 0.0])), np.pi - 1e-6, rtol=1e-12)


def test_rotation_angle_bad_input():
    with pytest.raises(ValueError, match=r"`R` must have shape \(3, 3\) or \(\.\.\., 3, 3\); got \(2, 2\)"):
        rotation_angle(np.eye(2))
