"""Long experiments show a tqdm bar when asked and stay silent under SLAMLAB_PROGRESS=0 (issue 16).

Each case runs a small size twice: silent (the environment the tests and nbval use) and with
``progress=True``; the bar names its loop on stderr, and it changes nothing in the result.
"""

from __future__ import annotations

import numpy as np
import pytest

import slamlab as sl


def _both(capsys, monkeypatch, run):
    monkeypatch.setenv("SLAMLAB_PROGRESS", "0")
    quiet = run(None)
    assert capsys.readouterr().err == ""
    shown = run(True)
    return quiet, shown, capsys.readouterr().err


def test_hough_slam_bar_over_scans(capsys, monkeypatch):
    quiet, shown, err = _both(capsys, monkeypatch, lambda p: sl.studies.hough.run_sim_slam(
        8, with_icp=False, progress=p, rng=3))
    assert "Hough SLAM" in err
    assert "/8 " in err
    np.testing.assert_array_equal(quiet.slam.poses, shown.slam.poses)


def test_store_comparison_and_crossover_bars_over_stores(capsys, monkeypatch):
    quiet, shown, err = _both(capsys, monkeypatch, lambda p: sl.studies.kdtree.experiments.run_store_comparison(
        "table1", stores=("rebuild", "brute"), n_iterations=3, rng=1, progress=p))
    assert "stores" in err
    assert "/2 " in err
    assert quiet.recall == shown.recall
    _, _, err = _both(capsys, monkeypatch, lambda p: sl.studies.kdtree.experiments.run_crossover(
        (200, 400), stores=("rebuild", "multi", "brute"), n_queries=20, n_new=50, repeats=1, rng=1, progress=p))
    assert "crossover: stores" in err
    assert "/3 " in err


@pytest.mark.realdata
def test_feature_experiments_bars(capsys, monkeypatch, real_data):
    quiet, shown, err = _both(capsys, monkeypatch, lambda p: sl.studies.features.run_pair_evaluation(
        "graf", (2, 3), detectors=("ORB",), scale=0.25, n_points=100, progress=p))
    assert "pair evaluation" in err
    assert "/2 " in err
    np.testing.assert_array_equal(quiet.rep, shown.rep)
    _, _, err = _both(capsys, monkeypatch, lambda p: sl.studies.features.run_recall_vs_leaves(
        (1, 5), n_stored=300, n_queries=20, progress=p))
    assert "recall vs leaves" in err
    assert "/2 " in err


def test_one_progress_contract_bool_none_or_callable(capsys, monkeypatch):
    from slamlab._progress import check_progress, progress_bar

    monkeypatch.setenv("SLAMLAB_PROGRESS", "1")
    done = []
    assert list(progress_bar(range(3), desc="loop", progress=done.append)) == [0, 1, 2]
    assert done == [0, 1, 2]  # a callable gets each finished item's index, and no bar is drawn
    bar = progress_bar(total=2, progress=done.append)
    bar.update()
    bar.update()
    bar.close()
    assert done == [0, 1, 2, 0, 1]
    assert capsys.readouterr().err == ""
    assert list(progress_bar("ab", desc="letters", progress=True)) == ["a", "b"]
    assert "letters" in capsys.readouterr().err
    with pytest.raises(TypeError, match=r"`progress` must be True, False, None or a callable progress\(i\); got int"):
        progress_bar(range(2), progress=1)
    with pytest.raises(TypeError, match=r"`show` must be True, False, None or a callable progress\(i\); got str"):
        check_progress("yes", "show")

