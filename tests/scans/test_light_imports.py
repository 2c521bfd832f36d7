"""The plot and widget names of correlation and hough load on first use (tests/test_imports.py checks that
importing the 2-D packages loads no cv2, ipywidgets or pyplot)."""

import subprocess
import sys

HEAVY = ("cv2", "ipywidgets", "matplotlib.pyplot")
PACKAGES = "slamlab.sim, slamlab.correlation, slamlab.hough, slamlab.io, slamlab.scans, slamlab.geometry"


def _loaded(code: str) -> list[str]:
    out = subprocess.run([sys.executable, "-c", code + f"\nimport sys\nprint([m for m in {HEAVY!r} if m in sys.modules])"],
                         capture_output=True, text=True, check=True)
    return eval(out.stdout.strip().splitlines()[-1])


def test_plot_and_widget_names_still_resolve_lazily():
    import slamlab.correlation as C
    import slamlab.hough as H

    assert callable(C.plot_log_localisation)
    assert callable(H.real_log_figure)
    assert "explore_log_scan" in dir(C)
    assert "explore_real_log" in dir(H)
