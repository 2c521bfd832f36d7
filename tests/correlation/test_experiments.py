"""Ch. 5 experiments, the occupancy-grid builder and the real Intel log."""

import numpy as np
import pytest

from slamlab import correlation as C
from slamlab import sim as S
from slamlab.io import read_carmen


def test_table1_small_run_meets_the_source_bounds():
    r = C.run_table1(4, rng=5)
    assert r.true_poses.shape == r.est_poses.shape == (4, 3)
    # 004: position error <= 1 cell; heading error within about one 1° step
    assert r.err_x_cells.max() <= 1
    assert r.err_y_cells.max() <= 1
    assert r.err_heading_rad.max() <= np.radians(1.5)
    t = r.table()
    assert "max (004)" in t
    assert "0.0098" in t
    assert "0.0098" in r.source_table()
    assert "004: 0.0098 rad" in str(r)
    # true poses are whole free cells
    M = S.test_room_200()
    assert np.all(r.true_poses[:, :2] == np.round(r.true_poses[:, :2]))
    assert np.all(M[r.true_poses[:, 1].astype(int), r.true_poses[:, 0].astype(int)] == S.FREE)


def test_table1_noise_free_without_clutter_is_exact():
    r = C.run_table1(3, range_std_cells=0.0, clutter=False, rng=9)
    assert r.err_x_cells.max() == 0
    assert r.err_y_cells.max() == 0
    # true headings are continuous, estimates on the 1° grid: at most half a step off
    assert r.err_heading_rad.max() <= np.radians(0.5) + 1e-9


def test_monte_carlo_small():
    r = C.run_monte_carlo(6, rng=3)
    assert r.n_poses == 6
    assert r.failure_rate <= 1 / 6
    assert "failures" in r.table()
    with pytest.raises(ValueError, match="`size` must be one of"):
        C.run_monte_carlo("huge")


def test_constants_study_runs_both_choices():
    r = C.run_constants_study(2, extra_clutter=10, rng=1)
    assert r.half_max_area.shape == (2, 2)
    assert len(r.example_maps) == 2
    assert r.example_maps[0].shape == (200, 200)
    assert "a_c=0, a_p=1" in r.table()
    with pytest.raises(ValueError, match="`a_c` and `a_p` must differ"):
        C.run_constants_study(1, choices=((1.0, 1.0, 0.0),))


def test_occupancy_grid_from_exact_scans_reproduces_the_room():
    # scans cast in the test room from many poses, mapped back: walls hit come back as obstacles
    M = S.test_room_200()
    rf = S.Rangefinder(n_beams=720, max_range_cells=150, quantum_cells=0)
    poses = S.random_free_poses(M, 40, margin_cells=3, rng=2)
    scans = [rf.scan(M, p) for p in poses]
    R = np.array([s.ranges_cells for s in scans])
    H = np.array([s.hit for s in scans])
    G = C.occupancy_grid_from_scans(rf.angles_rad, R, H, poses, M.shape)
    seen = G != S.UNEXPLORED
    assert seen.mean() > 0.7
    # every cell labelled obstacle is an obstacle of M; free cells are free in M
    assert np.all(M[G == S.OBSTACLE] == S.OBSTACLE)
    assert np.mean(M[G == S.FREE] == S.FREE) > 0.999


def test_grid_frame_round_trip():
    f = C.GridFrame.around([[0.0, 0.0], [3.0, 1.0]], 0.5, 1.0)
    assert f.shape == (7, 11)
    P = np.array([[1.2, 0.7, 0.3]])
    np.testing.assert_allclose(f.to_metres(f.to_cells(P)), P)


def test_bad_input():
    with pytest.raises(ValueError, match="`hit` must be a bool array"):
        C.occupancy_grid_from_scans([0.0], [[1.0]], [[1]], [[0, 0, 0]], (3, 3))
    with pytest.raises(TypeError, match="`shape` must be a \\(rows, cols\\) tuple"):
        C.occupancy_grid_from_scans([0.0], [[1.0]], [[True]], [[0, 0, 0]], 3)
    with pytest.raises(ValueError, match="`poses_cells` must have shape"):
        C.occupancy_grid_from_scans([0.0], [[1.0]], [[True]], [[0, 0]], (3, 3))
    with pytest.raises(ValueError, match="`points_m` must hold at least one point"):
        C.GridFrame.around(np.zeros((0, 2)), 0.1)
    with pytest.raises(TypeError, match="`log` must be a CarmenLog"):
        C.run_intel_localisation(log="intel")


@pytest.mark.realdata
def test_intel_localisation_from_no_prior(shared_data):
    log = read_carmen(shared_data / "carmen-radish-corrected" / "intel-corrected.log.gz")
    idx = (50, 150, 350, 450, 550, 750, 850, 250, 650)
    r = C.run_intel_localisation(idx, log=log)
    # bound: at least 6 of 9 scans within 2 cells (0.4 m) and 5° of the corrected pose, from no prior;
    # the successful ones within 0.25 m and 2° (the grid is 0.2 m, headings 1°)
    assert r.success.sum() >= 6
    assert np.all(r.err_pos_m[r.success] <= 0.25)
    assert np.all(np.degrees(r.err_heading_rad[r.success]) <= 2.0)
    assert r.grid.shape[0] > 100
    assert "Intel Research Lab" in r.table()
