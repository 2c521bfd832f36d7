"""`make lab` starts JupyterLab for root too (containers, lab VMs): the README's first command must work."""

from __future__ import annotations

import os
import shutil
import subprocess
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent


@pytest.mark.skipif(shutil.which("make") is None, reason="make is not installed")
def test_make_lab_adds_allow_root_exactly_for_root():
    out = subprocess.run(["make", "-n", "lab", "LAB_ARGS=--no-browser"], cwd=ROOT, capture_output=True, text=True,
                         check=True).stdout
    line = next(x for x in out.splitlines() if "jupyter lab" in x)
    assert line.endswith("--no-browser notebooks/")
    assert ("--allow-root" in line) == (os.geteuid() == 0)
