"""The lab checks a student sees while working: ``check(task_id, fn)`` and ``answer(task_id, x)``.

The student's kernel holds no reference implementation, accepted range or model answer (issue 43):
what it holds is each lab's feedback file (:mod:`slamlab.lab.feedback`). :func:`check` runs the
student's function on the file's fixed cases — seeded random ones and the edge cases that matter —
and reports the first case whose value differs from the stored one (its inputs, the expected and the
received values, the task's hint), an exception in the student's code as one short message pointing
at the student's own line, a call to the library function the task asks to re-implement, or "not done
yet" while the function raises ``NotImplementedError`` (what nbgrader's student version holds).
:func:`answer` checks that an exploration's answer is a finite number of the asked form (a fraction,
a whole number, inside the quantity's physical bounds), records the attempt, and says that it is graded
when handed in. The grading itself (other cases, the references, the accepted ranges, the misconceptions'
hints) runs in the instructor's ``slamlab_grading`` package, from nbgrader's hidden tests.

Under nbgrader's autograder (``NBGRADER_EXECUTION`` set) a check that fails, errs or is not done yet
raises ``AssertionError`` with the same short message, so the cell scores zero; everywhere else a check
only prints and returns its :class:`CheckResult`.
"""

from __future__ import annotations

import contextlib
import json
import math
import os
import traceback
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from . import feedback
from .calls import call_watching
from .compare import Compare

__all__ = ["ATTEMPTS_ENV", "CheckResult", "answer", "attempts", "check", "explain_exception", "finish", "format_value",
           "task_ids"]

_PKG_DIR = str(Path(__file__).resolve().parent.parent)
#: The environment variable naming the file that records exploration attempts (default ``lab_attempts.json``
#: in the working folder, the notebook's: it is handed in with the notebook); "memory": this kernel only (the
#: test suite and the notebook runners, so that a fresh kernel counts from 1 and the stored outputs hold).
ATTEMPTS_ENV = "SLAMLAB_LAB_ATTEMPTS"
_IN_MEMORY: dict[str, list] = {}
_FAILING = ("failed", "error", "not done yet")


@dataclass(frozen=True)
class CheckResult:
    """What a check found.

    Parameters
    ----------
    task_id : str
        The checked task.
    status : str
        "passed", "failed", "error", "not done yet" (a function or an answer) or "recorded" (an answer of
        the asked form, graded when handed in).
    message : str
        What was printed.
    value : float, optional
        The recorded answer (for "recorded").
    """

    task_id: str
    status: str
    message: str
    value: float | None = None

    @property
    def passed(self) -> bool:
        """True when the check passed."""
        return self.status == "passed"

    def __str__(self) -> str:
        return self.message


def task_ids(prefix: str = "") -> list[str]:
    """The ids of the tasks with feedback, starting with ``prefix`` (e.g. "08.").

    Parameters
    ----------
    prefix : str
        Start of the ids; "" for every lab.

    Returns
    -------
    list of str
        Sorted ids.
    """
    chapters = [prefix[:2]] if len(prefix) >= 2 else sorted(p.stem for p in feedback.FEEDBACK_DIR.glob("*.json"))
    return sorted(k for ch in chapters for k in feedback.load(ch)["tasks"] if k.startswith(prefix))


def _task(task_id: str, kind: str) -> dict[str, Any]:
    t = feedback.load(str(task_id)[:2])["tasks"].get(task_id)
    if t is None:
        raise ValueError(f"`task_id` must be one of {', '.join(task_ids())}; got {task_id!r}")
    if t["kind"] != kind:
        use = "sl.lab.answer(task_id, value)" if t["kind"] == "number" else "sl.lab.check(task_id, your_function)"
        raise TypeError(f"{task_id!r} is checked with {use}")
    return t


# --- messages ---------------------------------------------------------------------------------------


def explain_exception(exc: BaseException) -> str:
    """Where in the student's code ``exc`` was raised: the last frame outside slamlab.

    Parameters
    ----------
    exc : BaseException
        The exception.

    Returns
    -------
    str
        "line N of your cell: <source>", or where else it was raised.
    """
    frames = [f for f in traceback.extract_tb(exc.__traceback__) if not f.filename.startswith(_PKG_DIR)
              and "slamlab_grading" not in f.filename]
    if not frames:
        return "inside a library call your function made"
    f = frames[-1]
    where = f"line {f.lineno} of your cell" if "ipykernel" in f.filename or f.filename.startswith("<") \
        else f"{Path(f.filename).name}, line {f.lineno}"
    return f"{where}: {f.line}" if f.line else where


def format_value(value: Any) -> str:
    """A short text of a case's inputs or values (arrays with at most 20 items shown).

    Parameters
    ----------
    value : object
        A dict of arguments, a tuple, an array or a scalar.

    Returns
    -------
    str
        The text.
    """
    with np.printoptions(precision=6, suppress=False, threshold=20, linewidth=100):
        if isinstance(value, dict):
            return ", ".join(f"{k}={format_value(v)}" for k, v in value.items())
        if isinstance(value, tuple):
            return "(" + ", ".join(format_value(v) for v in value) + ")"
        return np.array2string(np.asarray(value), separator=", ") if isinstance(value, (list, np.ndarray)) \
            else repr(value)


def finish(result: CheckResult, quiet: bool) -> CheckResult:
    """Print ``result`` (unless ``quiet``); under nbgrader raise it when it failed, erred or is not done yet.

    Parameters
    ----------
    result : CheckResult
        The outcome.
    quiet : bool
        Do not print.

    Returns
    -------
    CheckResult
        ``result``.
    """
    if not quiet:
        print(result.message)
    if os.environ.get("NBGRADER_EXECUTION") and result.status in _FAILING:
        raise AssertionError(result.message)
    return result


def _copy(value):
    """Each call gets its own copy, so a function that changes its inputs cannot change the next case."""
    return value.copy() if isinstance(value, np.ndarray) else value


def check_case(title: str, fn: Callable, n: int, n_cases: int, label: str, kwargs: dict, expected: Any,
             compare: Compare, hint: str, forbid, allow) -> CheckResult | None:
    """Run ``fn`` on one case; None when it agrees with ``expected``, else the failing :class:`CheckResult`.

    Parameters
    ----------
    title : str
        The task's name in the message.
    fn : callable
        The student's function.
    n, n_cases : int
        The case's number and the number of cases.
    label : str
        What the case is.
    kwargs : dict
        The case's arguments.
    expected : object
        The value the case expects.
    compare : Compare
        How to compare.
    hint : str
        The task's hint.
    forbid, allow : tuple of str
        The library functions the task forbids (:func:`slamlab.lab.calls.call_watching`).

    Returns
    -------
    CheckResult or None
        The failure (its ``task_id`` is left empty for the caller), or None.
    """
    try:
        received, called = call_watching(fn, {k: _copy(v) for k, v in kwargs.items()}, forbid=forbid, allow=allow)
    except NotImplementedError:
        return CheckResult("", "not done yet", f"{title}: not done yet.")
    except Exception as exc:  # noqa: BLE001 (the student's error becomes a short message)
        msg = (f"{title}: case {n} of {n_cases} ({label}) raised {type(exc).__name__}: {exc}\n"
               f"  at {explain_exception(exc)}\n  inputs: {format_value(kwargs)}\n  hint: {hint}")
        return CheckResult("", "error", msg)
    if called:
        msg = (f"{title}: case {n} of {n_cases} ({label}) called the library's {called[0]}: this task asks for "
               f"your own implementation (numpy and scipy are fine).")
        return CheckResult("", "failed", msg)
    diff = compare(expected, received, kwargs)
    if diff is not None:
        msg = (f"{title}: case {n} of {n_cases} ({label}) is wrong: {diff}\n"
               f"  inputs: {format_value(kwargs)}\n  expected: {format_value(expected)}\n"
               f"  received: {format_value(received)}\n  hint: {hint}")
        return CheckResult("", "failed", msg)
    return None


def check(task_id: str, fn: Callable, *, quiet: bool = False) -> CheckResult:
    """Run the student's ``fn`` on the task's feedback cases; print and return pass, the first failure, or
    "not done yet".

    Parameters
    ----------
    task_id : str
        An implementation task's id.
    fn : callable
        The student's function.
    quiet : bool
        Do not print the message.

    Returns
    -------
    CheckResult
        The outcome (under nbgrader a result that has not passed raises ``AssertionError`` instead).
    """
    t = _task(task_id, "function")
    if not callable(fn):
        return finish(CheckResult(task_id, "failed", f"{t['title']}: expected a function; got {type(fn).__name__}"),
                      quiet)
    compare = Compare(**t["compare"])
    cases = t["cases"]
    for n, case in enumerate(cases, start=1):
        bad = check_case(t["title"], fn, n, len(cases), case["label"], case["kwargs"], case["expected"], compare,
                       t["hint"], tuple(t["forbid"]), tuple(t["allow"]))
        if bad is not None:
            return finish(CheckResult(task_id, bad.status, bad.message), quiet)
    msg = (f"{t['title']}: passed the {len(cases)} feedback cases (graded on other cases when you hand in).")
    return finish(CheckResult(task_id, "passed", msg), quiet)


# --- explorations -------------------------------------------------------------------------------------


def _attempts_path() -> Path:
    return Path(os.environ.get(ATTEMPTS_ENV) or "lab_attempts.json")


def attempts(task_id: str | None = None) -> dict[str, list]:
    """The recorded exploration attempts: ``{task_id: [value, ...]}`` (one task's, or every task's).

    Parameters
    ----------
    task_id : str, optional
        One exploration's id; None for all.

    Returns
    -------
    dict
        The answers given so far, in order (a value that was not a number is recorded as its text).
    """
    if os.environ.get(ATTEMPTS_ENV) == "memory":
        record = {k: list(v) for k, v in _IN_MEMORY.items()}
    else:
        try:
            record = json.loads(_attempts_path().read_text(encoding="utf-8"))
        except (OSError, ValueError):
            record = {}
    return record if task_id is None else {task_id: record.get(task_id, [])}


def _record(task_id: str, value) -> int:
    record = attempts()
    record.setdefault(task_id, []).append(value if isinstance(value, (int, float)) and math.isfinite(value)
                                          else repr(value))
    if os.environ.get(ATTEMPTS_ENV) == "memory":
        _IN_MEMORY[task_id] = record[task_id]
        return len(record[task_id])
    with contextlib.suppress(OSError):  # a read-only folder: the count stays in this kernel's message only
        _attempts_path().write_text(json.dumps(record, indent=1) + "\n", encoding="utf-8")
    return len(record[task_id])


def answer(task_id: str, value, *, quiet: bool = False) -> CheckResult:
    """Record an exploration's answer: a finite number of the asked form (graded when handed in).

    ``value`` is the number, or a function returning it (called here; ``NotImplementedError`` from it
    means "not done yet", as in nbgrader's student version). The check says whether the answer has the
    form the question asks for (a number, finite, whole where a count is asked, inside the quantity's
    physical bounds, such as a fraction between 0 and 1); it does not say whether it is right: that is
    graded when the lab is handed in, and every attempt is recorded for the grader (:func:`attempts`).

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
        "recorded" (with the value), "failed" (not of the asked form), "error" or "not done yet" (under
        nbgrader the last three raise ``AssertionError``).
    """
    t = _task(task_id, "number")
    q = t["question"]
    if callable(value):  # a function that runs the experiment and returns the number
        try:
            value = value()
        except NotImplementedError:
            value = None
        except Exception as exc:  # noqa: BLE001 (the student's error becomes a short message)
            msg = f"{q} — your function raised {type(exc).__name__}: {exc}\n  at {explain_exception(exc)}"
            return finish(CheckResult(task_id, "error", msg), quiet)
    if value is None or value is Ellipsis:
        return finish(CheckResult(task_id, "not done yet", f"{q} — not done yet."), quiet)
    try:
        x = float(value)
    except (TypeError, ValueError):
        n = _record(task_id, value)
        return finish(CheckResult(task_id, "failed", f"{q} — expected a number; got {value!r} (attempt {n})."), quiet)
    n = _record(task_id, x)
    lo, hi = t["bounds"]
    problem = None
    if not math.isfinite(x):
        problem = "expected a finite number"
    elif t["integer"] and x != round(x):
        problem = f"expected a whole number ({t['unit']})"
    elif not lo <= x <= hi:
        problem = f"outside {lo:g}..{hi:g}, the possible values of {t['unit']}"
    if problem is not None:
        return finish(CheckResult(task_id, "failed", f"{q} — {x:g}: {problem} (attempt {n})."), quiet)
    msg = f"{q} — recorded {x:.6g} (attempt {n}); it is graded when you hand in the lab."
    return finish(CheckResult(task_id, "recorded", msg, value=x), quiet)
