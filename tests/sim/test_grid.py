"""Occupancy grids and the 004 test room."""

import numpy as np
import pytest
from scipy import ndimage

from slamlab.sim import grid as G


def test_data_file_matches_builder():
    assert np.array_equal(G.test_room_200(), G.build_test_room_200())


def test_test_room_has_three_values_and_closed_walls():
    M = G.test_room_200()
    assert M.shape == (200, 200)
    assert set(np.unique(M).tolist()) == {G.FREE, G.OBSTACLE, G.UNEXPLORED}
    # the border is wall or unexplored (a closed room)
    border = np.concatenate([M[0], M[-1], M[:, 0], M[:, -1]])
    assert np.all(border != G.FREE)
    # free space is one connected region (doorways open) and never touches unexplored cells
    _lab, n = ndimage.label(M == G.FREE)
    assert n == 1
    near_unexplored = ndimage.binary_dilation(M == G.UNEXPLORED)
    assert not np.any(near_unexplored & (M == G.FREE))


def test_measurement_room_only_adds_obstacles_on_free_cells():
    M, W = G.test_room_200(), G.measurement_room_200()
    changed = M != W
    assert changed.sum() > 20
    assert np.all(M[changed] == G.FREE)
    assert np.all(W[changed] == G.OBSTACLE)


def test_world_cell_round_trip_and_rounding():
    rng = np.random.default_rng(0)
    rc = rng.integers(-50, 50, (100, 2))
    assert np.array_equal(G.world_to_cell(G.cell_to_world(rc)), rc)
    # a point anywhere inside a cell's square maps to it; x is the column
    xy = G.cell_to_world(rc) + rng.uniform(-0.5, 0.4999, (100, 2))
    assert np.array_equal(G.world_to_cell(xy), rc)
    assert G.world_to_cell([5.0, 1.0]).tolist() == [1, 5]


def test_grid_values_lookup():
    g = np.array([[0, 1], [-1, 0]])
    assert G.grid_to_values(g, a_c=-2.0, a_p=3.0, a_n=0.5).tolist() == [[-2.0, 3.0], [0.5, -2.0]]


def test_free_cells_margin_matches_scipy_erosion():
    M = G.test_room_200()
    for m in (0, 1, 3):
        ours = G.free_cells(M, m)
        ref = ndimage.binary_erosion(M == G.FREE, np.ones((2 * m + 1,) * 2), border_value=0) if m else M == 0
        assert np.array_equal(ours, np.argwhere(ref))


def test_text_round_trip():
    M = G.build_test_room_200()
    assert np.array_equal(G.grid_from_text(G.grid_to_text(M)), M)


def test_add_clutter_draws_disc_and_rect():
    g = G.add_clutter(G.make_grid(20, 20), [("disc", 10, 5, 2.0), ("rect", 1, 2, 3, 2)])
    _rows, _cols = np.nonzero(g)
    assert g[5, 10] == 1
    assert g[5, 12] == 1
    assert g[5, 13] == 0
    assert g[7, 10] == 1
    assert g[2, 1:4].tolist() == [1, 1, 1]


@pytest.mark.parametrize(("bad", "exc", "match"), [
    ([[0, 2]], ValueError, "only 0 .free., 1 .obstacle. or -1"),
    ([[0.5, 1.0]], TypeError, "integer cell codes"),
    (np.zeros((0, 3), dtype=np.int8), ValueError, "must not be empty"),
    (np.zeros(3, dtype=np.int8), ValueError, "shape"),
    ([["a"]], TypeError, "numeric image"),
])
def test_check_grid_bad_input(bad, exc, match):
    with pytest.raises(exc, match=match):
        G.check_grid(bad)


def test_other_bad_input():
    with pytest.raises(ValueError, match=r"shape \(\.\.\., 2\)"):
        G.world_to_cell([1.0, 2.0, 3.0])
    with pytest.raises(ValueError, match="`xy` must be finite"):
        G.world_to_cell([np.nan, 2.0])
    with pytest.raises(ValueError, match="`fill` must be FREE"):
        G.make_grid(2, 2, fill=5)
    with pytest.raises(ValueError, match="`n_rows` must be >= 1"):
        G.make_grid(0, 2)
    with pytest.raises(TypeError, match="`a_p` must be a finite real"):
        G.grid_to_values([[0]], a_p=np.nan)
    with pytest.raises(ValueError, match="clutter\\[0\\]"):
        G.add_clutter([[0]], [("star", 1, 2)])
    with pytest.raises(ValueError, match="wrong number of fields"):
        G.add_clutter([[0]], [("disc", 1, 2)])
    with pytest.raises(ValueError, match="same length"):
        G.grid_from_text("..\n.\n")
    with pytest.raises(ValueError, match="may hold only"):
        G.grid_from_text("..x\n")
    with pytest.raises(ValueError, match="at least one row"):
        G.grid_from_text("")
    with pytest.raises(ValueError, match="`margin_cells` must be >= 0"):
        G.free_cells([[0]], -1)
