"""The plot and widget names of correlation and hough, and of their studies, load on first use (tests/test_imports.py
checks that importing the 2-D packages loads no cv2, ipywidgets or pyplot)."""

import subprocess
import sys

HEAVY = ("cv2", "ipywidgets", "matplotlib.pyplot")
PACKAGES = ("slamlab.sim, slamlab.correlation, slamlab.hough, slamlab.io, slamlab.scans, slamlab.geometry, "
            "slamlab.studies.correlation, slamlab.studies.hough")


def _loaded(code: str) -> list[str]:
    out = subprocess.run([sys.executable, "-c", code + f"\nimport sys\nprint([m for m in {HEAVY!r} if m in sys.modules])"],
                         capture_output=True, text=True, check=True)
    return eval(out.stdout.strip().splitlines()[-1])


def test_plot_and_widget_names_still_resolve_lazily():
    import slamlab.correlation as C
    import slamlab.hough as H
    import slamlab.studies.correlation as CS
    import slamlab.studies.hough as HS

    assert callable(C.plot_grid)
    assert callable(H.plot_accumulator)
    assert callable(CS.plot_log_localisation)
    assert callable(HS.real_log_figure)
    assert "explore_log_scan" in dir(CS)
    assert "explore_real_log" in dir(HS)


def test_importing_the_2d_packages_and_their_studies_loads_nothing_heavy():
    assert _loaded(f"import {PACKAGES}") == []
