"""Matching rules (000's 2x rule, ratio, mutual, Hamming) and 2-NN back ends against independent references."""

import cv2
import numpy as np
import pytest
from scipy.spatial import cKDTree

from slamlab.features import (
    accept_000,
    accept_ratio,
    hamming_distances,
    knn2,
    match_descriptors,
    mutual_mask,
)


def _data(seed=0, n=600, m=200, d=64):
    rng = np.random.default_rng(seed)
    T = rng.standard_normal((n, d)).astype(np.float32)
    T /= np.linalg.norm(T, axis=1, keepdims=True)
    Q = T[:m] + 0.05 * rng.standard_normal((m, d)).astype(np.float32)
    return Q, T


@pytest.mark.parametrize("method", ["brute", "kdtree"])
def test_exact_knn2_equals_ckdtree(method):
    Q, T = _data()
    d, i = knn2(Q, T, method=method)
    d_ref, i_ref = cKDTree(T.astype(np.float64)).query(Q.astype(np.float64), k=2)
    np.testing.assert_allclose(d, d_ref, rtol=1e-5)
    np.testing.assert_array_equal(i, i_ref)


def test_bbf_and_flann_are_approximate_but_close():
    Q, T = _data(1, n=3000)
    _, i_ref = knn2(Q, T, method="brute")
    for method in ("bbf", "flann"):
        d, i = knn2(Q, T, method=method, max_leaves=200, checks=200)
        assert np.mean(i[:, 0] == i_ref[:, 0]) > 0.8
        assert np.all(d[:, 0] <= d[:, 1] + 1e-6)


def test_hamming_equals_opencv_bfmatcher():
    rng = np.random.default_rng(2)
    A = rng.integers(0, 256, (50, 32), dtype=np.uint8)
    B = rng.integers(0, 256, (80, 32), dtype=np.uint8)
    D = hamming_distances(A, B)
    np.testing.assert_array_equal(D[3, 5], np.unpackbits(A[3] ^ B[5]).sum())
    bf = cv2.BFMatcher(cv2.NORM_HAMMING)
    ref = bf.knnMatch(A, B, k=2)
    d, _ = knn2(A, B)
    np.testing.assert_array_equal(d[:, 0], [m[0].distance for m in ref])
    np.testing.assert_array_equal(d[:, 1], [m[1].distance for m in ref])


def test_rules():
    dist = np.array([[1.0, 2.0], [1.0, 1.9], [3.0, 9.0], [0.0, 0.0]])
    # literal reading of 000: two zero distances satisfy d(C,B) >= 2 d(C,A); max_dist decides nothing there
    np.testing.assert_array_equal(accept_000(dist), [True, False, True, True])
    np.testing.assert_array_equal(accept_000(dist, max_dist=2.0), [True, False, False, True])
    np.testing.assert_array_equal(accept_ratio(dist, 0.5), [False, False, True, False])
    # 000's rule is Lowe's ratio 0.5 with >= instead of <
    rng = np.random.default_rng(3)
    d = np.sort(rng.random((1000, 2)), axis=1)
    np.testing.assert_array_equal(accept_000(d), accept_ratio(d, 0.5) | (d[:, 1] == 2 * d[:, 0]))


def test_mutual_and_match_descriptors():
    Q, T = _data(4, n=300, m=100)
    m = match_descriptors(Q, T, rule="000")
    assert len(m) > 80
    np.testing.assert_array_equal(m.train_idx, m.query_idx)  # queries are noisy copies of T[:100]
    mm = match_descriptors(Q, T, rule="ratio", ratio=0.8, mutual=True)
    assert set(mm.query_idx) <= set(match_descriptors(Q, T, rule="ratio", ratio=0.8).query_idx)
    np.testing.assert_array_equal(mutual_mask([2, 0, 2], [1, 5, 2]), [False, True, True])


def test_matching_bad_input():
    Q, T = _data(5, n=50, m=5)
    with pytest.raises(ValueError, match="`method` must be one of"):
        knn2(Q, T, method="ann")
    with pytest.raises(ValueError, match="same descriptor length"):
        knn2(Q[:, :10], T)
    with pytest.raises(ValueError, match="`query` must be a 2-D"):
        knn2(Q[0], T)
    with pytest.raises(TypeError, match="both be binary"):
        knn2(np.zeros((2, 64), np.uint8), T)
    with pytest.raises(ValueError, match="binary descriptors are matched with method='brute'"):
        knn2(np.zeros((2, 32), np.uint8), np.zeros((4, 32), np.uint8), method="kdtree")
    with pytest.raises(ValueError, match=r"`dist` must have shape \(M, 2\)"):
        accept_000(np.zeros(3))
    with pytest.raises(ValueError, match="`ratio` must be > 0"):
        accept_ratio(np.zeros((2, 2)), 0.0)
    with pytest.raises(ValueError, match="`rule` must be one of"):
        match_descriptors(Q, T, rule="lowe")
    with pytest.raises(ValueError, match="`query` must be finite"):
        knn2(np.full((2, 64), np.nan), T)
    with pytest.raises(TypeError, match="binary descriptors must be uint8"):
        hamming_distances(np.zeros((2, 4)), np.zeros((2, 4)))
