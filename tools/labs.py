#!/usr/bin/env python
"""Student versions of the labs and autograding, with nbgrader (``pip install 'slamlab[course]'``).

Usage::

    python tools/labs.py student [--out build/student]     # make student
    python tools/labs.py autograde SUBMISSIONS [--course build/course]   # make autograde SUBMISSIONS=...

``student`` copies ``notebooks/labs/*_lab.ipynb`` (nbgrader's source format: solutions between
``### BEGIN SOLUTION`` / ``### END SOLUTION``, graded cells with ids and points, the grading between
``### BEGIN HIDDEN TESTS`` / ``### END HIDDEN TESTS``) into an nbgrader course folder as the assignment
``labs``, runs ``nbgrader generate_assignment`` (which takes the solutions and hidden tests out) and copies
the student versions to ``--out``. Autograding needs the instructor's grading package (``grading/``,
``slamlab_grading``) importable: ``make venv`` installs it. ``autograde`` takes a folder holding one sub-folder per student
(``SUBMISSIONS/<student_id>/<NN_topic_lab>.ipynb``), runs ``nbgrader autograde`` and writes
``grades.csv`` (``nbgrader export``: one total per student) and ``grades_by_task.csv`` (the points of every
autograded cell: ``student_id, notebook, grade_id, score, max_score``) into the course folder, printing
the path of ``grades.csv``.
On a JupyterHub with nbgrader's own course set-up, the same notebooks go into ``source/`` there.
"""

from __future__ import annotations

import argparse
import csv
import os
import shutil
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
LAB_DIR = ROOT / "notebooks" / "labs"
ASSIGNMENT = "labs"


def _nbgrader(course: Path, *args: str) -> None:
    env = dict(os.environ)
    # nbgrader calls `alembic` (its database migrations) by name: this interpreter's scripts must be on PATH
    env["PATH"] = str(Path(sys.executable).parent) + os.pathsep + env.get("PATH", "")
    env.setdefault("MPLBACKEND", "Agg")
    env.setdefault("SLAMLAB_PROGRESS", "0")
    cmd = [sys.executable, "-m", "nbgrader", *args, f"--CourseDirectory.root={course}"]
    proc = subprocess.run(cmd, cwd=course, env=env, capture_output=True, text=True, check=False)
    if proc.returncode != 0 or "[ERROR]" in proc.stderr or "| ERROR]" in proc.stderr:
        raise SystemExit(f"nbgrader {' '.join(args)} failed:\n{proc.stderr[-3000:]}")


def lab_notebooks() -> list[Path]:
    """Every lab notebook, ``notebooks/labs/NN_topic_lab.ipynb``."""
    return sorted(LAB_DIR.glob("*_lab.ipynb"))


def make_student(out: Path, course: Path) -> list[Path]:
    """Generate the student versions into ``out``; return their paths."""
    source = course / "source" / ASSIGNMENT
    if source.exists():
        shutil.rmtree(source)
    source.mkdir(parents=True)
    for nb in lab_notebooks():
        shutil.copy2(nb, source / nb.name)
    _nbgrader(course, "generate_assignment", ASSIGNMENT, "--force")
    out.mkdir(parents=True, exist_ok=True)
    written = []
    for nb in sorted((course / "release" / ASSIGNMENT).glob("*.ipynb")):
        shutil.copy2(nb, out / nb.name)
        written.append(out / nb.name)
    return written


def autograde(submissions: Path, course: Path, jobs: int = 1) -> Path:
    """Autograde ``submissions/<student>/*.ipynb``; return the path of the grades CSV.

    With ``jobs`` > 1 the students are split into that many groups, each graded by its own nbgrader in a copy
    of the course folder (its own gradebook) at the same time; the groups' CSVs are joined into the course's.
    """
    if not (course / "source" / ASSIGNMENT).is_dir():
        make_student(course / "student", course)  # the gradebook needs the assignment first
    students = sorted(p for p in submissions.iterdir() if p.is_dir())
    if not students:
        raise SystemExit(f"no student folders in {submissions}")
    groups = [students[k::jobs] for k in range(max(1, min(jobs, len(students))))]
    if len(groups) == 1:
        _autograde_group(students, course)
        return course / "grades.csv"
    import concurrent.futures

    courses = []
    for k in range(len(groups)):
        part = course / f"part{k}"
        if part.exists():
            shutil.rmtree(part)
        shutil.copytree(course, part, ignore=shutil.ignore_patterns("part*", "submitted", "autograded"))
        courses.append(part)
    with concurrent.futures.ThreadPoolExecutor(len(groups)) as pool:
        list(pool.map(_autograde_group, groups, courses))
    for name in ("grades.csv", "grades_by_task.csv"):
        lines = [(c / name).read_text().splitlines() for c in courses]
        (course / name).write_text("\n".join([lines[0][0]] + [r for part in lines for r in part[1:]]) + "\n")
    for c in courses:  # the autograded notebooks where a single run puts them
        for sub in ("submitted", "autograded"):
            if (c / sub).is_dir():
                shutil.copytree(c / sub, course / sub, dirs_exist_ok=True)
    return course / "grades.csv"


def _autograde_group(students: list[Path], course: Path) -> None:
    """``nbgrader autograde`` of ``students`` in ``course``, then its ``grades.csv`` and ``grades_by_task.csv``."""
    for student in students:
        dst = course / "submitted" / student.name / ASSIGNMENT
        if dst.exists():
            shutil.rmtree(dst)
        dst.mkdir(parents=True)
        for nb in student.glob("*_lab.ipynb"):
            shutil.copy2(nb, dst / nb.name)
    _nbgrader(course, "autograde", ASSIGNMENT, "--force")
    _nbgrader(course, "export", "--to=grades.csv")
    export_by_task(course)


def export_by_task(course: Path) -> Path:
    """Write ``grades_by_task.csv``: the autograded points of every check cell of every submission.

    Parameters
    ----------
    course : Path
        The nbgrader course folder (holding ``gradebook.db`` after ``nbgrader autograde``).

    Returns
    -------
    Path
        The written CSV, one row per student, notebook and autograded cell.
    """
    from nbgrader.api import Gradebook

    out = course / "grades_by_task.csv"
    rows = []
    with Gradebook(f"sqlite:///{course / 'gradebook.db'}") as gb:
        for sub in gb.assignment_submissions(ASSIGNMENT):
            for nb in sub.notebooks:
                for grade in nb.grades:
                    if grade.cell.cell_type == "code":  # prose cells are graded by hand
                        rows.append((sub.student.id, nb.name, grade.name, grade.score, grade.max_score))
    with out.open("w", newline="") as fh:
        writer = csv.writer(fh)
        writer.writerow(["student_id", "notebook", "grade_id", "score", "max_score"])
        writer.writerows(sorted(rows))
    return out


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    sub = parser.add_subparsers(dest="command", required=True)
    st = sub.add_parser("student", help="write the student versions")
    st.add_argument("--out", type=Path, default=ROOT / "build" / "student")
    st.add_argument("--course", type=Path, default=ROOT / "build" / "course")
    ag = sub.add_parser("autograde", help="grade a folder of submissions")
    ag.add_argument("submissions", type=Path)
    ag.add_argument("--course", type=Path, default=ROOT / "build" / "course")
    ag.add_argument("--jobs", type=int, default=1, help="grade the students in this many groups at once")
    args = parser.parse_args(argv)
    course = args.course.resolve()
    course.mkdir(parents=True, exist_ok=True)
    if args.command == "student":
        for path in make_student(args.out.resolve(), course):
            print(path)
    else:
        print(autograde(args.submissions.resolve(), course, jobs=args.jobs))
    return 0


if __name__ == "__main__":
    sys.exit(main())
