"""slamlab.sweep: grids x seeds on joblib and Dask give one tidy, reproducible table."""

from __future__ import annotations

import dataclasses
import sys
from pathlib import Path

import numpy as np
import pytest

from slamlab.sweep import (
    fresh_seed_sequence,
    grid_points,
    result_row,
    root_seed_sequence,
    sweep,
)

sys.path.insert(0, str(Path(__file__).resolve().parent))
from sweep_tasks import noisy

GRID = {"scale": [1.0, 2.0, 3.0], "label": ["a", "b"]}


def test_each_run_draws_from_its_spawned_seed_sequence():
    table = sweep(noisy, GRID, seeds=2, rng=11, progress=False)
    assert len(table) == 12
    assert table.columns.tolist() == ["scale", "label", "replicate", "draw", "n", "error"]
    children = np.random.SeedSequence(11).spawn(12)
    for i, row in table.iterrows():
        rng = np.random.default_rng(children[i])
        assert row["draw"] == row["scale"] * rng.standard_normal()
    # replicates and grid points never share a stream (forked workers must not repeat numbers)
    assert table["draw"].abs().nunique() == 12


def test_table_identical_for_one_and_two_loky_workers():
    one = sweep(noisy, GRID, seeds=3, rng=5, n_jobs=1, progress=False)
    two = sweep(noisy, GRID, seeds=3, rng=5, n_jobs=2, progress=False)
    assert one.equals(two)


def test_table_identical_on_a_dask_local_cluster():
    distributed = pytest.importorskip("distributed")
    one = sweep(noisy, GRID, seeds=2, rng=5, progress=False)
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None) as cl, \
            distributed.Client(cl) as client:
        dask_table = sweep(noisy, GRID, seeds=2, rng=5, n_jobs=2, backend="dask", client=client, progress=False)
    assert one.equals(dask_table)


def test_a_failed_run_is_a_row_with_its_error():
    table = sweep(noisy, {"scale": [1.0, 2.0, 3.0]}, fixed={"fail_at": 2.0}, rng=1, progress=False)
    assert len(table) == 3
    assert table.loc[1, "error"] == "ValueError: scale 2.0 is not allowed"
    assert np.isnan(table.loc[1, "draw"])
    assert table.loc[[0, 2], "draw"].notna().all()
    assert table.loc[[0, 2], "error"].isna().all()


def test_on_error_raise_names_the_count_and_the_first_error():
    with pytest.raises(RuntimeError, match=r"^2 of 4 run\(s\) of a study failed; first: ValueError: scale 2.0 is "
                                           r"not allowed$"):
        sweep(noisy, {"scale": [1.0, 2.0, 3.0, 2.0]}, fixed={"fail_at": 2.0}, rng=1, progress=False,
              on_error="raise", desc="a study")
    # the default names the function; "row" (the default) keeps the failure as a row
    with pytest.raises(RuntimeError, match=r"^1 of 3 run\(s\) of noisy failed"):
        sweep(noisy, {"scale": [1.0, 2.0, 3.0]}, fixed={"fail_at": 2.0}, rng=1, progress=False, on_error="raise")
    rows = sweep(noisy, {"scale": [1.0, 2.0, 3.0]}, fixed={"fail_at": 2.0}, rng=1, progress=False, on_error="row")
    assert rows["error"].notna().sum() == 1
    # with no failure "raise" returns the same table as "row"
    ok = sweep(noisy, GRID, rng=4, progress=False, on_error="raise")
    assert ok.equals(sweep(noisy, GRID, rng=4, progress=False))
    with pytest.raises(ValueError, match="`on_error` must be one of 'row', 'raise'; got 'ignore'"):
        sweep(noisy, GRID, on_error="ignore")


def test_fresh_seed_sequence_restarts_the_children():
    ss = np.random.SeedSequence(9)
    first = ss.spawn(2)
    again = fresh_seed_sequence(ss).spawn(2)  # ss itself would give children 2 and 3 now
    assert [c.spawn_key for c in again] == [c.spawn_key for c in first] == [(0,), (1,)]
    assert np.array_equal(np.random.default_rng(again[1]).integers(1 << 30, size=4),
                          np.random.default_rng(first[1]).integers(1 << 30, size=4))
    # an int seed gives SeedSequence(seed)'s children, so sweeps from an int keep their streams
    assert fresh_seed_sequence(9).spawn(1)[0].generate_state(2).tolist() == \
        np.random.SeedSequence(9).spawn(1)[0].generate_state(2).tolist()
    g = np.random.default_rng(3)
    assert fresh_seed_sequence(g).entropy == root_seed_sequence(g).entropy == 3
    with pytest.raises(TypeError, match="`rng` must be a numpy Generator, an int seed, a SeedSequence or None"):
        fresh_seed_sequence(1.5)


def test_progress_bar_only_when_asked(capsys, monkeypatch):
    monkeypatch.setenv("SLAMLAB_PROGRESS", "0")
    sweep(noisy, GRID, rng=1)
    assert capsys.readouterr().err == ""
    sweep(noisy, GRID, rng=1, progress=True)
    assert "noisy" in capsys.readouterr().err  # tqdm's text bar names the function
    sweep(noisy, GRID, rng=1, progress=True, desc="a study")
    assert "a study" in capsys.readouterr().err  # or says what the caller names it
    done = []
    sweep(noisy, GRID, rng=1, progress=done.append)  # a callable: called with each finished run's index
    assert done == list(range(6))
    assert capsys.readouterr().err == ""


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
