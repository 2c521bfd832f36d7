"""The one grid ray caster (scans.cast_rays) against a fine-step ray march and closed forms, batched over poses."""

import numpy as np
import pytest

from slamlab.scans import FREE, OBSTACLE, cast_rays, make_grid


def _march(grid, pose, angles, rmax, step=1e-3):
    """Independent reference: walk each beam in tiny steps; the first sample inside an OBSTACLE cell is its return
    (a beam that has left the grid never returns)."""
    t = np.arange(0.0, rmax + step, step)
    th = pose[2] + np.asarray(angles)[:, None]
    r = np.floor(pose[1] + t * np.sin(th) + 0.5).astype(int)
    c = np.floor(pose[0] + t * np.cos(th) + 0.5).astype(int)
    inside = (r >= 0) & (r < grid.shape[0]) & (c >= 0) & (c < grid.shape[1])
    solid = inside & (grid[np.clip(r, 0, grid.shape[0] - 1), np.clip(c, 0, grid.shape[1] - 1)] == OBSTACLE)
    solid &= ~(np.cumsum(~inside, axis=1) > 0)
    hit = solid.any(axis=1)
    return np.where(hit, t[np.argmax(solid, axis=1)], rmax), hit


def _random_room(rng, shape=(30, 40), fill=0.08):
    g = np.where(rng.random(shape) < fill, OBSTACLE, FREE).astype(np.int8)
    g[[0, -1], :] = OBSTACLE
    g[:, [0, -1]] = OBSTACLE
    g[rng.random(shape) < 0.05] = -1  # unexplored cells are transparent
    return g


def test_matches_a_fine_step_march_on_small_random_grids():
    rng = np.random.default_rng(3)
    for _ in range(4):
        g = _random_room(rng)
        poses = np.column_stack([rng.uniform(1, 38, 6), rng.uniform(1, 28, 6), rng.uniform(-np.pi, np.pi, 6)])
        ang = rng.uniform(0, 2 * np.pi, 60)
        ranges, hit = cast_rays(g, poses, ang, 25.0)
        assert ranges.shape == hit.shape == (6, 60)
        for p, r_row, h_row in zip(poses, ranges, hit, strict=True):
            ref, ref_hit = _march(g, p, ang, 25.0, step=1e-3)
            agree = h_row == ref_hit
            assert agree.mean() > 0.97  # a march can step over the corner of a cell the ray clips
            both = agree & h_row
            # the march overshoots the face by less than one step; it also misses corners clipped by less
            assert np.quantile(np.abs(r_row - ref)[both], 0.98) < 1.1e-3
            assert np.all(r_row[~h_row] == 25.0)


def test_closed_form_in_an_empty_box_for_many_poses():
    # free box with walls at rows/cols 0 and 40: faces at 0.5 and 39.5
    g = make_grid(41, 41, OBSTACLE)
    g[1:40, 1:40] = FREE
    rng = np.random.default_rng(0)
    poses = np.column_stack([rng.uniform(1, 39, 5), rng.uniform(1, 39, 5), rng.uniform(-np.pi, np.pi, 5)])
    ang = np.linspace(0, 2 * np.pi, 361)[:-1]
    r, hit = cast_rays(g, poses, ang, 100.0)
    th = poses[:, 2:3] + ang
    c, s = np.cos(th), np.sin(th)
    x0, y0 = poses[:, :1], poses[:, 1:2]
    with np.errstate(divide="ignore"):
        tx = np.where(c > 0, (39.5 - x0) / c, np.where(c < 0, (0.5 - x0) / c, np.inf))
        ty = np.where(s > 0, (39.5 - y0) / s, np.where(s < 0, (0.5 - y0) / s, np.inf))
    assert hit.all()
    np.testing.assert_allclose(r, np.minimum(tx, ty), atol=1e-9)


def test_one_pose_gives_vectors_and_each_row_of_a_batch_is_that_pose():
    g = _random_room(np.random.default_rng(5))
    poses = np.array([[5.2, 7.9, 0.3], [20.0, 14.5, 2.0], [33.3, 3.3, -1.2]])
    ang = np.linspace(-np.pi, np.pi, 50)
    R, H = cast_rays(g, poses, ang, 30.0)
    for k, p in enumerate(poses):
        r, h = cast_rays(g, p, ang, 30.0)
        assert r.shape == h.shape == (50,)
        assert np.array_equal(r, R[k])
        assert np.array_equal(h, H[k])


def test_range_limit_grid_edge_and_start_cell():
    g = make_grid(10, 10)
    r, hit = cast_rays(g, [5, 5, 0], [0.0, 1.0], 3.0)
    assert not hit.any()
    assert r.tolist() == [3.0, 3.0]
    r, hit = cast_rays(g, [5, 5, 0], [0.0], 30.0)  # leaves the grid: no return
    assert (r.tolist(), hit.tolist()) == ([30.0], [False])
    g[5, 9] = OBSTACLE
    r, hit = cast_rays(g, [5, 5, 0], [0.0], 3.0)  # wall face at 3.5 > max range
    assert not hit[0]
    r, hit = cast_rays(g, [5, 5, 0], [0.0], 3.5)  # exactly at max range counts
    assert hit[0]
    assert r[0] == pytest.approx(3.5)
    r, hit = cast_rays(g, [[9.2, 5.1, 1.0], [-3.0, 5.0, 0.0]], [0.0], 20.0)
    assert (r[0, 0], hit[0, 0]) == (0.0, True)  # a pose inside an obstacle cell: range 0
    assert (r[1, 0], hit[1, 0]) == (20.0, False)  # a pose off the grid: no return


def test_bad_input_names_the_argument():
    g = make_grid(5, 5)
    with pytest.raises(ValueError, match=r"`poses` must have shape \(n, 3\)"):
        cast_rays(g, [[1, 2]], [0.0], 5)
    with pytest.raises(ValueError, match="`poses` must have length 3"):
        cast_rays(g, [1, 2], [0.0], 5)
    with pytest.raises(ValueError, match="`poses` must be finite"):
        cast_rays(g, [1, np.nan, 0], [0.0], 5)
    with pytest.raises(ValueError, match="`angles_rad` must be finite"):
        cast_rays(g, [1, 1, 0], [np.inf], 5)
    with pytest.raises(ValueError, match="`max_range` must be > 0"):
        cast_rays(g, [1, 1, 0], [0.0], 0)
    with pytest.raises(ValueError, match="`grid` must hold only 0"):
        cast_rays(np.full((3, 3), 7), [1, 1, 0], [0.0], 5)
