"""Self-checks for the lab assignments (``notebooks/labs/``): ``sl.lab.check(task_id, fn)``, ``sl.lab.answer(task_id, x)``.
See :mod:`slamlab.lab.core`. Each chapter's tasks live in ``tasks_<topic>.py`` and register themselves into
``core``'s registry when imported; they are imported on first use (:data:`TASK_MODULES`), so a lab's kernel loads
only its own chapter's tasks and packages (``core`` imports no task module: no import cycle).
"""

from importlib import import_module

from . import core
from .core import CheckResult, all_tasks, answer, check, task, tasks_of

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

__all__ = ["TASK_MODULES", "CheckResult", "all_tasks", "answer", "check", "load_tasks", "task", "tasks_of"]
