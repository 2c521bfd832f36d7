"""Self-checks for the lab assignments (``notebooks/labs/``): ``sl.lab.check(task_id, fn)``, ``sl.lab.answer(task_id, x)``.

See :mod:`slamlab.lab.core`. Each chapter's tasks live in ``tasks_<topic>.py`` and are
registered on first use.
"""

from .core import CheckResult, all_tasks, answer, check, task, tasks_of

__all__ = ["CheckResult", "all_tasks", "answer", "check", "task", "tasks_of"]
