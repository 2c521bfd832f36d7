"""Hough widgets: extreme slider values give a table or a readable message, never a traceback.

``ipywidgets.interactive`` swallows exceptions of its callback, so the tests call the callback.
"""

import re

import matplotlib
import pytest

from slamlab.studies.hough import widgets as W

matplotlib.use("Agg")


def _figures():
    plt = matplotlib.pyplot
    return [plt.figure(n) for n in plt.get_fignums()]


@pytest.mark.parametrize(("kw", "some_lines"), [({"range_std_cells": 0.0, "H_min": 3, "delta_rho": 0.25}, True),
                                                ({"range_std_cells": 1.0, "H_min": 80, "delta_rho": 3.0,
                                                  "clutter": True}, False)])
def test_accumulator_widget(capsys, kw, some_lines):
    w = W.explore_accumulator()
    capsys.readouterr()
    matplotlib.pyplot.close("all")  # the widget draws its defaults when built
    w.f(**{**w.kwargs, **kw})
    out = capsys.readouterr().out
    assert "Traceback" not in out
    assert "Cannot run" not in out
    m = re.search(r"pose 20: (\d+) returns, accumulator 180×(\d+) \(θ×ρ\), (\d+) peaks, (\d+) lines", out)
    assert m, out
    n_returns, n_rho, n_peaks, n_lines = (int(g) for g in m.groups())
    assert n_returns > 200
    # the rho axis spans ±r_max at the slider's Δρ: a finer Δρ gives a longer axis
    assert (n_rho > 700) if kw["delta_rho"] == 0.25 else (n_rho < 100)
    if some_lines:  # H_min = 3: walls give peaks and refitted lines
        assert n_peaks >= 5
        assert 3 <= n_lines <= n_peaks
    else:  # H_min = 80 is above every wall's vote count at Δρ = 3: nothing is found, and it says so
        assert (n_peaks, n_lines) == (0, 0)
    figs = _figures()
    assert len(figs) == 1
    assert len(figs[0].axes) >= 2
    matplotlib.pyplot.close("all")


def test_slam_widget_extremes(capsys):
    w = W.explore_hough_slam(n_poses=21)
    capsys.readouterr()
    matplotlib.pyplot.close("all")  # the widget draws its defaults when built
    w.f(**{**w.kwargs, "n_poses": 21, "H_min": 80, "range_std_cells": 1.0, "method": "two_lines", "refine": False})
    out = capsys.readouterr().out
    assert "Traceback" not in out
    assert "Cannot run" not in out
    # H_min = 80 finds no line in any scan: every one of the 20 steps falls back on odometry,
    # so the Hough SLAM row equals the odometry row
    assert "21 poses, range σ 1 cell" in out
    assert "20 lost steps" in out
    rows = {ln.split()[0]: ln.split()[-5:] for ln in out.splitlines() if ln.strip().startswith(("Hough", "odometry"))}
    assert rows["Hough"] == rows["odometry"]
    assert len(_figures()) == 1
    assert len(_figures()[0].axes) >= 3
    # a bad combination gives the message, not a traceback
    w.f(**{**w.kwargs, "delta_rho": 0.0})
    out = capsys.readouterr().out
    assert "Cannot run with these settings: `delta_rho` must be > 0" in out
    matplotlib.pyplot.close("all")


@pytest.mark.realdata
def test_real_log_widget(capsys):
    w = W.explore_real_log(n_scans=40)
    capsys.readouterr()
    matplotlib.pyplot.close("all")
    w.f(**{**w.kwargs, "name": "urg04lx", "n_scans": 40})
    out = capsys.readouterr().out
    assert out.startswith("URG-04LX log exp2.dat (raw odometry)")
    assert re.search(r"scans used\s+40\n", out)
    assert len(_figures()) == 1
    w.f(**{**w.kwargs, "H_min": 0})
    assert "Cannot run with these settings: `H_min` must be >= 1; got 0" in capsys.readouterr().out
    matplotlib.pyplot.close("all")
