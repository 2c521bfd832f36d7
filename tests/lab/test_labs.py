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


# --- four generated submissions per lab --------------------------------------------------------------------
# correct: the instructor solution, each exploration answered with the instructor's number (read from the stored
#          output of its check cell: a student may answer from any experiment, and the test need not rerun it);
# wrong:   a plausible wrong implementation of task 1, the last task raising (no other task calls it; an
#          exception must cost that task only), a typical wrong number for one exploration, the other
#          explorations not done; the other tasks right. (Wrong and raising were two submissions until issue 25:
#          one submission runs the lab once less, ~5 s of CI per lab, and tests the same cells.)
# empty:   the student version untouched.
#: Task 1 of each lab made wrong the way a student might: (text in the solution, its wrong replacement).
WRONG_TASK = {
    "01": ("F @ P @ F.T + Q", "F @ P @ F.T"),  # the process noise forgotten
    "02": ("II[1:, 1:] =", "II[:-1, :-1] ="),  # the zero row and column at the wrong end
    "03": ("D = np.sqrt(", "D = ("),  # squared distances
    "04": ("while sizes[i] > max_size(i):", "while sizes[i] >= max_size(i):"),  # a full tree merged
    "05": ("return (p1 + p2) / 2,", "return p1,"),  # the point on the first ray, not the midpoint
    "06": ("x + c * px - s * py, y + s * px + c * py", "x + c * px + s * py, y - s * px + c * py"),  # R transposed
    "07": ("theta = -np.pi / 2 + delta_theta_rad", "theta = delta_theta_rad"),  # theta from 0 instead of -pi/2
    "08": ('side="right"', 'side="left"'),  # the off-by-one at ties
    "09": ("C2 = b / (a + b) / rho_range", "C2 = b / (a + b)"),  # the uniform density forgotten
    "10": ("np.linalg.inv(odometry[-1]) @ odometry", "np.linalg.inv(odometry[0]) @ odometry"),  # the first line
}
#: The exploration answered wrong in the "wrong" submission: one whose check is quick.
WRONG_EXPLORATION = {"01": "e2", "02": "e1", "03": "e2", "04": "e2", "05": "e2", "06": "e1", "07": "e1",
                     "08": "e2", "09": "e2", "10": "e2"}
SUBMISSIONS = ("correct", "wrong", "empty")


def _replace_solution(source: str, body: str) -> str:
    """``source`` with the lines between ``### BEGIN SOLUTION`` and ``### END SOLUTION`` replaced by ``body``."""
    begin, end = source.index("### BEGIN SOLUTION"), source.index("### END SOLUTION")
    indent = source[source.rindex("\n", 0, begin) + 1:begin]
    return source[:begin] + "### BEGIN SOLUTION\n" + indent + body + "\n" + indent + source[end:]


def _stored_answer(nb, ex: str) -> float:
    """The number the instructor version's exploration ``ex`` passed with (its check cell's stored output)."""
    import re

    cell = next(c for c in nb.cells if c.metadata.get("nbgrader", {}).get("grade_id", "").endswith(f"_{ex}_check"))
    text = "".join(o.get("text", "") for o in cell.outputs)
    return float(re.search(r"— (\S+): passed\.", text).group(1))


def _last_task(nb) -> str:
    """The last implementation task of a lab ("t4"): the one the wrong submission makes raise (no later task calls it)."""
    parts = [c.metadata["nbgrader"]["grade_id"].split("_")[1] for c in nb.cells
             if c.metadata.get("nbgrader", {}).get("grade_id", "").endswith("_check")]
    return max(p for p in parts if p.startswith("t"))


def make_submission(lab: Path, kind: str):
    """The notebook a student of kind ``kind`` ("correct" or "wrong") hands in for ``lab``."""
    from slamlab import lab as sl_lab

    nb = nbformat.read(lab, as_version=4)
    num = lab.name[:2]
    assert _last_task(nb) != "t1", f"{lab.name}: the wrong submission needs task 1 and the last task apart"
    for c in nb.cells:
        gid = c.metadata.get("nbgrader", {}).get("grade_id", "")
        if not gid.endswith("_solution") or c.cell_type != "code":
            continue
        part = gid.split("_")[1]  # t1, t2, ..., e1, e2
        if part.startswith("e"):
            if kind == "correct":
                c.source = _replace_solution(c.source, f"return {_stored_answer(nb, part)!r}")
            elif kind == "wrong" and part == WRONG_EXPLORATION[num]:
                check = next(d for d in nb.cells if d.metadata.get("nbgrader", {}).get("grade_id") == f"lab{num}_{part}_check")
                task_id = check.source.split('"')[1]
                c.source = _replace_solution(c.source, f"return {float(sl_lab.task(task_id).wrong[0].value())!r}")
            else:
                c.source = _replace_solution(c.source, "raise NotImplementedError()")
        elif kind == "wrong" and part == "t1":
            old, new = WRONG_TASK[num]
            assert c.source.count(old) == 1, f"{lab.name}: {old!r} in\n{c.source}"
            c.source = c.source.replace(old, new)
        elif kind == "wrong" and part == _last_task(nb):
            c.source = _replace_solution(c.source, 'raise IndexError("index 3 is out of bounds")')
    return nb


def expected_points(lab: Path, kind: str) -> dict[str, float]:
    """Points per autograded cell of ``lab`` for a submission of kind ``kind``, from the notebook's metadata."""
    out = {}
    for c, m in _nbgrader_cells(nbformat.read(lab, as_version=4)):
        if not (m["grade"] and c.cell_type == "code"):
            continue
        part = m["grade_id"].split("_")[1]
        lost = (kind == "empty"
                or (kind == "wrong" and (part in ("t1", _last_task(nbformat.read(lab, as_version=4)))
                                         or part.startswith("e"))))
        out[m["grade_id"]] = 0.0 if lost else float(m["points"])
    return out


@pytest.fixture(scope="module")
def autograded(course, tmp_path_factory):
    """One ``nbgrader autograde`` of four submissions of every lab (see ``make_submission``).

    The tests below read it: the scores, and the empty student versions as nbgrader ran them (each lab's
    student version is executed once, here, rather than once more by nbclient for the student test).
    """
    root, students = course
    subs = tmp_path_factory.mktemp("submissions")
    for kind in SUBMISSIONS:
        (subs / kind).mkdir()
    for lab, student in zip(LABS, students, strict=True):
        shutil.copy2(student, subs / "empty" / student.name)
        for kind in ("correct", "wrong"):
            nbformat.write(make_submission(lab, kind), subs / kind / lab.name)
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
        nb = nbformat.read(root / "autograded" / "empty" / labs_tool.ASSIGNMENT / path.name, as_version=4)
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
def test_autograde_gives_each_submission_its_points_per_task(autograded):
    """Every autograded cell of every submission scores what the notebooks' metadata says it should."""
    with (autograded.parent / "grades_by_task.csv").open() as fh:
        got = {(r["student_id"], r["notebook"], r["grade_id"]): float(r["score"]) for r in csv.DictReader(fh)}
    expected = {(kind, lab.stem, gid): pts for kind in SUBMISSIONS for lab in LABS
                for gid, pts in expected_points(lab, kind).items()}
    wrong = {k: (v, got.get(k)) for k, v in expected.items() if got.get(k) != v}
    assert not wrong, f"(submission, lab, cell): (expected, scored): {wrong}"
    assert set(got) == set(expected)
    with autograded.open() as fh:
        totals = {r["student_id"]: float(r["raw_score"]) for r in csv.DictReader(fh)}
    for kind in SUBMISSIONS:  # nbgrader's own grades.csv: the total of the autograded points (prose is by hand)
        assert totals[kind] == sum(v for (k, _, _), v in expected.items() if k == kind), kind
    assert totals["empty"] == 0.0
    assert totals["correct"] == sum(m["points"] for lab in LABS for c, m in _nbgrader_cells(
        nbformat.read(lab, as_version=4)) if m["grade"] and c.cell_type == "code")


@pytest.mark.parametrize("lab", LABS, ids=[p.name for p in LABS])
def test_lab_checks_every_task_of_its_chapter_once(lab):
    import re

    from slamlab import lab as sl_lab

    nb = nbformat.read(lab, as_version=4)
    used = re.findall(r'sl\.lab\.(?:check|answer)\("([^"]+)"', "\n".join(c.source for c in nb.cells
                                                                       if c.cell_type == "code"))
    prefix = lab.name[:2] + "."
    assert sorted(used) == list(sl_lab.tasks_of(prefix)), f"{lab.name} checks {used}"
