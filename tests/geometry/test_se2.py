"""SE(2) on pose arrays: identities, batched = looped, closed forms, argument checks."""

import numpy as np
import pytest

from slamlab.geometry import (
    check_pose,
    check_poses,
    se2_compose,
    se2_integrate,
    se2_inverse,
    se2_relative,
    se2_transform,
    wrap_angle,
)


def _random_poses(n, seed):
    rng = np.random.default_rng(seed)
    return np.column_stack([rng.uniform(-10, 10, (n, 2)), rng.uniform(-np.pi, np.pi, n)])


def _close(a, b, atol=1e-9):
    a, b = np.asarray(a), np.asarray(b)
    np.testing.assert_allclose(a[..., :2], b[..., :2], atol=atol)
    np.testing.assert_allclose(wrap_angle(a[..., 2] - b[..., 2]), 0.0, atol=atol)


def test_compose_with_inverse_is_identity():
    A = _random_poses(50, 1)
    _close(se2_compose(A, se2_inverse(A)), np.zeros((50, 3)))
    _close(se2_compose(se2_inverse(A), A), np.zeros((50, 3)))
    _close(se2_inverse(se2_inverse(A)), A)


def test_relative_undoes_compose_and_is_associative():
    A, D, E = _random_poses(40, 2), _random_poses(40, 3), _random_poses(40, 4)
    _close(se2_relative(A, se2_compose(A, D)), D)
    _close(se2_compose(A, se2_relative(A, D)), D)
    _close(se2_compose(se2_compose(A, D), E), se2_compose(A, se2_compose(D, E)))
    _close(se2_relative(A, D), se2_compose(se2_inverse(A), D))


def test_batched_equals_looped_and_broadcasts():
    A, B = _random_poses(7, 5), _random_poses(7, 6)
    for f in (se2_compose, se2_relative):
        batched = f(A, B)
        for k in range(7):
            np.testing.assert_allclose(batched[k], f(A[k], B[k]), atol=1e-12)
        # one pose against many, and leading axes
        np.testing.assert_allclose(f(A[0], B), np.array([f(A[0], b) for b in B]), atol=1e-12)
        assert f(A.reshape(7, 1, 3), B.reshape(1, 7, 3)).shape == (7, 7, 3)
    pts = np.random.default_rng(7).normal(size=(7, 5, 2))
    batched = se2_transform(A, pts)
    for k in range(7):
        np.testing.assert_allclose(batched[k], se2_transform(A[k], pts[k]), atol=1e-12)


def test_closed_forms():
    # a quarter turn: (1, 2, 90°) ⊕ (3, 0, 0.1) moves 3 along +y
    np.testing.assert_allclose(se2_compose([1.0, 2.0, np.pi / 2], [3.0, 0.0, 0.1]), [1.0, 5.0, np.pi / 2 + 0.1],
                               atol=1e-12)
    np.testing.assert_allclose(se2_inverse([1.0, 0.0, np.pi / 2]), [0.0, 1.0, -np.pi / 2], atol=1e-12)
    np.testing.assert_allclose(se2_transform([1.0, 1.0, np.pi], [[1.0, 0.0]]), [[0.0, 1.0]], atol=1e-12)
    # headings wrapped to [-π, π)
    assert se2_compose([0, 0, 3.0], [0, 0, 1.0])[2] == pytest.approx(4.0 - 2 * np.pi)


def test_integrate_is_cumulative_compose():
    start = np.array([1.0, -2.0, 0.3])
    U = _random_poses(25, 8) * [0.3, 0.3, 0.2]
    P = se2_integrate(start, U)
    assert P.shape == (26, 3)
    loop = [start]
    for u in U:
        loop.append(se2_compose(loop[-1], u))
    _close(P, np.array(loop))
    _close(se2_relative(P[:-1], P[1:]), U)
    # unwrapped headings on request: the plain cumulative sum
    np.testing.assert_allclose(se2_integrate(start, U, wrap=False)[:, 2],
                               start[2] + np.concatenate([[0], np.cumsum(U[:, 2])]))


def test_checks():
    assert check_pose([1, 2, 3]).tolist() == [1.0, 2.0, 3.0]
    with pytest.raises(ValueError, match="`start_pose` must have length 3"):
        check_pose([1, 2], "start_pose")
    with pytest.raises(ValueError, match="`pose` must be finite"):
        check_pose([1, np.nan, 0])
    with pytest.raises(ValueError, match=r"`poses` must have shape \(n, 3\)"):
        check_poses([[0, 0]])
    with pytest.raises(ValueError, match="at least one pose"):
        check_poses(np.zeros((0, 3)))
    with pytest.raises(ValueError, match="`poses` must have 2 rows"):
        check_poses(np.zeros((3, 3)), n=2)
    with pytest.raises(ValueError, match=r"`a` must have shape \(3,\) or \(\.\.\., 3\)"):
        se2_compose([0, 0], [0, 0, 0])
    with pytest.raises(ValueError, match=r"`points` must have shape \(\.\.\., 2\)"):
        se2_transform([0, 0, 0], [1, 2, 3])
    with pytest.raises(ValueError, match=r"`increments` must have shape \(n, 3\)"):
        se2_integrate([0, 0, 0], [1, 2, 3])
