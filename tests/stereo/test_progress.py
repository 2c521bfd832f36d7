"""Stereo runs show a progress bar over the frames only when asked (issue 16), or call a callback."""

from __future__ import annotations

from slamlab.studies.stereo import run_experiment


def test_bar_only_when_asked_and_callback_per_frame(capsys, monkeypatch):
    monkeypatch.setenv("SLAMLAB_PROGRESS", "0")
    quiet = run_experiment("turn in place", n_frames=3, detector="orb")
    assert capsys.readouterr().err == ""
    shown = run_experiment("turn in place", n_frames=3, detector="orb", progress=True)
    err = capsys.readouterr().err
    assert "stereo SLAM: turn in place" in err
    assert "/3 " in err
    seen = []
    called = run_experiment("turn in place", n_frames=3, detector="orb", progress=seen.append)
    assert seen == [0, 1, 2]
    assert capsys.readouterr().err == ""
    # the bar changes nothing in the result
    assert (quiet.estimate == shown.estimate).all()
    assert (quiet.estimate == called.estimate).all()
