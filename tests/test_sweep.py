"""slamlab.sweep: grids x seeds on joblib and Dask give one tidy, reproducible table."""

from __future__ import annotations

import dataclasses
import sys
from pathlib import Path

import numpy as np
import pytest

from slamlab.sweep import grid_points, result_row, sweep

sys.path.insert(0, str(Path(__file__).resolve().parent))
from sweep_tasks import noisy

GRID = {"scale": [1.0, 2.0, 3.0], "label": ["a", "b"]}


def test_each_run_draws_from_its_spawned_seed_sequence():
    table = sweep(noisy, GRID, seeds=2, seed=11, progress=False)
    assert len(table) == 12
    assert table.columns.tolist() == ["scale", "label", "replicate", "draw", "n", "error"]
    children = np.random.SeedSequence(11).spawn(12)
    for i, row in table.iterrows():
        rng = np.random.default_rng(children[i])
        assert row["draw"] == row["scale"] * rng.standard_normal()
    # replicates and grid points never share a stream (forked workers must not repeat numbers)
    assert table["draw"].abs().nunique() == 12


def test_table_identical_for_one_and_two_loky_workers():
    one = sweep(noisy, GRID, seeds=3, seed=5, n_jobs=1, progress=False)
    two = sweep(noisy, GRID, seeds=3, seed=5, n_jobs=2, progress=False)
    assert one.equals(two)


def test_table_identical_on_a_dask_local_cluster():
    distributed = pytest.importorskip("distributed")
    one = sweep(noisy, GRID, seeds=2, seed=5, progress=False)
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None) as cl, \
            distributed.Client(cl) as client:
        dask_table = sweep(noisy, GRID, seeds=2, seed=5, n_jobs=2, backend="dask", client=client, progress=False)
    assert one.equals(dask_table)


def test_a_failed_run_is_a_row_with_its_error():
    table = sweep(noisy, {"scale": [1.0, 2.0, 3.0]}, fixed={"fail_at": 2.0}, seed=1, progress=False)
    assert len(table) == 3
    assert table.loc[1, "error"] == "ValueError: scale 2.0 is not allowed"
    assert np.isnan(table.loc[1, "draw"])
    assert table.loc[[0, 2], "draw"].notna().all()
    assert table.loc[[0, 2], "error"].isna().all()


def test_progress_bar_only_when_asked(capsys, monkeypatch):
    monkeypatch.setenv("SLAMLAB_PROGRESS", "0")
    sweep(noisy, GRID, seed=1)
    assert capsys.readouterr().err == ""
    sweep(noisy, GRID, seed=1, progress=True)
    assert "noisy" in capsys.readouterr().err  # tqdm's text bar names the function
    sweep(noisy, GRID, seed=1, progress=True, desc="a study")
    assert "a study" in capsys.readouterr().err  # or says what the caller names it


def test_result_row_forms():
    @dataclasses.dataclass(frozen=True)
    class R:
        rmse_m: float
        poses: np.ndarray

    class WithRow:
        def row(self):
            return {"x": 1}

    assert result_row(R(0.5, np.zeros(3))) == {"rmse_m": 0.5}
    assert result_row(WithRow()) == {"x": 1}
    assert result_row(np.float64(2.0)) == {"value": 2.0}
    with pytest.raises(TypeError, match="a sweep result must be a mapping"):
        result_row([1, 2])


def test_grid_points_and_bad_arguments():
    assert grid_points([{"a": 1}, {"a": 2, "b": 3}]) == [{"a": 1}, {"a": 2, "b": 3}]
    assert grid_points(None) == [{}]
    with pytest.raises(ValueError, match=r"`grid\['a'\]` must hold at least one value"):
        grid_points({"a": []})
    with pytest.raises(TypeError, match=r"`grid\['a'\]` must be a sequence of values; got str"):
        grid_points({"a": "xyz"})
    with pytest.raises(ValueError, match="`backend` must be one of 'sequential', 'loky', 'dask'"):
        sweep(noisy, GRID, backend="threads")
    with pytest.raises(ValueError, match=r"`fixed` and `grid` both set 'scale'"):
        sweep(noisy, GRID, fixed={"scale": 1.0})
    with pytest.raises(ValueError, match="`rng` is given by sweep from the seeds"):
        sweep(noisy, {"scale": [1.0], "rng": [1]})
    with pytest.raises(ValueError, match="`n_jobs` must be a positive number of workers or -1"):
        sweep(noisy, GRID, n_jobs=0)
    with pytest.raises(TypeError, match="`fn` must be callable"):
        sweep("noisy", GRID)
