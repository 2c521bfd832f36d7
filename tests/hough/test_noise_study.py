"""The Hough SLAM noise study on slamlab.sweep (issue 16): same table for any n_jobs, clear errors."""

from __future__ import annotations

import pandas as pd
import pytest

from slamlab.studies.hough import run_noise_study


def test_noise_study_same_for_one_and_two_workers_and_one_row_per_run():
    one = run_noise_study((0.0, 0.3), 2, n_poses=20, rng=5, progress=False)
    two = run_noise_study((0.0, 0.3), 2, n_poses=20, rng=5, n_jobs=2, progress=False)
    pd.testing.assert_frame_equal(one.runs, two.runs)
    assert one.table() == two.table()
    assert list(one.runs["range_std_cells"]) == [0.0, 0.0, 0.3, 0.3]
    assert list(one.runs["replicate"]) == [0, 1, 0, 1]
    # noise-free ranges (quantised to 0.1 cell, 004): the SLAM stays within a cell of the truth
    assert (one.runs.loc[one.runs["range_std_cells"] == 0.0, "max_pos_err"] < 1.0).all()
    assert "runs > 2 cells" in one.table()


@pytest.mark.parametrize(("kwargs", "match"), [
    ({"range_std_cells": (-0.1,)}, "range_std_cells"),
    ({"n_runs": 0}, "n_runs"),
    ({"n_poses": 2}, "n_poses"),
    ({"bad_pos_cells": 0.0}, "bad_pos_cells"),
])
def test_noise_study_bad_input(kwargs, match):
    with pytest.raises((ValueError, TypeError), match=match):
        run_noise_study(**kwargs)
