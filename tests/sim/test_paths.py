"""Trajectories: 004's 121-pose path, piecewise paths, random free poses."""

import numpy as np
import pytest

from slamlab.geometry import wrap_angle
from slamlab.sim import grid as G
from slamlab.sim import paths


def test_path_004_shape_and_structure():
    P = paths.path_004()
    assert P.shape == (121, 3)
    step = np.hypot(*np.diff(P[:, :2], axis=0).T)
    turn = np.abs(wrap_angle(np.diff(P[:, 2])))
    # turn at the start (in place), straight leg, turn (in place), straight leg
    assert np.all(step[:10] == 0)
    assert np.all(turn[:10] > 0)
    assert np.all(step[10:60] > 0)
    assert np.all(turn[10:60] < 1e-12)
    assert np.all(step[60:75] == 0)
    assert np.all(turn[60:75] > 0)
    assert np.all(step[75:] > 0)
    assert np.all(turn[75:] < 1e-12)
    # total rotation: two quarter turns
    assert np.sum(wrap_angle(np.diff(P[:, 2]))) == pytest.approx(-np.pi)


def test_path_004_stays_in_free_space_with_margin():
    for W in (G.test_room_200(), G.measurement_room_200()):
        rc = G.world_to_cell(P := paths.path_004()[:, :2])
        ok = G.free_cells(W, 3)
        okset = {tuple(x) for x in ok.tolist()}
        assert all(tuple(x) in okset for x in rc.tolist()), P


def test_path_004_resized():
    P = paths.path_004(61)
    assert P.shape == (61, 3)
    np.testing.assert_allclose(P[-1], paths.path_004()[-1], atol=1e-12)


def test_piecewise_path_closed_form():
    P = paths.piecewise_path([1, 1, np.pi / 2], [("line", 3.0, 3), ("turn", -np.pi / 2, 2), ("line", 2.0, 1)])
    np.testing.assert_allclose(P[:, :2], [[1, 1], [1, 2], [1, 3], [1, 4], [1, 4], [1, 4], [3, 4]], atol=1e-12)
    np.testing.assert_allclose(P[-1, 2], 0.0, atol=1e-12)


def test_random_free_poses():
    M = G.test_room_200()
    P = paths.random_free_poses(M, 500, margin_cells=2, rng=3)
    rc = G.world_to_cell(P[:, :2])
    ok = np.zeros(M.shape, bool)
    ok[tuple(G.free_cells(M, 2).T)] = True
    assert ok[rc[:, 0], rc[:, 1]].all()
    assert np.all((P[:, 2] >= 0) & (P[:, 2] < 2 * np.pi))
    assert np.array_equal(P, paths.random_free_poses(M, 500, margin_cells=2, rng=3))


def test_bad_input():
    with pytest.raises(ValueError, match="segments\\[0\\]"):
        paths.piecewise_path([0, 0, 0], [("jump", 1.0, 2)])
    with pytest.raises(TypeError, match="`segments` must be a sequence"):
        paths.piecewise_path([0, 0, 0], 5)
    with pytest.raises(ValueError, match="n_steps` must be >= 1"):
        paths.piecewise_path([0, 0, 0], [("line", 1.0, 0)])
    with pytest.raises(ValueError, match="`n_poses` must be >= 5"):
        paths.path_004(3)
    with pytest.raises(ValueError, match="no free cell"):
        paths.random_free_poses(G.make_grid(3, 3, G.OBSTACLE), 2)
    with pytest.raises(ValueError, match="`start_pose` must have length 3"):
        paths.piecewise_path([0, 0], [])
