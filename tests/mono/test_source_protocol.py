"""003 §4.2's corner subset, §5.5's best of 3 runs, §5.5.2's timing ranking and §5.1.2's observations (ours)."""

from __future__ import annotations

import dataclasses
import re

import numpy as np
import pytest

from slamlab.mono.epipolar import epipolar_candidates, epipolar_segments, extract_patches, search_epipolar
from slamlab.studies.mono import (
    practice_findings_table,
    run_epipolar_subset,
    run_failure_cases,
    run_repeats,
    run_still_start,
    source_timing_table,
    stage_timing_table,
)


# -- epipolar_candidates (003 §4.2) ------------------------------------------------------------------------
def _band_by_geometry(corners, a, b, tol):
    """(C, S) True where a corner is within tol of the line and its foot lies on the segment grown by tol (float64)."""
    d = b - a
    L = np.linalg.norm(d, axis=1)
    e = d / L[:, None]
    rel = corners[:, None, :] - a[None]  # (C, S, 2)
    along = np.einsum("csk,sk->cs", rel, e)
    dist = np.abs(rel[..., 0] * e[:, 1] - rel[..., 1] * e[:, 0])
    margin = np.minimum.reduce([tol - dist, along + tol, L + tol - along])
    return margin >= 0, np.abs(margin)


def test_candidates_are_the_corners_of_the_band_and_the_subsets_nest():
    rng = np.random.default_rng(0)
    corners = rng.uniform(0, 300, (400, 2))
    a = rng.uniform(0, 300, (50, 2))
    b = a + rng.uniform(-80, 80, (50, 2))
    ok = rng.random(50) > 0.1
    c = epipolar_candidates(corners, a, b, ok, tol_px=3.0)
    band, margin = _band_by_geometry(corners, a, b, 3.0)
    band &= ok[None]
    got = np.zeros_like(band)
    got[c.corner_idx, c.seed_idx] = True
    clear = margin > 1e-4  # away from the boundary, float32 and float64 agree
    np.testing.assert_array_equal(got[clear], band[clear])
    np.testing.assert_array_equal(c.n_band, got.sum(axis=0))
    # the row window, then the columns, then the band: each a subset of the one before
    assert np.all(c.n_rows >= c.n_box)
    assert np.all(c.n_box >= c.n_band)
    assert np.all(c.n_rows[~ok] == 0)
    # the rows and columns, counted by brute force over every corner (padding tol·√2)
    pad = 3.0 * np.sqrt(2)
    lo, hi = np.minimum(a, b) - pad, np.maximum(a, b) + pad
    in_rows = (corners[:, None, 1] >= lo[:, 1]) & (corners[:, None, 1] <= hi[:, 1])
    in_box = in_rows & (corners[:, None, 0] >= lo[:, 0]) & (corners[:, None, 0] <= hi[:, 0])
    np.testing.assert_array_equal(c.n_rows[ok], in_rows.sum(axis=0)[ok])
    np.testing.assert_array_equal(c.n_box[ok], in_box.sum(axis=0)[ok])


def test_candidates_of_a_horizontal_segment_on_the_pixel_grid():
    # every pixel within 2 px of (0, 10)-(50, 10): rows 8..12 and columns -2..52, cut to the image's 0..52
    u, v = np.meshgrid(np.arange(100.0), np.arange(30.0))
    pix = np.column_stack([u.ravel(), v.ravel()])
    c = epipolar_candidates(pix, [[0.0, 10.0]], [[50.0, 10.0]], tol_px=2.0)
    assert c.n_band.tolist() == [53 * 5]
    assert c.n_rows.tolist() == [100 * 5]  # rows 10 ± 2.83: 8..12


def test_candidates_equal_the_corners_search_epipolar_scores():
    rng = np.random.default_rng(3)
    K = np.array([[300.0, 0, 160], [0, 300.0, 120], [0, 0, 1]])
    T = np.eye(4)
    T[:3, 3] = [0.3, 0.02, 0.05]
    f = np.column_stack([rng.uniform(-0.4, 0.4, (40, 2)), np.ones(40)])
    f /= np.linalg.norm(f, axis=1, keepdims=True)
    mu, sigma = rng.uniform(0.2, 0.6, 40), np.full(40, 0.1)
    img = rng.integers(0, 255, (240, 320)).astype(np.uint8)
    corners = rng.integers(8, 230, (600, 2)).astype(np.float64)
    corners[:, 0] = rng.integers(8, 310, 600)
    m = search_epipolar(K, T, f, mu, sigma, extract_patches(img, np.zeros((40, 2)) + 50, 9), img, corners)
    a, b, ok = epipolar_segments(K, T, f, mu, sigma)
    c = epipolar_candidates(corners, a, b, ok, tol_px=2.0)
    np.testing.assert_array_equal(c.n_band, m.n_candidates)


@pytest.mark.parametrize(("kwargs", "match"), [
    ({"corners_uv": np.zeros((3, 3))}, "`corners_uv` must have shape"),
    ({"b": np.zeros((2, 2))}, "`a` and `b` must have one shape"),
    ({"ok": np.ones(2, bool)}, "`ok` must have shape"),
    ({"tol_px": 0.0}, "`tol_px`"),
])
def test_candidates_refuse_bad_input(kwargs, match):
    args = {"corners_uv": np.zeros((3, 2)), "a": np.zeros((1, 2)), "b": np.ones((1, 2))} | kwargs
    tol = args.pop("tol_px", 2.0)
    ok = args.pop("ok", None)
    with pytest.raises(ValueError, match=match):
        epipolar_candidates(args["corners_uv"], args["a"], args["b"], ok, tol_px=tol)


def test_epipolar_subset_counts_nest_and_grow_with_the_band():
    s = run_epipolar_subset(frames=(0, 3), tols_px=(1.0, 3.0), rng=5)
    every, narrow, wide = s.rows
    assert every[3] == s.n_corners  # every corner scored
    for row in (narrow, wide):
        _, rows, box, band, pix, matches, wrong = row
        assert rows >= box >= band
        assert pix >= band
        assert 0 <= wrong <= matches <= s.n_seeds
    assert wide[3] >= narrow[3]
    assert wide[4] > narrow[4]
    assert s.n_in_interval == s.n_seeds  # SVO's prior from 0.5 m holds every depth of the arena
    assert "003's subset" in s.table()
    with pytest.raises(ValueError, match="`frames` must name two different frames"):
        run_epipolar_subset(frames=(2, 2))


# -- best of 3 (003 §5.5), §5.1.2, §5.5.2 --------------------------------------------------------------------
@pytest.fixture(scope="module")
def small_runs():
    rep = run_repeats(("normal",), n_runs=2, n_frames=10, rng=7)
    fails = run_failure_cases(("normal",), n_frames=10, rng=7)
    return rep, fails


def test_run_1_of_the_repeats_is_the_chapters_run_and_best_is_the_smallest_ate(small_runs):
    rep, fails = small_runs
    assert rep.results[("normal", 0)].ate_m == fails["normal"].ate_m  # the same frames (case_seed of rng)
    ate = rep.ate_m("normal")
    assert ate[rep.best("normal")] == ate.min() <= np.median(ate)
    assert rep.results[("normal", 1)].ate_m != ate[0]  # other noise
    assert f"{ate[0]:.3f} / {ate[1]:.3f}" in rep.table()


def test_repeats_refuse_bad_input():
    with pytest.raises(ValueError, match="`n_runs`"):
        run_repeats(("normal",), n_runs=0)
    with pytest.raises(ValueError, match="`cases`"):
        run_repeats(("sideways",))


def test_stage_timing_sums_its_stages(small_runs):
    rep, _ = small_runs
    r = rep.results[("normal", 0)]
    stages = {"detect": 0.001, "align": 0.010, "match": 0.002, "refine": 0.003, "mapping": 0.020, "keyframe": 0.0}
    r = dataclasses.replace(r, stage_time_s=stages, fps=12.0)
    row = stage_timing_table({"x": r}).splitlines()[-1].split()
    assert row == ["x", "10.0", "2.0", "3.0", "15.0", "1.0", "20.0", "0.0", "21.0", "12"]
    with pytest.raises(TypeError, match="`runs"):
        stage_timing_table({"x": 1})


def test_source_timing_table_ranks_as_003_and_converts_the_40_percent():
    txt = source_timing_table()
    # 003 §5.5.2: SVO fastest, SDVL between SVO and LSD-SLAM, LSD-SLAM between SVO and ORB-SLAM, ORB-SLAM slowest
    for name, rank in (("SVO", 1), (r"SDVL \(003's, no ORB\)", 2), ("LSD-SLAM", 3), ("ORB-SLAM", 4), ("PTAM", "-")):
        assert re.search(rf"^\s*{name}\s+{rank}\s", txt, re.MULTILINE), name
    assert "1 / (1 - 0.40) = 1.67" in txt  # 1 / 0.6
    assert "33.3 ms" in txt  # 1000 / 30


def test_still_start_moving_run_is_the_chapters_normal_run(small_runs):
    rep, fails = small_runs
    st = run_still_start(3, n_frames=10, rng=7)
    assert st.moving.ate_m == fails["normal"].ate_m
    assert len(st.still.claimed) == 13
    assert not st.still.claimed[:3].any()  # no map while the camera stands still
    with pytest.raises(ValueError, match="`n_still`"):
        run_still_start(0)
    txt = practice_findings_table(fails | {"fast_motion": fails["normal"]},
                                  dataclasses.replace(rep, cases=("normal", "fast_motion"),
                                                      results=rep.results | {("fast_motion", i): rep.results[("normal", i)]
                                                                             for i in range(2)}), st)
    assert "not shown" in txt  # the same runs for both cases: no sensitivity to abrupt motion
    with pytest.raises(ValueError, match="must hold the case 'fast_motion'"):
        practice_findings_table(fails, rep, st)


def test_given_first_runs_are_used_as_they_are_and_checked(small_runs):
    rep, fails = small_runs
    again = run_repeats(("normal",), n_runs=2, n_frames=10, rng=7, first=fails)
    assert again.results[("normal", 0)] is fails["normal"]
    assert again.table() == rep.table()  # the same as running run 1 again
    with pytest.raises(ValueError, match=r"`first\['normal'\]` must be"):
        run_repeats(("normal",), n_runs=2, n_frames=12, rng=7, first=fails)  # 10 frames, not 12
    st = run_still_start(3, n_frames=10, rng=7, moving=fails["normal"])
    assert st.moving is fails["normal"]
    with pytest.raises(ValueError, match="`moving` must be"):
        run_still_start(3, n_frames=10, rng=7, moving=rep.results[("normal", 1)])  # named 'normal, run 2'
