"""Stored notebooks are fit to be nbval's reference (``tools/run_notebooks.py --check``)."""

from __future__ import annotations

import importlib.util
import re
from pathlib import Path

import nbformat
import pytest

ROOT = Path(__file__).resolve().parent.parent
NOTEBOOKS = sorted((ROOT / "notebooks").glob("*.ipynb"))
LABS = sorted((ROOT / "notebooks" / "labs").glob("*_lab.ipynb"))

FIRST_CELL = re.compile(
    r"%matplotlib inline\n"
    r"import numpy as np\n"
    r"import slamlab as sl\n"
    r"sl\.notebook_setup\(\)\n"
    r"SEED = \d+"
)


def _load_runner():
    spec = importlib.util.spec_from_file_location("run_notebooks", ROOT / "tools" / "run_notebooks.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


runner = _load_runner()


#: The browser suite's scratch notebook (tests/browser), which lives in notebooks/ for a few seconds while
#: that suite runs; under ``make test`` (pytest-xdist) it may run at the same time as this file.
BROWSER_SCRATCH = "zz_progress_check_"


def test_there_are_notebooks():
    assert NOTEBOOKS, "no notebooks/*.ipynb"
    found = [p for p in runner.default_notebooks() if not p.name.startswith(BROWSER_SCRATCH)]
    assert found == NOTEBOOKS + LABS


def test_filenames_numbered_uniquely():
    numbers = []
    for path in NOTEBOOKS:
        match = re.fullmatch(r"(\d\d)_[a-z0-9]+(_[a-z0-9]+)*\.ipynb", path.name)
        assert match, f"{path.name} is not named NN_topic.ipynb"
        numbers.append(match.group(1))
    assert len(numbers) == len(set(numbers)), f"repeated notebook numbers: {numbers}"


@pytest.fixture(params=NOTEBOOKS + LABS, ids=[p.name for p in NOTEBOOKS + LABS])
def notebook(request):
    return request.param, nbformat.read(request.param, as_version=4)


def test_stored_outputs_are_clean(notebook):
    path, nb = notebook
    problems = runner.check_notebook(nb, path.name)
    assert not problems, "\n".join(problems) + "\nFix the code, then run `make notebooks`."


def test_first_code_cell_is_the_shared_one(notebook):
    path, nb = notebook
    code = [c for c in nb.cells if c.cell_type == "code"]
    assert code, f"{path.name} has no code cell"
    assert FIRST_CELL.fullmatch(code[0].source.strip()), f"{path.name}: first code cell is\n{code[0].source}"


def test_widget_cells_ignore_output(notebook):
    path, nb = notebook
    for index, cell in enumerate(nb.cells):
        if cell.cell_type == "code" and "explore_" in cell.source:
            tags = cell.metadata.get("tags", [])
            assert "nbval-ignore-output" in tags, f"{path.name} cell {index}: widget cell needs nbval-ignore-output"


def test_no_skipped_cells(notebook):
    path, nb = notebook
    for index, cell in enumerate(nb.cells):
        tags = {t.lower() for t in cell.metadata.get("tags", [])}
        assert not tags & {"nbval-skip", "nbval_skip"}, f"{path.name} cell {index} is skipped by nbval"
        if cell.cell_type == "code":
            assert "NBVAL_SKIP" not in cell.source, f"{path.name} cell {index} is skipped by nbval"


# --- the checker itself, on small in-memory notebooks -------------------------------------------


def _nb(*cells):
    nb = nbformat.v4.new_notebook()
    nb.cells = list(cells)
    return nb


def _code(source, count, outputs=()):
    cell = nbformat.v4.new_code_cell(source, execution_count=count)
    cell.outputs = list(outputs)
    return cell


def test_check_accepts_clean_notebook():
    nb = _nb(nbformat.v4.new_markdown_cell("# t"), _code("1", 1), _code("2", 2))
    assert runner.check_notebook(nb, "t.ipynb") == []


def test_check_flags_every_problem():
    err = nbformat.v4.new_output("error", ename="ValueError", evalue="bad", traceback=[])
    stderr = nbformat.v4.new_output("stream", name="stderr", text="UserWarning: careful\n")
    cell = _code("x", 3, [err, stderr])
    cell.metadata["execution"] = {"iopub.status.busy": "2020"}
    nb = _nb(_code("a", None), cell, _code("  ", None))
    nb.metadata["widgets"] = {"state": {}}
    problems = "\n".join(runner.check_notebook(nb, "t.ipynb"))
    assert "raised ValueError: bad" in problems
    assert "wrote to stderr: 'UserWarning: careful'" in problems
    assert "volatile 'widgets'" in problems
    assert "volatile metadata 'execution'" in problems
    assert "execution count None, expected 1" in problems
    assert "execution count 3, expected 2" in problems
    assert "empty code cell" in problems


def test_strip_volatile_renumbers_and_removes_state():
    result = nbformat.v4.new_output("execute_result", data={"text/plain": "1"}, execution_count=7)
    a, b = _code("a", 5), _code("b", 7, [result])
    a.metadata["execution"] = {"x": 1}
    nb = _nb(a, b)
    nb.metadata["widgets"] = {"state": {}}
    nb.metadata["language_info"] = {"name": "python", "version": "3.11.7"}
    runner.strip_volatile(nb)
    assert [c.execution_count for c in nb.cells] == [1, 2]
    assert nb.cells[1].outputs[0].execution_count == 2
    assert "widgets" not in nb.metadata
    assert nb.metadata["language_info"] == {"name": "python"}
    assert runner.check_notebook(nb, "t.ipynb") == []
