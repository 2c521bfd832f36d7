"""Ch. 9 widgets: any slider values give a result or a readable message, never a traceback.

``ipywidgets.interactive`` swallows exceptions of its callback, so the tests call the callback.
"""

from __future__ import annotations

import matplotlib
import pytest

matplotlib.use("Agg")

W = pytest.importorskip("slamlab.studies.mono.widgets")


def _call(w, capsys, **kw):
    capsys.readouterr()
    matplotlib.pyplot.close("all")
    w.f(**{**w.kwargs, **kw})
    out = capsys.readouterr().out
    matplotlib.pyplot.close("all")
    assert "Traceback" not in out
    return out


def test_depth_filter_explorer_extremes(capsys):
    w = W.explore_depth_filter()
    out = _call(w, capsys, outlier_rate=0.9, tau=10**-1, n_obs=5)
    assert "Depth-filter convergence (tau = 0.1 1/m" in out
    assert "90" in out


def test_failure_case_selector_and_prior_toggle(capsys):
    w = W.explore_failure_cases(n_frames=12)
    out = _call(w, capsys, case="little_texture", motion_model="constant_position")
    assert "little_texture: 12 frames, correctly tracked 0 %" in out
    assert "too few tracked frames" in out
    out = _call(w, capsys, case="normal", motion_model="constant_velocity")
    assert "normal: 12 frames" in out


def test_motion_prior_widget(capsys):
    w = W.explore_motion_prior(n_frames=10)
    out = _call(w, capsys, sequence="arc", motion_model="constant_position", n_frames=10)
    assert "arc, constant_position: 10 frames" in out
