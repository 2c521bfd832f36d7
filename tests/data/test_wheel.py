"""An installed copy (a wheel, not a checkout) has the registry and the project-made files it reads (issue 41), and
the labs' feedback files but not the instructor's grading (issue 43)."""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]

CHECK = """
import slamlab, slamlab.data as d, slamlab.sim as sim
assert slamlab.__file__.startswith({target!r}), slamlab.__file__
assert d.project_root() is None                      # not a checkout
room = d.find_data("test_room_200.txt")
assert str(room).startswith({target!r}) and room.is_file(), room
assert sim.test_room_200().shape == (200, 200)
assert d.project_data_dir() == d.bundled_data_dir()  # no longer raises outside a checkout
from slamlab import lab                               # the labs' feedback files ship (issue 43)
assert len(lab.task_ids()) > 50 and lab.task_ids("08.")
print(len(d.registry().files), d.cache_dir())
"""


@pytest.mark.slow
def test_installed_wheel_reads_its_own_files(tmp_path):
    src = tmp_path / "src"  # a copy of what the wheel is built from, so nothing is built inside the checkout
    shutil.copytree(ROOT / "slamlab", src / "slamlab", ignore=shutil.ignore_patterns("__pycache__"))
    for name in ("pyproject.toml", "README.md"):
        shutil.copy(ROOT / name, src / name)
    wheels = tmp_path / "wheels"
    subprocess.run([sys.executable, "-m", "pip", "wheel", "--no-deps", "-q", str(src), "-w", str(wheels)],
                   check=True, capture_output=True)
    (wheel,) = wheels.glob("slamlab-*.whl")
    import zipfile

    names = zipfile.ZipFile(wheel).namelist()
    assert any(n.startswith("slamlab/lab/feedback/") and n.endswith(".json") for n in names)
    assert not any("grading" in n for n in names), "the instructor's grading is not part of the wheel"
    target = tmp_path / "site"
    subprocess.run([sys.executable, "-m", "pip", "install", "--no-deps", "-q", "--target", str(target), str(wheel)],
                   check=True, capture_output=True)
    elsewhere = tmp_path / "elsewhere"
    elsewhere.mkdir()
    env = {k: v for k, v in os.environ.items() if k not in ("SLAMLAB_DATA", "SLAMLAB_DATA_URL")}
    env |= {"PYTHONPATH": str(target), "SLAMLAB_CACHE": str(tmp_path / "cache")}
    out = subprocess.run([sys.executable, "-c", CHECK.format(target=str(target))], check=False, cwd=elsewhere,
                         env=env,
                         capture_output=True, text=True)
    assert out.returncode == 0, out.stderr
    n_files, cache = out.stdout.split()
    assert int(n_files) > 300
    assert cache == str((tmp_path / "cache").resolve())
    listing = subprocess.run([sys.executable, "-m", "slamlab.data", "list"], check=False, cwd=elsewhere, env=env,
                             capture_output=True, text=True)
    assert listing.returncode == 0, listing.stderr
    assert "carmen-radish-corrected  (5 files" in listing.stdout
