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


# --- a student in the browser (issue 26, goal 4; issue 43, item 6) -------------------------------------------
#: Three labs whose student versions run quickly; each is filled from its autograde submissions
#: (tests/lab/submissions/labNN.py): a named mistake, then the independent method.
STUDENT_LABS = ("01_kalman_filters_lab.ipynb", "04_landmark_stores_lab.ipynb", "08_probabilistic_localisation_lab.ipynb")
#: The student's kernel: slamlab's wheel only, no instructor package (the IPython startup file blocks it).
NO_GRADING = """
import sys as _sys
class _NoGrading:
    def find_spec(self, name, path=None, target=None):
        if name.split(".")[0] == "slamlab_grading":
            raise ModuleNotFoundError("No module named 'slamlab_grading'")
_sys.meta_path.insert(0, _NoGrading())
del _sys, _NoGrading
"""
PROBE = """
import importlib.util
try:
    importlib.util.find_spec("slamlab_grading")
    grading = "importable"
except ModuleNotFoundError:
    grading = "absent"
print("GRADING", grading, [n for n in dir(sl.lab) if any(w in n.lower() for w in ("accept", "reference", "why", "solution"))])
"""

_SET_SOURCE = """([path, i, src]) => {
    const panel = [...window.jupyterapp.shell.widgets('main')].find(w => w.context && w.context.path === path);
    panel.content.widgets[i].model.sharedModel.setSource(src);
}"""
_OUTPUT_TEXT = """([path, i]) => {
    const panel = [...window.jupyterapp.shell.widgets('main')].find(w => w.context && w.context.path === path);
    const area = panel.content.widgets[i].node.querySelector('.jp-OutputArea');
    return area ? area.textContent : '';
}"""


@pytest.fixture(scope="module")
def student_server(tmp_path_factory):
    """A JupyterLab server whose kernels cannot import the instructor's grading package (a student's)."""
    yield from suite.start_lab_server(tmp_path_factory, kernel_startup=NO_GRADING)


@pytest.fixture(scope="module")
def student_versions(tmp_path_factory):
    """The labs' student versions, as `make student` writes them (nbgrader generate_assignment)."""
    import nbformat

    spec = importlib.util.spec_from_file_location("labs_tool", suite.ROOT / "tools" / "labs.py")
    labs_tool = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(labs_tool)
    pytest.importorskip("nbgrader")
    tmp = tmp_path_factory.mktemp("student")
    return {p.name: nbformat.read(p, as_version=4) for p in labs_tool.make_student(tmp / "student", tmp / "course")}


def _cell_index(nb, grade_id: str) -> int:
    return next(i for i, c in enumerate(nb.cells) if c.metadata.get("nbgrader", {}).get("grade_id") == grade_id)


def _wrong_form(spec: dict):
    """An answer of the wrong form for an exploration's feedback record (a count for a fraction, a half step)."""
    import math

    lo, hi = spec["bounds"]
    if spec["integer"]:
        return (lo if math.isfinite(lo) else 0.0) + 0.5
    if math.isfinite(hi):
        return hi * 1000.0 + 1.0
    return "'about right'"


@pytest.mark.parametrize("lab_name", STUDENT_LABS)
def test_student_reads_the_hint_then_passes_with_another_method(student_server, browser, student_versions, lab_name):
    """A student opens a lab's student version in JupyterLab (a kernel without the grading package): a named mistake
    in an implementation task and an answer of the wrong form give their hints and no traceback; the same task
    written by another method than the instructor's passes, and the exploration's answer is recorded; nothing in
    the kernel can import the grading or names an accepted range, a reference or a solution."""
    import json as _json
    import sys
    import urllib.request as _request

    import nbformat

    from slamlab.lab import feedback

    sys.path.insert(0, str(suite.ROOT / "tests" / "lab"))
    from submissions import of_lab, replace_solution

    num = lab_name[:2]
    source = nbformat.read(suite.ROOT / "notebooks" / "labs" / lab_name, as_version=4)
    subs = of_lab(num)
    right = next(s for s in subs if s.kind == "independent")
    mistake = next(s for s in subs if s.kind.startswith("mistake_") and any(p.startswith("t") for p in s.lost))
    part = next(p for p in mistake.lost if p.startswith("t") and p in mistake.bodies)
    nb = student_versions[lab_name]
    task, task_check = _cell_index(nb, f"lab{num}_{part}_solution"), _cell_index(nb, f"lab{num}_{part}_check")
    number, number_check = _cell_index(nb, f"lab{num}_e1_solution"), _cell_index(nb, f"lab{num}_e1_check")
    setup = _cell_index(nb, f"lab{num}_setup")

    def full(grade_id: str, body: str) -> str:
        return replace_solution(source.cells[_cell_index(source, grade_id)].source, body)

    e1_id = next(c.source.split('"')[1] for c in nb.cells if c.metadata.get("nbgrader", {}).get("grade_id") ==
                 f"lab{num}_e1_check")
    wrong_number = f"return {_wrong_form(feedback.load(num)['tasks'][e1_id])}"
    path = f"labs/student_in_browser_{num}.ipynb"  # relative to the server's root (notebooks/); removed after
    base, token = student_server
    body = _json.dumps({"type": "notebook", "format": "json", "content": nb}).encode()
    url = f"{base}/api/contents/{path}?token={token}"
    _request.urlopen(_request.Request(url, data=body, method="PUT"), timeout=30).close()
    page = browser.new_page(viewport={"width": 1400, "height": 1000})
    try:
        page.goto(f"{base}/lab/workspaces/student{num}/tree/{path}?reset&token={token}", timeout=60_000)
        suite._wait_for_kernel(page, path)
        page.evaluate(_SET_SOURCE, [path, setup, nb.cells[setup].source + "\n" + PROBE])
        for attempt, (impl, value) in enumerate([(mistake.bodies[part], wrong_number),
                                                 (right.bodies[part], right.bodies["e1"])]):
            page.evaluate(_SET_SOURCE, [path, task, full(f"lab{num}_{part}_solution", impl)])
            page.evaluate(_SET_SOURCE, [path, number, full(f"lab{num}_e1_solution", value)])
            suite._run_all(page, path)
            checked = page.evaluate(_OUTPUT_TEXT, [path, task_check])
            answered = page.evaluate(_OUTPUT_TEXT, [path, number_check])
            probe = page.evaluate(_OUTPUT_TEXT, [path, setup])
            problems = suite._problems(page)
            assert not problems, f"attempt {attempt}: " + "; ".join(problems)  # no traceback, nothing on stderr
            assert "Traceback" not in checked + answered
            assert "GRADING absent []" in probe, probe
            if attempt == 0:
                assert "is wrong" in checked or "raised" in checked, checked
                assert "hint:" in checked, checked
                assert any(w in answered for w in ("outside", "whole number", "expected a number")), answered
            else:
                assert "passed the" in checked, checked
                assert "recorded" in answered, answered
            for word in ("accepted", "is not it", "Hint:"):  # the student's kernel never grades an exploration
                assert word not in answered, answered
    finally:
        page.close()
        suite._shut_down_sessions(base, token, path)
        _request.urlopen(_request.Request(url, method="DELETE"), timeout=30).close()
