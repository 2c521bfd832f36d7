"""The 2-D layer's one beam sampler (issue 42): free space along each beam, for the occupancy grid and correlation."""

import numpy as np
import pytest

from slamlab.scans import free_space_samples, occupancy_grid
from slamlab.sim import Rangefinder, test_room_200


def _by_hand(bearings, ranges, hit, step, margin, misses):
    """The samples by the definition, beam by beam: t = 0, step, ... while t < the beam's free length."""
    pts, beam = [], []
    for i, (a, r, h) in enumerate(zip(bearings, ranges, hit, strict=True)):
        end = max(r - margin - 1e-6, 0.0) if h else (r if misses else 0.0)
        k = 0
        while k * step < end:
            pts.append([k * step * np.cos(a), k * step * np.sin(a)])
            beam.append(i)
            k += 1
    return np.array(pts, dtype=float).reshape(-1, 2), np.array(beam, dtype=int)


@pytest.mark.parametrize(("step", "margin", "misses"), [(0.5, 0.0, True), (0.3, 0.7, False), (1.0, 2.5, True)])
def test_samples_equal_the_definition(step, margin, misses):
    rng = np.random.default_rng(3)
    a = rng.uniform(-np.pi, np.pi, 40)
    r = rng.uniform(0.0, 12.0, 40)
    r[:3] = [0.0, 1.0, 2.5]  # a zero range, a range on a sample, a short one inside the margin
    hit = rng.random(40) > 0.3
    pts, beam = free_space_samples(a, r, hit, step_cells=step, hit_margin_cells=margin, misses=misses)
    ref_pts, ref_beam = _by_hand(a, r, hit, step, margin, misses)
    np.testing.assert_array_equal(beam, ref_beam)  # ordered by beam, then by distance
    np.testing.assert_allclose(pts, ref_pts, rtol=0, atol=1e-12)
    assert pts.shape == (beam.size, 2)


def test_a_return_on_a_sample_is_not_sampled_and_misses_only_when_asked():
    pts, beam = free_space_samples([0.0, np.pi / 2], [1.5, 1.0], [True, False], step_cells=0.5)
    assert pts[:, 0].round(12).tolist() == [0.0, 0.5, 1.0, 0.0, 0.0]  # t < 1.5 - 1e-6: not 1.5
    assert beam.tolist() == [0, 0, 0, 1, 1]
    _, beam = free_space_samples([0.0, np.pi / 2], [1.5, 1.0], [True, False], step_cells=0.5, misses=False)
    assert beam.tolist() == [0, 0, 0]
    empty, none = free_space_samples([], [], np.zeros(0, bool), step_cells=0.5)
    assert empty.shape == (0, 2)
    assert none.size == 0


def test_occupancy_passes_are_the_samples_cells():
    # the grid's pass votes are exactly the cells of the sampler's points, beam after beam
    M = test_room_200()
    scans = [Rangefinder(n_beams=90, max_range_cells=40.0).scan(M, q) for q in ([60.0, 40.0, 0.3], [120.0, 80.0, 2.0])]
    poses = np.array([[60.0, 40.0, 0.3], [120.0, 80.0, 2.0]])
    og = occupancy_grid(scans, poses, M.shape, step_cells=0.5)
    passes = np.zeros(M.shape, dtype=np.int64)
    for s, q in zip(scans, poses, strict=True):
        pts, _ = free_space_samples(q[2] + s.bearings_rad, s.ranges, s.valid, step_cells=0.5)
        col = np.floor(q[0] + pts[:, 0] + 0.5).astype(int)
        row = np.floor(q[1] + pts[:, 1] + 0.5).astype(int)
        np.add.at(passes, (row, col), 1)
    np.testing.assert_array_equal(og.passes, passes)


def test_correlation_free_marks_come_from_the_sampler():
    from slamlab.correlation.samples import scan_samples

    s = Rangefinder(n_beams=60, max_range_cells=30.0).scan(test_room_200(), [60.0, 40.0, 0.0])
    for kw in ({}, {"delta_l_cells": 1.0, "step_cells": 0.25}, {"use_misses": True}):
        samples = scan_samples(s, **kw)
        pts, _ = free_space_samples(s.bearings_rad, s.ranges, s.valid, step_cells=kw.get("step_cells", 0.5),
                                    hit_margin_cells=kw.get("delta_l_cells", 0.0), misses=kw.get("use_misses", False))
        np.testing.assert_array_equal(samples.free, pts)


def test_bad_input_names_the_argument():
    ok = {"bearings_rad": [0.0, 1.0], "ranges": [1.0, 2.0], "hit": np.array([True, False])}
    with pytest.raises(ValueError, match="`ranges` must have length 2"):
        free_space_samples(ok["bearings_rad"], [1.0], ok["hit"], step_cells=0.5)
    with pytest.raises(ValueError, match="`ranges` must be >= 0"):
        free_space_samples(ok["bearings_rad"], [1.0, -2.0], ok["hit"], step_cells=0.5)
    with pytest.raises(ValueError, match="`hit` must be a bool array of shape"):
        free_space_samples(ok["bearings_rad"], ok["ranges"], [1, 0], step_cells=0.5)
    with pytest.raises(ValueError, match="`step_cells` must be > 0"):
        free_space_samples(**ok, step_cells=0.0)
    with pytest.raises(ValueError, match="`hit_margin_cells` must be >= 0"):
        free_space_samples(**ok, step_cells=0.5, hit_margin_cells=-1.0)
    with pytest.raises(TypeError, match="`misses` must be a bool"):
        free_space_samples(**ok, step_cells=0.5, misses=1)
