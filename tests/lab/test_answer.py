"""The grading of an exploration (slamlab_grading.answer): accepted ranges and typical wrong answers (issue 26,
goals 2 and 6; issue 43), on made-up tasks."""

from __future__ import annotations

import pytest

from slamlab_grading import core


@pytest.fixture
def tasks(monkeypatch):
    """Two made-up explorations: one with the old tolerance form, one with a range and misconceptions."""
    calls = {"expected": 0}

    def expected():
        calls["expected"] += 1
        return 10.0

    old = core.ExplorationTask("t.old", "Old form", expected, atol=0.5, hint="think about X.")
    new = core.ExplorationTask(
        "t.new", "New form", expected, accepted=lambda: (9.0, 11.0), why="any seed gives 9..11",
        wrong=(core.WrongAnswer("previous grid step", lambda: 8.0, "that is the last value that fails.",
                                more="the question asks for the first value that succeeds."),
               core.WrongAnswer("centimetres", lambda: 1000.0, "check the unit.", rtol=0.05)),
        hint="think about Y.", more="vary one parameter at a time.")
    for t in (old, new):
        monkeypatch.setitem(core._REGISTRY, t.task_id, t)
    monkeypatch.delenv("NBGRADER_EXECUTION", raising=False)
    return calls


def test_old_signature_and_tolerance_still_work(tasks):
    assert core.answer("t.old", 10.4, quiet=True).passed
    assert core.answer("t.old", lambda: 9.6, quiet=True).passed
    r = core.answer("t.old", 10.6, quiet=True)
    assert r.status == "failed"
    assert r.message.endswith("Hint: think about X.")
    assert core.answer("t.old", None, quiet=True).status == "not done yet"


def test_accepted_range_is_closed_and_does_not_run_the_library(tasks):
    for x in (9.0, 10.0, 11.0):
        assert core.answer("t.new", x, quiet=True).passed
    for x in (8.99, 11.01):
        assert not core.answer("t.new", x, quiet=True).passed
    assert tasks["expected"] == 0  # the range comes from `accepted`, not from the library's own run
    assert core.task("t.new").accepted_range() == (9.0, 11.0)


def test_typical_wrong_answer_gets_its_misconception_and_more_after_more_than_one_attempt(tasks):
    first = core.answer("t.new", 8.0, quiet=True)
    assert first.status == "failed"
    assert "last value that fails" in first.message
    assert "first value that succeeds" not in first.message
    second = core.answer("t.new", 8.0, quiet=True, tried=2)
    assert "last value that fails" in second.message
    assert "first value that succeeds" in second.message
    unit = core.answer("t.new", 1030.0, quiet=True)  # within the wrong answer's own 5 %
    assert "check the unit" in unit.message


def test_other_wrong_value_gets_the_general_hint_then_more(tasks):
    first = core.answer("t.new", 50.0, quiet=True)
    assert first.message.endswith("Hint: think about Y.")
    assert core.answer("t.new", 50.0, quiet=True, tried=3).message.endswith("think about Y. vary one parameter at a time.")


def test_hint_never_contains_the_answer(tasks):
    for x in (8.0, 50.0, 1000.0):
        msg = core.answer("t.new", x, quiet=True).message
        hint = msg.split("Hint:", 1)[1]
        assert "10" not in hint
        assert "9" not in hint
        assert "11" not in hint


def test_nan_and_inf_are_wrong_not_errors(tasks):
    for x in (float("nan"), float("inf")):
        r = core.answer("t.new", x, quiet=True)
        assert r.status == "failed"
        assert "think about Y" in r.message


def test_bad_accepted_range_is_a_clear_error(monkeypatch):
    t = core.ExplorationTask("t.bad", "Bad", lambda: 1.0, accepted=lambda: (2.0, 1.0))
    with pytest.raises(ValueError, match="accepted"):
        t.accepted_range()


def test_autograder_raises_on_a_wrong_answer(tasks, monkeypatch):
    monkeypatch.setenv("NBGRADER_EXECUTION", "autograde")
    with pytest.raises(AssertionError, match="last value that fails"):
        core.answer("t.new", 8.0, quiet=True)


def test_grading_takes_the_students_recorded_answer_and_counts_the_attempts(tasks, tmp_path, monkeypatch, capsys):
    from slamlab import lab

    monkeypatch.setenv("SLAMLAB_LAB_ATTEMPTS", str(tmp_path / "attempts.json"))
    monkeypatch.setattr(lab.core, "_task", lambda tid, kind: {"kind": "number", "question": "New form",
                                                               "unit": "a length", "bounds": [0.0, 1e9],
                                                               "integer": False})
    lab.answer("t.new", 50.0, quiet=True)
    recorded = lab.answer("t.new", 8.0, quiet=True)
    assert recorded.status == "recorded"
    assert recorded.value == 8.0
    res = core.grade("t.new", recorded)
    out = capsys.readouterr().out
    assert "2 answer(s) recorded" in out
    assert res.status == "failed"
    assert "first value that succeeds" in res.message
    assert core.grade("t.new", lab.answer("t.new", 10.0, quiet=True)).passed
    not_a_number = lab.answer("t.new", "ten", quiet=True)
    assert core.grade("t.new", not_a_number, quiet=True).status == "failed"


def test_a_packaged_range_is_computed_once_and_a_made_up_one_every_time(tmp_path, monkeypatch):
    monkeypatch.setenv("SLAMLAB_GRADING_CACHE", str(tmp_path))
    calls = []

    def packaged():
        calls.append(1)
        return (1.0, 2.0)

    packaged.__module__ = "slamlab_grading.tasks_made_up"
    assert core.cached_range("99.explore.x", packaged) == (1.0, 2.0)
    assert core.cached_range("99.explore.x", packaged) == (1.0, 2.0)
    assert len(calls) == 1
    (cached,) = tmp_path.glob("99.explore.x.*.json")
    assert core.code_hash() in cached.name
    made_up = lambda: (calls.append(1), (3.0, 4.0))[1]
    assert core.cached_range("99.explore.y", made_up) == (3.0, 4.0)
    assert core.cached_range("99.explore.y", made_up) == (3.0, 4.0)
    assert len(calls) == 3
