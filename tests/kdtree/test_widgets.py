"""Store widgets: any slider combination prints a table or a readable message (callbacks called directly,
since ``ipywidgets.interactive`` swallows exceptions)."""

import matplotlib

from slamlab.kdtree import widgets as W

matplotlib.use("Agg")


def test_cost_model_widget_extremes(capsys):
    w = W.explore_cost_model()
    capsys.readouterr()
    w.f(**{**w.kwargs, "n1": 500, "q": 1.5, "s": 10, "m": 5000, "n": 5000, "C": 50.0})
    out = capsys.readouterr().out
    assert "n1" in out
    matplotlib.pyplot.close("all")


def test_stores_widget_small_run(capsys):
    w = W.explore_stores(n_iterations=2)
    capsys.readouterr()
    w.f(**{**w.kwargs, "n1": 100, "q": 1.5, "s": 10, "m": 10, "n_iterations": 2, "checks": 8})
    out = capsys.readouterr().out
    assert "recall@1" in out
    matplotlib.pyplot.close("all")
