"""The lab notebooks: nbgrader source format, student versions that run, autograding that scores right."""

from __future__ import annotations

import csv
import importlib.util
import shutil
from pathlib import Path

import nbformat
import pytest

ROOT = Path(__file__).resolve().parent.parent.parent
_spec = importlib.util.spec_from_file_location("labs_tool", ROOT / "tools" / "labs.py")
labs_tool = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(labs_tool)
LABS = labs_tool.lab_notebooks()


def _nbgrader_cells(nb):
    return [(c, c.metadata["nbgrader"]) for c in nb.cells if "nbgrader" in c.metadata]


def test_every_lab_belongs_to_a_chapter_notebook():
    assert LABS, "no notebooks/labs/*_lab.ipynb"
    for lab in LABS:
        assert (ROOT / "notebooks" / lab.name.replace("_lab.ipynb", ".ipynb")).is_file(), lab.name


def test_grade_ids_are_unique_across_every_lab():
    seen: dict[str, str] = {}
    for lab in LABS:
        for _, meta in _nbgrader_cells(nbformat.read(lab, as_version=4)):
            gid = meta["grade_id"]
            assert gid not in seen, f"grade id {gid!r} in {lab.name} and {seen[gid]}"
            seen[gid] = lab.name


@pytest.mark.parametrize("lab", LABS, ids=[p.name for p in LABS])
def test_lab_has_implementation_exploration_and_prose_tasks(lab):
    nb = nbformat.read(lab, as_version=4)
    cells = _nbgrader_cells(nb)
    solutions = [c for c, m in cells if m["solution"] and c.cell_type == "code"]
    checks = [c for c, m in cells if m["grade"] and c.cell_type == "code"]
    prose = [c for c, m in cells if m["solution"] and m["grade"] and c.cell_type == "markdown"]
    implementation = [c for c in checks if "sl.lab.check(" in c.source]
    exploration = [c for c in checks if "sl.lab.answer(" in c.source]
    assert 3 <= len(implementation) <= 5
    assert 2 <= len(exploration) <= 3
    assert prose
    assert all("### BEGIN SOLUTION" in c.source and "### END SOLUTION" in c.source for c in solutions)
    assert all(m.get("points", 0) > 0 and m["locked"] for c, m in cells if m["grade"] and c.cell_type == "code")


@pytest.fixture(scope="module")
def course(tmp_path_factory):
    pytest.importorskip("nbgrader")
    root = tmp_path_factory.mktemp("course")
    # nbgrader stops a cell after 30 s by default (a CellTimeoutError, and a lost point): on a loaded machine,
    # and with make test's two workers sharing the cores, a lab's exploration cell can take longer than that
    # (03's did, under load 7). nbgrader reads this file from the course folder.
    (root / "nbgrader_config.py").write_text("c = get_config()  # noqa: F821\nc.Execute.timeout = 600\n")
    students = labs_tool.make_student(root / "student", root)
    return root, students


@pytest.fixture(scope="module")
def autograded(course, tmp_path_factory):
    """One ``nbgrader autograde`` of two submissions: the instructor versions and the blank student versions.

    Both tests below read it: the scores, and the blank versions as nbgrader ran them (each lab's student
    version is executed once, here, rather than once more by nbclient for the student test).
    """
    root, students = course
    subs = tmp_path_factory.mktemp("submissions")
    (subs / "instructor").mkdir()
    (subs / "blank").mkdir()
    for lab in LABS:
        shutil.copy2(lab, subs / "instructor" / lab.name)
    for path in students:
        shutil.copy2(path, subs / "blank" / path.name)
    return labs_tool.autograde(subs, root)


@pytest.mark.slow
def test_student_versions_run_and_say_not_done_yet(course, autograded):
    """The student versions, executed by nbgrader (``NBGRADER_EXECUTION`` set), run without an error except
    in their check cells, and each check cell says "not done yet". Under nbgrader a check that has not passed
    prints its message and then raises it (so that the cell scores 0); outside nbgrader it only prints
    (``tests/lab/test_check.py``), so a student sees the message and no traceback."""
    root, students = course
    assert [p.name for p in students] == [p.name for p in LABS]
    for path in students:
        assert "### BEGIN SOLUTION" not in path.read_text(encoding="utf-8"), path.name
        nb = nbformat.read(root / "autograded" / "blank" / labs_tool.ASSIGNMENT / path.name, as_version=4)
        assert len([c for c in nb.cells if c.cell_type == "code"]) == len(
            [c for c in nbformat.read(path, as_version=4).cells if c.cell_type == "code"]), path.name
        for c in nb.cells:
            if c.cell_type != "code":
                continue
            assert c.execution_count is not None, f"{path.name}: not executed:\n{c.source}"
            assert "### BEGIN SOLUTION" not in c.source
            errors = [o for o in c.outputs if o.output_type == "error"]
            if "sl.lab.check(" in c.source or "sl.lab.answer(" in c.source:
                text = "".join(o.get("text", "") for o in c.outputs)
                assert "not done yet" in text, f"{path.name}: {c.source} printed {text!r}"
                assert all(o.ename == "AssertionError" and "not done yet" in o.evalue for o in errors), \
                    f"{path.name}: {c.source} raised {[(o.ename, o.evalue) for o in errors]}"
            else:
                assert not errors, f"{path.name}: error in\n{c.source}"


@pytest.mark.slow
def test_autograde_full_points_for_solutions_zero_for_blank(autograded):
    with autograded.open() as fh:
        rows = {r["student_id"]: r for r in csv.DictReader(fh)}
    auto_points = sum(m["points"] for lab in LABS for c, m in _nbgrader_cells(nbformat.read(lab, as_version=4))
                      if m["grade"] and c.cell_type == "code")
    assert float(rows["instructor"]["raw_score"]) == auto_points  # every autograded cell; prose is graded by hand
    assert float(rows["blank"]["raw_score"]) == 0.0


@pytest.mark.parametrize("lab", LABS, ids=[p.name for p in LABS])
def test_lab_checks_every_task_of_its_chapter_once(lab):
    import re

    from slamlab import lab as sl_lab

    nb = nbformat.read(lab, as_version=4)
    used = re.findall(r'sl\.lab\.(?:check|answer)\("([^"]+)"', "\n".join(c.source for c in nb.cells
                                                                       if c.cell_type == "code"))
    prefix = lab.name[:2] + "."
    assert sorted(used) == list(sl_lab.tasks_of(prefix)), f"{lab.name} checks {used}"
