"""Landmark stores: 000's invariant after every add, exactness against cKDTree, the base rule, BBF recall."""

import numpy as np
import pytest
from scipy.spatial import cKDTree

from slamlab.kdtree.knn import exact_knn
from slamlab.kdtree.stores import (
    BruteForceStore,
    FlannStore,
    MultiKDTree,
    NonBaseBuffer,
    RebuildStore,
    make_store,
    merge_knn,
    multi_tree_sizes,
)
from slamlab.studies.kdtree.workloads import surf_like_descriptors


def _exact(X, Q, k=2):
    return cKDTree(X.astype(np.float64)).query(Q.astype(np.float64), k=k)


@pytest.mark.parametrize(("n1", "q"), [(4, 2.0), (10, 1.5), (25, 5.5), (7, 3.3)])
def test_multi_invariant_after_every_add(n1, q):
    rng = np.random.default_rng(n1)
    mt = MultiKDTree(n1, q, tree="ckdtree")
    total = 0
    for _ in range(120):
        b = int(rng.integers(1, 3 * n1))
        mt.add(rng.random((b, 3)), np.arange(total, total + b))
        total += b
        assert mt.check_invariant()
        sizes, maxs = mt.sizes, mt.max_sizes
        assert sum(sizes) == total == len(mt)
        # independent restatement of 000's invariant
        for i, s in enumerate(sizes):
            assert s <= np.floor(n1 * q ** i + 1e-9)
            assert s == 0 or i == 0 or s > np.floor(n1 * q ** (i - 1) + 1e-9)
        assert np.floor(n1 * q ** (len(maxs) - 1) + 1e-9) >= total


def test_multi_one_batch_larger_than_several_trees():
    mt = MultiKDTree(10, 2.0, tree="ckdtree")
    mt.add(np.random.default_rng(0).random((75, 2)), np.arange(75))
    assert mt.sizes == [0, 0, 0, 75]
    assert mt.check_invariant()


@pytest.mark.parametrize("tree", ["ckdtree", "exact"])
def test_multi_exact_equals_ckdtree_over_all_points(tree):
    rng = np.random.default_rng(3)
    mt = MultiKDTree(50, 2.5, tree=tree, leaf_size=4)
    X = rng.standard_normal((1500, 8)).astype(np.float32)
    for s in range(0, 1500, 130):
        mt.add(X[s:s + 130], np.arange(s, min(s + 130, 1500)) + 7)
    assert mt.n_trees >= 2
    Q = rng.standard_normal((200, 8)).astype(np.float32)
    d, i = mt.query(Q)
    d_ref, i_ref = _exact(X, Q)
    np.testing.assert_allclose(d, d_ref, rtol=1e-5, atol=1e-6)
    np.testing.assert_array_equal(i, i_ref + 7)
    assert mt.counters.trees_searched == mt.n_trees


def test_multi_bbf_unlimited_checks_equals_exact():
    rng = np.random.default_rng(4)
    X = rng.standard_normal((800, 6)).astype(np.float32)
    mt = MultiKDTree(40, 3.0, tree="bbf", leaf_size=4, checks=10**6)
    for s in range(0, 800, 100):
        mt.add(X[s:s + 100], np.arange(s, s + 100))
    Q = rng.standard_normal((100, 6)).astype(np.float32)
    _d, i = mt.query(Q)
    np.testing.assert_array_equal(i, _exact(X, Q)[1])


@pytest.mark.parametrize("tree", ["ckdtree", "exact", "brute"])
def test_rebuild_store_exact(tree):
    rng = np.random.default_rng(5)
    X = rng.random((600, 5)).astype(np.float32)
    s = RebuildStore(tree=tree, leaf_size=3, base_seen_times=1)
    s.add(X[:300], np.arange(300))
    s.end_iteration()
    s.add(X[300:], np.arange(300, 600))
    s.end_iteration()
    Q = rng.random((80, 5)).astype(np.float32)
    d, i = s.query(Q)
    d_ref, i_ref = _exact(X, Q)
    np.testing.assert_allclose(d, d_ref, rtol=1e-5, atol=1e-6)
    np.testing.assert_array_equal(i, i_ref)
    assert s.counters.points_rebuilt == 300 + 600


@pytest.mark.parametrize(("n", "k"), [(1000, 2), (1000, 1), (1000, 3), (1, 2), (5, 2)])
def test_brute_force_equals_ckdtree(n, k):
    rng = np.random.default_rng(n + k)
    X = rng.standard_normal((n, 64)).astype(np.float32)
    s = BruteForceStore()
    s.add(X[: n // 2], np.arange(n // 2))
    s.add(X[n // 2:], np.arange(n // 2, n))
    Q = rng.standard_normal((50, 64)).astype(np.float32)
    d, i = s.query(Q, k=k)
    kk = min(k, n)
    d_ref, i_ref = _exact(X, Q, k=kk)
    d_ref, i_ref = d_ref.reshape(50, kk), i_ref.reshape(50, kk)
    np.testing.assert_allclose(d[:, :kk], d_ref, rtol=1e-4, atol=1e-4)
    np.testing.assert_array_equal(i[:, :kk], i_ref)
    if kk < k:
        assert np.all(np.isinf(d[:, kk:]))
        assert np.all(i[:, kk:] == -1)


def test_brute_force_against_faiss():
    faiss = pytest.importorskip("faiss")
    X, _ = surf_like_descriptors(5000, rng=1)
    Q, _ = surf_like_descriptors(200, rng=2)
    s = BruteForceStore()
    s.add(X, np.arange(5000))
    d, i = s.query(Q)
    ix = faiss.IndexFlatL2(64)
    ix.add(X)
    d2, i2 = ix.search(Q, 2)
    np.testing.assert_allclose(d, np.sqrt(np.maximum(d2, 0)), atol=1e-3)
    assert np.mean(i[:, 0] == i2[:, 0]) > 0.99  # float32 near-ties may swap


def test_base_rule_promotes_after_three_sightings_and_drops_after_seven_iterations():
    rng = np.random.default_rng(6)
    base = MultiKDTree(100, 2.0, tree="ckdtree")
    buf = NonBaseBuffer(base, base_seen_times=3, max_non_base_time=7, tree="ckdtree")
    buf.add(rng.random((4, 3)), np.array([10, 11, 12, 13]))
    buf.observe([10, 11])
    buf.end_iteration()  # iteration 0: 10, 11 seen twice
    assert len(base) == 0
    buf.observe([10, 99])  # 99 is unknown: ignored
    buf.end_iteration()  # iteration 1: 10 seen 3 times -> base
    assert base.sizes[0] == 1
    assert set(buf.buffer_ids.tolist()) == {11, 12, 13}
    for t in range(2, 7):
        buf.end_iteration()
        assert len(buf) == 4, t  # first sighting at most 7 iterations old: kept
    buf.end_iteration()  # end of iteration 7: 11, 12, 13 time out
    assert len(buf) == 1
    assert buf.n_dropped == 3
    assert buf.n_promoted == 1


def test_query_among_with_points_in_the_buffer_only_equals_the_exact_search():
    """Before any promotion the base is empty; the search among given ids must still see the buffer's points
    (it raised a ValueError: the empty base's points had width 0). Reference: exact_knn on the chosen rows."""
    rng = np.random.default_rng(8)
    buf = NonBaseBuffer(MultiKDTree(100, 2.0, tree="ckdtree"), tree="ckdtree")
    X, Q = rng.random((20, 64)).astype(np.float32), rng.random((5, 64)).astype(np.float32)
    buf.add(X, np.arange(100, 120))
    among = np.arange(100, 120, 2)
    d, i = buf.query_among(Q, among, k=2)
    d_ref, i_ref = exact_knn(Q, X[::2], 2, among)
    np.testing.assert_array_equal(i, i_ref)
    np.testing.assert_allclose(d, d_ref)


def test_rebuild_store_applies_the_same_rule_as_buffer():
    rng = np.random.default_rng(7)
    a = make_store("rebuild", base_seen_times=3, tree="ckdtree")
    b = make_store("multi", n1=20, q=2.0, base_seen_times=3, tree="ckdtree")
    X = rng.random((400, 4)).astype(np.float32)
    for t in range(20):
        ids = np.arange(20 * t, 20 * t + 20)
        seen = rng.choice(20 * t + 1, 10) if t else np.empty(0, dtype=np.int64)
        for s in (a, b):
            s.observe(seen)
            s.add(X[ids], ids)
            s.end_iteration()
    assert len(a) == len(b)
    stored_b = np.sort(np.concatenate([b.buffer_ids, *b.base._ids]))
    np.testing.assert_array_equal(np.sort(a.ids), stored_b)
    Q = rng.random((60, 4)).astype(np.float32)
    da, ia = a.query(Q)
    db, ib = b.query(Q)
    np.testing.assert_allclose(da, db, rtol=1e-6)
    np.testing.assert_array_equal(ia, ib)
    _d_ref, i_ref = _exact(a.points, Q)
    np.testing.assert_array_equal(ia, a.ids[i_ref])


def test_bbf_recall_clustered_high_uniform_collapses():
    X, _protos = surf_like_descriptors(20000, rng=8)
    rng = np.random.default_rng(9)
    Qc = X[rng.integers(0, 20000, 300)] + 0.01 * rng.standard_normal((300, 64)).astype(np.float32)
    mt = MultiKDTree(2000, 3.0)
    for s in range(0, 20000, 2500):
        mt.add(X[s:s + 2500], np.arange(s, s + 2500))
    rec_c = np.mean(mt.query(Qc)[1][:, 0] == _exact(X, Qc)[1][:, 0])
    U, _ = surf_like_descriptors(20000, clustered=False, rng=10)
    Qu, _ = surf_like_descriptors(300, clustered=False, rng=11)
    mu = MultiKDTree(2000, 3.0)
    for s in range(0, 20000, 2500):
        mu.add(U[s:s + 2500], np.arange(s, s + 2500))
    rec_u = np.mean(mu.query(Qu)[1][:, 0] == _exact(U, Qu)[1][:, 0])
    assert rec_c > 0.9
    assert rec_u < 0.3


def test_flann_store_recall():
    X, _ = surf_like_descriptors(5000, rng=12)
    rng = np.random.default_rng(13)
    Q = X[rng.integers(0, 5000, 200)] + 0.01 * rng.standard_normal((200, 64)).astype(np.float32)
    s = FlannStore(checks=200)
    s.add(X[:2500], np.arange(2500) + 5)
    s.add(X[2500:], np.arange(2500, 5000) + 5)
    _d, i = s.query(Q)
    assert np.mean(i[:, 0] == _exact(X, Q)[1][:, 0] + 5) > 0.9


def test_counters_multi_rebuilds_less_than_rebuild_store():
    X, _ = surf_like_descriptors(6000, rng=14)
    a, b = RebuildStore(base_seen_times=1), MultiKDTree(500, 3.0)  # every point kept, as in the multi kd-tree
    for s in range(0, 6000, 300):
        for st in (a, b):
            st.add(X[s:s + 300], np.arange(s, s + 300))
            st.end_iteration()
    assert a.counters.points_rebuilt == sum(range(300, 6001, 300))
    assert b.counters.points_rebuilt < a.counters.points_rebuilt / 3


def test_empty_store_and_merge_knn():
    s = MultiKDTree(10, 2.0)
    d, i = s.query(np.zeros((3, 4)))
    assert d.shape == (3, 2)
    assert np.all(np.isinf(d))
    assert np.all(i == -1)
    d, i = merge_knn([np.array([[0.5]])], [np.array([[4]])], k=2)
    assert d.tolist() == [[0.5, np.inf]]
    assert i.tolist() == [[4, -1]]


def test_bad_input():
    s = MultiKDTree(10, 2.0)
    s.add(np.zeros((2, 4)), [0, 1])
    with pytest.raises(ValueError, match=r"`X` must have shape \(N, 4\)"):
        s.add(np.zeros((2, 5)), [2, 3])
    with pytest.raises(ValueError, match="`X` must be finite"):
        s.add(np.full((1, 4), np.nan), [2])
    with pytest.raises(TypeError, match="`ids` must be an integer array"):
        s.add(np.zeros((1, 4)), [2.5])
    with pytest.raises(ValueError, match=r"`ids` must have shape \(2,\)"):
        s.add(np.zeros((2, 4)), [1])
    with pytest.raises(ValueError, match=r"`Q` must have shape \(N, 4\)"):
        s.query(np.zeros((2, 3)))
    with pytest.raises(ValueError, match="`q` must be > 1"):
        MultiKDTree(10, 1.0)
    with pytest.raises(ValueError, match="`tree` must be one of"):
        RebuildStore(tree="ball")
    with pytest.raises(ValueError, match="`checks` must be >= 1"):
        MultiKDTree(10, 2.0, checks=0)
    with pytest.raises(TypeError, match="`base` must be a LandmarkStore"):
        NonBaseBuffer(base=[1, 2])
    with pytest.raises(ValueError, match="`name` must be one of"):
        make_store("lsh")
    with pytest.raises(TypeError, match="`X` must be a numeric array"):
        s.add(np.array([["a"] * 4]), [5])


def test_class_sizes_follow_the_size_function():
    rng = np.random.default_rng(15)
    batches = rng.integers(1, 40, 60).tolist()
    mt = MultiKDTree(12, 2.5, tree="ckdtree")
    hist = multi_tree_sizes(12, 2.5, batches)
    total = 0
    for b, h in zip(batches, hist, strict=True):
        mt.add(rng.random((b, 2)), np.arange(total, total + b))
        total += b
        assert mt.sizes == h


def test_flann_seed_repeats():
    X, _ = surf_like_descriptors(3000, rng=16)
    Q, _ = surf_like_descriptors(200, rng=17)
    out = []
    for _ in range(2):
        s = FlannStore(opencv_seed=3)
        s.add(X, np.arange(3000))
        out.append(s.query(Q)[1])
    np.testing.assert_array_equal(out[0], out[1])


def test_exact_store_keeps_its_augmented_rows_in_step_with_adds_and_drops():
    """The cached [x, |x|²/2] rows (issue 17) follow adds, capacity growth and base-rule drops; queries
    stay exact (cKDTree over the stored points) across many small blocks of the ranking GEMM."""
    from slamlab.kdtree.knn import _exact_knn_float, augment_rows
    from slamlab.kdtree.stores import ExactStore

    rng = np.random.default_rng(5)
    s = ExactStore(base_seen_times=2, max_non_base_time=2)
    next_id = 0
    for it in range(8):
        n = int(rng.integers(200, 900))
        s.add(rng.standard_normal((n, 16)).astype(np.float32), np.arange(next_id, next_id + n))
        next_id += n
        s.observe(s.ids[rng.random(len(s)) < 0.3])
        Q = rng.standard_normal((40, 16)).astype(np.float32)
        d, i = s.query(Q)
        d_ref, i_ref = _exact(s.points, Q)
        np.testing.assert_array_equal(i, s.ids[i_ref])
        np.testing.assert_allclose(d, d_ref, rtol=1e-5)
        s.end_iteration()
        np.testing.assert_array_equal(s._pts.augmented, augment_rows(s.points))
        assert it < 2 or s.dropped_ids.size  # the base rule drops points after the first iterations
    # tiny blocks: most later blocks are skipped by the running bound, the result stays exact
    X = s.points
    _, ii = _exact_knn_float(Q, X, 2, block=64)
    d_ref, i_ref = _exact(X, Q)
    np.testing.assert_array_equal(ii, i_ref)
