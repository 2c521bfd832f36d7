"""`make test-latest` (tools/test_latest.py): the lock/freeze version diff and the report, on small fixtures.

No network and no venv here: the parts that read pip's and the plugin's output are tested on text written below.
"""

from __future__ import annotations

import importlib.util
import json
import sys
from pathlib import Path

import nbformat
import pytest

ROOT = Path(__file__).resolve().parent.parent
_spec = importlib.util.spec_from_file_location("tools_test_latest", ROOT / "tools" / "test_latest.py")
tl = importlib.util.module_from_spec(_spec)
sys.modules[_spec.name] = tl  # the dataclass needs its module registered
_spec.loader.exec_module(tl)

LOCK = """\
# Exact versions of every package slamlab[test] installs
numpy==2.4.6; python_full_version >= "3.11"
numpy==2.2.6; python_full_version < "3.11"
opencv-python-headless==5.0.0.93
Jinja2==3.1.6
pyransac3d==0.7.0
"""

FREEZE = """\
-e git+https://example.org/slamlab@abc#egg=slamlab
jinja2==3.1.6
numpy==2.4.6
opencv_python_headless==5.1.0.95
slamlab-grading @ file:///work/main/grading
pip==26.0
"""


def _py311(marker: str) -> bool:
    """Markers as on Python 3.11 (the two numpy lines need it), independent of the interpreter running the test."""
    return {'python_full_version >= "3.11"': True, 'python_full_version < "3.11"': False}[marker]


def test_constraints_keep_the_lines_whose_marker_holds_and_normalise_names():
    assert tl.parse_constraints(LOCK, marker_holds=_py311) == {
        "numpy": "2.4.6", "opencv-python-headless": "5.0.0.93", "jinja2": "3.1.6", "pyransac3d": "0.7.0"}


def test_freeze_skips_editable_and_url_lines():
    assert tl.parse_freeze(FREEZE) == {"jinja2": "3.1.6", "numpy": "2.4.6", "opencv-python-headless": "5.1.0.95",
                                       "pip": "26.0"}


def test_version_diff_lists_changed_and_missing_packages_only():
    diff = tl.version_diff(tl.parse_constraints(LOCK, marker_holds=_py311), tl.parse_freeze(FREEZE))
    # jinja2 and numpy are equal; pip is the installer (skipped); pyransac3d is in the lock only (bench extra)
    assert diff == [("opencv-python-headless", "5.0.0.93", "5.1.0.95"), ("pyransac3d", "0.7.0", None)]
    table = tl.format_version_diff(diff)
    assert table.splitlines()[2].split() == ["opencv-python-headless", "5.0.0.93", "5.1.0.95"]
    assert table.splitlines()[3].split() == ["pyransac3d", "0.7.0", "—"]
    assert tl.format_version_diff([]) == "every installed package has the lock's version"


def test_first_difference():
    assert tl.first_difference("a\nb\nc\n", "a\nb\nc\n") is None
    assert tl.first_difference("a\nMSER 137\n", "a\nMSER 1798\n") == (2, "MSER 137", "MSER 1798")
    assert tl.first_difference("a\n", "a\nextra\n") == (2, "<none>", "extra")


def test_split_nodeid():
    assert tl.split_nodeid("notebooks/labs/02_x_lab.ipynb::Cell 4") == ("notebooks/labs/02_x_lab.ipynb", 4)
    with pytest.raises(ValueError, match="nodeid"):
        tl.split_nodeid("tests/test_x.py::test_y")


@pytest.fixture
def tiny_repo(tmp_path):
    """notebooks/02_t.ipynb: markdown, code (nbval Cell 0), markdown, code (Cell 1), code (Cell 2)."""
    nb = nbformat.v4.new_notebook()
    nb.cells = [nbformat.v4.new_markdown_cell("m"), nbformat.v4.new_code_cell("a"),
                nbformat.v4.new_markdown_cell("m"), nbformat.v4.new_code_cell("b"), nbformat.v4.new_code_cell("c")]
    (tmp_path / "notebooks").mkdir()
    nbformat.write(nb, tmp_path / "notebooks" / "02_t.ipynb")
    return tmp_path


def test_cells_from_records_maps_nbval_cells_to_ipynb_indices(tiny_repo):
    records = [
        {"nodeid": "notebooks/02_t.ipynb::Cell 1", "key": "stdout",
         "stored": "summary\nMSER (OpenCV)        137\n", "new": "summary\nMSER (OpenCV)       1798\n"},
        {"nodeid": "notebooks/02_t.ipynb::Cell 1", "failed": True, "message": "Cell outputs differ"},
        {"nodeid": "notebooks/02_t.ipynb::Cell 2", "failed": True, "message": "ValueError: `x` must be > 0"},
    ]
    cells = tl.cells_from_records(records, root=tiny_repo)
    assert cells == [
        tl.CellDiff("notebooks/02_t.ipynb", 1, 3, "stdout", 2, "MSER (OpenCV)        137", "MSER (OpenCV)       1798"),
        tl.CellDiff("notebooks/02_t.ipynb", 2, 4, "error", None, "", "ValueError: `x` must be > 0"),
    ]
    report = tl.format_report(cells, [("opencv-python-headless", "5.0.0.93", "5.1.0.95")], n_notebooks=3)
    lines = report.splitlines()
    assert lines[0] == "2 cell(s) differ in 1 of 3 notebook(s):"
    assert lines[1] == "  notebooks/02_t.ipynb cell 3 (nbval Cell 1), stdout line 2:"
    assert lines[2] == "      stored: MSER (OpenCV)        137"
    assert lines[3] == "      new:    MSER (OpenCV)       1798"
    assert lines[4] == "  notebooks/02_t.ipynb cell 4 (nbval Cell 2): error"
    assert "opencv-python-headless" in lines[-1]


def test_report_when_nothing_differs_and_long_lines_are_clipped():
    assert tl.format_report([], [], n_notebooks=21).splitlines()[0] == "no cell differs in 21 notebook(s)"
    cell = tl.CellDiff("notebooks/x.ipynb", 0, None, "stdout", 1, "s" * 300, "n")
    stored_line = tl.format_report([cell], [], 1).splitlines()[2]
    assert stored_line.endswith("…")
    assert len(stored_line) == len("      stored: ") + tl.MAX_LINE
    assert "cell ?" in tl.format_report([cell], [], 1)


def test_read_records_reads_every_process_file(tmp_path):
    (tmp_path / "1.jsonl").write_text(json.dumps({"nodeid": "a.ipynb::Cell 0", "failed": True}) + "\n")
    (tmp_path / "2.jsonl").write_text(json.dumps({"nodeid": "b.ipynb::Cell 1", "failed": True}) + "\n\n")
    assert [r["nodeid"] for r in tl.read_records(tmp_path)] == ["a.ipynb::Cell 0", "b.ipynb::Cell 1"]


def test_select_notebooks_takes_chapters_and_their_labs():
    names = [p.relative_to(ROOT).as_posix() for p in tl.select_notebooks(["02"])]
    assert names == ["notebooks/02_feature_detectors.ipynb", "notebooks/labs/02_feature_detectors_lab.ipynb"]
    everything = tl.select_notebooks(None)
    assert len(everything) == len(list((ROOT / "notebooks").glob("*.ipynb"))) + len(
        list((ROOT / "notebooks" / "labs").glob("*.ipynb")))
    with pytest.raises(ValueError, match="--only"):
        tl.select_notebooks(["99"])


def test_long_lines_are_shown_around_their_first_difference():
    stored, new = "x" * 150 + "0.54", "x" * 150 + "0.52"
    cell = tl.CellDiff("notebooks/x.ipynb", 0, 7, "stdout", 6, stored, new)
    lines = tl.format_report([cell], [], 1).splitlines()
    start = len(stored) - (tl.MAX_LINE - 1)  # the window ends with the lines (a full window, the change in view)
    assert lines[1] == f"  notebooks/x.ipynb cell 7 (nbval Cell 0), stdout line 6 from column {start + 1}:"
    assert lines[2] == "      stored: …" + stored[start:]
    assert lines[3] == "      new:    …" + new[start:]


def test_report_names_the_changed_files_when_a_cell_differs():
    cell = tl.CellDiff("notebooks/x.ipynb", 0, 1, "stdout", 1, "a", "b")
    report = tl.format_report([cell], [], 1, changed=["slamlab/a.py", "slamlab/b.py"])
    assert "the versions): slamlab/a.py, slamlab/b.py" in report
    assert "changed in the working tree" not in tl.format_report([], [], 1, changed=["slamlab/a.py"])
