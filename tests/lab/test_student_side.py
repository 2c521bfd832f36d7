"""What a student's kernel holds and shows (issue 43): ``sl.lab.check`` against the stored feedback cases,
``sl.lab.answer`` checking only the form of an answer, the forbidden library calls, and a walk of every public
name reachable from ``import slamlab`` for references, accepted ranges and model answers."""

from __future__ import annotations

import inspect
import json
import math
import signal
import subprocess
import sys
import textwrap

import numpy as np
import pytest

import slamlab_grading as grading
from slamlab import lab
from slamlab.lab import feedback


@pytest.fixture(autouse=True)
def _attempts_file(tmp_path, monkeypatch):
    monkeypatch.setenv("SLAMLAB_LAB_ATTEMPTS", str(tmp_path / "lab_attempts.json"))
    monkeypatch.delenv("NBGRADER_EXECUTION", raising=False)


def kf_predict(x, P, F, Q):  # 000 §1.2, written here
    return F @ x, F @ P @ F.T + Q


def test_a_correct_function_passes_the_feedback_cases(capsys):
    res = lab.check("01.kf_predict", kf_predict)
    n = len(feedback.load("01")["tasks"]["01.kf_predict"]["cases"])
    assert res.passed
    assert capsys.readouterr().out.startswith(f"Task 1, KF predict: passed the {n} feedback cases")


def test_a_wrong_function_gets_the_first_failing_case_and_the_hint():
    res = lab.check("01.kf_predict", lambda x, P, F, Q: (F @ x, F @ P @ F + Q), quiet=True)  # F^T missing
    assert res.status == "failed"
    assert "is wrong: item 1 of the returned tuple" in res.message
    assert "expected:" in res.message
    assert "received:" in res.message
    assert "hint:" in res.message


def test_not_done_yet_error_and_copied_inputs():
    def todo(x, P, F, Q):
        raise NotImplementedError

    def broken(x, P, F, Q):
        wrong = x @ np.ones((7, 7))  # the student's own line
        return wrong, P

    def mutating(x, P, F, Q):
        out = F @ x, F @ P @ F.T + Q
        P[:] = 0.0  # changes the caller's array: must not change the next case
        return out

    assert (lab.check("01.kf_predict", todo, quiet=True).message) == "Task 1, KF predict: not done yet."
    res = lab.check("01.kf_predict", broken, quiet=True)
    assert res.status == "error"
    assert "wrong = x @ np.ones((7, 7))" in res.message
    assert "Traceback" not in res.message
    assert "slamlab" not in res.message.replace("sl.lab", "")
    assert lab.check("01.kf_predict", mutating, quiet=True).passed


@pytest.mark.parametrize("how", ["lambda", "alias", "inside"])
def test_calling_the_library_function_the_task_re_implements_fails(how):
    import slamlab as sl
    from slamlab.filters import kf_predict as kp

    def inside(x, P, F, Q):
        return tuple(kp(x, P, F, Q))

    fn = {"lambda": lambda x, P, F, Q: sl.filters.kf_predict(x, P, F, Q), "alias": kp, "inside": inside}[how]
    for res in (lab.check("01.kf_predict", fn, quiet=True), grading.check("01.kf_predict", fn, quiet=True)):
        assert res.status == "failed"
        assert "called the library's slamlab.filters" in res.message
        assert "kf_predict" in res.message


def test_call_watching_names_forbidden_calls_and_restores_the_profiler():
    from slamlab.geometry import wrap_angle

    before = sys.getprofile()
    result, called = lab.call_watching(lambda a: wrap_angle(a) + np.cos(a), {"a": 4.0})
    assert math.isclose(result, wrap_angle(4.0) + np.cos(4.0))
    assert called
    assert called[0].startswith("slamlab.geometry")
    assert called[0].endswith("wrap_angle")
    assert lab.call_watching(lambda a: np.cos(a), {"a": 1.0})[1] == []
    assert lab.call_watching(lambda a: wrap_angle(a), {"a": 1.0}, forbid=("slamlab.filters",))[1] == []
    assert sys.getprofile() is before


def test_answer_checks_the_form_records_every_attempt_and_never_says_right_or_wrong(monkeypatch):
    tid = "99.explore.made_up"
    spec = {"kind": "number", "question": "Steps", "points": 2, "unit": "a number of steps", "bounds": [1.0, 1e6],
            "integer": True}
    monkeypatch.setattr(lab.core, "_task", lambda task_id, kind: spec)
    inside = 1.0
    assert "possible values of a number of steps" in lab.answer(tid, 0.0, quiet=True).message
    assert lab.answer(tid, None, quiet=True).status == "not done yet"
    assert lab.answer(tid, "three", quiet=True).status == "failed"
    assert lab.answer(tid, float("nan"), quiet=True).status == "failed"
    assert "whole number" in lab.answer(tid, inside + 0.5, quiet=True).message
    res = lab.answer(tid, lambda: inside, quiet=True)
    assert res.status == "recorded"
    assert res.value == inside
    assert "graded when you hand in" in res.message
    assert "attempt 5" in res.message
    assert len(lab.attempts(tid)[tid]) == 5
    for word in ("passed", "wrong", "not it", "correct"):
        assert word not in res.message


def test_under_nbgrader_only_failures_raise(monkeypatch):
    monkeypatch.setenv("NBGRADER_EXECUTION", "autograde")
    assert lab.check("01.kf_predict", kf_predict, quiet=True).passed
    with pytest.raises(AssertionError, match="not done yet"):
        lab.check("01.kf_predict", lambda x, P, F, Q: (_ for _ in ()).throw(NotImplementedError), quiet=True)
    tid = next(t for t in lab.task_ids("08.") if feedback.load("08")["tasks"][t]["kind"] == "number")
    lo = feedback.load("08")["tasks"][tid]["bounds"][0]
    assert lab.answer(tid, lo if math.isfinite(lo) else 0.0, quiet=True).status == "recorded"
    with pytest.raises(AssertionError, match="expected a number"):
        lab.answer(tid, "three", quiet=True)


def test_task_lookup_errors():
    with pytest.raises(ValueError, match="`task_id` must be one of"):
        lab.check("99.nothing", kf_predict)
    with pytest.raises(TypeError, match=r"sl\.lab\.answer"):
        lab.check("01.explore.q_scale", kf_predict)
    with pytest.raises(TypeError, match=r"sl\.lab\.check"):
        lab.answer("01.kf_predict", 3)


# --- what the student's kernel holds -------------------------------------------------------------------------


def test_feedback_files_hold_every_task_and_match_the_grading():
    """The shipped files are what ``python -m slamlab_grading feedback`` writes now (regenerate after a change)."""
    assert lab.task_ids() == sorted(grading.all_tasks())
    for chapter in sorted(grading.TASK_MODULES):
        shipped = (feedback.FEEDBACK_DIR / f"{chapter}.json").read_text(encoding="utf-8")
        assert shipped == grading.feedback_file(chapter), f"{chapter}.json is stale: python -m slamlab_grading feedback"


def test_exploration_records_hold_only_the_form_of_the_answer():
    for tid, t in grading.all_tasks().items():
        if not isinstance(t, grading.ExplorationTask):
            continue
        rec = feedback.load(tid[:2])["tasks"][tid]
        assert set(rec) == {"kind", "question", "points", "unit", "bounds", "integer"}, tid
        lo, hi = t.accepted_range()
        b_lo, b_hi = rec["bounds"]
        assert b_lo <= lo, f"{tid}: the form check would refuse a right answer"
        assert hi <= b_hi, f"{tid}: the form check would refuse a right answer"
        assert (b_hi - b_lo) >= 10 * max(hi - lo, 1e-12) or (b_lo, b_hi) == (0.0, 1.0), \
            f"{tid}: bounds {rec['bounds']} give the accepted range {lo, hi} away"


def _public_objects():
    """Every public object reachable from ``import slamlab`` (every public module of the package, their public
    attributes, the public attributes of public classes), with its dotted name."""
    import importlib
    import pkgutil

    import slamlab

    names = ["slamlab"] + [m.name for m in pkgutil.walk_packages(slamlab.__path__, "slamlab.")
                           if not any(p.startswith("_") for p in m.name.split(".")[1:])]
    seen, out = set(), []
    for name in names:
        mod = importlib.import_module(name)
        for attr in dir(mod):
            if attr.startswith("_"):
                continue
            obj = getattr(mod, attr)
            if id(obj) in seen:
                continue
            seen.add(id(obj))
            out.append((f"{name}.{attr}", obj))
            if inspect.isclass(obj):
                for a in dir(obj):
                    if not a.startswith("_") and callable(m := getattr(obj, a, None)) and id(m) not in seen:
                        seen.add(id(m))
                        out.append((f"{name}.{attr}.{a}", m))
    return out


def test_slamlab_never_imports_the_grading():
    code = textwrap.dedent("""
        import importlib, pkgutil, sys
        class Block:
            def find_spec(self, name, path=None, target=None):
                if name.split(".")[0] == "slamlab_grading":
                    raise ImportError("the student's kernel has no slamlab_grading")
        sys.meta_path.insert(0, Block())
        import slamlab
        for m in pkgutil.walk_packages(slamlab.__path__, "slamlab."):
            importlib.import_module(m.name)
        from slamlab import lab
        assert lab.task_ids(), "no feedback"
        print(sorted(k for k in sys.modules if k.startswith("slamlab_grading")))
    """)
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=False, timeout=300)
    assert out.returncode == 0, out.stderr[-2000:]
    assert out.stdout.strip().splitlines()[-1] == "[]"


class _TooSlow(Exception):
    pass


def _too_slow(signum, frame):
    raise _TooSlow


def test_no_public_name_of_slamlab_is_a_task_or_passes_an_implementation_task():
    """The walk of issue 43's first done-when: no reachable object carries a reference, an accepted range, a
    ``why`` or misconceptions, and no reachable callable passes the grading of any implementation task when
    handed in as the student's function (a library function is refused by the forbidden-call check)."""
    objects = _public_objects()
    assert len(objects) > 500
    for name, obj in objects:
        assert not isinstance(obj, (grading.Task, grading.ExplorationTask)), name
        for attr in ("reference", "accepted", "accepted_range", "why", "wrong", "misconception"):
            assert not (hasattr(obj, attr) and not inspect.ismodule(obj) and attr in getattr(obj, "__dict__", {})), \
                f"{name}.{attr}"
    passed, tried = [], set()
    for tid, t in grading.all_tasks().items():
        if not isinstance(t, grading.Task):
            continue
        case = t.cases(np.random.default_rng(0))[0]
        for name, obj in objects:
            if not callable(obj) or inspect.isclass(obj):
                continue
            try:
                params = inspect.signature(obj).parameters.values()
                inspect.signature(obj).bind(**case.kwargs)
            except (TypeError, ValueError):
                continue
            if any(p.kind is p.VAR_KEYWORD for p in params):  # takes any keyword: not a task's signature
                continue
            tried.add((tid, name))
            signal.signal(signal.SIGALRM, _too_slow)
            signal.alarm(10)  # a library function that starts a long run with these arguments is no solution
            try:
                res = grading.check(tid, obj, quiet=True)
            except Exception:  # noqa: BLE001, S112 (a callable that is not a student's function at all)
                continue
            finally:
                signal.alarm(0)
            if res.passed:
                passed.append((tid, name))
    assert ("01.kf_predict", "slamlab.filters.kf_predict") in tried, sorted(tried)[:20]  # the walk reaches it
    assert not passed, f"public names that pass an implementation task: {passed}"


def test_the_attempts_file_is_plain_json(tmp_path, monkeypatch):
    tid = next(t for t in lab.task_ids("01.") if feedback.load("01")["tasks"][t]["kind"] == "number")
    lo, _hi = feedback.load("01")["tasks"][tid]["bounds"]
    lab.answer(tid, lo if math.isfinite(lo) else 1.0, quiet=True)
    lab.answer(tid, "x", quiet=True)
    record = json.loads((tmp_path / "lab_attempts.json").read_text())
    assert record[tid][1] == "'x'"
    assert len(record[tid]) == 2


@pytest.mark.parametrize("value", [np.zeros((0, 2)), np.zeros((3, 0, 4), np.int8), np.arange(6.0).reshape(2, 3),
                                   (np.array([1, 2]), 3.5, None, "x"), {"a": [1, 2], "b": float("inf")}])
def test_the_feedback_codec_keeps_shapes_dtypes_and_types(value):
    back = feedback.decode(json.loads(json.dumps(feedback.encode(value))))
    if isinstance(value, np.ndarray):
        assert back.shape == value.shape  # an empty array too (a "no queries" case is (0, 2), not (0,))
        assert back.dtype == value.dtype
        np.testing.assert_array_equal(back, value)
    else:
        assert type(back) is type(value)
        assert repr(back) == repr(value)
