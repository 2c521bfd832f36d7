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


def test_interactive_text_form_is_one_short_line(capsys):
    """What a notebook stores beside the widget: the explore function's name and its control count, never
    ipywidgets' own form (the first controls spelled out, cut at 110 characters plus an ellipsis)."""
    import ipywidgets as widgets

    from slamlab.widgets import interactive, slider

    def explore_something_with_a_long_name():
        def show(noise_std, detector):
            pass

        return interactive(show, noise_std=slider(widgets.FloatSlider, 0.5, 0.0, 20.0, 0.5, "image noise σ [grey]" * 5),
                           detector=widgets.Dropdown(options=["SURF (ours)", "SIFT (OpenCV)"], description="detector"))

    w = explore_something_with_a_long_name()
    capsys.readouterr()
    assert isinstance(w, widgets.interactive)
    text = w._repr_mimebundle_()["text/plain"]
    assert text == "explore_something_with_a_long_name: 2 controls (ipywidgets)"
    assert len(text) <= 60
    assert "\n" not in text
    # ipywidgets' options pass through: a run button instead of an update on every change
    manual = interactive(lambda n: None, {"manual": True, "manual_name": "run"}, n=slider(widgets.IntSlider, 1, 1, 3, 1, "n"))
    assert manual.manual_button.description == "run"
    # named after the function that built it (here the test); a long name drops the "(ipywidgets)"
    assert repr(manual) == "test_interactive_text_form_is_one_short_line: 1 control"
