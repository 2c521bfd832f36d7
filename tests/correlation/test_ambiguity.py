"""The ambiguity measure and the mode joining consecutive scans by odometry (ours, on 004 §7)."""

import numpy as np
import pytest

from slamlab import correlation as C
from slamlab import sim as S
from slamlab.geometry import wrap_angle
from slamlab.studies import correlation as CS

EXACT = {"dtype": "float64", "delta_alpha_rad": np.radians(10.0)}


def _corner() -> np.ndarray:
    """One corner: two walls meeting at (10, 10), free space inside the quadrant, the rest unexplored."""
    g = np.full((60, 60), S.UNEXPLORED, dtype=np.int8)
    g[10, 10:55] = S.OBSTACLE
    g[10:55, 10] = S.OBSTACLE
    g[11:55, 11:55] = S.FREE
    return g


def _rival_by_definition(grid, scan, loc, params):
    """Best score of a pose > rival_radius_cells or > rival_heading_rad from the peak, from the full stack
    computed per heading by ``scipy.signal.fftconvolve`` (independent of the streamed search)."""
    T, o = C.scan_stamps(scan, loc.headings_rad, params=params)
    D = C.score_maps(S.grid_to_values(grid), T, o, method="fftconvolve")
    rows, cols = np.indices(D.shape[1:])
    near_cells = np.hypot(rows - loc.row, cols - loc.col) <= params.rival_radius_cells
    dh = np.abs(wrap_angle(loc.headings_rad - loc.pose[2]))
    masked = D.copy()
    masked[dh <= params.rival_heading_rad] = np.where(near_cells, -np.inf, masked[dh <= params.rival_heading_rad])
    return D.max(), masked.max()


def test_corridor_reads_as_ambiguous():
    g = CS.corridor_grid()
    scan = S.Rangefinder(n_beams=360, max_range_cells=25.0, quantum_cells=0.0).scan(g, [100.0, 25.0, np.pi])
    p = C.LocaliseParams(**EXACT)
    loc = C.localise(g, scan, params=p)
    best, rival = _rival_by_definition(g, scan, loc, p)
    assert loc.score == pytest.approx(best, rel=1e-12)
    assert loc.rival_score == pytest.approx(rival, rel=1e-12)
    # every shift along the corridor and the half turn score exactly as high: a tie
    assert loc.rival_score == pytest.approx(loc.score, rel=1e-12)
    assert loc.ambiguity == pytest.approx(1.0, abs=1e-12)
    assert "ambiguity 1.000" in str(loc)
    assert loc.margin == pytest.approx(0.0, abs=1e-9)  # a tie: no margin


def test_unique_corner_reads_as_unambiguous():
    g = _corner()
    truth = np.array([30.0, 25.0, np.radians(40.0)])
    scan = S.Rangefinder(n_beams=360, max_range_cells=80.0).scan(g, truth)
    p = C.LocaliseParams(**EXACT)
    loc = C.localise(g, scan, params=p)
    assert (loc.col, loc.row) == (30, 25)
    assert np.degrees(loc.pose[2]) == pytest.approx(40.0)
    best, rival = _rival_by_definition(g, scan, loc, p)
    assert loc.score == pytest.approx(best, rel=1e-12)
    assert loc.rival_score == pytest.approx(rival, rel=1e-12)
    # the rival pose lies outside the excluded disc or heading window
    rp = loc.rival_pose
    far = (np.hypot(rp[0] - loc.col, rp[1] - loc.row) > p.rival_radius_cells
           or abs(wrap_angle(rp[2] - loc.pose[2])) > p.rival_heading_rad)
    assert far
    # a tie reads 1 (the corridor); the corner's best rival, a quarter turn that lays one wall along the
    # other, gets clearly less than the peak above the wrong headings' median
    assert loc.ambiguity < 0.9
    # the margin by its definition: (best - rival) / sqrt(best - median of the headings' best scores)
    base = np.median(loc.best_per_heading)
    assert loc.margin == pytest.approx((best - rival) / np.sqrt(best - base), rel=1e-9)
    assert loc.margin > 1.2  # not flagged at the threshold of docs/benchmarks.md


def test_rival_window_parameters_and_switch():
    g = _corner()
    scan = S.Rangefinder(n_beams=180, max_range_cells=80.0).scan(g, [30.0, 25.0, np.radians(40.0)])
    p = C.LocaliseParams(**EXACT, rival_radius_cells=2.0, rival_heading_rad=np.radians(10.0))
    loc = C.localise(g, scan, params=p)
    assert loc.rival_score == pytest.approx(_rival_by_definition(g, scan, loc, p)[1], rel=1e-12)
    # a smaller excluded window can only find a rival as good or better
    wide = C.localise(g, scan, **EXACT)
    assert loc.rival_score >= wide.rival_score
    off = C.localise(g, scan, **EXACT, ambiguity=False)
    assert np.isnan(off.ambiguity)
    assert np.isnan(off.margin)
    assert off.rival_pose is None
    assert (off.row, off.col, off.heading_index) == (wide.row, wide.col, wide.heading_index)


def test_two_scans_joined_by_odometry_break_the_half_turn_tie():
    g = CS.corridor_grid()
    rf = S.Rangefinder(n_beams=360, max_range_cells=25.0, quantum_cells=0.0)
    # moving towards -x: the scan at (100, 25) sees a plain corridor, the one 30 cells before sees the dead end
    poses = np.array([[100.0, 25.0, np.pi], [130.0, 25.0, np.pi]])
    scans = [rf.scan(g, q) for q in poses]
    single = C.localise(g, scans[0], **EXACT)
    assert np.degrees(C.heading_error(single.pose[2], np.pi)) == pytest.approx(180.0)  # the half-turn twin
    assert single.ambiguity == pytest.approx(1.0, abs=1e-12)
    joined = C.localise_joined(g, scans, poses, **EXACT)
    assert (joined.col, joined.row) == (100, 25)
    assert C.heading_error(joined.pose[2], np.pi) == pytest.approx(0.0, abs=1e-12)
    assert joined.n_scans == 2
    # the dead end pins the pose: every rival (a shift along the corridor, the half turn) now scores lower
    assert joined.rival_score < joined.score
    assert joined.ambiguity < 1.0
    # one scan joined is the plain localisation
    one = C.localise_joined(g, scans[:1], poses[:1], **EXACT)
    assert (one.row, one.col, one.heading_index, one.score) == (single.row, single.col, single.heading_index,
                                                                single.score)


def test_joined_bad_input():
    g = _corner()
    s = S.Rangefinder(n_beams=36, max_range_cells=40.0).scan(g, [30.0, 25.0, 0.0])
    with pytest.raises(TypeError, match="`scans` must be a list or tuple of Scan; got Scan"):
        C.localise_joined(g, s, [[0, 0, 0]])
    with pytest.raises(ValueError, match="`scans` must hold at least one scan"):
        C.localise_joined(g, [], np.zeros((0, 3)))
    with pytest.raises(ValueError, match=r"`odom_poses` must have 2 rows"):
        C.localise_joined(g, [s, s], [[0, 0, 0]])
    with pytest.raises(TypeError, match=r"`scans\[1\]` must be a slamlab.scans.Scan"):
        C.localise_joined(g, [s, 3], [[0, 0, 0], [1, 0, 0]])
    with pytest.raises(ValueError, match="`rival_heading_rad` must be < π"):
        C.LocaliseParams(rival_heading_rad=4.0)
    with pytest.raises(TypeError, match="`ambiguity` must be a bool"):
        C.LocaliseParams(ambiguity=1)


def test_corridor_tie_run_reports_both_modes():
    r = CS.run_corridor_tie()
    assert np.degrees(C.heading_error(r.single.pose[2], r.true_pose[2])) == pytest.approx(180.0)
    assert r.single.ambiguity == pytest.approx(1.0, abs=1e-12)
    assert (r.joined.col, r.joined.row) == (100, 25)
    assert r.joined.n_scans == 2
    t = r.table()
    assert "2 scans + odometry" in t
    assert "1.000" in t
    assert str(r).startswith("corridor: one scan 180° off")
    with pytest.raises(ValueError, match="`spacing_cells` must be"):
        CS.run_corridor_tie(spacing_cells=-1.0)


def test_margin_edge_cases():
    """The margin's sentinels: no rival pose (inf), a peak no better than the median heading (0), not searched (NaN)."""
    kw = {"pose": np.zeros(3), "row": 0, "col": 0, "heading_index": 0, "score": 9.0,
          "headings_rad": np.zeros(3), "best_per_heading": np.array([9.0, 5.0, 1.0]), "score_map": np.zeros((1, 1))}
    assert C.Localisation(**kw, rival_score=-np.inf).margin == np.inf
    assert np.isnan(C.Localisation(**kw).margin)
    assert C.Localisation(**kw, rival_score=8.0).margin == pytest.approx(0.5)  # (9 - 8) / sqrt(9 - 5)
    flat = {**kw, "best_per_heading": np.array([9.0, 9.0, 9.0])}
    assert C.Localisation(**flat, rival_score=8.0).margin == 0.0
