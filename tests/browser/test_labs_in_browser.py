"""The labs in a real browser: the same checks as the chapters' (test_notebooks_in_browser.py), in a file of
their own so that pytest-xdist's ``--dist loadfile`` runs them on the other worker, beside the chapters."""

from __future__ import annotations

import importlib.util
from pathlib import Path

import pytest

_spec = importlib.util.spec_from_file_location("_browser_suite", Path(__file__).with_name("test_notebooks_in_browser.py"))
suite = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(suite)

pytestmark = pytest.mark.browser
# the same module-scoped fixtures: this file gets a JupyterLab server and a Chromium of its own
lab_server = suite.lab_server
browser = suite.browser


@pytest.mark.parametrize("notebook", suite.LABS, ids=[p.name for p in suite.LABS])
def test_lab_runs_in_jupyterlab(lab_server, browser, notebook):
    """The lab runs in JupyterLab: every cell, no error, every widget view, one control moved."""
    suite.test_notebook_runs_in_jupyterlab(lab_server, browser, notebook)


# --- a student in the browser (issue 26, goal 4) -------------------------------------------------------------
#: Lab 08: its cells are quick (its explorations' accepted ranges are closed forms).
STUDENT_LAB = "08_probabilistic_localisation_lab.ipynb"
STUDENT_PATH = "labs/student_in_browser_08.ipynb"  # relative to the server's root (notebooks/); removed after
WRONG_TASK = '''def low_variance(weights, n, r):
    c = np.cumsum(np.asarray(weights, dtype=float))
    return np.searchsorted(c / c[-1], r + np.arange(n) / n, side="left")
'''
RIGHT_TASK = '''def low_variance(weights, n, r):
    c = np.cumsum(np.asarray(weights, dtype=float))
    c = c / c[-1]
    c[-1] = 1.0
    return np.minimum(np.searchsorted(c, r + np.arange(n) / n, side="right"), len(c) - 1)
'''
WRONG_NUMBER = "def surviving_fraction():\n    return 1.0\n"  # the low-variance sampler's answer, not multinomial's
RIGHT_NUMBER = "def surviving_fraction():\n    return 0.632\n"

_SET_SOURCE = """([path, i, src]) => {
    const panel = [...window.jupyterapp.shell.widgets('main')].find(w => w.context && w.context.path === path);
    panel.content.widgets[i].model.sharedModel.setSource(src);
}"""
_OUTPUT_TEXT = """([path, i]) => {
    const panel = [...window.jupyterapp.shell.widgets('main')].find(w => w.context && w.context.path === path);
    const area = panel.content.widgets[i].node.querySelector('.jp-OutputArea');
    return area ? area.textContent : '';
}"""


def _student_version(tmp_path) -> dict:
    """Lab 08's student version, as `make student` writes it (nbgrader generate_assignment)."""
    import nbformat

    spec = importlib.util.spec_from_file_location("labs_tool", suite.ROOT / "tools" / "labs.py")
    labs_tool = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(labs_tool)
    pytest.importorskip("nbgrader")
    students = labs_tool.make_student(tmp_path / "student", tmp_path / "course")
    path = next(p for p in students if p.name == STUDENT_LAB)
    return nbformat.read(path, as_version=4)


def _cell_index(nb, grade_id: str) -> int:
    return next(i for i, c in enumerate(nb.cells) if c.metadata.get("nbgrader", {}).get("grade_id") == grade_id)


def test_student_reads_the_hint_then_passes(lab_server, browser, tmp_path):
    """A student opens lab 08's student version in JupyterLab, writes a wrong sampler (``side="left"``) and a
    wrong number, runs all cells: both checks show a hint, no traceback; then right ones: both say "passed"."""
    import json as _json
    import urllib.request as _request

    base, token = lab_server
    nb = _student_version(tmp_path)
    task, task_check = _cell_index(nb, "lab08_t1_solution"), _cell_index(nb, "lab08_t1_check")
    number, number_check = _cell_index(nb, "lab08_e1_solution"), _cell_index(nb, "lab08_e1_check")
    body = _json.dumps({"type": "notebook", "format": "json", "content": nb}).encode()
    url = f"{base}/api/contents/{STUDENT_PATH}?token={token}"
    _request.urlopen(_request.Request(url, data=body, method="PUT"), timeout=30).close()
    page = browser.new_page(viewport={"width": 1400, "height": 1000})
    try:
        page.goto(f"{base}/lab/workspaces/student08/tree/{STUDENT_PATH}?reset&token={token}", timeout=60_000)
        suite._wait_for_kernel(page, STUDENT_PATH)
        for attempt, (impl, value) in enumerate([(WRONG_TASK, WRONG_NUMBER), (RIGHT_TASK, RIGHT_NUMBER)]):
            page.evaluate(_SET_SOURCE, [STUDENT_PATH, task, impl])
            page.evaluate(_SET_SOURCE, [STUDENT_PATH, number, value])
            suite._run_all(page, STUDENT_PATH)
            checked = page.evaluate(_OUTPUT_TEXT, [STUDENT_PATH, task_check])
            answered = page.evaluate(_OUTPUT_TEXT, [STUDENT_PATH, number_check])
            problems = suite._problems(page)
            assert not problems, f"attempt {attempt}: " + "; ".join(problems)  # no traceback, nothing on stderr
            assert "Traceback" not in checked + answered
            if attempt == 0:
                assert "is wrong" in checked, checked
                assert "hint:" in checked, checked
                assert "is not it" in answered, answered
                assert "Hint:" in answered, answered
                assert "searchsorted" not in checked + answered  # a hint names the misconception, not the code
            else:
                assert "passed" in checked, checked
                assert "passed" in answered, answered
    finally:
        page.close()
        suite._shut_down_sessions(base, token, STUDENT_PATH)
        _request.urlopen(_request.Request(url, method="DELETE"), timeout=30).close()
