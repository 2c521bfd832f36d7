"""The lab notebooks: nbgrader source format, student versions that run, autograding that scores right."""

from __future__ import annotations

import csv
import importlib.util
import shutil
import sys
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


# --- what students hand in: tests/lab/submissions/labNN.py, and the untouched student version -------------------
sys.path.insert(0, str(Path(__file__).resolve().parent))
from submissions import build, lost_cells, of_lab

#: The student ids of the autograde run: a lab's submissions by kind ("mistake_*" numbered in the lab's order).
KINDS = ("independent", "other_seed", "mistake1", "mistake2", "mistake3", "empty")


def _by_student(lab: Path) -> dict:
    """Student id -> the lab's :class:`~submissions.Submission` (None: the untouched student version)."""
    subs = of_lab(lab.name[:2])
    out = {s.kind: s for s in subs if not s.kind.startswith("mistake_")}
    for k, s in enumerate([s for s in subs if s.kind.startswith("mistake_")], start=1):
        out[f"mistake{k}"] = s
    out["empty"] = None
    return out


@pytest.mark.parametrize("lab", LABS, ids=[p.name for p in LABS])
def test_every_lab_has_a_submission_of_each_kind(lab):
    """Issue 43: correct by another method, correct with another seed or setting, two named mistakes (and empty)."""
    subs = of_lab(lab.name[:2])
    kinds = [s.kind for s in subs]
    assert "independent" in kinds, lab.name
    assert "other_seed" in kinds, lab.name
    assert sum(k.startswith("mistake_") for k in kinds) >= 2, lab.name
    assert len([k for k in _by_student(lab) if k.startswith("mistake")]) <= 3, "KINDS has three mistake ids"
    parts = {c.metadata["nbgrader"]["grade_id"].split("_")[1] for c, m in _nbgrader_cells(nbformat.read(lab, as_version=4))
             if m["grade"] and c.cell_type == "code"}
    independent = next(s for s in subs if s.kind == "independent")
    assert set(independent.bodies) == parts, f"{lab.name}: the independent submission must redo every task"
    for s in subs:
        assert set(s.lost) <= parts, (lab.name, s.kind)
        assert bool(s.lost) == s.kind.startswith("mistake_"), (lab.name, s.kind)


@pytest.mark.parametrize("lab", LABS, ids=[p.name for p in LABS])
def test_check_cells_give_feedback_and_hide_the_grading(lab):
    """Every check cell: the student's feedback (sl.lab.check / sl.lab.answer) visible, the grading of the same task
    in nbgrader's hidden tests."""
    import re

    for c, m in _nbgrader_cells(nbformat.read(lab, as_version=4)):
        if not (m["grade"] and c.cell_type == "code"):
            continue
        visible, hidden = c.source.split("### BEGIN HIDDEN TESTS")
        tid = re.search(r'sl\.lab\.(?:check|answer)\("([^"]+)"', visible).group(1)
        assert "slamlab_grading" not in visible, c.source
        assert f'slamlab_grading.grade("{tid}", ' in hidden, c.source
        assert hidden.rstrip().endswith("### END HIDDEN TESTS"), c.source


@pytest.fixture(scope="module")
def autograded(course, tmp_path_factory):
    """One ``nbgrader autograde`` of every lab's submissions (tests/lab/submissions) and its empty student version.

    The tests below read it: the scores, and the empty student versions as nbgrader ran them (each lab's
    student version is executed once, here, rather than once more by nbclient for the student test).
    """
    root, students = course
    subs = tmp_path_factory.mktemp("submissions")
    for lab, student in zip(LABS, students, strict=True):
        for kind, sub in _by_student(lab).items():
            (subs / kind).mkdir(exist_ok=True)
            if sub is None:
                shutil.copy2(student, subs / kind / student.name)
            else:
                nbformat.write(build(lab, sub), subs / kind / lab.name)
    return labs_tool.autograde(subs, root, jobs=2)  # two groups of students at once (CI has a 20-minute goal)


def expected_points(lab: Path, student: str) -> dict[str, float]:
    """Points per autograded cell of ``lab`` for the submission of ``student``, from the notebook's metadata."""
    sub = _by_student(lab).get(student)
    lost = lost_cells(lab, sub) if sub is not None else set()
    out = {}
    for c, m in _nbgrader_cells(nbformat.read(lab, as_version=4)):
        if m["grade"] and c.cell_type == "code":
            part = m["grade_id"].split("_")[1]
            out[m["grade_id"]] = 0.0 if sub is None or part in lost else float(m["points"])
    return out


@pytest.mark.slow
def test_student_versions_run_and_say_not_done_yet(course, autograded):
    """The student versions, executed by nbgrader (``NBGRADER_EXECUTION`` set), run without an error except
    in their check cells, and each check cell says "not done yet". Under nbgrader a check that has not passed
    prints its message and then raises it (so that the cell scores 0); outside nbgrader it only prints
    (``tests/lab/test_check.py``), so a student sees the message and no traceback."""
    root, students = course
    assert [p.name for p in students] == [p.name for p in LABS]
    for path in students:
        text = path.read_text(encoding="utf-8")
        assert "### BEGIN SOLUTION" not in text, path.name
        assert "slamlab_grading" not in text, path.name  # nbgrader took the hidden tests out
        assert "HIDDEN TESTS" not in text, path.name
        nb = nbformat.read(root / "autograded" / "empty" / labs_tool.ASSIGNMENT / path.name, as_version=4)
        assert len([c for c in nb.cells if c.cell_type == "code"]) == len(
            [c for c in nbformat.read(path, as_version=4).cells if c.cell_type == "code"]), path.name
        for c in nb.cells:
            if c.cell_type != "code":
                continue
            assert c.execution_count is not None, f"{path.name}: not executed:\n{c.source}"
            assert "### BEGIN SOLUTION" not in c.source
            errors = [o for o in c.outputs if o.output_type == "error"]
            if "sl.lab.check(" in c.source or "sl.lab.answer(" in c.source:  # nbgrader put the hidden tests back
                text = "".join(o.get("text", "") for o in c.outputs)
                assert "not done yet" in text, f"{path.name}: {c.source} printed {text!r}"
                assert all(o.ename == "AssertionError" and "not done yet" in o.evalue for o in errors), \
                    f"{path.name}: {c.source} raised {[(o.ename, o.evalue) for o in errors]}"
            else:
                assert not errors, f"{path.name}: error in\n{c.source}"


@pytest.mark.slow
def test_autograde_gives_each_submission_its_points_per_task(autograded):
    """Every autograded cell of every submission scores what its submission says: full points for the correct ones
    (another method, another seed), zero where a named mistake sits, zero for the empty student version."""
    with (autograded.parent / "grades_by_task.csv").open() as fh:
        got = {(r["student_id"], r["notebook"], r["grade_id"]): float(r["score"]) for r in csv.DictReader(fh)}
    expected = {(kind, lab.stem, gid): pts for kind in KINDS for lab in LABS
                for gid, pts in expected_points(lab, kind).items() if kind in _by_student(lab)}
    wrong = {k: (v, got.get(k)) for k, v in expected.items() if got.get(k) != v}
    assert not wrong, f"(submission, lab, cell): (expected, scored): {wrong}"
    assert set(got) >= set(expected)
    with autograded.open() as fh:
        totals = {r["student_id"]: float(r["raw_score"]) for r in csv.DictReader(fh)}
    for kind, total in totals.items():  # nbgrader's own grades.csv: the total of the autograded points (prose by hand)
        assert total == sum(v for (k, _, _), v in expected.items() if k == kind), kind
    assert totals["empty"] == 0.0
    full = sum(m["points"] for lab in LABS for c, m in _nbgrader_cells(nbformat.read(lab, as_version=4))
               if m["grade"] and c.cell_type == "code")
    assert totals["independent"] == totals["other_seed"] == full


@pytest.mark.parametrize("lab", LABS, ids=[p.name for p in LABS])
def test_lab_checks_every_task_of_its_chapter_once(lab):
    import re

    import slamlab_grading as sl_lab

    nb = nbformat.read(lab, as_version=4)
    used = re.findall(r'sl\.lab\.(?:check|answer)\("([^"]+)"', "\n".join(c.source for c in nb.cells
                                                                       if c.cell_type == "code"))
    prefix = lab.name[:2] + "."
    assert sorted(used) == list(sl_lab.tasks_of(prefix)), f"{lab.name} checks {used}"


_site_spec = importlib.util.spec_from_file_location("build_site_tool", ROOT / "tools" / "build_site.py")
build_site = importlib.util.module_from_spec(_site_spec)
_site_spec.loader.exec_module(build_site)


@pytest.mark.parametrize("lab", LABS, ids=[p.name for p in LABS])
def test_every_hand_graded_answer_has_a_rubric_whose_points_add_up(lab):
    """Issue 43, item 5: a rubric with points for every hand-graded question (the site's instructor guide lists
    them): ``**Rubric (N points).**`` with N the cell's points, and the breakdown's points ("1 point: ...") sum
    to N."""
    import json
    import re

    nb = json.loads(lab.read_text(encoding="utf-8"))
    rubrics = build_site.lab_rubrics(nb)
    hand = [c for c in nb["cells"] if c["cell_type"] == "markdown"
            and c["metadata"].get("nbgrader", {}).get("solution") and c["metadata"]["nbgrader"].get("grade")]
    assert len(rubrics) == len(hand) >= 3, lab.name  # the questions (two or three) and the open investigation
    for (label, points, text), c in zip(rubrics, hand, strict=True):
        src = "".join(c["source"])
        head = re.match(r"\*\*Rubric \((\d+(?:\.\d+)?) points?\)\.\*\*", src)
        assert float(head.group(1)) == points == float(c["metadata"]["nbgrader"]["points"]), (lab.name, label)
        parts = [float(x) for x in re.findall(r"(\d+(?:\.\d+)?) points?\b(?! in all)", text)]
        assert parts, f"{lab.name} {label}: no point breakdown in {text!r}"
        assert sum(parts) == points, f"{lab.name} {label}: the breakdown {parts} does not add up to {points:g}"
        if label.startswith("Q"):  # an open investigation may have a rubric alone
            assert len(src.strip()) > len(text) + 40, f"{lab.name} {label}: the model answer follows the rubric"
