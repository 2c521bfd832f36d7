"""Descriptor streams of 000's Table 1 and Table 2 runs: sizes, the base rule, descriptor realism."""

import numpy as np
import pytest
from scipy.spatial import cKDTree

from slamlab.kdtree.stores import make_store
from slamlab.studies.kdtree.workloads import SCENARIOS, make_workload, scenario, surf_like_descriptors


@pytest.mark.parametrize(("name", "lo", "hi"), [("table1", 11000, 15000), ("table2", 60000, 70000)])
def test_full_scenarios_reach_000s_sizes(name, lo, hi):
    w = make_workload(name, rng=0)
    assert lo <= w.stored[-1] <= hi  # 000: ~13000 (Table 1), ~65000 (Table 2)
    q = np.array([it.queries.shape[0] for it in w.iterations[10:]])
    assert 300 <= q.mean() <= 500  # ~400 searches per iteration
    assert all(it.new_X.shape == (SCENARIOS[name].n_new, 64) for it in w.iterations)


def test_descriptors_unit_float32_surf_layout():
    X, P = surf_like_descriptors(1000, rng=1)
    assert X.dtype == np.float32
    np.testing.assert_allclose(np.linalg.norm(X, axis=1), 1.0, atol=1e-5)
    assert np.all(X.reshape(-1, 16, 4)[:, :, 2:] >= 0)  # the |dx|, |dy| sums
    assert P.shape == (256, 64)
    U, none = surf_like_descriptors(10, clustered=False, rng=1)
    assert none is None
    np.testing.assert_allclose(np.linalg.norm(U, axis=1), 1.0, atol=1e-5)


def test_reobservations_match_their_landmark():
    w = make_workload("table2", n_iterations=20, rng=2)
    X = np.concatenate([it.new_X for it in w.iterations])
    it = w.iterations[-1]
    stored = X[: 19 * w.scenario.n_new]
    d, i = cKDTree(stored).query(it.queries, 2)
    re = it.truth >= 0
    assert np.mean(i[re, 0] == it.truth[re]) > 0.97
    # distance ratio test separates re-observations from clutter (what 000's matcher relies on)
    assert np.median(d[re, 0] / d[re, 1]) < 0.6 < np.median(d[~re, 0] / d[~re, 1])


def test_stored_count_equals_what_the_stores_keep():
    w = make_workload("table1", n_iterations=25, rng=3)
    s = make_store("rebuild", base_seen_times=3, tree="ckdtree")
    for t, it in enumerate(w.iterations):
        s.observe(it.observed)
        s.add(it.new_X, it.new_ids)
        s.end_iteration()
        assert len(s) == w.stored[t]
    assert w.stored[-1] < 25 * w.scenario.n_new  # non-base points time out


def test_deterministic_and_changes():
    a = make_workload("table1", n_iterations=3, rng=5)
    b = make_workload("table1", n_iterations=3, rng=5)
    np.testing.assert_array_equal(a.iterations[2].queries, b.iterations[2].queries)
    assert scenario("table2", n_new=10).n_new == 10
    assert "3 iterations" in str(a)


def test_bad_input():
    with pytest.raises(ValueError, match="`name` must be one of"):
        make_workload("table3")
    with pytest.raises(ValueError, match="unknown scenario field"):
        scenario("table1", n_points=5)
    with pytest.raises(ValueError, match="`n_new` must be >= 1"):
        make_workload("table1", n_new=0)
    with pytest.raises(ValueError, match=r"`p_track` must be in \[0, 1\)"):
        make_workload("table1", p_track=1.0)
    with pytest.raises(TypeError, match="`name_or_scenario` must be a scenario name"):
        make_workload(3)
