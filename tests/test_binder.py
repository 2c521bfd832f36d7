"""The Binder / repo2docker environment installs our lock (pip --dry-run against constraints.txt)."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent


def test_binder_files_point_at_the_lock():
    req = (ROOT / "binder" / "requirements.txt").read_text().split("\n")
    assert "-c ../constraints.txt" in req
    assert "-e ." in req
    assert (ROOT / "binder" / "runtime.txt").read_text().strip() == "python-3.11"


@pytest.mark.slow
def test_binder_requirements_resolve_against_constraints():
    """pip resolves the Binder requirements with every pin of the lock (a conflict fails the run)."""
    proc = subprocess.run(
        [sys.executable, "-m", "pip", "install", "--dry-run", "--ignore-installed", "--quiet", "--report", "-",
         "-r", "binder/requirements.txt"],
        cwd=ROOT, capture_output=True, text=True, timeout=600, check=False,
    )
    assert proc.returncode == 0, proc.stderr[-2000:]
    import json

    report = json.loads(proc.stdout)
    pins = dict(line.split(";")[0].strip().split("==") for line in (ROOT / "constraints.txt").read_text().splitlines()
                if "==" in line and not line.startswith("#"))
    installed = {item["metadata"]["name"].lower().replace("_", "-"): item["metadata"]["version"]
                 for item in report["install"]}
    assert "slamlab" in installed
    for name in ("numpy", "scipy", "opencv-python-headless", "jupyterlab", "ipywidgets"):
        assert installed[name] == pins[name], name
