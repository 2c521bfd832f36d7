"""Store widgets: any slider combination prints a table or a readable message (callbacks called directly,
since ``ipywidgets.interactive`` swallows exceptions)."""

import matplotlib

from slamlab.kdtree.cost_model import iter_time, run_cost_model
from slamlab.studies.kdtree import widgets as W
from slamlab.studies.kdtree.experiments import run_store_comparison

matplotlib.use("Agg")


def test_cost_model_widget_extremes(capsys):
    w = W.explore_cost_model()
    capsys.readouterr()
    w.f(**{**w.kwargs, "n1": 500, "q": 1.5, "s": 10, "m": 5000, "n": 5000, "C": 50.0})
    out = capsys.readouterr().out
    # the widget prints the model's value at the sliders and the optimum of the same run_cost_model call
    here = float(iter_time(500, 1.5, n=5000, s=10, m=5000, C=50.0))
    _, bn1, bq, best, _ = run_cost_model(n=5000, s=10, m=5000, C=50.0).optimum
    assert out.strip() == (f"iterTime at n1 = 500, q = 1.50: {here:.3g} steps, {here / best:.3f} x the optimum "
                           f"(n1 = {bn1:.0f}, q = {bq:.2f})")
    assert here >= best
    matplotlib.pyplot.close("all")


def test_stores_widget_small_run(capsys):
    w = W.explore_stores(n_iterations=2)
    capsys.readouterr()
    w.f(**{**w.kwargs, "n1": 100, "q": 1.5, "s": 10, "m": 10, "n_iterations": 2, "checks": 8})
    out = capsys.readouterr().out
    ref = run_store_comparison("table2", stores=("rebuild", "multi"), n1=100, q=1.5, checks=8, n_iterations=2,
                               n_new=10, p_track=0.0, n_old=9, n_clutter=1, rng=2010)
    assert ref.table() in out  # the same run the tests can make, printed whole
    matplotlib.pyplot.close("all")
