"""Self-checks for the lab assignments (``notebooks/labs/``): ``sl.lab.check(task_id, fn)``, ``sl.lab.answer(task_id, x)``.

See :mod:`slamlab.lab.core`. Each chapter's tasks live in ``tasks_<topic>.py``, which register them
into ``core``'s registry when imported here (``core`` imports no task module: no import cycle).
"""

from . import (  # noqa: F401  (each registers its tasks on import)
    tasks_correlation,
    tasks_features,
    tasks_filters,
    tasks_hough,
    tasks_localisation,
    tasks_mono,
    tasks_planes,
    tasks_stereo,
    tasks_stores,
)
from .core import CheckResult, all_tasks, answer, check, task, tasks_of

__all__ = ["CheckResult", "all_tasks", "answer", "check", "task", "tasks_of"]
