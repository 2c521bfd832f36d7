"""002's compression claim: the counts and bytes of the raw clouds and of the plane map (ours: the measure)."""

import numpy as np
import pytest

from slamlab.planes import Plane, PlaneMap, describe_plane, extract_planes
from slamlab.studies.planes import flight_frames, flight_storage, map_storage, run_flight
from slamlab.studies.planes.experiments import flight_or_simulate


def _hand_map():
    """Two planes of 3 and 2 cells and 5 points on no plane in 4 voxels (0.1 m): counts known by hand."""
    m = PlaneMap(voxel_m=0.1)
    m.planes.append(Plane.from_cells(np.array([0, 0, 1.0]), 1.0, np.eye(4), 0.25, [[0, 0], [0, 1], [3, 3]],
                                     [2, 1, 4], [20.0, 5.0, 8.0]))
    m.planes.append(Plane.from_cells(np.array([1.0, 0, 0]), 2.0, np.eye(4), 0.25, [[-1, 0], [-1, 1]],
                                     [1, 1], [3.0, 4.0]))
    m.voxels.add([[0.01, 0.01, 0.01], [0.02, 0.02, 0.02], [0.15, 0.0, 0.0], [0.0, 0.15, 0.0], [0.0, 0.0, 0.15]])
    return m


def test_hand_made_bytes():
    s = map_storage(_hand_map(), [100, 60], [7, 3])
    assert (s.n_frames, s.raw_points, s.off_plane_points) == (2, 160, 10)
    assert (s.n_planes, s.n_cells, s.n_voxels, s.voxel_points) == (2, 5, 4, 5)
    # 160 points x (x, y, z, I) x 4 bytes; 2 planes x 21 values + 5 cells x 4 values; 10 points x 4 values
    assert s.raw_bytes() == 160 * 16 == 2560
    assert s.plane_bytes() == (2 * 21 + 5 * 4) * 4 == 248
    assert s.off_plane_bytes() == 10 * 16 == 160
    assert s.voxel_bytes() == 4 * 16 == 64
    assert s.ratio() == pytest.approx(2560 / (248 + 160))
    assert s.ratio(voxels=True) == pytest.approx(2560 / (248 + 64))
    # cells merged 2 x 2: (0,0) and (0,1) fall in one block, (3,3) in another; (-1,0), (-1,1) in one: 3 cells
    assert dict(s.merged_cells)[2] == 3
    # 8-byte values double every item: the same ratio
    s8 = map_storage(_hand_map(), [100, 60], [7, 3], bytes_per_value=8)
    assert s8.raw_bytes() == 2 * s.raw_bytes()
    assert s8.plane_bytes() == 2 * s.plane_bytes()
    assert s8.ratio() == pytest.approx(s.ratio())
    # numpy as held: per plane n (24) + T (128) + p and cell side (16) + per cell ij (16), N (8), sum (8),
    # key (8), mean (8); voxels: 3 keys (24) + count (8) each
    assert s.held_bytes == 2 * (24 + 128 + 16) + 5 * 48 + 4 * 32
    tab = s.table()
    assert "ratio raw / (plane map + points on no plane)" in tab
    assert f"{2560 / (248 + 160):.1f}" in tab
    assert "2 x 2 cells merged" in tab
    assert "6.3" in str(s)     # 2560 / 408 = 6.27


def test_merged_cells_equal_a_coarser_description():
    # an independent count: describing the same points with a cell twice (four times) as wide
    rng = np.random.default_rng(5)
    pts = np.c_[rng.uniform(-3, 3, (4000, 2)), np.full(4000, 1.0)]
    keep = np.hypot(pts[:, 0] - 1, pts[:, 1]) > 1.2            # a hole: the block count is not just the area
    pts = pts[keep]
    fine = describe_plane(pts, np.ones(len(pts)), [0, 0, 1.0], 1.0, cell_m=0.25, incidence_correction=False)
    m = PlaneMap()
    m.planes.append(fine)
    s = map_storage(m, [len(pts)], [0], merge_factors=(2, 4))
    for f, cells in s.merged_cells:
        coarse = describe_plane(pts, np.ones(len(pts)), [0, 0, 1.0], 1.0, cell_m=0.25 * f,
                                incidence_correction=False)
        assert cells == len(coarse.ij)
    assert "(2 x 2 cells merged)" in s.table()
    assert "(4 x 4 cells merged)" in s.table()


def test_storage_bad_input():
    m = _hand_map()
    with pytest.raises(TypeError, match="plane_map"):
        map_storage([], [1], [0])
    with pytest.raises(ValueError, match="frame_points"):
        map_storage(m, [], [])
    with pytest.raises(ValueError, match="frame_points"):
        map_storage(m, [1.5], [0])
    with pytest.raises(ValueError, match="frame_off_plane"):
        map_storage(m, [10, 10], [11, 0])
    with pytest.raises(ValueError, match="frame_off_plane"):
        map_storage(m, [10, 10], [1])
    with pytest.raises(ValueError, match="bytes_per_value"):
        map_storage(m, [10], [1], bytes_per_value=2)
    with pytest.raises(TypeError, match="bytes_per_value"):
        map_storage(m, [10], [1], bytes_per_value=4.0)
    with pytest.raises(ValueError, match="merge_factors"):
        map_storage(m, [10], [1], merge_factors=(1,))
    with pytest.raises(TypeError, match="result"):
        flight_storage(m)


def test_flight_counts_match_the_frames_and_the_voxel_store():
    fl = run_flight(4.0, rng=0, n_particles=50)
    s = flight_storage(fl)
    flight = flight_or_simulate(None, 4.0, 0)                     # the flight run_flight simulated
    sizes = [len(fr) for _, fr, _, _ in flight_frames(flight)]
    np.testing.assert_array_equal(s.frame_points, sizes)          # the frames' own sizes
    assert np.all((s.frame_off_plane >= 0) & (s.frame_off_plane < s.frame_points))
    # the filter puts every `thin`-th point on no plane into the voxel store: the same count, frame by frame
    thin = fl.params.thin
    assert s.voxel_points == int(np.sum(-(-s.frame_off_plane // thin)))
    assert s.raw_points == sum(sizes)
    assert s.n_planes == len(fl.map)
    assert s.n_cells == sum(len(pl.ij) for pl in fl.map.planes)


def test_points_of_a_rejected_narrow_plane_stay_on_no_plane():
    # a wide floor and a narrow band (0.2 m) of a wall: the band is dropped by `min_width_m`; its points must
    # come back as points on no plane (every point: on exactly one plane, or on none)
    rng = np.random.default_rng(0)
    floor = np.c_[rng.uniform(-2, 2, (3000, 2)), np.zeros(3000)]
    band = np.c_[np.full(800, 2.5), rng.uniform(-2, 2, 800), rng.uniform(1.0, 1.2, 800)]
    X = np.concatenate([floor, band])
    found, leftover = extract_planes(X, tolerance_m=0.01, min_support=300, min_width_m=0.6, rng=1)
    assert len(found) == 1
    on_plane = np.zeros(len(X), int)
    for _, _, idx in found:
        on_plane[idx] += 1
    np.testing.assert_array_equal(on_plane + leftover, np.ones(len(X)))
    assert leftover[3000:].all()
    assert not leftover[:3000].any()
