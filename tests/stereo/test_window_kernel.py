"""The compiled window search for binary descriptors against its numpy version (our addition to 000 §3.4;
issue 25): same nearest / second nearest, distances and pair counts, bit for bit, ties included."""

import numpy as np
import pytest

from slamlab._compiled import numba_enabled
from slamlab.stereo.local_stages import _pair_distances, _two_nearest
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
    ref = _two_nearest(qi, rows, _pair_distances(D, Dt, qi, rows))
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
