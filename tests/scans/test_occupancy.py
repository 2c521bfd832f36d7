"""The one occupancy-grid builder (both rules) and the likelihood field against brute force."""

import numpy as np
import pytest

from slamlab.scans import (
    FREE,
    OBSTACLE,
    UNEXPLORED,
    GridFrame,
    OccupancyGrid,
    Scan,
    check_grid,
    likelihood_field,
    occupancy_grid,
)


def _box_scan(n=360):
    # a robot at (10, 10) in a box whose wall faces are x = 4.5, 15.5 and y = 4.5, 15.5 (cells 4 and 16 solid)
    b = 2 * np.pi * np.arange(n) / n
    c, s = np.cos(b), np.sin(b)
    with np.errstate(divide="ignore"):
        tx = np.where(c > 0, 5.5 / c, np.where(c < 0, -5.5 / c, np.inf))
        ty = np.where(s > 0, 5.5 / s, np.where(s < 0, -5.5 / s, np.inf))
    return Scan(b, np.minimum(tx, ty), np.ones(n, bool))


def test_count_rule_draws_the_box():
    g = occupancy_grid([_box_scan()], [[10.0, 10.0, 0.0]], (21, 21))
    assert isinstance(g, OccupancyGrid)
    assert g.rule == "count"
    grid = g.grid
    assert grid.dtype == np.int8
    # the wall cells (rows/cols 4 and 16) are obstacles, the inside free, outside unexplored
    assert np.all(grid[4, 5:16] == OBSTACLE)
    assert np.all(grid[16, 5:16] == OBSTACLE)
    assert np.all(grid[5:16, 4] == OBSTACLE)
    assert np.all(grid[5:16, 16] == OBSTACLE)
    assert np.all(grid[5:16, 5:16] == FREE)
    assert np.all(grid[:4] == UNEXPLORED)
    assert np.all(grid[:, 17:] == UNEXPLORED)
    assert g.hits.sum() == 360
    assert g.passes[10, 10] >= 360


def test_endpoint_rule_and_thresholds():
    s = Scan([0.0, 0.0], [3.5, 3.5], [True, True])
    e = occupancy_grid([s], [[1, 1, 0]], (3, 6), rule="endpoints")
    assert e.grid[1].tolist() == [-1, -1, -1, -1, -1, 1]
    assert e.passes.sum() == 0
    assert (occupancy_grid([s], [[1, 1, 0]], (3, 6), rule="endpoints", min_hits=3).grid == UNEXPLORED).all()
    # a cell passed by many beams and hit by few stays free under the count rule
    through = Scan(np.zeros(10), np.full(10, 6.0), np.ones(10, bool))
    hit_once = Scan([0.0], [3.5], [True])
    g = occupancy_grid([through, hit_once], [[0, 1, 0], [1, 1, 0]], (3, 8), step_cells=1.0)
    assert g.hits[1, 5] == 1
    assert g.passes[1, 5] == 10
    assert g.grid[1, 5] == FREE
    assert occupancy_grid([through, hit_once], [[0, 1, 0], [1, 1, 0]], (3, 8), step_cells=1.0,
                          hit_ratio=0.05).grid[1, 5] == OBSTACLE


def test_misses_carve_free_space_only_when_asked():
    miss = Scan([0.0], [4.0], [False], max_range=4.0)
    # samples t = 0, 0.5, ..., 3.5 < 4: the last one (x = 3.5) lies in cell 4
    assert occupancy_grid([miss], [[0, 0, 0]], (1, 6)).grid.tolist() == [[0, 0, 0, 0, 0, -1]]
    assert (occupancy_grid([miss], [[0, 0, 0]], (1, 6), misses_free=False).grid == UNEXPLORED).all()


def test_metric_scans_through_a_frame():
    s_m = Scan([0.0], [1.0], [True], unit="m")
    frame = GridFrame(x0_m=-1.0, y0_m=-1.0, cell_m=0.5, shape=(5, 8))
    g = occupancy_grid([s_m.to_cells(frame.cell_m)], frame.to_cells([[0.0, 0.0, 0.0]]), frame.shape)
    # the return at (1, 0) m is cell (row 2, col 4)
    assert g.grid[2, 4] == OBSTACLE
    assert g.grid[2, 2] == FREE


def test_bad_input():
    s = Scan([0.0], [1.0], [True])
    with pytest.raises(ValueError, match="at least one scan"):
        occupancy_grid([], np.zeros((0, 3)), (3, 3))
    with pytest.raises(TypeError, match=r"`scans\[0\]` must be a Scan"):
        occupancy_grid([([0.0], [1.0], [True])], [[0, 0, 0]], (3, 3))
    with pytest.raises(ValueError, match=r"`scans\[0\]` must be in cell units"):
        occupancy_grid([Scan([0.0], [1.0], [True], unit="m")], [[0, 0, 0]], (3, 3))
    with pytest.raises(ValueError, match="`poses` must have 1 rows"):
        occupancy_grid([s], [[0, 0, 0], [1, 1, 0]], (3, 3))
    with pytest.raises(ValueError, match="`rule` must be one of"):
        occupancy_grid([s], [[0, 0, 0]], (3, 3), rule="last")
    with pytest.raises(TypeError, match="`shape` must be a"):
        occupancy_grid([s], [[0, 0, 0]], [3, 3])


def _brute_force_distance(grid, cell):
    obs = np.argwhere(grid == OBSTACLE)
    out = np.empty(grid.shape)
    for r in range(grid.shape[0]):
        for c in range(grid.shape[1]):
            out[r, c] = np.hypot(obs[:, 0] - r, obs[:, 1] - c).min() * cell
    return out


def test_likelihood_field_matches_brute_force():
    rng = np.random.default_rng(3)
    grid = np.where(rng.random((13, 17)) < 0.08, OBSTACLE, FREE).astype(np.int8)
    grid[0, 0] = OBSTACLE
    grid[5:7, 3:9] = UNEXPLORED  # unexplored cells are not obstacles
    ref = _brute_force_distance(grid, 0.25)
    np.testing.assert_allclose(likelihood_field(grid, cell_m=0.25), ref, atol=1e-12)
    np.testing.assert_allclose(likelihood_field(grid, cell_m=0.25, max_dist=0.6), np.minimum(ref, 0.6), atol=1e-12)
    assert np.all(likelihood_field(grid)[grid == OBSTACLE] == 0)


def test_likelihood_field_without_obstacles_and_bad_input():
    empty = np.zeros((3, 4), np.int8)
    assert np.all(likelihood_field(empty, max_dist=2.0) == 2.0)
    assert np.all(np.isinf(likelihood_field(empty)))
    with pytest.raises(ValueError, match="`cell_m` must be > 0"):
        likelihood_field(empty, cell_m=0)
    with pytest.raises(ValueError, match="must hold only 0"):
        likelihood_field([[0, 2]])
    assert check_grid([[0, 1]]).dtype == np.int8


def test_exact_scans_reproduce_the_room():
    # scans cast in the test room from many poses, mapped back: walls hit come back as obstacles
    from slamlab import sim as S

    M = S.test_room_200()
    rf = S.Rangefinder(n_beams=720, max_range_cells=150, quantum_cells=0)
    poses = S.random_free_poses(M, 40, margin_cells=3, rng=2)
    G = occupancy_grid([rf.scan(M, p) for p in poses], poses, M.shape).grid
    seen = G != UNEXPLORED
    assert seen.mean() > 0.7
    # every cell labelled obstacle is an obstacle of M; free cells are free in M
    assert np.all(M[G == OBSTACLE] == OBSTACLE)
    assert np.mean(M[G == FREE] == FREE) > 0.999


def test_grid_frame_round_trip_and_checks():
    f = GridFrame.around([[0.0, 0.0], [3.0, 1.0]], 0.5, 1.0)
    assert f.shape == (7, 11)
    P = np.array([[1.2, 0.7, 0.3]])
    np.testing.assert_allclose(f.to_metres(f.to_cells(P)), P)
    with pytest.raises(ValueError, match="`points_m` must hold at least one point"):
        GridFrame.around(np.zeros((0, 2)), 0.1)
    with pytest.raises(ValueError, match="`cell_m` must be > 0"):
        GridFrame(0.0, 0.0, 0.0, (2, 2))
