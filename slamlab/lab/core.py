"""Self-checks for the lab assignments: the student's function against the library's on seeded cases.

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

import math
import os
import traceback
from collections.abc import Callable, Iterable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from .._validate import as_rng

__all__ = ["Case", "CheckResult", "ExplorationTask", "Task", "WrongAnswer", "answer", "check", "register", "task"]

_PKG_DIR = str(Path(__file__).resolve().parent.parent)
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
    compare : callable, optional
        ``compare(expected, received) -> str | None``; default :func:`allclose`.
    points : int
        The task's points.
    """

    task_id: str
    title: str
    reference: Callable[..., Any]
    cases: Callable[[np.random.Generator], list[Case]]
    hint: str
    compare: Callable[[Any, Any], str | None] = field(default=None)
    points: int = 1


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

    def accepted_range(self) -> tuple[float, float]:
        """The closed range of values that pass."""
        if self.accepted is not None:
            lo, hi = (float(v) for v in self.accepted())
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


@dataclass(frozen=True)
class CheckResult:
    """What a check found.

    Parameters
    ----------
    task_id : str
        The checked task.
    status : str
        "passed", "failed", "error" or "not done yet".
    message : str
        What was printed.
    """

    task_id: str
    status: str
    message: str

    @property
    def passed(self) -> bool:
        return self.status == "passed"

    def __str__(self) -> str:
        return self.message


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


# --- comparing ----------------------------------------------------------------------------------


def allclose(rtol: float = 1e-7, atol: float = 1e-9) -> Callable[[Any, Any], str | None]:
    """Compare arrays, scalars or tuples of them elementwise with ``rtol``/``atol``.

    Parameters
    ----------
    rtol, atol : float
        Relative and absolute tolerance (as :func:`numpy.allclose`).

    Returns
    -------
    callable
        ``compare(expected, received) -> str | None``: None when they agree, else the difference.
    """

    def compare(expected, received) -> str | None:
        if isinstance(expected, tuple):
            if not isinstance(received, (tuple, list)) or len(received) != len(expected):
                got = f"a {type(received).__name__}" + (f" of {len(received)}" if hasattr(received, "__len__") else "")
                return f"expected a tuple of {len(expected)} values; got {got}"
            for i, (e, r) in enumerate(zip(expected, received, strict=True)):
                diff = compare(e, r)
                if diff is not None:
                    return f"item {i} of the returned tuple: {diff}"
            return None
        e = np.asarray(expected, dtype=float)
        try:
            r = np.asarray(received, dtype=float)
        except (TypeError, ValueError):
            return f"expected numbers; got {type(received).__name__}"
        if r.shape != e.shape:
            return f"expected shape {e.shape}; got shape {r.shape}"
        if not np.allclose(r, e, rtol=rtol, atol=atol, equal_nan=True):
            k = np.unravel_index(np.argmax(np.abs(r - e)), e.shape) if e.shape else ()
            return f"largest difference at index {tuple(int(i) for i in k)}: expected {float(e[k]):.6g}, got {float(r[k]):.6g}"
        return None

    return compare


# --- running a student's function ---------------------------------------------------------------


def _student_line(exc: BaseException) -> str:
    """Where in the student's code ``exc`` was raised: the last frame outside slamlab."""
    frames = [f for f in traceback.extract_tb(exc.__traceback__) if not f.filename.startswith(_PKG_DIR)]
    if not frames:
        return "inside a library call your function made"
    f = frames[-1]
    where = f"line {f.lineno} of your cell" if "ipykernel" in f.filename or f.filename.startswith("<") \
        else f"{Path(f.filename).name}, line {f.lineno}"
    return f"{where}: {f.line}" if f.line else where


def _fmt(value: Any) -> str:
    with np.printoptions(precision=6, suppress=False, threshold=20, linewidth=100):
        if isinstance(value, dict):
            return ", ".join(f"{k}={_fmt(v)}" for k, v in value.items())
        if isinstance(value, tuple):
            return "(" + ", ".join(_fmt(v) for v in value) + ")"
        return np.array2string(np.asarray(value), separator=", ") if isinstance(value, (list, np.ndarray)) \
            else repr(value)


def _finish(result: CheckResult, quiet: bool) -> CheckResult:
    if not quiet:
        print(result.message)
    if os.environ.get("NBGRADER_EXECUTION") and not result.passed:
        raise AssertionError(result.message)
    return result


def check(task_id: str, fn: Callable, *, rng=0, quiet: bool = False) -> CheckResult:
    """Run the student's ``fn`` on the task's cases; print and return pass, the first failure, or "not done yet".

    Parameters
    ----------
    task_id : str
        An implementation task's id.
    fn : callable
        The student's function.
    rng : numpy.random.Generator, int or None
        The random cases' stream (an int seed: the same cases every time).
    quiet : bool
        Do not print the message.

    Returns
    -------
    CheckResult
        The outcome (under nbgrader a result that has not passed raises ``AssertionError`` instead).
    """
    t = task(task_id)
    if not isinstance(t, Task):
        raise TypeError(f"{task_id!r} is answered with a number: use sl.lab.answer({task_id!r}, value)")
    if not callable(fn):
        return _finish(CheckResult(task_id, "failed", f"{t.title}: expected a function; got {type(fn).__name__}"),
                       quiet)
    compare = t.compare or allclose()
    cases = t.cases(as_rng(rng))
    for n, case in enumerate(cases, start=1):
        expected = t.reference(**case.kwargs)
        try:
            received = fn(**{k: _copy(v) for k, v in case.kwargs.items()})
        except NotImplementedError:
            return _finish(CheckResult(task_id, "not done yet", f"{t.title}: not done yet."), quiet)
        except Exception as exc:  # noqa: BLE001 (the student's error becomes a short message)
            msg = (f"{t.title}: case {n} of {len(cases)} ({case.label}) raised {type(exc).__name__}: {exc}\n"
                   f"  at {_student_line(exc)}\n  inputs: {_fmt(case.kwargs)}\n  hint: {t.hint}")
            return _finish(CheckResult(task_id, "error", msg), quiet)
        diff = compare(expected, received)
        if diff is not None:
            msg = (f"{t.title}: case {n} of {len(cases)} ({case.label}) is wrong: {diff}\n"
                   f"  inputs: {_fmt(case.kwargs)}\n  expected: {_fmt(expected)}\n  received: {_fmt(received)}\n"
                   f"  hint: {t.hint}")
            return _finish(CheckResult(task_id, "failed", msg), quiet)
    return _finish(CheckResult(task_id, "passed", f"{t.title}: passed ({len(cases)} cases)."), quiet)


def _copy(value):
    """Each call gets its own copy, so a function that changes its inputs cannot change the next case."""
    return value.copy() if isinstance(value, np.ndarray) else value


def answer(task_id: str, value, *, quiet: bool = False) -> CheckResult:
    """Check a number found by experiment: inside the task's accepted range, or else which misconception it shows.

    ``value`` is the number, or a function returning it (called here; ``NotImplementedError``
    from it means "not done yet", as in nbgrader's student version). The accepted range is the
    task's ``accepted()`` (an independent computation), or the library's own run within the task's
    tolerance. A wrong value that matches one of the task's typical wrong answers gets the hint
    naming that misconception; from the second failed attempt at a task on, the hint says more.

    Parameters
    ----------
    task_id : str
        An exploration task's id.
    value : float or callable
        The number, or a function returning it.
    quiet : bool
        Do not print the message.

    Returns
    -------
    CheckResult
        The outcome (under nbgrader a result that has not passed raises ``AssertionError`` instead).
    """
    t = task(task_id)
    if not isinstance(t, ExplorationTask):
        raise TypeError(f"{task_id!r} is an implementation task: use sl.lab.check({task_id!r}, your_function)")
    if callable(value):  # a function that runs the experiment and returns the number
        try:
            value = value()
        except NotImplementedError:
            value = None
        except Exception as exc:  # noqa: BLE001 (the student's error becomes a short message)
            msg = f"{t.question} — your function raised {type(exc).__name__}: {exc}\n  at {_student_line(exc)}"
            return _finish(CheckResult(task_id, "error", msg), quiet)
    if value is None or value is Ellipsis:
        return _finish(CheckResult(task_id, "not done yet", f"{t.question} — not done yet."), quiet)
    try:
        x = float(value)
    except (TypeError, ValueError):
        return _finish(CheckResult(task_id, "failed", f"{t.question} — expected a number; got {value!r}"), quiet)
    lo, hi = t.accepted_range()
    centre = float(t.expected()) if t.accepted is None else (lo + hi) / 2
    shown = _shown(x, t.atol + t.rtol * abs(centre))  # as many decimals as the task's tolerance resolves
    if lo <= x <= hi:
        _ATTEMPTS.pop(task_id, None)
        return _finish(CheckResult(task_id, "passed", f"{t.question} — {shown}: passed."), quiet)
    _ATTEMPTS[task_id] = n_failed = _ATTEMPTS.get(task_id, 0) + 1
    w = t.misconception(x) if math.isfinite(x) else None
    hint, more = (w.hint, w.more) if w is not None else (t.hint, t.more)
    if n_failed >= 2 and more:
        hint = f"{hint} {more}"
    return _finish(CheckResult(task_id, "failed", f"{t.question} — {shown} is not it. Hint: {hint}"), quiet)


#: Failed ``answer`` attempts per task in this kernel (a second failed attempt may get a fuller hint).
_ATTEMPTS: dict[str, int] = {}


def _shown(x: float, tol: float) -> str:
    """``x`` to the decimals that the tolerance resolves (a number found by experiment on another machine
    can differ in its last digits; what the check can tell apart is what is printed)."""
    if not tol > 0 or not math.isfinite(x):
        return f"{x:g}"
    return f"{round(x, max(0, math.ceil(-math.log10(tol)))):g}"


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
