"""Ch. 5 widgets: every slider combination gives a result or a readable message."""

import matplotlib.pyplot as plt
import pytest

from slamlab.studies import correlation as CS


def test_explore_localisation_messages(capsys):
    w = CS.explore_localisation()
    capsys.readouterr()
    for kw, expect in (({"a_c": 1.0, "a_p": 1.0}, "must differ"), ({"x": 101, "y": 50}, "not in free space"),
                       ({"n_beams": 30, "delta_alpha_deg": 10.0, "extra_clutter": 20}, "pose x=")):
        w.f(**{**w.kwargs, **kw})
        out = capsys.readouterr().out
        assert expect in out
        assert "Traceback" not in out
        plt.close("all")


@pytest.mark.realdata
def test_explore_log_scan(capsys):
    w = CS.explore_log_scan(scan=50)
    capsys.readouterr()
    w.f(**{**w.kwargs, "a_c": 1.0, "a_p": 1.0})
    assert "Cannot run with these settings" in capsys.readouterr().out
    w.f(**{**w.kwargs, "scan": 909, "exclude": 0})
    assert "intel-corrected.log.gz scan 909 (1 scan(s) joined by the logged odometry): error" \
        in capsys.readouterr().out
    w.f(**{**w.kwargs, "scan": 0, "joined": 3})  # no scan before the first: it is localised alone
    assert "scan 0 (1 scan(s) joined" in capsys.readouterr().out
    w.f(**{**w.kwargs, "scan": 250, "joined": 3, "exclude": 0})
    out = capsys.readouterr().out
    assert "scan 250 (3 scan(s) joined" in out
    assert "ambiguity" in out
    plt.close("all")
