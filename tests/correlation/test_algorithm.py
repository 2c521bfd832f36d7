"""Correlation localisation (004 §7): index mapping, three correlation methods, exact recovery."""

import numpy as np
import pytest
from scipy.signal import correlate

from slamlab import correlation as C
from slamlab import sim as S
from slamlab.scans import Scan
from slamlab.studies import correlation as CS


def test_score_maps_three_methods_agree_with_scipy_correlate():
    rng = np.random.default_rng(0)
    M = rng.normal(size=(23, 17))
    T = rng.normal(size=(3, 10, 10))
    o = 5
    D = {m: C.score_maps(M, T, o, method=m) for m in ("batched", "fftconvolve", "direct")}
    for n in range(3):
        full = correlate(M, T[n], mode="full", method="direct")  # C[a, b]; robot row = a + o - (S - 1)
        a0 = 10 - 1 - o
        ref = full[a0:a0 + 23, a0:a0 + 17]
        for m in D:
            np.testing.assert_allclose(D[m][n], ref, atol=1e-9, err_msg=m)
    np.testing.assert_allclose(C.score_maps(M, T, o, dtype=np.float32), D["direct"], atol=1e-4)


def test_index_mapping_closed_form():
    # a single obstacle cell in M and a single mark in T: the score is nonzero only where the
    # robot cell + (T offset) lands on the obstacle
    M = np.zeros((30, 40))
    M[12, 25] = 1.0
    T = np.zeros((1, 12, 12))
    o = 6
    T[0, o + 3, o - 4] = 2.0  # 3 rows up, 4 columns left of the robot
    for method in ("batched", "fftconvolve", "direct"):
        D = C.score_maps(M, T, o, method=method)[0]
        assert np.unravel_index(np.argmax(D), D.shape) == (12 - 3, 25 + 4)
        assert D.max() == pytest.approx(2.0)
        assert np.abs(D).sum() == pytest.approx(2.0)


def _reference_stamp(angles, ranges, heading, S, o, a_c=-1.0, a_p=1.0, hit_offset=0.5, step=0.5):
    """Independent plain rasterisation of one T_n (float64, per beam)."""
    T = np.zeros((S, S))
    for pts_val in ("free", "obs"):
        for a, r in zip(angles, ranges, strict=True):
            th = heading + a
            t = np.arange(0.0, r - 1e-6, step) if pts_val == "free" else np.linspace(0.01, hit_offset, 2)
            if pts_val == "obs":
                t = r + t
            col = np.floor(t * np.cos(th) + 0.5).astype(int) + o
            row = np.floor(t * np.sin(th) + 0.5).astype(int) + o
            T[row, col] = a_c if pts_val == "free" else a_p
    return T


def test_rasterise_matches_plain_reference():
    M = S.test_room_200()
    s = S.Rangefinder(n_beams=120, max_range_cells=80).scan(M, [70, 30, 0.0])
    # headings off the axes: beams at multiples of 3° put no sample exactly on a cell face
    headings = np.radians([1.0, 37.0, 91.0, 269.0, 359.0])
    T, o = C.scan_stamps(s, headings)
    assert T.shape[1] == 2 * o
    for n, th in enumerate(headings):
        ref = _reference_stamp(s.bearings_rad[s.valid], s.ranges[s.valid], th, T.shape[1], o)
        # float32 coordinates / quarter-turn reuse may round a sample lying on a cell face differently
        assert np.count_nonzero(T[n] != ref) <= 3
        assert np.count_nonzero(ref) > 500


def test_quarter_turns_are_grid_rotations():
    M = S.test_room_200()
    s = S.Rangefinder(n_beams=90, max_range_cells=60).scan(M, [70, 30, 0.0])
    T, o = C.scan_stamps(s, np.radians([10.0, 100.0, 190.0, 280.0]))
    # a quarter turn maps the robot-frame offset (dx, dy) to (-dy, dx): T'[o + dx, o - dy] = T[o + dy, o + dx]
    for q in range(1, 4):
        ref = np.zeros_like(T[0])
        rows, cols = np.nonzero(T[0])
        dy, dx = rows - o, cols - o
        for _ in range(q):
            dx, dy = -dy, dx
        ref[o + dy, o + dx] = T[0][rows, cols]
        assert np.array_equal(T[q], ref)


@pytest.mark.parametrize("seed", [1, 2, 3])
def test_noise_free_scan_comes_back_exactly(seed):
    M = S.test_room_200()
    P = S.random_free_poses(M, 4, margin_cells=2, rng=seed)
    P[:, 2] = np.radians(np.round(np.degrees(P[:, 2])))  # on the Δα = 1° grid
    rf = S.Rangefinder(n_beams=360, max_range_cells=100)
    for p in P:
        loc = C.localise(M, rf.scan(M, p))
        assert (loc.col, loc.row) == (int(p[0]), int(p[1]))
        assert loc.pose[2] == pytest.approx(np.mod(p[2], 2 * np.pi), abs=1e-9)


def test_tracking_window_agrees_with_full_search_and_float32():
    W = S.measurement_room_200()
    M = S.test_room_200()
    rf = S.Rangefinder(n_beams=360, max_range_cells=100, range_std_cells=0.3)
    p = np.array([150.0, 80.0, 2.3])
    s = rf.scan(W, p, rng=5)
    full = C.localise(M, s, dtype="float64")
    track = C.localise(M, s, prior_heading_rad=np.radians(130.0), window_rad=np.radians(10), dtype="float64")
    f32 = C.localise(M, s)  # the default: float32
    assert C.LocaliseParams().dtype == "float32"
    assert track.headings_rad.size == 21
    assert (track.row, track.col) == (full.row, full.col) == (f32.row, f32.col) == (80, 150)
    assert C.heading_error(track.pose[2], full.pose[2]) < 1e-9
    assert C.heading_error(full.pose[2], p[2]) <= np.radians(1.0)
    assert full.best_per_heading.size == 360
    assert full.score == pytest.approx(full.best_per_heading.max())
    assert f32.score == pytest.approx(full.score, rel=1e-5)
    assert C.heading_error(f32.pose[2], full.pose[2]) < 1e-9
    assert full.score_map.shape == M.shape


def test_sharpest_peak_needs_opposite_signs():
    # with a_c = a_n = 0, free space carries no information: the peak can only be as sharp or flatter
    M = S.test_room_200()
    s = S.Rangefinder(n_beams=360, max_range_cells=100).scan(M, [60, 40, 0.5])
    opp = C.localise(M, s, prior_heading_rad=0.5, window_rad=0.0)
    pos = C.localise(M, s, prior_heading_rad=0.5, window_rad=0.0, a_c=0.0, a_p=1.0)
    def rel_second(d, r, c):
        d = d.copy()
        d[max(r - 3, 0):r + 4, max(c - 3, 0):c + 4] = -np.inf
        return d.max()
    sharp_opp = (opp.score - rel_second(opp.score_map, opp.row, opp.col)) / opp.score
    sharp_pos = (pos.score - rel_second(pos.score_map, pos.row, pos.col)) / pos.score
    assert sharp_opp > sharp_pos


def test_heading_candidates():
    h = C.heading_candidates(np.radians(1.0))
    assert h.size == 360
    np.testing.assert_allclose(np.degrees(h[[0, 1, -1]]), [0, 1, 359])
    assert C.heading_candidates(np.radians(7.0)).size == 51  # 51·7° = 357° < 360°


def test_bad_input():
    M = S.test_room_200()
    scan = S.Rangefinder(n_beams=8, max_range_cells=50).scan(M, [70, 30, 0])
    with pytest.raises(ValueError, match="`a_c` and `a_p` must differ"):
        C.localise(M, scan, a_c=1.0, a_p=1.0)
    with pytest.raises(TypeError, match="`a_n` must be a finite real"):
        C.localise(M, scan, a_n=np.inf)
    with pytest.raises(ValueError, match="`window_rad` needs `prior_heading_rad`"):
        C.localise(M, scan, window_rad=0.1)
    with pytest.raises(ValueError, match="`delta_alpha_rad` must be > 0"):
        C.localise(M, scan, delta_alpha_rad=0.0)
    with pytest.raises(TypeError, match=r"`scan` must be a slamlab.scans.Scan; got list"):
        C.localise(M, [1, 2, 3])
    with pytest.raises(TypeError, match=r"`scan` must be a slamlab.scans.Scan; got tuple"):
        C.localise(M, ([0.0], [5.0], np.array([True])))
    with pytest.raises(ValueError, match="no return"):
        C.localise(M, Scan([0.0, 1.0], [5.0, 5.0], np.array([False, False])))
    with pytest.raises(ValueError, match="`scan` must be in cell units; got unit 'm'"):
        C.localise(M, Scan([0.0], [5.0], [True], unit="m"))
    with pytest.raises(ValueError, match="`step_cells` must be <= 1"):
        C.scan_stamps(Scan([0.0], [1.0], [True]), [0.0], step_cells=2.0)
    with pytest.raises(ValueError, match="`step_cells` must be <= 1"):
        C.localise(M, scan, step_cells=2.0)
    with pytest.raises(ValueError, match="`dtype` must be one of"):
        C.localise(M, scan, dtype="float16")
    with pytest.raises(TypeError, match=r"LocaliseParams has no field.*'delta_alpha_deg'"):
        C.localise(M, scan, delta_alpha_deg=1.0)
    with pytest.raises(TypeError, match="`params` must be a LocaliseParams or None; got dict"):
        C.localise(M, scan, params={"a_c": 0.0})
    with pytest.raises(ValueError, match="`l_max` must cover the longest beam"):
        C.scan_stamps(Scan([0.0], [10.0], [True]), [0.0], l_max=3)
    with pytest.raises(ValueError, match=r"`T` must have shape \(n, S, S\)"):
        C.score_maps(np.zeros((4, 4)), np.zeros((3, 4)), 1)
    with pytest.raises(ValueError, match="`method` must be one of"):
        C.score_maps(np.zeros((4, 4)), np.zeros((1, 4, 4)), 1, method="fast")
    with pytest.raises(ValueError, match="`origin` must be <= 3"):
        C.score_maps(np.zeros((4, 4)), np.zeros((1, 4, 4)), 9)
    with pytest.raises(ValueError, match="`M_values` must be finite"):
        C.score_maps(np.full((4, 4), np.nan), np.zeros((1, 4, 4)), 1)
    with pytest.raises(ValueError, match=r"only 0 .free., 1 .obstacle. or -1"):
        C.localise(np.full((5, 5), 3), scan)
    with pytest.raises(ValueError, match="`delta_alpha_rad` must be <= π"):
        C.heading_candidates(4.0)


def test_quarter_turn_search_equals_plain_stack_on_a_non_square_map():
    # localise() correlates base stamps with four rotated maps; compare with the plain batched stack
    M = S.test_room_200()[10:130, 5:190]
    s = S.Rangefinder(n_beams=180, max_range_cells=60, range_std_cells=0.2).scan(M, [90, 60, 1.0], rng=3)
    loc = C.localise(M, s, delta_alpha_rad=np.radians(3.0), dtype="float64")
    T, o = C.scan_stamps(s, loc.headings_rad)
    D = C.score_maps(S.grid_to_values(M), T, o, method="fftconvolve")
    np.testing.assert_allclose(loc.best_per_heading, D.reshape(D.shape[0], -1).max(axis=1), atol=1e-8)
    np.testing.assert_allclose(loc.score_map, D[loc.heading_index], atol=1e-8)
    assert np.unravel_index(np.argmax(D), D.shape) == (loc.heading_index, loc.row, loc.col)


def test_params_every_field_checked_and_sourced():
    p = C.LocaliseParams()
    assert set(p.sources()) == set(C.LocaliseParams.field_names())
    assert all(p.sources().values())
    assert p.delta_alpha_rad == pytest.approx(np.radians(1.0))
    bad = {"delta_alpha_rad": 0.0, "a_c": "x", "a_p": -1.0, "a_n": np.nan, "delta_l_cells": -1.0,
           "hit_offset_cells": -0.1, "step_cells": 0.0, "use_misses": 1, "chunk": 0, "dtype": "int8",
           "workers": 0}
    for name, value in bad.items():
        with pytest.raises((TypeError, ValueError), match=f"`{name}`"):
            C.LocaliseParams(**{name: value})
    # the a_c = a_p rule names both
    with pytest.raises(ValueError, match="`a_c` and `a_p` must differ"):
        C.LocaliseParams(a_c=1.0, a_p=1.0)
    assert "004 §7" in p.table()


def test_localise_params_object_equals_overrides():
    M = S.test_room_200()
    s = S.Rangefinder(n_beams=90, max_range_cells=60).scan(M, [70, 30, 0.3])
    p = C.LocaliseParams(delta_alpha_rad=np.radians(5.0), a_c=0.0)
    a = C.localise(M, s, params=p)
    b = C.localise(M, s, delta_alpha_rad=np.radians(5.0), a_c=0.0)
    assert (a.row, a.col, a.heading_index, a.score) == (b.row, b.col, b.heading_index, b.score)


def test_wall_balance_weights_corridor_walls_less():
    """Issue 25 (ours): returns on a corridor's long walls weigh less than those on its end wall; mean 1, cap 4."""
    from slamlab.correlation._fft import write_marks
    from slamlab.correlation.samples import scan_samples

    a = np.radians(np.arange(-90.0, 91.0))  # a corridor 4 cells wide along x, its end wall at x = 30
    r = np.minimum(np.abs(2.0 / np.where(np.sin(a) == 0, 1e-9, np.sin(a))), 30.0 / np.maximum(np.cos(a), 1e-9))
    h = np.ones(a.size, bool)
    w = scan_samples(Scan(a, r, h), wall_balance=True, a_p=2.0).obs_value / 2.0  # a_p times each sample's weight
    assert scan_samples(Scan(a, r, h), a_p=2.0).obs_value == 2.0  # no weights without wall_balance
    n_obs = w.size // a.size
    wb = w[::n_obs]
    end = np.abs(r * np.cos(a) - 30.0) < 1e-6
    assert w.size == n_obs * a.size
    assert wb[end].mean() > 2 * wb[~end].mean()
    assert np.isclose(wb.mean(), 1.0) or wb.max() == 4.0
    assert wb.max() <= 4.0
    # per-point values equal to a scalar stamp the same image, bit for bit
    pts = np.column_stack([r * np.cos(a), r * np.sin(a)])
    T1 = np.zeros((3, 80, 80), np.float32)
    T2 = np.zeros((3, 80, 80), np.float32)
    hd = np.radians([0.0, 10.0, 45.0])
    write_marks(T1, hd, pts[:0], pts, -1.0, 1.0, 40)
    write_marks(T2, hd, pts[:0], pts, -1.0, np.ones(a.size), 40)
    assert np.array_equal(T1, T2)
    with pytest.raises(TypeError, match="`wall_balance` must be a bool"):
        C.LocaliseParams(wall_balance=1)


def _explored_reference(M_codes, T, o, min_fraction, floor):
    """score_norm='explored' by hand: Σ T·M / Σ [T marked]·[M explored] per pose (scipy's correlate), floor
    where the marks on explored cells are fewer than ``min_fraction`` of the stamp's marks."""
    Mv = S.grid_to_values(M_codes)
    E = (M_codes != -1).astype(float)
    H, W = M_codes.shape
    Sz = T.shape[1]
    a0 = Sz - 1 - o
    out = np.empty((T.shape[0], H, W))
    for n in range(T.shape[0]):
        D = correlate(Mv, T[n], mode="full", method="direct")[a0:a0 + H, a0:a0 + W]
        ind = (T[n] != 0).astype(float)
        cnt = np.rint(correlate(E, ind, mode="full", method="direct")[a0:a0 + H, a0:a0 + W])
        out[n] = np.where(cnt >= min_fraction * ind.sum(), D / np.maximum(cnt, 1), floor)
    return out


@pytest.mark.parametrize("min_fraction", [0.3, 0.8])
def test_score_norm_explored_matches_definition(min_fraction):
    """Issue 25 (ours): the normalised score equals Σ T·M / (marks on explored cells), by hand, at every pose."""
    M = S.test_room_200()[20:80, 10:70].copy()
    M[:, 35:] = -1  # the right part unexplored (a leave-out's hole)
    scan = S.Rangefinder(n_beams=90, max_range_cells=25.0).scan(S.test_room_200(), [50.0, 45.0, np.radians(20)])
    hd = C.heading_candidates(np.radians(30.0))
    T, o = C.scan_stamps(scan, hd, dtype="float64")
    floor = -1.0 / min_fraction - 1.0  # the documented floor: -max|T|·max|M| / min_fraction - 1, here |T|, |M| <= 1
    ref = _explored_reference(M, T, o, min_fraction, floor)
    loc = C.localise(M, scan, delta_alpha_rad=np.radians(30.0), dtype="float64", ambiguity=False,
                     score_norm="explored", min_explored_fraction=min_fraction)
    n, r, c = np.unravel_index(np.argmax(ref), ref.shape)
    assert (loc.heading_index, loc.row, loc.col) == (n, r, c)
    assert loc.score == pytest.approx(ref[n, r, c], abs=1e-9)
    np.testing.assert_allclose(loc.score_map, ref[n], atol=1e-9)
    np.testing.assert_allclose(loc.best_per_heading, ref.reshape(ref.shape[0], -1).max(axis=1), atol=1e-9)
    # a few poses by the definition itself (loops over the stamp's cells)
    Mv, E = S.grid_to_values(M), M != -1
    for rr, cc in ((r, c), (10, 5), (30, 40), (55, 20)):
        num = cnt = 0.0
        for i, j in zip(*np.nonzero(T[n]), strict=True):
            y, x = rr + i - o, cc + j - o
            if 0 <= y < M.shape[0] and 0 <= x < M.shape[1]:
                num += T[n, i, j] * Mv[y, x]
                cnt += E[y, x]
        want = num / max(cnt, 1) if cnt >= min_fraction * np.count_nonzero(T[n]) else floor
        assert loc.score_map[rr, cc] == pytest.approx(want, abs=1e-9)
    # float32 FFTs find the same peak
    loc32 = C.localise(M, scan, delta_alpha_rad=np.radians(30.0), ambiguity=False, score_norm="explored",
                       min_explored_fraction=min_fraction)
    assert (loc32.heading_index, loc32.row, loc32.col) == (n, r, c)


def test_score_norm_floor_lies_below_every_score_with_heavy_free_marks():
    """Issue 25 (ours): with free marks weighted 5 (``free_mark_weight``), a map of obstacles only and a scan in open
    space, every pose with enough marks on explored cells scores about -5 per mark (free marks on obstacles); the
    poses with too few must still score lower, so the estimate keeps >= min_explored_fraction of its marks on the
    map (a floor of min(a_c, a_p, a_n) - 1 = -2 would let the off-map poses win)."""
    world = np.zeros((80, 80), dtype=np.int8)
    world[[0, -1], :] = 1
    world[:, [0, -1]] = 1
    scan = S.Rangefinder(n_beams=90, max_range_cells=60.0).scan(world, [40.0, 40.0, 0.0])
    M = np.ones((160, 160), dtype=np.int8)  # every cell an obstacle
    hd = C.heading_candidates(np.radians(30.0))
    loc = C.localise(M, scan, delta_alpha_rad=np.radians(30.0), dtype="float64", ambiguity=False,
                     score_norm="explored", min_explored_fraction=0.8, free_mark_weight=5.0)
    T, o = C.scan_stamps(scan, hd, a_c=-5.0, a_p=1.0, dtype="float64")
    marks = np.argwhere(T[loc.heading_index] != 0) - o + [loc.row, loc.col]
    inside = np.all((marks >= 0) & (marks < 160), axis=1)
    assert inside.mean() >= 0.8
    assert loc.score < -3.0  # a real normalised score (free marks on obstacles dominate), not a floor


def test_score_norm_bad_parameters():
    M = S.test_room_200()
    rf = S.Rangefinder(n_beams=36, max_range_cells=30)
    s = rf.scan(M, [70, 30, 0.0])
    kw = {"delta_alpha_rad": np.radians(90.0), "ambiguity": False}
    for f in (C.localise, lambda M, s, **k: C.localise_joined(M, [s], np.zeros((1, 3)), **k)):
        with pytest.raises(ValueError, match="`score_norm` must be one of"):
            f(M, s, score_norm="mean", **kw)
        with pytest.raises(ValueError, match="`min_explored_fraction` must be > 0"):
            f(M, s, score_norm="explored", min_explored_fraction=0.0, **kw)
        with pytest.raises(ValueError, match="`min_explored_fraction` must be <= 1"):
            f(M, s, score_norm="explored", min_explored_fraction=1.5, **kw)
        with pytest.raises(TypeError, match="`min_explored_fraction` must be a real number"):
            f(M, s, score_norm="explored", min_explored_fraction="0.5", **kw)
        with pytest.raises(ValueError, match="needs `a_n` to differ"):
            f(M, s, score_norm="explored", a_c=0.0, **kw)
    # off by default: "none" is the raw score, bit for bit
    a, b = C.localise(M, s, **kw), C.localise(M, s, score_norm="none", **kw)
    assert (a.row, a.col, a.heading_index, a.score) == (b.row, b.col, b.heading_index, b.score)
    assert "score_norm" not in C.LocaliseParams.field_names()


def test_free_mark_weight_scales_the_stamps_free_marks_only():
    """Issue 25 (ours): free_mark_weight = λ puts λ·a_c at the stamp's free marks, a_p at its obstacle marks; the
    map keeps 004's values, so the search maximises the definition with that stamp."""
    M = S.test_room_200()[20:100, 0:90]
    scan = S.Rangefinder(n_beams=90, max_range_cells=25.0).scan(M, [40.0, 30.0, np.radians(33.0)])
    hs = C.heading_candidates(np.radians(10.0))
    T1, o = C.scan_stamps(scan, hs, dtype="float64")
    Tl, _ = C.scan_stamps(scan, hs, dtype="float64", free_mark_weight=0.25)
    assert np.array_equal(Tl, np.where(T1 == -1.0, -0.25, T1))
    D = C.score_maps(S.grid_to_values(M), Tl, o, method="direct")
    loc = C.localise(M, scan, delta_alpha_rad=np.radians(10.0), free_mark_weight=0.25, dtype="float64",
                     ambiguity=False)
    assert np.isclose(loc.score, D.max())
    assert np.isclose(D[loc.heading_index, loc.row, loc.col], D.max())
    # the score's terms: the free ones scale by λ, the obstacle ones do not, and they still sum to the score
    poses = [[40, 30, np.radians(30.0)], [45, 28, np.radians(120.0)]]
    d1, dl = CS.score_terms(M, scan, poses), CS.score_terms(M, scan, poses, free_mark_weight=0.25)
    np.testing.assert_array_equal(dl[["free_on_free", "free_on_obs"]], 0.25 * d1[["free_on_free", "free_on_obs"]])
    np.testing.assert_array_equal(dl[["obs_on_obs", "obs_on_free"]], d1[["obs_on_obs", "obs_on_free"]])
    np.testing.assert_allclose(dl[list(CS.TERM_NAMES)].sum(axis=1), dl["score"])
    with pytest.raises(ValueError, match="`free_mark_weight`"):
        C.LocaliseParams(free_mark_weight=0.0)
