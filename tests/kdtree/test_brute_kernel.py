"""The compiled top-c selection of the blocked brute force against the numpy path (issue 25)."""

import numpy as np
import pytest

from slamlab import _threads
from slamlab._compiled import numba_enabled
from slamlab._threads import blas_one_thread, blas_threads_settable
from slamlab.kdtree import _brute_kernel as _brute
from slamlab.kdtree import knn
from slamlab.kdtree._brute_kernel import top_c_blocks, update_top_c
from slamlab.kdtree.stores import BruteForceStore


def _both(Q, X, k, block=None):
    """(numpy path, compiled path) of the float exact k-NN, with the same blocks."""
    kk = min(k, X.shape[0])
    return (knn._exact_knn_float(Q, X, kk, block=block), knn._exact_knn_float_compiled(Q, X, kk, block=block))


def _reference(Q, X, k):
    """Full float64 distance matrix, sorted by (distance, index)."""
    X64 = X.astype(np.float64)
    D = np.array([np.sqrt(((q - X64) ** 2).sum(-1)) for q in Q.astype(np.float64)])  # one query at a time
    o = np.lexsort((np.broadcast_to(np.arange(X.shape[0]), D.shape), D), axis=1)[:, :k]
    return np.take_along_axis(D, o, axis=1), o


@pytest.mark.parametrize("k", [1, 2])
@pytest.mark.parametrize("block", [None, 512, 700])
def test_compiled_equals_numpy_on_random_float32(k, block):
    rng = np.random.default_rng(k * 1000 + (block or 0))
    X = rng.standard_normal((5000, 16)).astype(np.float32)
    Q = rng.standard_normal((300, 16)).astype(np.float32)
    (d0, i0), (d1, i1) = _both(Q, X, k, block)
    np.testing.assert_array_equal(i1, i0)
    np.testing.assert_array_equal(d1, d0)  # same candidates, same float64 recomputation: bit-for-bit
    d_ref, i_ref = _reference(Q, X, k)
    np.testing.assert_array_equal(i1, i_ref)
    np.testing.assert_allclose(d1, d_ref, rtol=1e-12)


@pytest.mark.parametrize("k", [1, 2])
def test_duplicates_and_ties_keep_the_lowest_index(k):
    rng = np.random.default_rng(7)
    base = rng.integers(0, 3, (40, 4)).astype(np.float32)  # a coarse grid: many equal distances
    X = base[rng.integers(0, 40, 3000)]  # every point many times over, spread across blocks
    Q = np.vstack([X[:50], rng.integers(0, 3, (50, 4)).astype(np.float32) + 0.5])
    (d0, i0), (d1, i1) = _both(Q, X, k, block=512)
    _d_ref, i_ref = _reference(Q, X, k)
    np.testing.assert_array_equal(i1, i_ref)  # ties: lowest database index first
    np.testing.assert_array_equal(i0, i_ref)
    np.testing.assert_array_equal(d1, d0)


@pytest.mark.parametrize("n", [1, 2])
def test_fewer_points_than_k(n):
    rng = np.random.default_rng(n)
    X = rng.standard_normal((n, 8)).astype(np.float32)
    Q = rng.standard_normal((5, 8)).astype(np.float32)
    s = BruteForceStore()
    s.add(X, np.arange(n) + 10)
    d, i = s.query(Q, 2)
    d_ref, i_ref = _reference(Q, X, n)
    np.testing.assert_array_equal(i[:, :n], i_ref + 10)
    np.testing.assert_allclose(d[:, :n], d_ref, rtol=1e-12)
    assert np.all(i[:, n:] == -1)
    assert np.all(np.isinf(d[:, n:]))
    (d0, i0), (d1, i1) = _both(Q, X, 2)
    np.testing.assert_array_equal(i1, i0)
    np.testing.assert_array_equal(d1, d0)


def test_kernel_one_block_by_hand():
    G = np.array([[3.0, 1.0, 2.0, 1.0, 0.5], [9.0, 9.0, 9.0, 9.0, 9.0]], np.float32)
    key = np.full((2, 3), np.inf, np.float32)
    idx = np.full((2, 3), -1, np.int64)
    update_top_c(G, 100, key, idx, 0, 2)
    assert idx.tolist() == [[104, 101, 103], [100, 101, 102]]
    assert key.tolist() == [[0.5, 1.0, 1.0], [9.0, 9.0, 9.0]]
    update_top_c(np.array([[1.0, 0.0]], np.float32), 200, key[:1], idx[:1], 0, 1)  # equal key: stays out
    assert idx[0].tolist() == [201, 104, 101]


@pytest.mark.parametrize("b", [1, 63, 64, 65, 130, 262])
def test_kernel_equals_a_sort_across_chunk_edges(b):
    # by definition: the c smallest finite keys seen so far, ordered by (key, database index); keys drawn from a few
    # values (many ties), some +inf and NaN (never kept), over several blocks whose width b crosses the 64-key chunks
    rng = np.random.default_rng(b)
    c, M = 3, 40
    key = np.full((M, c), np.inf, np.float32)
    idx = np.full((M, c), -1, np.int64)
    seen = []
    for s0 in range(0, 4 * b, b):
        G = rng.integers(0, 6, (M, b)).astype(np.float32) - 0.5 * (s0 // b)  # later blocks smaller: more inserts
        G[rng.random((M, b)) < 0.05] = np.inf
        G[rng.random((M, b)) < 0.05] = np.nan
        update_top_c(G, s0, key, idx, 0, M)
        seen.append(G)
    allk = np.hstack(seen)
    for i in range(M):
        j = np.flatnonzero(np.isfinite(allk[i]))
        o = j[np.lexsort((j, allk[i, j]))][:c]
        assert idx[i].tolist() == o.tolist() + [-1] * (c - o.size)
        np.testing.assert_array_equal(key[i, :o.size], allk[i, o])


def test_store_rejects_nan_as_before():
    s = BruteForceStore()
    s.add(np.zeros((3, 4), np.float32), [0, 1, 2])
    with pytest.raises(ValueError, match="`X` must be finite"):
        s.add(np.full((1, 4), np.nan), [3])
    with pytest.raises(ValueError, match="`Q` must be finite"):
        s.query(np.full((1, 4), np.nan))


def test_numpy_path_under_no_numba(monkeypatch):
    rng = np.random.default_rng(3)
    X = rng.standard_normal((900, 8)).astype(np.float32)
    Q = rng.standard_normal((20, 8)).astype(np.float32)
    d1, i1 = knn.exact_knn(Q, X, 2)
    monkeypatch.setenv("SLAMLAB_NO_NUMBA", "1")
    d0, i0 = knn.exact_knn(Q, X, 2)
    np.testing.assert_array_equal(i1, i0)
    np.testing.assert_array_equal(d1, d0)


def test_overflowing_keys_fall_back_to_numpy():
    X = np.array([[0.0, 0.0], [1.0, 0.0], [3e19, 0.0]], np.float32)  # |x|²/2 overflows float32: key inf
    Q = np.array([[0.5, 0.0], [2e19, 0.0]], np.float32)
    with np.errstate(over="ignore", invalid="ignore"):  # the overflow itself (both paths)
        (d0, i0), (d1, i1) = _both(Q, X, 2)
    np.testing.assert_array_equal(i1, i0)
    np.testing.assert_array_equal(d1, d0)


@pytest.mark.parametrize("block", [128, 300])
def test_two_workers_equal_one_worker_and_numpy(block):
    rng = np.random.default_rng(block)
    X = rng.standard_normal((5000, 16)).astype(np.float32)
    Q = rng.standard_normal((101, 16)).astype(np.float32)
    d2, i2 = knn._exact_knn_float_compiled(Q, X, 2, block=block, workers=2)
    d1, i1 = knn._exact_knn_float_compiled(Q, X, 2, block=block, workers=1)
    d0, i0 = knn._exact_knn_float(Q, X, 2)
    np.testing.assert_array_equal(i2, i1)
    np.testing.assert_array_equal(d2, d1)
    np.testing.assert_array_equal(i2, i0)
    np.testing.assert_array_equal(d2, d0)


def test_two_workers_ties_across_blocks_keep_the_lowest_index():
    # integer coordinates: every key is exact in float32 whatever the product's order, so the candidate lists
    # of one and two workers must agree entry for entry; every point recurs in many blocks of both workers
    rng = np.random.default_rng(5)
    base = rng.integers(0, 3, (40, 4)).astype(np.float32)
    X = base[rng.integers(0, 40, 6000)]
    Q = np.vstack([X[:60], rng.integers(0, 3, (40, 4)).astype(np.float32) + 0.5])
    Qa, Xa = knn._query_rows(Q), knn.augment_rows(X)
    for _ in range(3):  # which worker takes which block varies from run to run; the result must not
        np.testing.assert_array_equal(_brute.top_c_blocks(Qa, Xa, 3, 128, 2), _brute.top_c_blocks(Qa, Xa, 3, 128, 1))
    _d_ref, i_ref = _reference(Q, X, 2)
    np.testing.assert_array_equal(knn._exact_knn_float_compiled(Q, X, 2, block=128, workers=2)[1], i_ref)


@pytest.mark.skipif(not numba_enabled(), reason="SLAMLAB_NO_NUMBA: the store takes the numpy path")
def test_store_takes_two_workers_for_large_problems(monkeypatch):
    rng = np.random.default_rng(9)
    X = rng.standard_normal((3000, 8)).astype(np.float32)
    Q = rng.standard_normal((300, 8)).astype(np.float32)  # 900 000 keys: two workers by default
    s = BruteForceStore()
    s.add(X, np.arange(3000) + 7)
    calls = []
    monkeypatch.setattr(_brute, "top_c_blocks", lambda *a: calls.append(a[-1]) or top_c_blocks(*a))
    with monkeypatch.context() as m:
        m.setattr(knn, "_TWO_WORKERS_MIN_KEYS", 1 << 62)
        d1, i1 = s.query(Q, 2)
    d2, i2 = s.query(Q, 2)
    assert calls == [1, 2 if blas_threads_settable() else 1]
    np.testing.assert_array_equal(i2, i1)
    np.testing.assert_array_equal(d2, d1)


@pytest.mark.skipif(not blas_threads_settable(), reason="numpy's BLAS thread count cannot be set here")
def test_blas_one_thread_nests_and_restores():
    get = _threads._openblas_threads()[0]
    before = get()
    with blas_one_thread():
        assert get() == 1
        with blas_one_thread():
            assert get() == 1
        assert get() == 1
    assert get() == before
