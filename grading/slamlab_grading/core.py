"""The grading of the lab assignments (instructor only): the student's function against the reference on
cases the student has not seen, and an exploration's number against its accepted range.

A :class:`Task` names the library's reference function, the cases to try (seeded random
ones and the edge cases that matter), how to compare results, and one hint. :func:`check`
runs a student's function on every case and reports, in a few lines, the first case that
fails (its inputs, the expected and the received values, the hint), or "passed", or "not
done yet" while the function still raises ``NotImplementedError`` (what nbgrader's student
version holds). An exception raised by the student's code is shown as one short message
pointing at the student's own line, never as a traceback through slamlab.

Under nbgrader's autograder (``NBGRADER_EXECUTION`` set) a check that does not pass raises
``AssertionError`` with the same short message, so the cell scores zero; everywhere else a
check only prints and returns its :class:`CheckResult`.
"""

from __future__ import annotations

import contextlib
import functools
import hashlib
import json
import math
import os
from collections.abc import Callable, Iterable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from slamlab._validate import as_rng
from slamlab.lab.calls import ALLOWED, FORBIDDEN
from slamlab.lab.compare import Compare, allclose
from slamlab.lab.core import CheckResult, check_case, finish

__all__ = ["GRADING_RNG", "Case", "ExplorationTask", "Task", "WrongAnswer", "allclose", "answer", "check",
           "feedback_of", "grade", "register", "task"]

#: The seed of the cases the grading runs (the student's feedback file holds the cases of seed 0).
GRADING_RNG = 20261207

_REGISTRY: dict[str, Task | ExplorationTask] = {}


def _load_nothing(chapter: str | None) -> None:
    """The default loader: no task module (``slamlab.lab`` installs its own on import)."""


#: Imports the task modules of one chapter ("01") or, for None or an unknown chapter, of every chapter, so that
#: their tasks are registered; installed by :mod:`slamlab.lab` (``core`` itself imports no task module). A lab's
#: kernel then imports only its own chapter's tasks and packages.
_loader: Callable[[str | None], None] = _load_nothing


@dataclass(frozen=True)
class Case:
    """One call to try: a label for the report and the keyword arguments.

    Parameters
    ----------
    label : str
        What the case is, as the report names it ("seeded 3", "empty input").
    kwargs : dict
        The keyword arguments of the call.
    """

    label: str
    kwargs: dict[str, Any]


@dataclass(frozen=True)
class Task:
    """An implementation task: the student's function must agree with ``reference`` on every case.

    ``cases(rng)`` returns the cases (seeded random ones first, then edge cases); ``compare(expected,
    received)`` returns None when they agree, else a short description of the difference.

    Parameters
    ----------
    task_id : str
        Unique id, "NN.name" (NN the lab).
    title : str
        The task's name in every message.
    reference : callable
        The library's function the student's must agree with.
    cases : callable
        ``cases(rng) -> list[Case]``.
    hint : str
        Shown with a failing case: the misconception, never code.
    compare : Compare, optional
        ``compare(expected, received, kwargs) -> str | None``; default :func:`slamlab.lab.compare.allclose`.
    points : int
        The task's points.
    forbid, allow : tuple of str
        The library functions the student's may not call (prefixes of ``module.qualname``,
        :func:`slamlab.lab.calls.call_watching`): by default all of slamlab but its lab checks.
    """

    task_id: str
    title: str
    reference: Callable[..., Any]
    cases: Callable[[np.random.Generator], list[Case]]
    hint: str
    compare: Compare = field(default_factory=allclose)
    points: int = 1
    forbid: tuple[str, ...] = FORBIDDEN
    allow: tuple[str, ...] = ALLOWED


@dataclass(frozen=True)
class WrongAnswer:
    """A typical wrong answer to an exploration and the misconception that leads to it.

    ``value()`` computes the wrong number the misconception gives (from the same independent
    computation as the accepted range); a received value within ``atol + rtol·|value|`` of it gets
    ``hint`` (which names the misconception, never the answer or code) and, from the second failed
    attempt on, ``more`` as well (still no code).

    Parameters
    ----------
    label : str
        The misconception's name.
    value : callable
        ``value() -> float``: the number the misconception gives.
    hint : str
        Shown for a matching answer.
    more : str
        Added to the hint from the second failed attempt on.
    rtol, atol : float
        How close a received value must be to ``value()`` to match.
    """

    label: str
    value: Callable[[], float]
    hint: str
    more: str = ""
    rtol: float = 0.0
    atol: float = 1e-9


@dataclass(frozen=True)
class ExplorationTask:
    """A question answered with a number found by running an experiment; ``accept(value)`` says if it is right.

    Without ``accepted`` a value passes within ``atol + rtol·|expected()|`` of ``expected()`` (the
    library's own run). With ``accepted`` it passes inside the closed range ``accepted()`` returns,
    a range derived from an independent computation and wide enough for every correct method
    (other seeds, grids or run counts where the question allows); ``why`` states, for the
    instructor, what the range is and why. ``wrong`` lists the typical wrong answers, each mapped to
    a hint naming its misconception; ``hint`` is for any other wrong value and ``more`` is added to
    it from the second failed attempt on.

    Parameters
    ----------
    task_id : str
        Unique id, "NN.explore.name".
    question : str
        The question, as every message names it.
    expected : callable
        ``expected() -> float``: the library's own run (the centre when ``accepted`` is None).
    rtol, atol : float
        Tolerance around ``expected()`` when ``accepted`` is None.
    hint : str
        Shown for a wrong value that matches no typical wrong answer.
    points : int
        The task's points.
    accepted : callable, optional
        ``accepted() -> (lo, hi)``: the closed range that passes, from an independent computation.
    why : str
        For the instructor: what the range is and why.
    wrong : tuple of WrongAnswer
        The typical wrong answers.
    more : str
        Added to ``hint`` from the second failed attempt on.
    unit : str
        What the answer is, as the student's check names it ("a fraction of the particles").
    bounds : tuple of float
        The answer's physical bounds (a fraction: 0..1): the student's check refuses a value outside.
    integer : bool
        The answer is a whole number.
    answered_by : tuple of str
        The public names of slamlab that compute the answer: the exploration's text may not name them.
    """

    task_id: str
    question: str
    expected: Callable[[], float]
    rtol: float = 0.0
    atol: float = 0.0
    hint: str = ""
    points: int = 1
    accepted: Callable[[], tuple[float, float]] | None = None
    why: str = ""
    wrong: tuple[WrongAnswer, ...] = ()
    more: str = ""
    unit: str = "the quantity asked"
    bounds: tuple[float, float] = (-math.inf, math.inf)
    integer: bool = False
    answered_by: tuple[str, ...] = ()

    def accepted_range(self) -> tuple[float, float]:
        """The closed range of values that pass (a task of the grading package's own: cached on disk, see
        :func:`cached_range`)."""
        if self.accepted is not None:
            lo, hi = cached_range(self.task_id, self.accepted)
            if not lo <= hi:
                raise ValueError(f"{self.task_id}: `accepted` must return (lo, hi) with lo <= hi; got ({lo}, {hi})")
            return lo, hi
        exp = float(self.expected())
        tol = self.atol + self.rtol * abs(exp)
        return exp - tol, exp + tol

    def misconception(self, x: float) -> WrongAnswer | None:
        """The typical wrong answer ``x`` matches, if any (the first in ``wrong``).

        Parameters
        ----------
        x : float
            The received value.

        Returns
        -------
        WrongAnswer or None
            The first matching typical wrong answer.
        """
        for w in self.wrong:
            v = float(w.value())
            if abs(x - v) <= w.atol + w.rtol * abs(v):
                return w
        return None


#: Where :func:`cached_range` keeps the accepted ranges (default ``~/.cache/slamlab_grading``).
CACHE_ENV = "SLAMLAB_GRADING_CACHE"


@functools.cache
def code_hash() -> str:
    """The sha256 of every Python file of slamlab and of this package: a cached range is valid for this code only."""
    import slamlab

    h = hashlib.sha256()
    for root in (Path(slamlab.__file__).parent, Path(__file__).parent):
        for f in sorted(root.rglob("*.py")):
            h.update(str(f.relative_to(root.parent)).encode())
            h.update(f.read_bytes())
    return h.hexdigest()[:16]


def cached_range(task_id: str, accepted: Callable[[], tuple[float, float]]) -> tuple[float, float]:
    """``accepted()``, kept on disk for the same code (:func:`code_hash`): an autograde of 200 students computes
    each exploration's independent range once, not once per notebook.

    Only a task defined in this package is cached (a test's made-up task is not); the folder is
    ``$SLAMLAB_GRADING_CACHE`` or ``~/.cache/slamlab_grading``, one small JSON file per task and code, written
    atomically (two autograders may share it).

    Parameters
    ----------
    task_id : str
        The task.
    accepted : callable
        ``accepted() -> (lo, hi)``.

    Returns
    -------
    tuple of float
        ``(lo, hi)``.
    """
    if not getattr(accepted, "__module__", "").startswith(__package__ + "."):
        return tuple(float(v) for v in accepted())
    folder = Path(os.environ.get(CACHE_ENV) or Path.home() / ".cache" / "slamlab_grading")
    path = folder / f"{task_id}.{code_hash()}.json"
    try:
        lo, hi = json.loads(path.read_text(encoding="utf-8"))
        return float(lo), float(hi)
    except (OSError, ValueError, TypeError):
        pass
    lo, hi = (float(v) for v in accepted())
    with contextlib.suppress(OSError):  # a read-only home: computed every time
        folder.mkdir(parents=True, exist_ok=True)
        tmp = path.with_suffix(f".{os.getpid()}.tmp")
        tmp.write_text(json.dumps([lo, hi]), encoding="utf-8")
        os.replace(tmp, path)
    return lo, hi


def register(t: Task | ExplorationTask) -> Task | ExplorationTask:
    """Add a task to the registry (ids are unique).

    Parameters
    ----------
    t : Task or ExplorationTask
        The task.

    Returns
    -------
    Task or ExplorationTask
        ``t``.
    """
    if t.task_id in _REGISTRY:
        raise ValueError(f"task id {t.task_id!r} is registered twice")
    _REGISTRY[t.task_id] = t
    return t


def task(task_id: str) -> Task | ExplorationTask:
    """The registered task ``task_id``.

    Parameters
    ----------
    task_id : str
        A registered id.

    Returns
    -------
    Task or ExplorationTask
        The task.
    """
    if task_id not in _REGISTRY:
        _loader(str(task_id)[:2])
    try:
        return _REGISTRY[task_id]
    except KeyError:
        _loader(None)
        known = ", ".join(sorted(_REGISTRY))
        raise ValueError(f"`task_id` must be one of {known}; got {task_id!r}") from None


def all_tasks() -> dict[str, Task | ExplorationTask]:
    """Every task of every chapter by id."""
    _loader(None)
    return dict(_REGISTRY)


def check(task_id: str, fn: Callable, *, rng=GRADING_RNG, quiet: bool = False) -> CheckResult:
    """Grade the student's ``fn``: the reference on the task's cases drawn with ``rng`` (not the feedback's).

    Parameters
    ----------
    task_id : str
        An implementation task's id.
    fn : callable
        The student's function.
    rng : numpy.random.Generator, int or None
        The random cases' stream (the feedback file holds those of seed 0).
    quiet : bool
        Do not print the message.

    Returns
    -------
    CheckResult
        The outcome (under nbgrader a result that has not passed raises ``AssertionError`` instead).
    """
    t = task(task_id)
    if not isinstance(t, Task):
        raise TypeError(f"{task_id!r} is answered with a number: use answer({task_id!r}, value)")
    if not callable(fn):
        return finish(CheckResult(task_id, "failed", f"{t.title}: expected a function; got {type(fn).__name__}"),
                      quiet)
    cases = t.cases(as_rng(rng))
    for n, case in enumerate(cases, start=1):
        bad = check_case(t.title, fn, n, len(cases), case.label, case.kwargs, t.reference(**case.kwargs), t.compare,
                       t.hint, t.forbid, t.allow)
        if bad is not None:
            return finish(CheckResult(task_id, bad.status, f"graded: {bad.message}"), quiet)
    return finish(CheckResult(task_id, "passed", f"graded: {t.title}: passed ({len(cases)} cases)."), quiet)


def answer(task_id: str, value, *, quiet: bool = False, tried: int = 1) -> CheckResult:
    """Grade a number found by experiment: inside the task's accepted range, or else which misconception it shows.

    ``value`` is the number, a function returning it (called here; ``NotImplementedError`` from it means
    "not done yet"), or the :class:`~slamlab.lab.CheckResult` the student's ``sl.lab.answer`` returned.
    The accepted range is the task's ``accepted()`` (an independent computation), or the library's own run
    within the task's tolerance. A wrong value that matches one of the task's typical wrong answers gets
    the hint naming that misconception; ``more`` is added when the student tried more than once.

    Parameters
    ----------
    task_id : str
        An exploration task's id.
    value : float, callable or CheckResult
        The answer.
    quiet : bool
        Do not print the message.
    tried : int
        How many answers the student recorded (``sl.lab.attempts``).

    Returns
    -------
    CheckResult
        The outcome (under nbgrader a result that has not passed raises ``AssertionError`` instead).
    """
    t = task(task_id)
    if not isinstance(t, ExplorationTask):
        raise TypeError(f"{task_id!r} is an implementation task: use check({task_id!r}, your_function)")
    if isinstance(value, CheckResult):
        if value.status != "recorded":
            return finish(CheckResult(task_id, "failed", f"graded: {t.question} — no answer of the asked form."),
                          quiet)
        value = value.value
    if callable(value):  # a function that runs the experiment and returns the number
        try:
            value = value()
        except NotImplementedError:
            value = None
        except Exception as exc:  # noqa: BLE001 (the student's error becomes a short message)
            msg = f"graded: {t.question} — the function raised {type(exc).__name__}: {exc}"
            return finish(CheckResult(task_id, "error", msg), quiet)
    if value is None or value is Ellipsis:
        return finish(CheckResult(task_id, "not done yet", f"graded: {t.question} — not done yet."), quiet)
    try:
        x = float(value)
    except (TypeError, ValueError):
        return finish(CheckResult(task_id, "failed", f"graded: {t.question} — expected a number; got {value!r}"),
                      quiet)
    lo, hi = t.accepted_range()
    centre = float(t.expected()) if t.accepted is None else (lo + hi) / 2
    shown = _shown(x, t.atol + t.rtol * abs(centre))  # as many decimals as the task's tolerance resolves
    if lo <= x <= hi:
        return finish(CheckResult(task_id, "passed", f"graded: {t.question} — {shown}: passed.", value=x), quiet)
    w = t.misconception(x) if math.isfinite(x) else None
    hint, more = (w.hint, w.more) if w is not None else (t.hint, t.more)
    if tried >= 2 and more:
        hint = f"{hint} {more}"
    return finish(CheckResult(task_id, "failed", f"graded: {t.question} — {shown} is not it. Hint: {hint}", value=x),
                  quiet)


def grade(task_id: str, submitted, *, quiet: bool = False) -> CheckResult:
    """What nbgrader's hidden test of a lab's check cell calls: :func:`check` for a function, :func:`answer`
    for an exploration (with the attempts the student recorded, printed for the grader).

    Parameters
    ----------
    task_id : str
        The task.
    submitted : callable, float or CheckResult
        The student's function, or the exploration's answer (the result of ``sl.lab.answer``).
    quiet : bool
        Do not print the message.

    Returns
    -------
    CheckResult
        The outcome (under nbgrader a result that has not passed raises ``AssertionError``).
    """
    from slamlab.lab import attempts

    t = task(task_id)
    if isinstance(t, Task):
        return check(task_id, submitted, quiet=quiet)
    tried = len(attempts(task_id)[task_id])
    if not quiet:
        print(f"graded: {task_id}: {tried} answer(s) recorded")
    return answer(task_id, submitted, quiet=quiet, tried=tried)


def _shown(x: float, tol: float) -> str:
    """``x`` to the decimals that the tolerance resolves (a number found by experiment on another machine
    can differ in its last digits; what the check can tell apart is what is printed)."""
    if not tol > 0 or not math.isfinite(x):
        return f"{x:g}"
    return f"{round(x, max(0, math.ceil(-math.log10(tol)))):g}"


def feedback_of(task_id: str, *, rng=0) -> dict[str, Any]:
    """What the student's feedback file holds for one task: no reference, range or model answer.

    Parameters
    ----------
    task_id : str
        The task.
    rng : numpy.random.Generator or int
        The feedback cases' stream (seed 0; the grading draws others).

    Returns
    -------
    dict
        An implementation task: its title, hint, points, comparison, forbidden calls and its cases with the
        values they expect; an exploration: its question, points and the form of its answer.
    """
    t = task(task_id)
    if isinstance(t, Task):
        cases = [{"label": c.label, "kwargs": c.kwargs, "expected": t.reference(**c.kwargs)}
                 for c in t.cases(as_rng(rng))]
        return {"kind": "function", "title": t.title, "hint": t.hint, "points": t.points,
                "compare": {"kind": t.compare.kind, "rtol": t.compare.rtol, "atol": t.compare.atol},
                "forbid": list(t.forbid), "allow": list(t.allow), "cases": cases}
    return {"kind": "number", "question": t.question, "points": t.points, "unit": t.unit,
            "bounds": [float(b) for b in t.bounds], "integer": t.integer}


def tasks_of(prefix: str) -> Iterable[str]:
    """Ids of the registered tasks starting with ``prefix`` (e.g. "01.").

    Parameters
    ----------
    prefix : str
        Start of the ids.

    Returns
    -------
    list of str
        The matching ids, sorted.
    """
    _loader(prefix[:2] if len(prefix) >= 2 else None)
    return sorted(k for k in _REGISTRY if k.startswith(prefix))
