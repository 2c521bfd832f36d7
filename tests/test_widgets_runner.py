"""The one widget runner: a failing run prints its message and draws nothing; a good run prints its table, then draws."""

import pytest

from slamlab.widgets import show_run


class _Result:
    def table(self):
        return "n   value\n1   2.50"


def _fail(exc):
    def run():
        raise exc

    return run


@pytest.mark.parametrize("exc", [ValueError("`n` must be >= 1; got 0"), TypeError("`n` must be an int; got str")])
def test_failing_run_prints_the_message_and_does_not_draw(capsys, exc):
    drawn = []
    assert show_run(_fail(exc), drawn.append) is None
    assert capsys.readouterr().out == f"Cannot run with these settings: {exc}\n"
    assert drawn == []


def test_good_run_prints_the_table_then_draws(capsys):
    res = _Result()
    events = []

    def draw(r):
        events.append(("draw", r, capsys.readouterr().out))  # what was printed before drawing

    assert show_run(lambda: res, draw) is None
    assert events == [("draw", res, "n   value\n1   2.50\n")]
    assert capsys.readouterr().out == ""


def test_table_callable_and_no_draw(capsys):
    show_run(lambda: 3, table=lambda n: f"{n} scans\nsecond table")
    assert capsys.readouterr().out == "3 scans\nsecond table\n"


def test_errors_chooses_what_is_caught(capsys):
    drawn = []
    # not in the default tuple: a missing data file is a bug for a widget that reads none
    with pytest.raises(FileNotFoundError, match=r"intel\.log"):
        show_run(_fail(FileNotFoundError("intel.log")), drawn.append)
    # a widget that reads data files adds it
    show_run(_fail(FileNotFoundError("intel.log")), drawn.append,
                 errors=(ValueError, TypeError, FileNotFoundError))
    assert capsys.readouterr().out == "Cannot run with these settings: intel.log\n"
    assert drawn == []


def test_errors_in_table_or_draw_propagate(capsys):
    def bad_draw(_):
        raise ValueError("a bug in the plot")

    with pytest.raises(ValueError, match="a bug in the plot"):
        show_run(lambda: _Result(), bad_draw)
    assert "Cannot run" not in capsys.readouterr().out
