"""The stores' one settings object (issue 42): one default per field, every store and study reads it, and a
field a study sets itself is refused by name."""

import numpy as np
import pytest

from slamlab.kdtree import StoreParams
from slamlab.kdtree.stores import (
    BruteForceStore,
    ExactStore,
    FlannStore,
    MultiKDTree,
    NonBaseBuffer,
    RebuildStore,
    make_store,
)
from slamlab.studies.kdtree.experiments import run_crossover, run_store_comparison
from slamlab.studies.kdtree.workloads import SCENARIOS, RecordingStore


def test_one_default_per_field_with_its_source():
    p = StoreParams()
    assert (p.base_seen_times, p.max_non_base_time, p.n1, p.q, p.checks) == (3, 7, 3500, 5.5, 200)
    src = StoreParams.sources()
    assert src["base_seen_times"].startswith("000 §3.4")
    assert src["max_non_base_time"].startswith("000 §3.4")
    assert src["n1"].startswith("000 §4.1.2")
    assert src["q"].startswith("000 §4.1.2")
    # the scenario's MaxNonBaseTime is the same default, not a second one
    assert SCENARIOS["table1"].max_non_base_time == p.max_non_base_time


@pytest.mark.parametrize(("field", "value", "error", "match"), [
    ("base_seen_times", 0, ValueError, "`base_seen_times` must be >= 1"),
    ("max_non_base_time", 0, ValueError, "`max_non_base_time` must be >= 1"),
    ("n1", 2.5, TypeError, "`n1` must be an integer"),
    ("q", 1.0, ValueError, "`q` must be > 1"),
    ("tree", "ball", ValueError, "`tree` must be one of"),
    ("leaf_size", 0, ValueError, "`leaf_size` must be >= 1"),
    ("checks", 0, ValueError, "`checks` must be >= 1"),
])
def test_every_field_is_checked_by_name(field, value, error, match):
    with pytest.raises(error, match=match):
        StoreParams(**{field: value})
    with pytest.raises(error, match=match):
        make_store("multi", **{field: value})


def test_a_misspelt_field_is_a_type_error():
    with pytest.raises(TypeError, match=r"StoreParams has no field.*'base_seen_time'"):
        make_store("rebuild", base_seen_time=3)
    with pytest.raises(TypeError, match="unexpected keyword argument 'n1'"):
        RebuildStore(n1=100)  # the rebuilt tree has no n1: not taken silently


def test_every_store_takes_the_default_base_rule_unless_it_says_otherwise():
    rule = (3, 7)
    for store in (RebuildStore(), ExactStore(), NonBaseBuffer(), make_store("rebuild"), make_store("multi")):
        assert (store.params.base_seen_times, store.params.max_non_base_time) == rule, store
    # the brute-force reference keeps every point: said by its explicit argument
    assert BruteForceStore().params.base_seen_times == 1
    # the stereo pipeline's positional call still reads as (base_seen_times, max_non_base_time)
    assert (ExactStore(2, 5).params.base_seen_times, ExactStore(2, 5).params.max_non_base_time) == (2, 5)


def test_params_reach_every_part_of_a_store():
    p = StoreParams(base_seen_times=2, max_non_base_time=4, n1=50, q=2.5, tree="ckdtree", leaf_size=3, checks=40)
    buf = make_store("multi", params=p)
    assert buf.params == p
    assert buf.base.params == p
    assert (buf.base.n1, buf.base.q, buf.base.tree_kind, buf.leaf_size, buf.checks) == (50, 2.5, "ckdtree", 3, 40)
    assert make_store("flann", params=p).base.checks == 40
    assert make_store("brute", params=p).params == p.replace(tree="brute")  # its buffer: brute force
    # an argument the store names changes that field of params, the others stay
    r = RebuildStore(params=p, checks=7)
    assert r.params == p.replace(checks=7)
    assert MultiKDTree(10, params=p).params == p.replace(n1=10)
    assert FlannStore(params=p).params.checks == 40
    # the rule reaches the book: a point seen once more (2 sightings) becomes base, the rest go after age 4
    buf = NonBaseBuffer(MultiKDTree(10, 2.0, tree="ckdtree"), params=p)
    buf.add(np.eye(3), [0, 1, 2])
    buf.observe([0])
    buf.end_iteration()
    assert len(buf.base) == 1
    X, ids = buf.stored()  # buffer and base alike
    assert sorted(ids.tolist()) == [0, 1, 2]
    np.testing.assert_array_equal(X[np.argsort(ids)], np.eye(3))
    for _ in range(3):
        buf.end_iteration()
    assert len(buf) == 3
    buf.end_iteration()
    assert len(buf) == 1
    assert buf.n_dropped == 2


def test_rebuild_store_drops_with_the_default_rule_and_keeps_all_with_one_sighting():
    X = np.random.default_rng(0).random((10, 4)).astype(np.float32)
    a, b = RebuildStore(tree="ckdtree"), RebuildStore(tree="ckdtree", base_seen_times=1)
    for s in (a, b):
        s.add(X, np.arange(10))
        for _ in range(8):
            s.end_iteration()
    assert len(a) == 0  # never seen again: dropped after MaxNonBaseTime = 7 iterations
    assert len(b) == 10


def test_crossover_settings_reach_the_stores_and_the_base_rule_is_its_own():
    r = run_crossover((300, 600), stores=("rebuild", "multi"), n_queries=40, n_new=100, repeats=1, n1=100, q=2.0,
                      tree="ckdtree", progress=False)
    assert r.params == StoreParams(n1=100, q=2.0, tree="ckdtree", base_seen_times=1)
    assert r.recall["rebuild"].tolist() == [1.0, 1.0]  # an exact tree: the setting reached the stores
    assert r.recall["multi"].tolist() == [1.0, 1.0]
    r2 = run_crossover((300,), stores=("multi",), n_queries=20, n_new=100, repeats=1,
                       params=StoreParams(n1=150, q=3.0), progress=False)
    assert (r2.params.n1, r2.params.q) == (150, 3.0)
    for field, value in (("base_seen_times", 2), ("max_non_base_time", 3)):
        with pytest.raises(ValueError, match=f"`{field}` is set by run_crossover itself"):
            run_crossover((300,), stores=("multi",), n_queries=20, n_new=100, repeats=1, **{field: value})
        with pytest.raises(ValueError, match=f"`{field}` is set by run_crossover itself"):
            run_crossover((300,), stores=("multi",), params=StoreParams(**{field: value}))


def test_store_comparison_settings_and_the_scenarios_base_rule():
    # Table 1 and Table 2 keep 000's rules: 3 sightings within 7 iterations, and everything base at once
    t1 = run_store_comparison("table1", stores=("brute",), n_iterations=2, progress=False)
    assert t1.params == StoreParams()
    t2 = run_store_comparison("table2", stores=("brute",), n_iterations=2, progress=False)
    assert t2.params == StoreParams(base_seen_times=1)
    # params and store fields reach the stores: an exact tree finds every first neighbour
    r = run_store_comparison("table1", stores=("rebuild", "multi"), n_iterations=4, n_new=100,
                             params=StoreParams(tree="ckdtree", n1=100), q=2.0, progress=False)
    assert r.params == StoreParams(tree="ckdtree", n1=100, q=2.0)
    assert (r.n1, r.q, r.checks) == (100, 2.0, 200)
    assert r.recall["rebuild"] == 1.0
    assert r.recall["multi"] == 1.0
    # the base rule is a scenario field: it reaches the workload and the stores
    r = run_store_comparison("table2", stores=("rebuild",), n_iterations=3, n_new=50, base_seen_times=2,
                             max_non_base_time=5, progress=False)
    assert (r.params.base_seen_times, r.params.max_non_base_time) == (2, 5)
    for field, value in (("base_seen_times", 2), ("max_non_base_time", 3)):
        with pytest.raises(ValueError, match=f"`{field}` is the scenario's"):
            run_store_comparison("table1", n_iterations=1, params=StoreParams(**{field: value}))
    with pytest.raises(TypeError, match=r"unknown keyword.*'n_point'"):
        run_store_comparison("table1", n_iterations=1, n_point=3)
    with pytest.raises(TypeError, match="`params` must be a StoreParams"):
        run_store_comparison("table1", n_iterations=1, params={"n1": 100})


def test_recorded_workload_counts_with_the_default_rule():
    rng = np.random.default_rng(1)
    rec = RecordingStore(ExactStore())
    for t in range(9):
        rec.query(rng.random((3, 4)).astype(np.float32))
        rec.add(rng.random((2, 4)).astype(np.float32), [2 * t, 2 * t + 1])
        rec.end_iteration()
    w = rec.workload()
    assert (w.scenario.base_seen_times, w.scenario.max_non_base_time) == (3, 7)
    assert w.stored.tolist() == [2, 4, 6, 8, 10, 12, 14, 14, 14]  # never re-seen: dropped from age 7
    assert rec.workload(base_seen_times=1).stored[-1] == 18
