"""The stereo matching's pair distances in blocks bounded in bytes (issue 45: a student's kernel in 512 MiB)."""

import numpy as np
import pytest

from slamlab.stereo import _pairs
from slamlab.stereo._pairs import pair_distances


def _reference(A, B, ia, ib):
    """Each pair's distance on its own: Euclidean in float32 differences, Hamming by unpacked bits."""
    if A.dtype == np.uint8:
        return np.unpackbits(A[ia] ^ B[ib], axis=1).sum(axis=1).astype(float)
    return np.array([np.sqrt(np.dot(d, d)) for d in (A[ia].astype(np.float32) - B[ib])], dtype=float)


@pytest.mark.parametrize("dim", [64, 128])
def test_float_distances_do_not_depend_on_the_block(dim):
    rng = np.random.default_rng(dim)
    A, B = (rng.standard_normal((n, dim)).astype(np.float32) for n in (300, 280))
    ia, ib = rng.integers(0, 300, 5000), rng.integers(0, 280, 5000)
    whole = pair_distances(A, B, ia, ib, block=ia.size)
    for block in (1, 7, 1024, None):
        assert np.array_equal(pair_distances(A, B, ia, ib, block=block), whole)
    np.testing.assert_allclose(whole, _reference(A, B, ia, ib), rtol=1e-5)


def test_hamming_distances_do_not_depend_on_the_block():
    rng = np.random.default_rng(3)
    A, B = (rng.integers(0, 256, (n, 32), dtype=np.uint8) for n in (200, 150))
    ia, ib = rng.integers(0, 200, 3000), rng.integers(0, 150, 3000)
    for block in (1, 100, None):
        assert np.array_equal(pair_distances(A, B, ia, ib, block=block), _reference(A, B, ia, ib))


def test_the_default_block_of_sift_pairs_stays_within_the_byte_bound(monkeypatch):
    # 128-d float32 rows (512 bytes): 2^22 / 512 = 8192 pairs per block, 4 MiB per gathered side (the former
    # 2^16 pairs held 32 MiB per array); ORB's 32-byte rows keep the former 2^16
    assert _pairs._block_rows(np.zeros((1, 128), np.float32)) == 8192
    assert _pairs._block_rows(np.zeros((1, 64), np.float32)) == 16384
    assert _pairs._block_rows(np.zeros((1, 32), np.uint8)) == 1 << 16
    monkeypatch.setattr(_pairs, "PAIR_BLOCK_BYTES", 1 << 12)  # 8 rows of 512 bytes: many blocks, same distances
    rng = np.random.default_rng(5)
    A = rng.standard_normal((50, 128)).astype(np.float32)
    ia, ib = rng.integers(0, 50, 1001), rng.integers(0, 50, 1001)
    assert _pairs._block_rows(A) == 8
    assert np.array_equal(pair_distances(A, A, ia, ib), pair_distances(A, A, ia, ib, block=ia.size))
