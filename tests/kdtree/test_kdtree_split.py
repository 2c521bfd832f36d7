"""The kd-tree's split rules and split gaps (``KDTree(split=, gap=)``, issue 25): valid trees, exact search equal
to scipy's, the compiled search equal to the numpy one, and the recall they are for."""

import numpy as np
import pytest
from scipy.spatial import cKDTree

import slamlab.kdtree.tree as tree_mod
from slamlab.kdtree import KDTree, bbf_trace, build_kdtree
from slamlab.kdtree.build import SPLIT_RULES


def _clustered(rng, n, dim, dtype=np.float64, n_clusters=20):
    centres = 5 * rng.standard_normal((n_clusters, dim))
    return (centres[rng.integers(0, n_clusters, n)] + 0.3 * rng.standard_normal((n, dim))).astype(dtype)


def _data(kind, rng, n, dim):
    if kind == "clustered":
        return _clustered(rng, n, dim), _clustered(rng, 100, dim)
    X, Q = rng.standard_normal((n, dim)), rng.standard_normal((100, dim))
    if kind == "ties":  # a coarse grid: equal values, equal distances, duplicate points
        X, Q = np.round(2 * X) / 2, np.round(2 * Q) / 2
    return X, Q


def _check_tree(t, X):
    """Every split separates its halves along split_dim (left <= split_lo <= split_val <= split_hi <= right),
    both halves are non-empty, the leaves cover ``perm`` and ``perm`` is a permutation."""
    assert np.array_equal(np.sort(t["perm"]), np.arange(len(X)))
    span = {}

    def rng_of(node):  # the perm range under a node
        if node not in span:
            if t["left"][node] < 0:
                span[node] = (t["start"][node], t["stop"][node])
            else:
                span[node] = (rng_of(t["left"][node])[0], rng_of(t["right"][node])[1])
        return span[node]

    for node in np.flatnonzero(t["left"] >= 0):
        d = t["split_dim"][node]
        (a, b), (c, e) = rng_of(t["left"][node]), rng_of(t["right"][node])
        assert a < b == c < e
        lv, rv = X[t["perm"][a:b], d], X[t["perm"][c:e], d]
        assert lv.max() == t["split_lo"][node] <= t["split_val"][node] <= t["split_hi"][node] <= rv.min()
        if not t["gap"]:
            assert t["split_lo"][node] == t["split_hi"][node] == t["split_val"][node]
        else:
            assert t["split_hi"][node] == rv.min()


@pytest.mark.parametrize("split", SPLIT_RULES)
def test_split_rules_build_valid_trees(split):
    rng = np.random.default_rng(5)
    for kind in ("random", "clustered", "ties"):
        X, _ = _data(kind, rng, 700, 6)
        for gap in (False, True):
            for leaf_size in (1, 5):
                t = build_kdtree(X, split=split, gap=gap, leaf_size=leaf_size)
                _check_tree(t, X)
                assert (t["stop"] - t["start"])[t["left"] < 0].max() <= leaf_size


def test_variance_mean_is_flanns_split():
    # coordinate of largest variance, cut at its mean; points equal to the cut fill the side nearer half
    X = np.array([[0.0, 0], [1, 10], [2, 10], [3, 10], [4, 10], [20, 0]])
    t = build_kdtree(X, split="variance-mean", gap=True)
    assert t["split_dim"][0] == 0  # variance of x (43.7) > variance of y (22.2)
    assert t["split_lo"][0] == 4
    assert t["split_hi"][0] == 20
    X = np.array([[0.0], [1], [1], [1], [1], [2]])  # mean 1: lim1 = 1 < 3 <= lim2 = 5 -> half goes left
    t = build_kdtree(X, split="variance-mean", leaf_size=3)
    assert t["stop"][t["left"][0]] == 3
    assert t["split_val"][0] == 1.0
    t = build_kdtree(np.array([[0.0], [1], [2], [3], [30]]), split="variance-midrange", gap=True)
    assert t["split_lo"][0] == 3
    assert t["split_hi"][0] == 30


def test_identical_points_split_in_half():
    X = np.full((9, 3), 0.1)
    for split in SPLIT_RULES:
        tree = KDTree(X, split=split, gap=True)
        assert tree.height == 4  # halves of 4 and 5, ... as the balanced build
        d, _i = tree.query(X[:2], k=3)
        np.testing.assert_array_equal(d, 0.0)


@pytest.mark.parametrize("split", ["variance-mean", "variance-midrange", "spread-mean"])
def test_exact_search_equals_ckdtree(split):
    rng = np.random.default_rng(7)
    for kind, dim in (("random", 5), ("clustered", 16), ("ties", 3)):
        X, Q = _data(kind, rng, 1000, dim)
        d_ref, i_ref = cKDTree(X).query(Q, k=3)
        for gap in (False, True):
            tree = KDTree(X, split=split, gap=gap, leaf_size=1 if gap else 4)
            for bound in ("max", "incremental"):
                d, i = tree.query(Q, k=3, bound=bound)  # compiled where numba is enabled
                np.testing.assert_allclose(d, d_ref, rtol=1e-12, atol=1e-12)
                if bound == "incremental":  # the numpy search too (the kernel equals it: the test below)
                    d_np, _i_np, _ = tree_mod._lockstep_search(tree._t, tree.leaf_points, Q, 3, None, bound)
                    np.testing.assert_allclose(np.sqrt(d_np), d_ref, rtol=1e-12, atol=1e-12)
                if kind != "ties":  # equal distances: any of the tied ids is right
                    np.testing.assert_array_equal(i, i_ref)


@pytest.mark.parametrize("split", ["variance-mean", "variance-midrange", "spread-midrange"])
def test_kernel_equals_numpy_on_split_trees(split):
    pytest.importorskip("numba")
    from slamlab.kdtree._kernels import bbf_search

    rng = np.random.default_rng(8)
    X, Q = _clustered(rng, 2000, 24, np.float32), _clustered(rng, 150, 24, np.float32)
    for gap in (False, True):
        tree = KDTree(X, split=split, gap=gap)
        for bound in ("max", "incremental", "sum"):
            tree.query(Q[:1], bound=bound)  # the cell bounds, for "incremental"
            for max_leaves in (7, 200):
                d_np, i_np, st = tree_mod._lockstep_search(tree._t, tree.leaf_points, Q, 2, max_leaves, bound)
                d_c, i_c, nodes, leaves, _ = bbf_search(tree._t, tree.leaf_points, Q, 2, max_leaves, bound)
                np.testing.assert_array_equal(d_c, d_np)
                np.testing.assert_array_equal(i_c, i_np)
                np.testing.assert_array_equal(nodes, st.nodes_visited)
                np.testing.assert_array_equal(leaves, st.leaves_visited)


def test_trace_equals_batch_on_a_gap_tree():
    rng = np.random.default_rng(9)
    X, Q = _clustered(rng, 1500, 8), _clustered(rng, 20, 8)
    tree = KDTree(X, split="variance-midrange", gap=True)
    for bound in ("max", "incremental", "sum"):
        d, i = tree.query(Q, k=2, max_leaves=15, bound=bound)
        for row in range(len(Q)):
            dt, it, _events = bbf_trace(tree, Q[row], k=2, max_leaves=15, bound=bound)
            np.testing.assert_allclose(dt, d[row], rtol=1e-12)
            np.testing.assert_array_equal(it, i[row])


def test_split_options_recall_at_least_the_default():
    # a fixed clustered set in 32-d, 1-point leaves, 30 leaves per query: FLANN's split and the gaps
    # (each, and together) recall the true nearest neighbour at least as often as the balanced default
    rng = np.random.default_rng(12)
    X, Q = _clustered(rng, 6000, 32, np.float32, 60), _clustered(rng, 400, 32, np.float32, 60)
    _, i_ref = cKDTree(X).query(Q, k=1)

    def recall(**opts):
        _, i = KDTree(X, **opts).query(Q, k=2, max_leaves=30, bound="incremental")
        return np.mean(i[:, 0] == i_ref)

    base = recall()
    assert recall(split="variance-mean") >= base
    assert recall(gap=True) >= base
    assert recall(split="variance-mean", gap=True) >= recall(split="variance-mean")
    assert recall(split="variance-midrange", gap=True) >= base


def test_bad_split_options():
    X = np.zeros((4, 2))
    with pytest.raises(ValueError, match="`split` must be one of"):
        KDTree(X, split="median")
    with pytest.raises(TypeError, match="`gap` must be a bool"):
        build_kdtree(X, gap="yes")
    assert "split='variance-mean', gap=True" in repr(KDTree(X, split="variance-mean", gap=True))
    assert repr(KDTree(X)) == "KDTree(n=4, k=2, leaf_size=1, height=2)"
