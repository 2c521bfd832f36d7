"""The compiled BBF (``slamlab.kdtree._kernels``) returns what the numpy lock-step BBF returns, bit for bit."""

import numpy as np
import pytest
from scipy.spatial import cKDTree

import slamlab.kdtree.tree as tree_mod
from slamlab.kdtree import KDTree

pytest.importorskip("numba")
from slamlab.kdtree._kernels import bbf_search


def _clustered(rng, n, dim, dtype):
    centres = 5 * rng.standard_normal((20, dim))
    return (centres[rng.integers(0, 20, n)] + 0.3 * rng.standard_normal((n, dim))).astype(dtype)


def _assert_same(tree, Q, k, max_leaves):
    d_np, i_np, st = tree_mod._lockstep_search(tree._t, tree.leaf_points, Q, k, max_leaves)
    d_c, i_c, nodes, leaves, dists = bbf_search(tree._t, tree.leaf_points, Q, k, max_leaves)
    np.testing.assert_array_equal(d_c, d_np)  # bit for bit: same summation order as numpy's einsum
    np.testing.assert_array_equal(i_c, i_np)  # same leaf order and tie-breaking
    np.testing.assert_array_equal(nodes, st.nodes_visited)
    np.testing.assert_array_equal(leaves, st.leaves_visited)
    np.testing.assert_array_equal(dists, st.distance_evals)


@pytest.mark.parametrize("dtype", [np.float32, np.float64])
@pytest.mark.parametrize(("kind", "n", "dim", "leaf_size"), [("random", 1000, 5, 1), ("random", 600, 64, 8),
                                                            ("clustered", 1500, 16, 3), ("ties", 800, 3, 1)])
def test_kernel_equals_numpy_lockstep(dtype, kind, n, dim, leaf_size):
    rng = np.random.default_rng(11)
    if kind == "clustered":
        X, Q = _clustered(rng, n, dim, dtype), _clustered(rng, 150, dim, dtype)
    else:
        X, Q = rng.standard_normal((n, dim)).astype(dtype), rng.standard_normal((150, dim)).astype(dtype)
        if kind == "ties":  # a coarse grid: equal distances, equal bounds, duplicate points
            X, Q = np.round(2 * X) / 2, np.round(2 * Q) / 2
    tree = KDTree(X, leaf_size=leaf_size)
    for k in (1, 2, 3):
        for m in (1, 7, 200, None):
            _assert_same(tree, Q.astype(tree.leaf_points.dtype), k, m)


def test_kernel_reproduces_the_pending_table_compaction(monkeypatch):
    # numpy sorts the pending table every 32 rounds when it is mostly holes; that changes which of two
    # equal bounds is popped first, so the kernel must compact in the same round
    calls = []
    compact = tree_mod._compact_pending

    def spy(pb, pn, free, width):
        w = compact(pb, pn, free, width)
        calls.append(w < width)
        return w

    monkeypatch.setattr(tree_mod, "_compact_pending", spy)
    rng = np.random.default_rng(2)
    X, Q = _clustered(rng, 3000, 8, np.float32), _clustered(rng, 200, 8, np.float32)
    tree = KDTree(X)
    _assert_same(tree, Q, 2, 200)
    assert any(calls)


def test_kernel_unlimited_is_exact_like_ckdtree():
    rng = np.random.default_rng(3)
    X, Q = _clustered(rng, 3000, 10, np.float64), _clustered(rng, 200, 10, np.float64)
    for leaf_size in (1, 8):
        d, i = KDTree(X, leaf_size=leaf_size).query(Q, k=3)
        d_ref, i_ref = cKDTree(X).query(Q, k=3)
        np.testing.assert_allclose(d, d_ref, rtol=1e-12, atol=1e-12)
        np.testing.assert_array_equal(i, i_ref)


def test_query_takes_the_kernel_unless_disabled(monkeypatch):
    rng = np.random.default_rng(4)
    X, Q = rng.random((700, 4)).astype(np.float32), rng.random((60, 4)).astype(np.float32)
    tree = KDTree(X, np.arange(700) + 100, leaf_size=2)
    d_c, i_c = tree.query(Q, k=2, max_leaves=5)
    leaves_c = tree.last_stats.leaves_visited
    monkeypatch.setenv("SLAMLAB_NO_NUMBA", "1")
    d_np, i_np = tree.query(Q, k=2, max_leaves=5)
    np.testing.assert_array_equal(d_c, d_np)
    np.testing.assert_array_equal(i_c, i_np)
    np.testing.assert_array_equal(leaves_c, tree.last_stats.leaves_visited)
    assert i_c.min() >= 100


@pytest.mark.parametrize("bound", ["incremental", "sum"])
def test_kernel_equals_numpy_with_the_other_bounds(bound):
    rng = np.random.default_rng(6)
    X, Q = _clustered(rng, 2000, 12, np.float32), _clustered(rng, 150, 12, np.float32)
    tree = KDTree(X, leaf_size=2)
    tree.query(Q[:1], bound=bound)  # computes the cells' intervals
    for m in (5, 60, None):
        d_np, i_np, st = tree_mod._lockstep_search(tree._t, tree.leaf_points, Q, 2, m, bound)
        d_c, i_c, _, leaves, _ = bbf_search(tree._t, tree.leaf_points, Q, 2, m, bound)
        np.testing.assert_array_equal(d_c, d_np)
        np.testing.assert_array_equal(i_c, i_np)
        np.testing.assert_array_equal(leaves, st.leaves_visited)


def test_incremental_bound_is_exact_unlimited_and_recalls_at_least_the_default():
    rng = np.random.default_rng(7)
    X, Q = _clustered(rng, 6000, 16, np.float32), _clustered(rng, 400, 16, np.float32)
    tree = KDTree(X)
    _, i_ref = cKDTree(X.astype(np.float64)).query(Q.astype(np.float64), k=2)
    _, i = tree.query(Q, k=2, bound="incremental")  # a valid lower bound: unlimited search stays exact
    np.testing.assert_array_equal(i, i_ref)
    leaves_exact = tree.last_stats.mean_leaves
    tree.query(Q, k=2)
    assert leaves_exact <= tree.last_stats.mean_leaves  # a tighter bound prunes more
    for m in (20, 50, 100):
        rec = {b: np.mean(tree.query(Q, k=2, max_leaves=m, bound=b)[1][:, 0] == i_ref[:, 0])
               for b in ("max", "incremental")}
        assert rec["incremental"] >= rec["max"], (m, rec)


def test_bound_is_checked():
    tree = KDTree(np.zeros((4, 2)))
    with pytest.raises(ValueError, match="`bound` must be one of"):
        tree.query(np.zeros(2), bound="mean")
