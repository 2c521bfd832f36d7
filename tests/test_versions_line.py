"""Every notebook's and lab's first output states the versions its outputs were stored with (issue: dependency drift).

The stored line must name the versions of the lock (``constraints.txt``), the environment ``make notebooks`` stores
outputs in; nbval's sanitiser masks the numbers, so this test is what keeps the line honest after ``make lock``.
"""

from __future__ import annotations

import json
import re
import subprocess
import sys
from pathlib import Path

import pytest

import slamlab as sl

ROOT = Path(__file__).resolve().parents[1]
NOTEBOOKS = sorted((ROOT / "notebooks").glob("[0-9][0-9]_*.ipynb")) + sorted(
    (ROOT / "notebooks" / "labs").glob("[0-9][0-9]_*.ipynb"))


def _lock() -> dict[str, str]:
    pins = {}
    for line in (ROOT / "constraints.txt").read_text().splitlines():
        m = re.match(r"^([A-Za-z0-9_.-]+)==([^\s;#]+)", line.strip())
        if m:
            pins[m.group(1).lower()] = m.group(2)
    return pins


def _expected_line() -> str:
    pins = _lock()
    return (f"stored with numpy {pins['numpy']} · scipy {pins['scipy']} · "
            f"OpenCV {pins['opencv-python-headless']} · slamlab {sl.__version__}")


def test_versions_line_reads_the_installed_distributions():
    import cv2
    import numpy as np
    import scipy

    line = sl.versions_line()
    assert line.startswith("stored with numpy ")
    assert f"numpy {np.__version__} ·" in line
    assert f"scipy {scipy.__version__} ·" in line
    # cv2.__version__ is the library's (5.0.0); the wheel's version adds the build (5.0.0.93)
    assert re.search(rf"OpenCV {re.escape(cv2.__version__)}(\.\d+)? ·", line), line
    assert line.endswith(f"slamlab {sl.__version__}")
    assert len(line) <= 110


def test_notebook_setup_prints_the_line_first():
    # in a fresh process: notebook_setup changes numpy's print options and the heap of the process it runs in
    code = ("import slamlab as sl\n"
            "sl.notebook_setup()\n"
            "print('--')\n"
            "sl.notebook_setup(show_versions=False)\n"
            "print('--')")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    assert out == sl.versions_line() + "\n--\n--\n"


@pytest.mark.parametrize("path", NOTEBOOKS, ids=lambda p: p.relative_to(ROOT / "notebooks").as_posix())
def test_first_output_states_the_lock_versions(path):
    nb = json.loads(path.read_text())
    first = next(c for c in nb["cells"] if c["cell_type"] == "code")
    assert "sl.notebook_setup()" in "".join(first["source"])
    streams = [o for o in first.get("outputs", []) if o.get("output_type") == "stream"]
    assert streams, f"{path.name}: the first code cell has no printed output (re-execute the notebook)"
    text = "".join(streams[0]["text"]).splitlines()[0]
    assert text == _expected_line(), (
        f"{path.name}: the first output says {text!r}; the lock gives {_expected_line()!r} "
        "(re-execute the notebooks in the lock's venv: make notebooks)")
