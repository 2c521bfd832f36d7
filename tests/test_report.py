"""`make report`: a chapter notebook re-run by papermill with other parameters shows their results."""

from __future__ import annotations

import importlib.util
from pathlib import Path

import nbformat
import pytest

ROOT = Path(__file__).resolve().parent.parent
_spec = importlib.util.spec_from_file_location("report", ROOT / "tools" / "report.py")
report = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(report)


def _outputs(nb) -> str:
    return "".join(o.get("text", "") for c in nb.cells if c.cell_type == "code" for o in c.get("outputs", []))


def test_every_chapter_notebook_has_one_parameters_cell():
    for path in sorted((ROOT / "notebooks").glob("0[01]_*.ipynb")):
        nb = nbformat.read(path, as_version=4)
        tagged = [c for c in nb.cells if "parameters" in c.metadata.get("tags", [])]
        assert len(tagged) == (0 if path.name.startswith("00") else 1), path.name


@pytest.mark.slow
def test_report_runs_notebook_01_with_fewer_runs(tmp_path):
    out = report.run_report("1", report.parse_params(["CV_RUNS=5", "MC_RUNS=3"]), tmp_path)
    assert out.name == "01_kalman_filters-CV_RUNS=5-MC_RUNS=3.ipynb"
    nb = nbformat.read(out, as_version=4)
    injected = [c for c in nb.cells if "injected-parameters" in c.metadata.get("tags", [])]
    assert len(injected) == 1
    text = _outputs(nb)
    assert "CV target, 5 runs x 50 steps" in text  # the stored notebook says 50 runs
    assert "linearised KF diverged in" in text
    assert "of 3 runs" in text


def test_parse_params_reads_literals_and_words():
    assert report.parse_params(["N=3", "x=0.5", "detector=orb", "sizes=(1, 2)"]) == {
        "N": 3, "x": 0.5, "detector": "orb", "sizes": (1, 2)}
    with pytest.raises(SystemExit, match="NAME=value"):
        report.parse_params(["3=x"])
