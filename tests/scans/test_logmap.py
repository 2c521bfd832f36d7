"""A map from a log (scans.log_grid): leave-out by subtracting counts = a recount of the other scans; the map's
obstacles lie on the walls that made the scans; range limit; bad input."""

from dataclasses import dataclass

import numpy as np
import pytest

from slamlab import scans as SC
from slamlab.sim import grid as G
from slamlab.sim.rangefinder import Rangefinder

CELL_M = 0.1  # the simulated room's cell size: the log is metric


@dataclass
class _Log:
    """The three things log_grid reads of a log (as slamlab.io.CarmenLog has them)."""

    poses: np.ndarray
    all_scans: list

    @property
    def n_scans(self) -> int:
        return len(self.all_scans)

    def scans(self, indices=None):
        return list(self.all_scans) if indices is None else [self.all_scans[i] for i in indices]


@pytest.fixture(scope="module")
def room_log():
    room = G.test_room_200()
    rng = np.random.default_rng(9)
    xy = [rng.uniform(40, 160, 2) for _ in range(200)]
    P = np.array([[x, y, rng.uniform(-np.pi, np.pi)] for x, y in xy if room[int(y + 0.5), int(x + 0.5)] == G.FREE][:25])
    rf = Rangefinder(n_beams=180, max_range_cells=80, quantum_cells=0)
    scans = [rf.scan(room, p).to_metres(CELL_M) for p in P]
    poses_m = np.column_stack([P[:, :2] * CELL_M, P[:, 2]])
    return room, _Log(poses_m, scans)


def test_leave_out_by_subtraction_equals_a_recount_of_the_other_scans(room_log):
    _, log = room_log
    frame, scans_c, Pc, counts = SC.log_counts(log, cell_m=0.2, max_range_m=6.0)
    leave = [3, 4, 5, 17, 4]
    keep = [j for j in range(log.n_scans) if j not in leave]
    recount = SC.occupancy_grid([scans_c[j] for j in keep], Pc[keep], frame.shape).grid
    grid, frame2, _, Pc2 = SC.log_grid(log, cell_m=0.2, max_range_m=6.0, leave_out=leave)
    np.testing.assert_array_equal(grid, recount)
    np.testing.assert_array_equal(SC.leave_out_grid(counts, scans_c, Pc, leave), recount)
    assert frame2 == frame
    np.testing.assert_array_equal(Pc2, frame.to_cells(log.poses))
    assert SC.log_grid(log, cell_m=0.2, max_range_m=6.0)[0].tolist() == counts.grid.tolist()


def test_obstacles_lie_on_the_walls_that_made_the_scans(room_log):
    room, log = room_log
    grid, frame, _, _ = SC.log_grid(log, cell_m=0.2, max_range_m=6.0)
    rc = np.argwhere(grid == SC.OBSTACLE)
    assert rc.shape[0] > 100
    centres_m = frame.to_metres(np.column_stack([rc[:, 1], rc[:, 0], np.zeros(len(rc))]))[:, :2]
    # every obstacle cell of the 0.2 m map is within one of its cells of an obstacle cell of the 0.1 m room
    walls = np.argwhere(room == G.OBSTACLE)[:, ::-1] * CELL_M
    from scipy.spatial import cKDTree

    d, _ = cKDTree(walls).query(centres_m)
    assert np.all(d <= 0.2 * np.sqrt(2) / 2 + CELL_M * np.sqrt(2) / 2 + 1e-9)


def test_readings_at_or_beyond_max_range_become_no_return(room_log):
    _, log = room_log
    _, scans_c, _, _ = SC.log_counts(log, cell_m=0.2, max_range_m=3.0)
    for s_m, s_c in zip(log.scans(), scans_c, strict=True):
        short = s_m.valid & (s_m.ranges < 3.0)
        np.testing.assert_array_equal(s_c.valid, short)
        assert s_c.unit == "cell"
        assert s_c.max_range == pytest.approx(15.0)
        np.testing.assert_allclose(s_c.ranges[~short], 15.0)


def test_bad_input_names_the_argument(room_log):
    _, log = room_log
    with pytest.raises(TypeError, match="`log` must be a laser log"):
        SC.log_grid([1, 2, 3])
    with pytest.raises(ValueError, match="`cell_m` must be > 0"):
        SC.log_grid(log, cell_m=0.0)
    with pytest.raises(ValueError, match="`max_range_m` must be > 0"):
        SC.log_counts(log, max_range_m=-1.0)
    _frame, scans_c, Pc, counts = SC.log_counts(log)
    with pytest.raises(ValueError, match=r"`leave_out` must hold scan indices in \[0, 24\]"):
        SC.leave_out_grid(counts, scans_c, Pc, [3, 25])
    with pytest.raises(TypeError, match="`counts` must be an OccupancyGrid"):
        SC.leave_out_grid(counts.grid, scans_c, Pc, [3])


def test_map_coverage_counts_end_points_near_walls():
    # a wall along column 10 (rows 0..20); a scan at (0, 10) looking along +x with beams hitting the wall, one beam
    # short of it by 2 cells, one beam that is a miss: coverage counts returns only, within the Chebyshev radius
    g = np.zeros((21, 21), dtype=np.int8)
    g[:, 10] = SC.OBSTACLE
    s = SC.Scan([0.0, 0.0, 0.3, 0.0], [10.0, 8.0, 10.0 / np.cos(0.3), 5.0], [True, True, True, False])
    pose = np.array([0.0, 10.0, 0.0])
    # hits: (col 10, row 10) on the wall; (col 8) two cells short; (col 10, row 10 + 3.09) on the wall
    assert SC.map_coverage(g, s, pose) == pytest.approx(2 / 3)
    assert SC.map_coverage(g, s, pose, radius_cells=2) == 1.0
    # shifted one cell back from the wall: the hits still covered at radius 1 (the short beam now 3 cells off),
    # none at radius 0
    assert SC.map_coverage(g, s, pose - [1.0, 0.0, 0.0], radius_cells=0) == 0.0
    assert SC.map_coverage(g, s, pose - [1.0, 0.0, 0.0], radius_cells=1) == pytest.approx(2 / 3)
    # end points outside the grid are not covered; a scan without returns covers nothing
    assert SC.map_coverage(g, s, [0.0, 10.0, np.pi], radius_cells=1) == 0.0
    assert SC.map_coverage(g, SC.Scan([0.0], [3.0], [False]), pose) == 0.0


def test_map_coverage_bad_input():
    g = np.zeros((5, 5), dtype=np.int8)
    s = SC.Scan([0.0], [1.0], [True])
    with pytest.raises(TypeError, match="`scan_cells` must be a Scan"):
        SC.map_coverage(g, np.ones(3), [0, 0, 0])
    with pytest.raises(ValueError, match="`pose_cells` must be a finite"):
        SC.map_coverage(g, s, [0, 0])
    with pytest.raises(ValueError, match="`pose_cells` must be a finite"):
        SC.map_coverage(g, s, [0, np.nan, 0])
    with pytest.raises(ValueError, match="`radius_cells`"):
        SC.map_coverage(g, s, [0, 0, 0], radius_cells=-1)
    with pytest.raises(ValueError, match="`grid` must hold only"):
        SC.map_coverage(np.full((5, 5), 7), s, [0, 0, 0])
