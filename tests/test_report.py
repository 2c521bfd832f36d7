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


#: Chapter notebooks with a cell tagged ``parameters`` (00, the overview, has none).
PARAMETERISED = ("01", "02", "03", "04", "05", "06", "07", "08", "09", "10")


def test_every_chapter_notebook_has_one_parameters_cell():
    for number in ("00", *PARAMETERISED):
        path = report.find_notebook(number)
        nb = nbformat.read(path, as_version=4)
        tagged = [i for i, c in enumerate(nb.cells) if "parameters" in c.metadata.get("tags", [])]
        if number == "00":
            assert tagged == [], path.name
            continue
        # right after the shared first cell (which sets SEED), so papermill's values, SEED too, override both
        assert tagged == [1], path.name
        assert "SEED = " in nb.cells[0].source
        # every name it sets is used by the cells below
        names = [line.split("=")[0].strip() for line in nb.cells[1].source.splitlines()
                 if line and not line.startswith("#")]
        below = "".join(c.source for c in nb.cells[2:] if c.cell_type == "code")
        assert names, path.name
        for name in names:
            assert name in below, f"{path.name}: {name} unused"


@pytest.mark.slow
def test_report_runs_notebook_01_with_fewer_runs(tmp_path):
    out = report.run_report("1", report.parse_params(["CV_RUNS=5", "MC_RUNS=3"]), tmp_path)
    assert out.name == "01_kalman_filters-CV_RUNS=5-MC_RUNS=3.ipynb"
    nb = nbformat.read(out, as_version=4)
    injected = [c for c in nb.cells if "injected-parameters" in c.metadata.get("tags", [])]
    assert len(injected) == 1
    text = _outputs(nb)
    assert "CV target, 5 runs x 50 steps" in text  # the stored notebook says 50 runs
    assert "diverged: linearised KF" in text
    assert "of 3 runs" in text


def test_parse_params_reads_literals_and_words():
    assert report.parse_params(["N=3", "x=0.5", "detector=orb", "sizes=(1, 2)"]) == {
        "N": 3, "x": 0.5, "detector": "orb", "sizes": (1, 2)}
    with pytest.raises(SystemExit, match="NAME=value"):
        report.parse_params(["3=x"])


@pytest.mark.slow
@pytest.mark.realdata
def test_report_runs_notebook_06_with_fewer_poses(tmp_path, real_data):
    params = report.parse_params(["TABLE1_POSES=3", "MC_SIZE=4", "CONSTANTS_POSES=2", "SENSOR_POSES=2",
                                  "LOG_EVERY=300", "LOG_JOINED=(1, 3)"])
    out = report.run_report("06", params, tmp_path)
    assert out.name == ("06_correlation_localisation-TABLE1_POSES=3-MC_SIZE=4-CONSTANTS_POSES=2-SENSOR_POSES=2-"
                        "LOG_EVERY=300-LOG_JOINED=(1,3).ipynb")
    text = _outputs(nbformat.read(out, as_version=4))
    assert "every 300th from 300 to 900" in text
    assert "every 100th" not in text
    # the stored notebook says 10 / 12 / 6 poses
    assert "Table 1, 3 poses" in text
    assert "Monte Carlo, 4 poses" in text
    assert "Monte Carlo (4 poses): position exact" in text
    assert "2 poses, clutter of 004 Fig. 3b + 60 extra discs" in text
    assert "Beam aperture: the same 2 random poses" in text
    assert "Monte Carlo, 12 poses" not in text
