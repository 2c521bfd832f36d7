"""The 2-D packages import no OpenCV, ipywidgets or pyplot (CONVENTIONS: imports stay light)."""

import subprocess
import sys
from pathlib import Path

import slamlab

HEAVY = ("cv2", "ipywidgets", "matplotlib.pyplot")
PACKAGES = "slamlab.sim, slamlab.correlation, slamlab.hough, slamlab.io, slamlab.scans, slamlab.geometry"


def _loaded(code: str) -> list[str]:
    out = subprocess.run([sys.executable, "-c", code + f"\nimport sys\nprint([m for m in {HEAVY!r} if m in sys.modules])"],
                         capture_output=True, text=True, check=True)
    return eval(out.stdout.strip().splitlines()[-1])


def test_2d_packages_import_nothing_heavy():
    # slamlab/__init__.py (not part of these packages) is bypassed: a bare package object with the same path
    root = str(Path(slamlab.__file__).parent)
    code = (f"import sys, types\npkg = types.ModuleType('slamlab'); pkg.__path__ = [{root!r}]\n"
            f"sys.modules['slamlab'] = pkg\nimport {PACKAGES}")
    assert _loaded(code) == []


def test_2d_packages_add_nothing_heavy_to_import_slamlab():
    base = set(_loaded("import slamlab"))
    assert set(_loaded(f"import {PACKAGES}")) <= base


def test_plot_and_widget_names_still_resolve_lazily():
    import slamlab.correlation as C
    import slamlab.hough as H

    assert callable(C.plot_log_localisation)
    assert callable(H.real_log_figure)
    assert "explore_log_scan" in dir(C)
    assert "explore_real_log" in dir(H)
