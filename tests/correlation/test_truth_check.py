"""Issue 25: score failure or search failure? The search's score at any pose, and the truth check of the log runs."""

import numpy as np
import pytest

from slamlab import correlation as C
from slamlab import sim as S
from slamlab.correlation.samples import ScanSamples, scan_samples
from slamlab.correlation.scoring import pose_scores
from slamlab.io import read_carmen
from slamlab.studies import correlation as CS


def test_pose_scores_equal_the_definition_at_grid_poses():
    # score_maps(method="direct") is the correlation's definition on the stamps T_n; pose_scores rasterises the
    # samples at each pose itself: at grid poses (integer cells, candidate headings incl. quarter turns) they agree
    M = S.test_room_200()[20:100, 0:90]
    Mv = S.grid_to_values(M)
    scan = S.Rangefinder(n_beams=90, max_range_cells=25.0, range_std_cells=0.3).scan(
        M, [40.0, 30.0, np.radians(33.0)], rng=3)
    hs = C.heading_candidates(np.radians(7.5))
    T, o = C.scan_stamps(scan, hs, dtype="float64")
    D = C.score_maps(Mv, T, o, method="direct")
    rng = np.random.default_rng(0)
    n, r, c = rng.integers(0, hs.size, 300), rng.integers(0, M.shape[0], 300), rng.integers(0, M.shape[1], 300)
    got = pose_scores(Mv, scan_samples(scan), np.column_stack([c, r, hs[n]]))
    np.testing.assert_array_equal(got, D[n, r, c])
    # off the grid, a sample is counted in the cell it falls in: one obstacle sample 3.4 cells ahead on a map with
    # one obstacle cell, robot at (10.3, 5.0) heading 0 -> the sample at x = 13.7 lies in column 14 (centre 14)
    M1 = np.zeros((11, 21))
    M1[5, 14] = 1.0
    one_obs = ScanSamples(np.zeros((0, 2)), np.array([[3.4, 0.0]]), -1.0, 1.0, 3.4, 1, C.LocaliseParams())
    one = pose_scores(M1, one_obs, [[10.3, 5.0, 0.0], [10.0, 5.0, 0.0], [10.3, 5.0, np.pi]])
    assert one.tolist() == [1.0, 0.0, 0.0]


@pytest.mark.realdata
def test_truth_check_on_csail_scans(real_data):
    log = read_carmen(real_data / "carmen-radish-corrected" / "csail-corrected.log.gz")
    r = CS.run_log_localisation(log, (100, 150), joined=(1,), truth_check=True, ambiguity=False)
    d = r.truth_check()
    assert list(d["scan"]) == [100, 150]
    assert set(d["kind"]) <= {"ok", "score", "search", "grid"}
    assert (d["kind"] == "ok").tolist() == r.success[0].tolist()
    # the search scored every grid pose: the best near the truth is never above its estimate; for a success the
    # estimate lies near the truth, so the two are the same score
    assert np.all(d["score_truth"] <= d["score_est"])
    assert np.all(d.loc[d["ok"], "score_truth"] == d.loc[d["ok"], "score_est"])
    assert d.loc[d["ok"], "score_truth_fine"].isna().all()
    assert d.loc[~d["ok"], "score_truth_fine"].notna().all()
    assert d["walls_truth"].between(0, 1).all()
    assert d["walls_est"].between(0, 1).all()
    assert "kind" in r.failure_table()
    # the terms add up to the truth check's scores (construction), the origins split the unexplored marks
    from slamlab.studies.correlation._log_scan import TRUTH_COLUMNS

    for who in ("est", "truth"):
        total = sum(d[f"{who}_{t}"] for t in CS.TERM_NAMES)
        np.testing.assert_array_equal(total.to_numpy(), d[f"score_{who}"].to_numpy())
    for what, n in (("unex_obs", "truth_n_obs_unexplored"), ("unex_free", "truth_n_free_unexplored"),
                    ("conf_obs", "truth_n_obs_on_free")):
        np.testing.assert_array_equal(sum(d[f"{what}_{w}"] for w in ("1", "2", "none")).to_numpy(), d[n].to_numpy())
    assert set(TRUTH_COLUMNS) <= set(d.columns)
    assert "free/free" in r.terms_table()
    assert "truth - est." in r.terms_table()
    with pytest.raises(TypeError, match="`truth_check` must be a bool"):
        CS.run_log_localisation(log, (100,), truth_check="yes")
    with pytest.raises(ValueError, match="`truth_check` and `refine` score by the definition with a_n = 0"):
        CS.run_log_localisation(log, (100,), truth_check=True, a_n=0.5)
    with pytest.raises(ValueError, match="score by the raw correlation; got score_norm = 'explored'"):
        CS.run_log_localisation(log, (100,), truth_check=True, score_norm="explored")
    with pytest.raises(ValueError, match="`refine`"):
        CS.run_log_localisation(log, (100,), refine=-1)
    with pytest.raises(TypeError, match="`refine`"):
        CS.run_log_localisation(log, (100,), refine=2.5)
    with pytest.raises(ValueError, match="`refine_heading_rad`"):
        CS.run_log_localisation(log, (100,), refine=3, refine_heading_rad=-0.1)
    with pytest.raises(ValueError, match="this result has no truth check"):
        CS.run_log_localisation(log, (100,), ambiguity=False, delta_alpha_rad=np.radians(10.0)).truth_check()


def test_distinct_peaks_keeps_the_best_apart():
    from slamlab.correlation._fft import distinct_peaks

    hs = np.radians(np.arange(360.0))
    peaks = np.array([[10.0, 0, 5, 5], [9.0, 1, 5, 6], [8.0, 0, 20, 5], [7.0, 90, 5, 5], [6.0, 359, 5, 5]])
    # (9, 1°, one cell away) and (6, 359°, same cell) lie within 2 cells and 3° of the best: dropped
    assert distinct_peaks(peaks, hs, 5, 2.0, np.radians(3.0))[:, 0].tolist() == [10.0, 8.0, 7.0]
    assert distinct_peaks(peaks, hs, 2, 2.0, np.radians(3.0))[:, 0].tolist() == [10.0, 8.0]


def test_refine_scores_at_least_the_grid_peak_and_the_truth():
    from slamlab.correlation.algorithm import localise_samples
    from slamlab.correlation.samples import joined_samples

    M = S.test_room_200()
    Mv = S.grid_to_values(M)
    truth = np.array([60.5, 40.5, np.radians(30.5)])  # half a cell and half a degree off the search's grid
    scan = S.Rangefinder(n_beams=360, max_range_cells=60.0).scan(M, truth)
    samples = joined_samples([scan], np.zeros((1, 3)), ambiguity=False)
    grid = localise_samples(Mv, samples)
    fine = localise_samples(Mv, samples, refine=3)
    s_grid, s_fine = pose_scores(Mv, samples, np.vstack([grid.pose, fine.pose]))
    assert s_fine >= s_grid  # the refinement lattice holds the grid peak itself
    # the truth is within 1 cell and 1° of the grid peak, on the lattice: the refined pose scores at least as high
    assert np.hypot(*(grid.pose[:2] - truth[:2])) <= 1.0
    assert s_fine >= pose_scores(Mv, samples, truth[None])[0]
    assert np.hypot(*(fine.pose[:2] - truth[:2])) <= 1.0
    assert abs(np.degrees(fine.pose[2] - truth[2])) <= 1.0 + 1e-9
    assert fine.score == grid.score  # the score and the rival stay the grid search's


def test_score_terms_sum_to_the_score_and_count_every_mark():
    # construction: every marked cell is a free or an obstacle mark on a free, obstacle or unexplored map cell, and
    # only the first two kinds of map cell count (a_n = 0), so the four signed terms add up to the score; at grid
    # poses that score is the correlation's definition (score_maps(method="direct"))
    M = S.test_room_200()[20:100, 0:90].copy()
    M[30:50, 60:90] = -1  # an unexplored block (UNEXPLORED = -1) so that marks fall on unexplored cells too
    Mv = S.grid_to_values(M)
    scan = S.Rangefinder(n_beams=90, max_range_cells=25.0, range_std_cells=0.3).scan(
        S.test_room_200()[20:100, 0:90], [40.0, 30.0, np.radians(33.0)], rng=3)
    hs = C.heading_candidates(np.radians(7.5))
    T, o = C.scan_stamps(scan, hs, dtype="float64")
    D = C.score_maps(Mv, T, o, method="direct")
    rng = np.random.default_rng(1)
    n, r, c = rng.integers(0, hs.size, 40), rng.integers(0, M.shape[0], 40), rng.integers(0, M.shape[1], 40)
    grid_poses = np.column_stack([c, r, hs[n]]).astype(float)
    off_grid = grid_poses + rng.uniform(-0.5, 0.5, grid_poses.shape) * [1, 1, 0.1]
    d = CS.score_terms(M, scan, np.vstack([grid_poses, off_grid]))
    terms = d[list(CS.TERM_NAMES)].sum(axis=1).to_numpy()
    np.testing.assert_array_equal(terms, d["score"].to_numpy())
    np.testing.assert_array_equal(d["score"].to_numpy()[:40], D[n, r, c])
    np.testing.assert_array_equal(d["score"].to_numpy()[40:], pose_scores(Mv, scan_samples(scan), off_grid))
    # with 004's ±1 values each term is ± its count
    for t, sign in (("obs_on_obs", 1), ("obs_on_free", -1), ("free_on_free", 1), ("free_on_obs", -1)):
        np.testing.assert_array_equal(d[t].to_numpy(), sign * d[f"n_{t}"].to_numpy())
    assert (d["n_obs_unexplored"] > 0).any()
    assert (d["n_free_unexplored"] > 0).any()
    # a mark counts once: the stamp's marked cells at a grid pose are the nonzero cells of T_n
    counts = d[[c for c in d.columns if c.startswith("n_")]].sum(axis=1).to_numpy()[:40]
    np.testing.assert_array_equal(counts, np.count_nonzero(T[n], axis=(1, 2)))


def test_score_terms_bad_input():
    M = S.test_room_200()[:40, :40]
    scan = S.Rangefinder(n_beams=30, max_range_cells=10.0).scan(M, [20.0, 20.0, 0.0])
    with pytest.raises(ValueError, match="`a_n` must be 0"):
        CS.score_terms(M, scan, [[20, 20, 0.0]], a_n=0.5)
    with pytest.raises(TypeError, match=r"`scan` must be a slamlab\.scans\.Scan"):
        CS.score_terms(M, [1.0, 2.0], [[20, 20, 0.0]])
    with pytest.raises(ValueError, match="`poses` must have shape"):
        CS.score_terms(M, scan, [20, 20, 0.0])
    with pytest.raises(ValueError, match="`poses` must lie within"):
        CS.score_terms(M, scan, [[1e6, 20, 0.0]])
    with pytest.raises(ValueError, match="`poses`"):
        CS.score_terms(M, scan, [[np.nan, 20, 0.0]])
    with pytest.raises(ValueError, match="`grid`"):
        CS.score_terms(np.full((5, 5), 7), scan, [[2, 2, 0.0]])


def test_unexplored_origin_counts_the_nearest_left_out_scan():
    from slamlab.correlation.scoring import PoseMarks
    from slamlab.studies.correlation._log_scan import unexplored_origin

    # five marks on a 3x4 map: obstacle marks on unexplored (0, 0), (0, 1), (0, 2) and outside; a free mark on
    # unexplored (1, 0); an obstacle mark on a map free cell (2, 3) (value a_c = -1)
    row, col = np.array([0, 0, 0, -1, 1, 2]), np.array([0, 1, 2, 0, 0, 3])
    marks = PoseMarks(row, col, np.ones(6), np.array([0, 0, 0, 0, 0, -1.0]),
                      np.array([True, True, True, True, False, True]))
    seen_a, hit_a = np.zeros((3, 4), bool), np.zeros((3, 4), bool)
    seen_b, hit_b = np.zeros((3, 4), bool), np.zeros((3, 4), bool)
    seen_a[0, 0] = seen_a[1, 0] = True  # the scan 2 steps away saw (0, 0) and (1, 0)
    seen_b[0, 0] = seen_b[0, 1] = True  # the scan 1 step back saw (0, 0) and (0, 1) and hit (2, 3)
    seen_b[2, 3] = hit_b[2, 3] = True
    out = unexplored_origin(marks, (3, 4), [(2, (seen_a, hit_a)), (-1, (seen_b, hit_b))], -1.0)
    assert out == {"unex_obs_1": 2, "unex_obs_2": 0, "unex_obs_none": 2, "unex_free_1": 0, "unex_free_2": 1,
                   "unex_free_none": 0, "conf_obs_1": 1, "conf_obs_2": 0, "conf_obs_none": 0}
