"""The lab checks a student runs while working (``notebooks/labs/``): ``sl.lab.check(task_id, fn)`` and
``sl.lab.answer(task_id, x)``. See :mod:`slamlab.lab.core`.

This package holds the feedback only: fixed cases with the values they expect, the form of each
exploration's answer, and the hints. The grading (references, accepted ranges, the misconceptions)
lives in the instructor's ``slamlab_grading`` package (``grading/`` in the repository, not part of the
library or its site) and runs in nbgrader's hidden tests.
"""

from .calls import call_watching
from .compare import Compare, allclose
from .core import CheckResult, answer, attempts, check, task_ids

__all__ = ["CheckResult", "Compare", "allclose", "answer", "attempts", "call_watching", "check", "task_ids"]
