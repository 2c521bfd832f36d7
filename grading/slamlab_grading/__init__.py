"""The grading of slamlab's labs (instructor only: not part of the library, its wheel or its site).

nbgrader's hidden tests in each lab's check cells call :func:`grade`: an implementation task runs the
student's function against the reference (:attr:`Task.reference`) on cases the student has not seen and
checks that it calls no library function the task asks to re-implement; an exploration's number is
graded against its accepted range (from theory or an independent computation over every seed the question
allows), and a typical wrong number gets the hint naming its misconception. Each chapter's tasks live in
``tasks_<topic>.py`` and register themselves on import (:data:`TASK_MODULES`).

:func:`export_feedback` writes what the student's kernel may hold (``slamlab/lab/feedback/NN.json``:
fixed cases with their expected values, the form of each answer): ``python -m slamlab_grading feedback``.
"""

from __future__ import annotations

import json
from importlib import import_module
from pathlib import Path

from . import core
from .core import (
    Case,
    ExplorationTask,
    Task,
    WrongAnswer,
    all_tasks,
    answer,
    check,
    feedback_of,
    grade,
    register,
    task,
    tasks_of,
)

#: The module that registers each chapter's tasks.
TASK_MODULES = {"01": "tasks_filters", "02": "tasks_features", "03": "tasks_features", "04": "tasks_stores",
                "05": "tasks_stereo", "06": "tasks_correlation", "07": "tasks_hough", "08": "tasks_localisation",
                "09": "tasks_mono", "10": "tasks_planes"}


def load_tasks(chapter: str | None = None) -> None:
    """Import the task modules of one chapter, or of every chapter (their tasks register on import).

    Parameters
    ----------
    chapter : str, optional
        Two digits ("01"); None or a chapter without tasks: every chapter.
    """
    names = [TASK_MODULES[chapter]] if chapter in TASK_MODULES else sorted(set(TASK_MODULES.values()))
    for name in names:
        import_module(f"{__name__}.{name}")


core._loader = load_tasks


def feedback_file(chapter: str) -> str:
    """The text of ``slamlab/lab/feedback/<chapter>.json``: every task of the lab, as :func:`feedback_of` gives it.

    Parameters
    ----------
    chapter : str
        Two digits ("08").

    Returns
    -------
    str
        JSON text (sorted keys, compact).
    """
    from slamlab.lab.feedback import encode

    tasks = {tid: feedback_of(tid) for tid in tasks_of(f"{chapter}.")}
    return json.dumps(encode({"tasks": tasks}), sort_keys=True, ensure_ascii=False, separators=(",", ":")) + "\n"


def export_feedback(folder: Path | None = None, chapters=None) -> list[Path]:
    """Write the labs' feedback files into ``folder`` (default: the library's ``slamlab/lab/feedback``).

    Parameters
    ----------
    folder : Path, optional
        Where to write.
    chapters : iterable of str, optional
        The labs ("08"); None: every lab.

    Returns
    -------
    list of Path
        The written files.
    """
    from slamlab.lab.feedback import FEEDBACK_DIR

    folder = Path(folder) if folder is not None else FEEDBACK_DIR
    folder.mkdir(parents=True, exist_ok=True)
    out = []
    for chapter in sorted(chapters or TASK_MODULES):
        path = folder / f"{chapter}.json"
        path.write_text(feedback_file(chapter), encoding="utf-8")
        out.append(path)
    return out


__all__ = ["TASK_MODULES", "Case", "ExplorationTask", "Task", "WrongAnswer", "all_tasks", "answer", "check",
           "export_feedback", "feedback_file", "feedback_of", "grade", "load_tasks", "register", "task", "tasks_of"]
