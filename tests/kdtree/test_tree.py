"""Teaching kd-tree: exact search = cKDTree, BBF unlimited = exact, BBF trace = batch BBF, build invariants."""

import numpy as np
import pytest
from scipy.spatial import cKDTree

from slamlab.kdtree import KDTree, bbf_trace, build_kdtree


@pytest.mark.parametrize(("n", "k", "leaf_size"), [(500, 2, 1), (1000, 3, 5), (3000, 8, 4), (800, 64, 1), (700, 64, 16)])
def test_exact_equals_ckdtree(n, k, leaf_size):
    rng = np.random.default_rng(n + k)
    X = rng.standard_normal((n, k))
    Q = rng.standard_normal((150, k))
    tree = KDTree(X, leaf_size=leaf_size)
    d, i = tree.query(Q, k=2)
    d_ref, i_ref = cKDTree(X).query(Q, k=2)
    np.testing.assert_allclose(d, d_ref, rtol=1e-12, atol=1e-12)
    np.testing.assert_array_equal(i, i_ref)  # continuous random data: no distance ties


def test_exact_with_ids_and_float32():
    rng = np.random.default_rng(1)
    X = rng.random((400, 16)).astype(np.float32)
    ids = rng.permutation(400) + 1000
    tree = KDTree(X, ids)
    assert tree.points.dtype == np.float32
    d, i = tree.query(X[:50] + 0.01, k=3)
    d_ref, i_ref = cKDTree(X.astype(np.float64)).query((X[:50] + 0.01).astype(np.float32).astype(np.float64), k=3)
    np.testing.assert_allclose(d, d_ref, rtol=1e-5)
    np.testing.assert_array_equal(i, ids[i_ref])


@pytest.mark.parametrize("leaf_size", [1, 8])
def test_bbf_unlimited_equals_exact(leaf_size):
    rng = np.random.default_rng(2)
    X = rng.standard_normal((1000, 12))
    Q = rng.standard_normal((60, 12))
    tree = KDTree(X, leaf_size=leaf_size)
    d, i = tree.query(Q, k=2)
    d_b, i_b = tree.query(Q, k=2, max_leaves=tree.n_leaves)
    np.testing.assert_array_equal(i_b, i)
    np.testing.assert_array_equal(d_b, d)


def test_bbf_stops_after_max_leaves_and_recall_grows():
    rng = np.random.default_rng(3)
    X = rng.standard_normal((1500, 64))
    Q = X[:60] + 0.3 * rng.standard_normal((60, 64))
    tree = KDTree(X)
    _, i_exact = tree.query(Q, k=2)
    exact_leaves = tree.last_stats.leaves_visited
    assert exact_leaves.mean() > 0.5 * tree.n_leaves  # 64-d: exact search sees most leaves
    recalls = []
    for m in (1, 10, 100, 1200):
        _, i = tree.query(Q, k=2, max_leaves=m)
        assert tree.last_stats.leaves_visited.max() <= m
        assert np.all(tree.last_stats.distance_evals == tree.last_stats.leaves_visited)  # one point per leaf
        recalls.append(np.mean(i[:, 0] == i_exact[:, 0]))
    assert recalls == sorted(recalls)
    assert recalls[-1] > 0.9
    assert recalls[0] < recalls[-1]


def test_trace_equals_batch_bbf():
    rng = np.random.default_rng(4)
    X = rng.standard_normal((600, 5))
    tree = KDTree(X, leaf_size=3)
    Q = rng.standard_normal((20, 5))
    for m in (1, 4, None):
        d, i = tree.query(Q, k=2, max_leaves=m)
        for j in range(len(Q)):
            dj, ij, events = bbf_trace(tree, Q[j], k=2, max_leaves=m)
            np.testing.assert_allclose(dj, d[j], rtol=1e-12)
            np.testing.assert_array_equal(ij, i[j])
            assert sum(e[0] == "leaf" for e in events) == tree.last_stats.leaves_visited[j]


def test_build_is_balanced_median_split_on_largest_spread():
    rng = np.random.default_rng(5)
    X = rng.random((1000, 4)) * np.array([1.0, 10.0, 2.0, 0.5])
    t = build_kdtree(X, leaf_size=1)
    assert t["split_dim"][0] == 1  # coordinate of largest spread
    left, right = t["left"], t["right"]
    sizes = t["stop"] - t["start"]
    assert np.all(sizes[left < 0] == 1)
    depth = t["depth"][left < 0]
    assert depth.max() - depth.min() <= 1  # balanced
    assert depth.max() == int(np.ceil(np.log2(1000)))
    # every point reaches its own leaf: left subtree <= split <= right subtree
    P = X[t["perm"]]

    def check(node, lo, hi):
        if left[node] < 0:
            return
        d, s = t["split_dim"][node], t["split_val"][node]
        sub_l = P[_span(t, left[node])][:, d]
        sub_r = P[_span(t, right[node])][:, d]
        assert sub_l.max() <= s <= sub_r.min()
        assert abs(len(sub_l) - len(sub_r)) <= 1

    for node in range(min(63, t["split_dim"].size)):
        check(node, None, None)


def _span(t, node):
    """Indices (in leaf order) of all points under ``node``."""
    out, stack = [], [node]
    while stack:
        n = stack.pop()
        if t["left"][n] < 0:
            out.extend(range(t["start"][n], t["stop"][n]))
        else:
            stack += [t["left"][n], t["right"][n]]
    return np.array(out)


def test_ties_duplicates_and_tiny_trees():
    X = np.array([[1.0, 0.0]] * 10 + [[2.0, 0.0]] * 5)
    tree = KDTree(X, leaf_size=2)
    d, i = tree.query([[1.0, 0.0], [2.1, 0.0]], k=2)
    np.testing.assert_array_equal(d[0], [0.0, 0.0])
    assert set(i[0]) <= set(range(10))
    np.testing.assert_allclose(d[1], [0.1, 0.1])
    one = KDTree([[3.0, 4.0]])
    d, i = one.query([0.0, 0.0], k=2)
    assert d[0] == pytest.approx(5.0)
    assert np.isinf(d[1])
    assert i.tolist() == [0, -1]


def test_bad_input():
    with pytest.raises(ValueError, match="`points` must be 2-dimensional"):
        KDTree(np.zeros(5))
    with pytest.raises(ValueError, match="`points` must hold at least one point"):
        KDTree(np.zeros((0, 3)))
    with pytest.raises(ValueError, match="`points` must be finite"):
        KDTree([[np.nan, 1.0]])
    with pytest.raises(TypeError, match="`ids` must be an integer array"):
        KDTree(np.zeros((3, 2)), ids=[0.5, 1.0, 2.0])
    with pytest.raises(ValueError, match=r"`ids` must have shape \(3,\)"):
        KDTree(np.zeros((3, 2)), ids=[1, 2])
    with pytest.raises(ValueError, match="`leaf_size` must be >= 1"):
        KDTree(np.zeros((3, 2)), leaf_size=0)
    tree = KDTree(np.zeros((3, 2)))
    with pytest.raises(ValueError, match=r"`Q` must have shape \(M, 2\)"):
        tree.query(np.zeros((4, 3)))
    with pytest.raises(ValueError, match="`max_leaves` must be >= 1"):
        tree.query(np.zeros((1, 2)), max_leaves=0)
    with pytest.raises(TypeError, match="`k` must be an integer"):
        tree.query(np.zeros((1, 2)), k=1.5)
    with pytest.raises(TypeError, match="`tree` must be a KDTree"):
        bbf_trace(np.zeros((3, 2)), [0.0, 0.0])
