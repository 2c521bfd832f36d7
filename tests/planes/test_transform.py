"""The reconstructed plane transform of 002 and our batched LM, on exact synthetic cases (002 Fig. 1, 2)."""

import numpy as np
import pytest
from scipy.optimize import least_squares
from scipy.spatial.transform import Rotation

from slamlab.planes import lm_pose, plane_pair_jacobian, plane_pair_residuals, planes_to_body, planes_to_map

R_TRUE = Rotation.from_euler("xyz", [0.1, -0.2, 0.7]).as_matrix()
T_TRUE = np.array([1.0, 2.0, 0.5])


def _map_planes(k, seed=0):
    rng = np.random.default_rng(seed)
    n = np.array([[1.0, 0, 0], [0, 1.0, 0], [0, 0, 1.0], [0.6, 0.8, 0.0]])[:k]
    n = n @ Rotation.from_euler("z", 0.3).as_matrix().T
    return n, rng.uniform(2, 6, k)


def test_transform_round_trip_and_point_incidence():
    n_m, p_m = _map_planes(4)
    n_b, p_b = planes_to_body(n_m, p_m, R_TRUE, T_TRUE)
    n2, p2 = planes_to_map(n_b, p_b, R_TRUE, T_TRUE)
    np.testing.assert_allclose(n2, n_m, atol=1e-12)
    np.testing.assert_allclose(p2, p_m, atol=1e-12)
    # a point on map plane 0, seen in the body, lies on the body plane: x_b = R^T (x_m - t)
    x_m = p_m[0] * n_m[0] + np.cross(n_m[0], [0, 0, 1.0]) * 0.7
    x_b = R_TRUE.T @ (x_m - T_TRUE)
    assert n_b[0] @ x_b == pytest.approx(p_b[0], abs=1e-12)


def test_jacobian_matches_central_differences():
    n_m, p_m = _map_planes(3)
    n_b, p_b = planes_to_body(n_m, p_m, R_TRUE, T_TRUE)
    R0 = R_TRUE @ Rotation.from_rotvec([0.05, -0.03, 0.08]).as_matrix()
    t0 = T_TRUE + np.array([0.3, -0.2, 0.1])

    def f(x):
        R = R0 @ Rotation.from_rotvec(x[:3]).as_matrix()
        return plane_pair_residuals(R[None], (t0 + x[3:])[None], n_m[None], p_m[None], n_b[None], p_b[None]).ravel()

    eps = 1e-6
    J_num = np.stack([(f(e * eps) - f(-e * eps)) / (2 * eps) for e in np.eye(6)], axis=1)
    J = plane_pair_jacobian(R0[None], n_m[None])[0].reshape(-1, 6)
    np.testing.assert_allclose(J, J_num, atol=1e-9)


def _scipy_lm(R0, t0, n_m, p_m, n_b, p_b):
    def fun(x):
        R = Rotation.from_rotvec(x[:3]).as_matrix()
        return plane_pair_residuals(R[None], x[3:][None], n_m[None], p_m[None], n_b[None], p_b[None]).ravel()

    x0 = np.r_[Rotation.from_matrix(R0).as_rotvec(), t0]
    sol = least_squares(fun, x0, method="lm", xtol=1e-15, ftol=1e-15, gtol=1e-15)
    return Rotation.from_rotvec(sol.x[:3]).as_matrix(), sol.x[3:]


@pytest.mark.parametrize("k", [3, 4])
def test_lm_agrees_with_scipy_lm_on_exact_cases(k):
    n_m, p_m = _map_planes(k)
    n_b, p_b = planes_to_body(n_m, p_m, R_TRUE, T_TRUE)
    rng = np.random.default_rng(k)
    R0 = np.stack([R_TRUE @ Rotation.from_rotvec(rng.normal(0, 0.05, 3)).as_matrix() for _ in range(5)])
    t0 = T_TRUE + rng.normal(0, 0.2, (5, 3))
    ours = lm_pose(R0, t0, np.broadcast_to(n_m, (5, k, 3)), np.broadcast_to(p_m, (5, k)), n_b, p_b, max_iters=50)
    assert ours.converged.all()
    for i in range(5):
        R_s, t_s = _scipy_lm(R0[i], t0[i], n_m, p_m, n_b, p_b)
        np.testing.assert_allclose(ours.R[i], R_s, atol=1e-9)
        np.testing.assert_allclose(ours.t[i], t_s, atol=1e-9)
        np.testing.assert_allclose(ours.R[i], R_TRUE, atol=1e-9)
        np.testing.assert_allclose(ours.t[i], T_TRUE, atol=1e-9)


@pytest.mark.parametrize(("k", "free_dims"), [(1, 2), (2, 1), (3, 0)])
def test_one_two_three_pairs_pin_to_plane_line_point(k, free_dims):
    """002 Fig. 2: the solved positions form a plane (1 pair), a line (2), a point (3); each particle lands on the
    orthogonal projection of its prediction onto that locus (closed form), to 1e-9."""
    n_m, p_m = _map_planes(k)
    n_b, p_b = planes_to_body(n_m, p_m, R_TRUE, T_TRUE)
    rng = np.random.default_rng(10 + k)
    P = 60
    R0 = np.stack([R_TRUE @ Rotation.from_rotvec(rng.normal(0, 0.03, 3)).as_matrix() for _ in range(P)])
    t0 = T_TRUE + rng.normal(0, 0.3, (P, 3))
    res = lm_pose(R0, t0, np.broadcast_to(n_m, (P, k, 3)), np.broadcast_to(p_m, (P, k)), n_b, p_b, max_iters=60)
    # every pair equation holds
    r = plane_pair_residuals(res.R, res.t, np.broadcast_to(n_m, (P, k, 3)), np.broadcast_to(p_m, (P, k)), n_b, p_b)
    assert np.abs(r).max() < 1e-9
    # translation: t0 projected onto {t : n_i . t = p_m,i - p_b,i}
    N = n_m
    c = p_m - p_b
    corr = np.linalg.pinv(N) @ (c[:, None] - N @ t0.T)
    np.testing.assert_allclose(res.t, t0 + corr.T, atol=1e-9)
    # the locus has the expected dimension
    s = np.linalg.svd(res.t - res.t.mean(0), compute_uv=False)
    assert np.sum(s > 1e-6) == free_dims


def test_prior_keeps_a_nearly_free_direction_near_the_prediction():
    # two walls 1.5 degrees apart: the bare system pins the along-wall coordinate badly, the prior does not
    n_m = np.array([[0.0, 1.0, 0.0], [np.sin(np.deg2rad(1.5)), -np.cos(np.deg2rad(1.5)), 0.0], [0, 0, 1.0]])
    p_m = np.array([5.0, 4.0, 3.0])
    n_b, p_b = planes_to_body(n_m, p_m, np.eye(3), np.zeros(3))
    p_b = p_b + np.array([0.0, 0.03, 0.0])                           # 3 cm error in one wall's offset
    t0 = np.zeros((1, 3))
    bare = lm_pose(np.eye(3)[None], t0, n_m[None], p_m[None], n_b, p_b, max_iters=50)
    prior = lm_pose(np.eye(3)[None], t0, n_m[None], p_m[None], n_b, p_b, sigma_n=0.02, sigma_p_m=0.03,
                    prior_sigma=[0.01] * 3 + [0.05] * 3, max_iters=50)
    assert abs(bare.t[0, 0]) > 0.5                         # 0.03 / sin(1.5 deg) = 1.15 m along x
    assert abs(prior.t[0, 0]) < 0.05


def test_lm_bad_shapes():
    with pytest.raises(ValueError, match="R0"):
        lm_pose(np.eye(3), np.zeros(3), np.zeros((1, 1, 3)), [1.0], [[1.0, 0, 0]], [1.0])
    with pytest.raises(ValueError, match="t0"):
        lm_pose(np.eye(3)[None], np.zeros(3), np.zeros((1, 1, 3)), [1.0], [[1.0, 0, 0]], [1.0])
    with pytest.raises(ValueError, match="mask"):
        lm_pose(np.eye(3)[None], np.zeros((1, 3)), np.ones((1, 1, 3)), [[1.0]], [[1.0, 0, 0]], [1.0],
                mask=np.ones((2, 1)))


def test_one_lm_step_is_the_damped_gauss_newton_step():
    """One iteration equals -(J^T J + lambda I)^-1 J^T r with J by central differences (to 1e-9)."""
    n_m, p_m = _map_planes(3)
    n_b, p_b = planes_to_body(n_m, p_m, R_TRUE, T_TRUE)
    R0 = R_TRUE @ Rotation.from_rotvec([0.02, -0.01, 0.03]).as_matrix()
    t0 = T_TRUE + np.array([0.1, -0.05, 0.02])

    def f(x):
        R = R0 @ Rotation.from_rotvec(x[:3]).as_matrix()
        return plane_pair_residuals(R[None], (t0 + x[3:])[None], n_m[None], p_m[None], n_b[None], p_b[None]).ravel()

    eps = 1e-6
    J = np.stack([(f(e * eps) - f(-e * eps)) / (2 * eps) for e in np.eye(6)], axis=1)
    lam = 0.5
    step = -np.linalg.solve(J.T @ J + lam * np.eye(6), J.T @ f(np.zeros(6)))
    res = lm_pose(R0[None], t0[None], n_m[None], p_m[None], n_b, p_b, lambda0=lam, max_iters=1)
    np.testing.assert_allclose(res.R[0], R0 @ Rotation.from_rotvec(step[:3]).as_matrix(), atol=1e-9)
    np.testing.assert_allclose(res.t[0], t0 + step[3:], atol=1e-9)
