"""Store comparison (000 Tables 1-2), crossover and C fitted on this machine: small runs."""

import numpy as np
import pytest

from slamlab.kdtree.cost_model import calibrate_C, minimise_iter_time
from slamlab.studies.kdtree.experiments import (
    TABLES_000,
    CrossoverResult,
    fit_C,
    recall_at_1,
    run_crossover,
    run_store_comparison,
)


@pytest.fixture(scope="module")
def table1():
    return run_store_comparison("table1", n_iterations=12, stores=("rebuild", "multi", "brute"), n1=500, q=3.0)


def test_comparison_counts_and_recall(table1):
    r = table1
    assert r.recall["brute"] == 1.0  # exact store against the exact reference
    assert 0.85 < r.recall["rebuild"] <= 1.0
    assert 0.85 < r.recall["multi"] <= 1.0
    # the rebuilt tree rebuilds every kept point every iteration; the multi kd-tree far fewer
    assert r.ops["rebuild"]["rebuilt_max"] == r.stored_end
    assert r.ops["multi"]["rebuilt_mean"] < r.ops["rebuild"]["rebuilt_mean"]
    # BBF examines at most `checks` points per tree
    assert r.ops["rebuild"]["evals_max"] <= r.checks
    t = r.table()
    assert "recall@1 vs exact" in t
    assert "Table 1" in t


def test_timed_table_has_000s_figures(table1):
    t = table1.timed_table()
    for row in ("mean add", "max add", "mean search", "max search", "mean iteration", "max iteration"):
        assert row in t
    assert "<515" in t  # 000's multi kd-tree bound, Table 1
    assert TABLES_000["table2"]["kd-tree"][0] == 524
    ms = table1.times_ms("multi")
    assert ms[4] == pytest.approx(np.mean(1e3 * (table1.add_s["multi"] + table1.search_s["multi"])))


def test_table2_flann_and_all_base():
    r = run_store_comparison("table2", n_iterations=6, stores=("flann", "multi"), n_new=300)
    assert r.stored_end == 6 * 300  # all points base at once: nothing dropped
    assert r.recall["flann"] > 0.85


def test_crossover_small():
    r = run_crossover((500, 2000), stores=("rebuild", "multi", "brute"), n_queries=100, n_new=200, n1=300, q=3.0,
                      repeats=1)
    assert r.recall["brute"].tolist() == [1.0, 1.0]
    assert np.all(r.recall["multi"] > 0.8)
    assert np.all(r.iteration_s("rebuild") > 0)
    np.testing.assert_allclose(r.crossover(), _crossover_by_hand(r.sizes, r.iteration_s("rebuild"),
                                                                 r.iteration_s("multi")), rtol=1e-12, equal_nan=True)
    assert "stored points" in r.table()
    assert "rebuilt kd-tree" in r.timed_table()


def _crossover_by_hand(sizes, t_a, t_b):
    """The first size of the final run of sizes where b is faster, log-interpolated with the one before."""
    faster = t_b < t_a
    if not faster[-1]:
        return float("nan")
    i = len(faster) - 1
    while i > 0 and faster[i - 1]:
        i -= 1
    if i == 0:
        return float(sizes[0])
    da, db = np.log(t_b[i - 1] / t_a[i - 1]), np.log(t_b[i] / t_a[i])
    return float(np.exp(np.log(sizes[i - 1]) + da / (da - db) * (np.log(sizes[i]) - np.log(sizes[i - 1]))))


@pytest.mark.parametrize(
    ("rebuild", "multi", "expected"),
    [
        ((1.0, 2.0, 4.0, 8.0), (2.0, 2.0, 2.0, 2.0), 2000.0),  # equal at 2000, faster from there on
        ((1.0, 2.0, 4.0, 8.0), (2.0, 4.0, 8.0, 16.0), float("nan")),  # never faster
        ((3.0, 3.0, 3.0, 3.0), (1.0, 1.0, 1.0, 1.0), 1000.0),  # faster everywhere: the first size
        ((1.0, 4.0, 1.0, 4.0), (2.0, 2.0, 2.0, 2.0), 8000.0 / np.sqrt(2.0)),  # faster, slower again, then faster
    ],
)
def test_crossover_from_given_times(rebuild, multi, expected):
    sizes = np.array([1000.0, 2000.0, 4000.0, 8000.0])
    r = CrossoverResult(sizes, ("rebuild", "multi"), {}, 100, 100,
                        add_s={"rebuild": np.array(rebuild), "multi": np.array(multi)},
                        search_s={"rebuild": np.zeros(4), "multi": np.zeros(4)})
    np.testing.assert_allclose(r.crossover(), expected, equal_nan=True)
    np.testing.assert_allclose(_crossover_by_hand(sizes, np.array(rebuild), np.array(multi)), expected, equal_nan=True)


def test_fit_C():
    r = fit_C(n=3000, s=100, m=100)
    # C follows from the measured times by 000's calibration, and the optimum from C by the model
    assert calibrate_C(r.s, r.t_search_s, r.m, r.t_build_s, r.n) == r.C
    n1, q, *_ = minimise_iter_time(n=50000, s=500, m=500, C=r.C)
    assert (n1, q) == (r.n1, r.q)
    assert f"C = {r.C:.1f}" in str(r)


def test_recall_and_bad_input():
    assert recall_at_1(np.array([[1.0, 2.0]]), np.array([[1.0, 2.0]])) == 1.0
    with pytest.raises(ValueError, match="`stores` must be one of"):
        run_store_comparison("table1", stores=("kd",), n_iterations=1)
    with pytest.raises(ValueError, match="`stores` must name at least one store"):
        run_store_comparison("table1", stores=(), n_iterations=1)
    with pytest.raises(ValueError, match="`sizes` must be increasing"):
        run_crossover((1000, 500))
    with pytest.raises(ValueError, match="`n_iterations` must be >= 1"):
        run_store_comparison("table1", n_iterations=0)


def test_dimension_study_exact_search_visits_almost_all_leaves_in_64d():
    from slamlab.studies.kdtree.experiments import run_dimension_study

    r = run_dimension_study((2, 64), n=2000, n_queries=40)
    by = {row[0]: row for row in r.rows}
    assert by["uniform 2-d"][2] < 5.0  # low dimension: exact search visits few leaves
    assert by["uniform 64-d"][2] > 90.0  # 64-d: almost all
    assert by["uniform 64-d"][4] < 0.5  # BBF recall collapses on uniform vectors
    assert by["clustered SURF-like"][4] > 0.85  # and holds on clustered descriptors
    assert "BBF recall@1" in r.table()


def test_ours_vs_source_prints_the_runs_figures(table1):
    from slamlab.kdtree.cost_model import run_cost_model
    from slamlab.studies.kdtree.experiments import ours_vs_source, run_dimension_study

    cost = run_cost_model()
    dim = run_dimension_study((8, 64), n=500, n_queries=20)
    t2 = run_store_comparison("table2", n_iterations=3, stores=("rebuild", "multi"), n1=500, q=3.0)
    table = ours_vs_source(cost, dim, table1, t2)
    assert f"n1 = {cost.literal[1]:.0f}, q = {cost.literal[2]:.2f}" in table
    assert f"n1 = {cost.optimum[1]:.0f}, q = {cost.optimum[2]:.2f}" in table
    assert f"{table1.recall['rebuild']:.3f} / {table1.recall['multi']:.3f}" in table
    assert f"{t2.stored_end} (3 iterations)" in table
    assert "8.98" in table
