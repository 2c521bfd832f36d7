"""The compiled two-nearest kernels for binary descriptors against their numpy versions (issue 25): the window
search (our addition to 000 §3.4), the stereo matching's epipolar pairs (000 §3.3) and the brute-force search of
the last frame's landmarks; same nearest / second nearest, distances and pair counts, bit for bit, ties included."""

import numpy as np
import pytest

from slamlab._compiled import numba_enabled
from slamlab.kdtree.knn import exact_knn
from slamlab.stereo._pairs import pair_distances, pairs_two_nearest, two_nearest
from slamlab.stereo.local_stages import _epipolar_two_nearest, epipolar_pairs
from slamlab.stereo.map_stages import _radius_pairs, _window_two_nearest


@pytest.mark.skipif(not numba_enabled(), reason="numba disabled (SLAMLAB_NO_NUMBA)")
@pytest.mark.parametrize("trial", range(6))
def test_window_kernel_matches_numpy(trial):
    rng = np.random.default_rng(trial)
    k, n = int(rng.integers(1, 1500)), int(rng.integers(1, 2500))
    D = rng.integers(0, 256, (k, 32), dtype=np.uint8)
    Dt = rng.integers(0, 256, (n, 32), dtype=np.uint8)
    if trial % 3 == 0:  # many equal distances: the first in the numpy order must win both ranks
        Dt[: n // 2] = Dt[0]
        D[: k // 2] = D[0]
    uv = rng.uniform(0, 768, (k, 2))
    uv_t = rng.uniform(-20, 790, (n, 2))
    if trial % 2:  # whole pixels: pairs exactly at the radius
        uv, uv_t = np.round(uv), np.round(uv_t)
    qi, rows = _radius_pairs(uv, uv_t, 15.0)
    q, r1, d1, d2, r2, n_pairs = _window_two_nearest(D, uv, Dt, uv_t, 15.0)
    assert n_pairs == qi.size
    ref = two_nearest(qi, rows, pair_distances(D, Dt, qi, rows))
    for a, b in zip(ref, (q, r1, d1, d2, r2), strict=True):
        np.testing.assert_array_equal(a, b)


def test_window_numpy_path_without_numba(monkeypatch):
    monkeypatch.setenv("SLAMLAB_NO_NUMBA", "1")
    uv = np.array([[10.0, 10.0], [100.0, 100.0]])
    D = np.zeros((2, 32), np.uint8)
    Dt = np.zeros((2, 32), np.uint8)
    Dt[1, 0] = 0b111
    q, r1, d1, d2, r2, n_pairs = _window_two_nearest(D, uv, Dt, np.array([[12.0, 10.0], [11.0, 11.0]]), 15.0)
    assert q.tolist() == [0]
    assert (r1.tolist(), d1.tolist(), d2.tolist(), r2.tolist(), n_pairs) == ([0], [0.0], [3.0], [1], 2)


def _random_descriptors(rng, k, n, trial, n_bytes=32):
    D = rng.integers(0, 256, (k, n_bytes), dtype=np.uint8)
    Dt = rng.integers(0, 256, (n, n_bytes), dtype=np.uint8)
    if trial % 3 == 0 and n:  # many equal distances: the first in the numpy order must win both ranks
        Dt[: n // 2] = Dt[0]
        D[: k // 2] = D[0]
    return D, Dt


@pytest.mark.skipif(not numba_enabled(), reason="numba disabled (SLAMLAB_NO_NUMBA)")
@pytest.mark.parametrize("trial", range(6))
def test_stereo_kernel_matches_numpy(trial):
    """The stereo matching's two nearest over the epipolar pairs (000 §3.3): kernel = numpy, ties included."""
    rng = np.random.default_rng(100 + trial)
    k, n = int(rng.integers(1, 1500)), int(rng.integers(1, 1500))
    D, Dt = _random_descriptors(rng, k, n, trial)
    uv_l = rng.uniform(0, 576, (k, 2))
    uv_r = np.round(rng.uniform(0, 576, (n, 2))) if trial % 2 else rng.uniform(0, 576, (n, 2))
    F = np.array([[0.0, 0.0, 0.0], [0.0, 0.0, -1.0], [0.0, 1.0, 0.0]])  # rectified: the epipolar lines are rows
    qi, ti = epipolar_pairs(uv_l, uv_r, F, 2.0)
    ref = two_nearest(qi, ti, pair_distances(D, Dt, qi, ti))
    for a, b in zip(ref, pairs_two_nearest(D, Dt, qi, ti), strict=True):
        np.testing.assert_array_equal(a, b)


@pytest.mark.skipif(not numba_enabled(), reason="numba disabled (SLAMLAB_NO_NUMBA)")
@pytest.mark.parametrize("trial", range(8))
def test_fused_epipolar_kernel_matches_numpy(trial):
    """The stereo matching in one pass (epipolar test + two nearest, 000 §3.3) = epipolar_pairs, then the
    numpy two nearest of their Hamming distances: same queries, nearest, second and distances, ties included;
    on a rectified rig, a slightly rotated one (lines not quite rows: the distance test decides) and, for the
    numpy path, steep lines."""
    rng = np.random.default_rng(200 + trial)
    k, n = int(rng.integers(1, 1500)), int(rng.integers(1, 1500))
    D, Dt = _random_descriptors(rng, k, n, trial)
    uv_l = rng.uniform(0, 576, (k, 2))
    uv_r = np.round(rng.uniform(0, 576, (n, 2))) if trial % 2 else rng.uniform(0, 576, (n, 2))
    if trial % 4 == 3:  # whole-pixel rows on both sides: distances exactly at the tolerance
        uv_l = np.round(uv_l)
    F = np.array([[0.0, 0.0, 0.0], [0.0, 0.0, -1.0], [0.0, 1.0, 0.0]])  # rectified: the epipolar lines are rows
    if trial >= 4:  # a small rotation about the optical axis: tilted lines
        e = 0.01 * (trial - 3)
        F = F @ np.array([[np.cos(e), -np.sin(e), 0.0], [np.sin(e), np.cos(e), 0.0], [0.0, 0.0, 1.0]])
    qi, ti = epipolar_pairs(uv_l, uv_r, F, 2.0)
    ref = two_nearest(qi, ti, pair_distances(D, Dt, qi, ti))
    for a, b in zip(ref, _epipolar_two_nearest(D, Dt, uv_l, uv_r, F, 2.0), strict=True):
        np.testing.assert_array_equal(a, b)


def test_fused_epipolar_numpy_paths(monkeypatch):
    """Steep epipolar lines (every pair a candidate) and numba off: epipolar_pairs + the two nearest."""
    D = np.zeros((2, 32), np.uint8)
    Dt = np.zeros((3, 32), np.uint8)
    Dt[1, 0] = 0b111
    uv_l = np.array([[5.0, 10.0], [50.0, 20.0]])
    uv_r = np.array([[4.0, 300.0], [5.0, 100.0], [90.0, 20.0]])
    F_cols = np.array([[0.0, 0.0, 1.0], [0.0, 0.0, 0.0], [-1.0, 0.0, 0.0]])  # lines are columns: u_r = u_l
    out = _epipolar_two_nearest(D, Dt, uv_l, uv_r, F_cols, 1.5)  # left 0: right 0 (1 px off, Hamming 0) and 1 (3)
    assert [x.tolist() for x in out] == [[0], [0], [0.0], [3.0], [1]]
    monkeypatch.setenv("SLAMLAB_NO_NUMBA", "1")
    F_rows = np.array([[0.0, 0.0, 0.0], [0.0, 0.0, -1.0], [0.0, 1.0, 0.0]])
    out = _epipolar_two_nearest(D, Dt, uv_l, uv_r, F_rows, 1.5)  # left 1: right 2 on its row, alone
    assert [x.tolist() for x in out] == [[1], [2], [0.0], [np.inf], [-1]]


@pytest.mark.skipif(not numba_enabled(), reason="numba disabled (SLAMLAB_NO_NUMBA)")
@pytest.mark.parametrize(("n", "n_bytes"), [(0, 32), (1, 32), (2, 32), (900, 32), (900, 8), (333, 64)])
def test_brute_force_kernel_matches_exact_knn(n, n_bytes, monkeypatch):
    """exact_knn's binary 2-NN (the search of the last frame's landmarks, the ORB stores): the kernel = OpenCV's
    batchDistance (the numpy path), ties included, for descriptors of 1, 4 and 8 words."""
    rng = np.random.default_rng(n)
    D, Dt = _random_descriptors(rng, 700, n, 0, n_bytes)
    ids = rng.permutation(5 * n + 1)[:n] + 3
    compiled = exact_knn(D, Dt, 2, ids)
    monkeypatch.setenv("SLAMLAB_NO_NUMBA", "1")
    for a, b in zip(exact_knn(D, Dt, 2, ids), compiled, strict=True):
        np.testing.assert_array_equal(a, b)


def test_numpy_paths_without_numba(monkeypatch):
    monkeypatch.setenv("SLAMLAB_NO_NUMBA", "1")
    D = np.zeros((2, 32), np.uint8)
    Dt = np.zeros((3, 32), np.uint8)
    Dt[1, 0] = 0b111
    q, r1, d1, d2, r2 = pairs_two_nearest(D, Dt, np.array([1, 1]), np.array([1, 2]))
    assert (q.tolist(), r1.tolist(), d1.tolist(), d2.tolist(), r2.tolist()) == ([1], [2], [0.0], [3.0], [1])
    dist, ids = exact_knn(D, Dt, 2, np.array([5, 6, 7]))
    assert dist.tolist() == [[0.0, 0.0]] * 2
    assert ids.tolist() == [[5, 7]] * 2


@pytest.mark.skipif(not numba_enabled(), reason="numba disabled (SLAMLAB_NO_NUMBA)")
@pytest.mark.parametrize(("half_px", "search_px"), [(5, 4), (1, 1), (2, 3), (3, 6), (4, 2), (6, 4)])
def test_subpixel_kernel_matches_numpy(half_px, search_px, monkeypatch):
    """The sub-pixel disparity refinement (our addition to 000 §3.3) with its patch costs compiled = the numpy
    version, bit for bit: refined right keypoints and masks, on random images and on smooth ones (many equal
    costs); a 13 x 13 patch (more terms than the kernel's summation order covers) takes numpy either way."""
    from slamlab.stereo._sad_kernel import sad_costs
    from slamlab.stereo.local_stages import _subpixel_disparity

    rng = np.random.default_rng(10 * half_px + search_px)
    H, W = 120, 160
    noise = rng.integers(0, 256, (2, H, W)).astype(np.uint8)
    yy, xx = np.mgrid[0:H, 0:W]
    smooth = np.stack([(xx * 3 + yy) % 256, (xx * 3 + yy + 7) % 256]).astype(np.uint8)
    m = 3000
    uvl = np.column_stack([rng.uniform(-2, W + 1, m), rng.uniform(-2, H + 1, m)])
    uvr = uvl - np.column_stack([rng.uniform(0, 30, m), np.zeros(m)])
    uvl[:50] = np.round(uvl[:50]) + 0.5  # halfway columns: np.rint's ties
    for IL, IR in (noise, smooth):
        compiled = _subpixel_disparity(IL, IR, uvl, uvr, half_px, search_px)
        with monkeypatch.context() as mp:
            mp.setenv("SLAMLAB_NO_NUMBA", "1")
            ref = _subpixel_disparity(IL, IR, uvl, uvr, half_px, search_px)
        assert compiled[2].sum() > (m // 4 if IL is noise[0] else 0)  # the ramp: equal costs, mostly at an end
        for a, b in zip(ref, compiled, strict=True):
            np.testing.assert_array_equal(a, b)
    # the costs themselves, against the numpy expression
    from numpy.lib.stride_tricks import sliding_window_view

    if (2 * half_px + 1) ** 2 <= 128:
        IL, IR = noise
        h, s, P = half_px, search_px, 2 * half_px + 1
        r = rng.integers(h, H - h, 500)
        c = rng.integers(h, W - h, 500)
        cr = rng.integers(h + s, W - h - s, 500)
        lp = sliding_window_view(IL, (P, P))[r - h, c - h].astype(np.float32)
        lp -= lp.mean(axis=(1, 2), keepdims=True)
        strip = sliding_window_view(IR, (P, P + 2 * s))[r - h, cr - h - s].astype(np.float32)
        ref = np.stack([np.abs(lp - (strip[:, :, k:k + P] - strip[:, :, k:k + P].mean(axis=(1, 2), keepdims=True)))
                        .sum(axis=(1, 2)) for k in range(2 * s + 1)], axis=1)
        np.testing.assert_array_equal(sad_costs(IL, IR, r, c, cr, h, s), ref)


@pytest.mark.parametrize("trial", range(6))
def test_radius_cells_ranges_and_pairs(trial):
    """The window search's grid (our addition to 000 §3.4): each query's 3 column ranges are where the cells'
    keys sit in the sorted keys (as np.searchsorted finds them), and the pairs within the radius are exactly those
    of a brute-force distance test, grouped by ascending query."""
    from slamlab.stereo.map_stages import _radius_cells

    rng = np.random.default_rng(300 + trial)
    k, n = int(rng.integers(1, 300)), int(rng.integers(1, 500))
    uv, uv_t = rng.uniform(-20, 700, (k, 2)), rng.uniform(-20, 700, (n, 2))
    if trial % 2:  # whole pixels: pairs exactly at the radius
        uv, uv_t = np.round(uv), np.round(uv_t)
    radius = (15.0, 7.5, 40.0)[trial % 3]
    order, lo, hi = _radius_cells(uv, uv_t, radius)
    lo_xy = np.minimum(uv.min(axis=0), uv_t.min(axis=0))
    cq, ct = (np.floor((p - lo_xy) / radius).astype(np.int64) for p in (uv, uv_t))
    ny = int(max(cq[:, 1].max(), ct[:, 1].max())) + 3
    keys = ((ct[:, 0] + 1) * ny + ct[:, 1] + 1)[order]
    base = (cq[:, 0:1] + 1 + np.arange(-1, 2)) * ny + cq[:, 1:2] + 1
    np.testing.assert_array_equal(lo, np.searchsorted(keys, base - 1, side="left"))
    np.testing.assert_array_equal(hi, np.searchsorted(keys, base + 1, side="right"))
    qi, ti = _radius_pairs(uv, uv_t, radius)
    d2 = ((uv[:, None, :] - uv_t[None, :, :]) ** 2).sum(axis=2)
    assert np.all(np.diff(qi) >= 0)
    assert sorted(zip(qi.tolist(), ti.tolist(), strict=True)) == sorted(zip(*np.nonzero(d2 <= radius**2), strict=True))
