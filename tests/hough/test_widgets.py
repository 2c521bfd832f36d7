"""Hough widgets: extreme slider values give a table or a readable message, never a traceback.

``ipywidgets.interactive`` swallows exceptions of its callback, so the tests call the callback.
"""

import matplotlib
import pytest

from slamlab.hough import widgets as W

matplotlib.use("Agg")


@pytest.mark.parametrize("kw", [{"range_std_cells": 0.0, "H_min": 3, "delta_rho": 0.25},
                                {"range_std_cells": 1.0, "H_min": 80, "delta_rho": 3.0, "clutter": True}])
def test_accumulator_widget(capsys, kw):
    w = W.explore_accumulator()
    capsys.readouterr()
    w.f(**{**w.kwargs, **kw})
    out = capsys.readouterr().out
    assert out.strip()
    assert "Traceback" not in out
    if "Cannot run" not in out:  # the accumulator and the scan with its lines
        assert [len(matplotlib.pyplot.figure(n).axes) for n in matplotlib.pyplot.get_fignums()][-1] >= 2
    matplotlib.pyplot.close("all")


def test_slam_widget_extremes(capsys):
    w = W.explore_hough_slam(n_poses=21)
    capsys.readouterr()
    w.f(**{**w.kwargs, "n_poses": 21, "H_min": 80, "range_std_cells": 1.0, "method": "two_lines", "refine": False})
    out = capsys.readouterr().out
    assert ("Ex" in out or "error" in out or "Cannot run" in out)
    matplotlib.pyplot.close("all")
