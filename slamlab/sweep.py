"""Parameter grids × seeds on joblib or Dask, as one tidy table (our addition; no source section).

:func:`sweep` runs a function once per (grid point, replicate) and returns a pandas
DataFrame with one row per run: the parameters, the replicate number, the results
and an ``error`` column (a run that raises is a row with its error, never a lost
run). Each run draws its random numbers from its own ``numpy.random.Generator``
built from ``SeedSequence(rng).spawn(n_runs)[i]`` (``rng``: an int seed, a
``SeedSequence``, a Generator or None, see :func:`root_seed_sequence`), where ``i`` is
the run's place in the task list (grid points in order, replicates inside each). A
run's numbers therefore depend on nothing but ``rng`` and ``i``, and the table is the same for
``n_jobs=1``, ``n_jobs=2`` and a Dask cluster.

Engines: ``backend="sequential"`` (the default for one job) runs in this process;
``"loky"`` (the default for more jobs) uses joblib's process pool; ``"dask"`` hands
the tasks to a ``dask.distributed`` cluster through joblib's Dask backend (pass the
``client``, or have one active). Install Dask with ``pip install 'slamlab[cluster]'``.

A function's result becomes columns by :func:`result_row`: a mapping as it is, an
object with a ``row()`` method by that, a dataclass by its scalar fields, a scalar as
``value``.
"""

from __future__ import annotations

import dataclasses
import itertools
import numbers
from collections.abc import Callable, Mapping, Sequence
from typing import Any

import numpy as np

from ._progress import progress_bar
from ._validate import as_rng, check_callable, check_choice, check_int

__all__ = ["fresh_seed_sequence", "grid_points", "raise_failed", "result_row",
           "root_seed_sequence", "sweep"]

BACKENDS = ("sequential", "loky", "dask")
ON_ERROR = ("row", "raise")


def grid_points(grid: Mapping[str, Sequence] | Sequence[Mapping[str, Any]] | None) -> list[dict[str, Any]]:
    """The points of a grid: the Cartesian product of a ``{name: values}`` mapping (first name slowest),
    a list of ``{name: value}`` points as given, or one empty point for ``None``.

    Parameters
    ----------
    grid : mapping of str to sequence, sequence of mapping, or None
        ``{name: values}`` (Cartesian product), a list of ``{name: value}`` points, or ``None``.

    Returns
    -------
    list of dict
        One ``{name: value}`` dict per point.

    Examples
    --------
    >>> grid_points({"a": [1, 2], "b": ["x"]})
    [{'a': 1, 'b': 'x'}, {'a': 2, 'b': 'x'}]
    """
    if grid is None:
        return [{}]
    if isinstance(grid, Mapping):
        names = list(grid)
        for name in names:
            if not isinstance(name, str):
                raise TypeError(f"`grid` keys must be parameter names (str); got {name!r}")
            vals = grid[name]
            if isinstance(vals, (str, bytes)) or not isinstance(vals, Sequence | np.ndarray):
                raise TypeError(f"`grid[{name!r}]` must be a sequence of values; got {type(vals).__name__}")
            if len(vals) == 0:
                raise ValueError(f"`grid[{name!r}]` must hold at least one value; got an empty sequence")
        return [dict(zip(names, combo, strict=True)) for combo in itertools.product(*(grid[n] for n in names))]
    if isinstance(grid, Sequence) and not isinstance(grid, (str, bytes)):
        points = []
        for i, point in enumerate(grid):
            if not isinstance(point, Mapping):
                raise TypeError(f"`grid[{i}]` must be a mapping of parameter values; got {type(point).__name__}")
            points.append(dict(point))
        if not points:
            raise ValueError("`grid` must hold at least one point; got an empty sequence")
        return points
    raise TypeError(f"`grid` must be a mapping name -> values, a sequence of points or None; got {type(grid).__name__}")


def root_seed_sequence(rng, name: str = "rng") -> np.random.SeedSequence:
    """The ``SeedSequence`` the runs' streams are spawned from: the sequence itself, or the one behind
    the one normaliser ``as_rng`` (``slamlab._validate``) applied to ``rng`` (``SeedSequence(rng)`` for an int, fresh entropy for None,
    a Generator's own, so ``Generator.spawn`` and :func:`sweep` give the same streams).

    Parameters
    ----------
    rng : int, SeedSequence, Generator or None
        Non-negative int, an existing sequence, a Generator (its own sequence is used) or ``None`` (fresh entropy).
    name : str
        Argument name used in the error messages (default ``"rng"``).

    Returns
    -------
    SeedSequence
        The root sequence.

    Examples
    --------
    >>> root_seed_sequence(7).entropy
    7
    """
    if isinstance(rng, np.random.SeedSequence):
        return rng
    return as_rng(rng, name).bit_generator.seed_seq


def fresh_seed_sequence(rng, name: str = "rng") -> np.random.SeedSequence:
    """:func:`root_seed_sequence` of ``rng`` as a new object that has spawned no children yet.

    ``SeedSequence.spawn`` is stateful (a second call gives the next children), so a study that runs one
    sweep per variant from the same ``rng`` (run ``i`` of every variant the same simulated run) gives each
    sweep its own copy. For an int seed the copy is ``SeedSequence(seed)``.

    Parameters
    ----------
    rng : int, SeedSequence, Generator or None
        See :func:`root_seed_sequence`.
    name : str
        The argument's name in error messages.

    Returns
    -------
    numpy.random.SeedSequence
        Same entropy and spawn key as ``root_seed_sequence(rng)``, no children spawned.

    Examples
    --------
    >>> ss = np.random.SeedSequence(3); _ = ss.spawn(2)
    >>> fresh_seed_sequence(ss).spawn(1)[0].spawn_key
    (0,)
    """
    ss = root_seed_sequence(rng, name)
    return np.random.SeedSequence(ss.entropy, spawn_key=ss.spawn_key, pool_size=ss.pool_size)


def _is_scalar(x: Any) -> bool:
    return x is None or isinstance(x, (numbers.Number, str, bool, np.generic))


def result_row(result: Any) -> dict[str, Any]:
    """A run's result as table columns (see the module docstring).

    Parameters
    ----------
    result : mapping, object with ``row()``, dataclass or scalar
        What a run returned.

    Returns
    -------
    dict
        Column name → value: the mapping itself, ``row()``'s mapping, the dataclass's scalar fields, or
        ``{"value": result}``.

    Examples
    --------
    >>> result_row(2.5)
    {'value': 2.5}
    >>> result_row({"rmse_m": 0.1, "ok": True})
    {'rmse_m': 0.1, 'ok': True}
    """
    if isinstance(result, Mapping):
        return dict(result)
    row = getattr(result, "row", None)
    if callable(row):
        out = row()
        if not isinstance(out, Mapping):
            raise TypeError(f"{type(result).__name__}.row() must return a mapping; got {type(out).__name__}")
        return dict(out)
    if dataclasses.is_dataclass(result) and not isinstance(result, type):
        return {f.name: getattr(result, f.name) for f in dataclasses.fields(result)
                if _is_scalar(getattr(result, f.name))}
    if _is_scalar(result):
        return {"value": result}
    raise TypeError(f"a sweep result must be a mapping, have row(), be a dataclass or a scalar; "
                    f"got {type(result).__name__}")


def _run_one(fn: Callable, point: dict[str, Any], fixed: dict[str, Any], rng_arg: str | None,
             seed_seq: np.random.SeedSequence) -> dict[str, Any]:
    """One task, in whichever process runs it: never raises, a failure is the row's ``error``."""
    kwargs = {**fixed, **point}
    if rng_arg is not None:
        kwargs[rng_arg] = np.random.default_rng(seed_seq)
    try:
        return {**result_row(fn(**kwargs)), "error": None}
    except Exception as exc:  # noqa: BLE001 (a failed run is a row with its error, never a lost run)
        return {"error": f"{type(exc).__name__}: {exc}"}


def _dask_config(client, n_jobs: int):
    """joblib's Dask backend on ``client``, as a context manager."""
    import contextlib

    import joblib

    stack = contextlib.ExitStack()
    stack.enter_context(client.as_current())
    stack.enter_context(joblib.parallel_config(backend="dask", n_jobs=n_jobs))
    return stack


def sweep(fn: Callable, grid: Mapping[str, Sequence] | Sequence[Mapping[str, Any]] | None = None, *,
          seeds: int = 1, rng=0, n_jobs: int = 1, backend: str | None = None, client=None,
          rng_arg: str | None = "rng", progress=None, fixed: Mapping[str, Any] | None = None,
          desc: str | None = None, on_error: str = "row"):
    """Run ``fn(**fixed, **point, rng=Generator)`` for every grid point × ``seeds`` replicates.

    Parameters
    ----------
    fn : callable
        Takes the grid's names (and ``fixed``) as keywords, and the Generator as ``rng_arg``.
    grid : mapping name -> values, sequence of points, or None
        See :func:`grid_points`.
    seeds : int
        Replicates per grid point (each with its own random stream).
    rng : int, SeedSequence, Generator or None
        Where every run's stream is spawned from (see :func:`root_seed_sequence`); default ``0``. An int
        gives the same table on every call.
    n_jobs : int
        Parallel workers (``-1``: one per core).
    backend : {"sequential", "loky", "dask"}, optional
        Default: "sequential" for ``n_jobs=1``, else "loky".
    client : dask.distributed.Client, optional
        The cluster for ``backend="dask"`` (default: the active client).
    rng_arg : str or None
        Keyword that receives the run's Generator; None for a deterministic ``fn``.
    progress : bool, callable or None
        Show a progress bar (default: on unless ``$SLAMLAB_PROGRESS=0``), or a callable ``progress(i)``
        (see :mod:`slamlab._progress`).
    fixed : mapping, optional
        Keywords passed unchanged to every run (not columns of the table).
    desc : str, optional
        The progress bar's label (default: the function's name); also names the sweep in the error
        raised by ``on_error="raise"``.
    on_error : {"row", "raise"}
        What a run that raises becomes: ``"row"`` (default) a row with the error's text in the ``error``
        column; ``"raise"`` a ``RuntimeError`` after all runs, naming how many failed and the first
        error (for callers to whom any failure is a bug).

    Returns
    -------
    pandas.DataFrame
        One row per run in task order: the parameters, ``replicate``, the results, ``error``.

    Raises
    ------
    RuntimeError
        With ``on_error="raise"``, when any run raised.

    Examples
    --------
    >>> def noisy(scale, rng):
    ...     return {"draw": round(float(scale * rng.standard_normal()), 6)}
    >>> table = sweep(noisy, {"scale": [1.0, 10.0]}, seeds=2, rng=7)
    >>> table.columns.tolist(), len(table)
    (['scale', 'replicate', 'draw', 'error'], 4)
    """
    import pandas as pd

    check_callable(fn, "fn")
    check_choice(on_error, "on_error", ON_ERROR)
    points = grid_points(grid)
    n_rep = check_int(seeds, "seeds", minimum=1)
    root = root_seed_sequence(rng)
    n_jobs = check_int(n_jobs, "n_jobs", minimum=-1)
    if n_jobs == 0:
        raise ValueError("`n_jobs` must be a positive number of workers or -1 (one per core); got 0")
    if backend is None:
        backend = "sequential" if n_jobs == 1 else "loky"
    check_choice(backend, "backend", BACKENDS)
    if rng_arg is not None and not isinstance(rng_arg, str):
        raise TypeError(f"`rng_arg` must be a keyword name (str) or None; got {type(rng_arg).__name__}")
    fixed = dict(fixed or {})
    clash = sorted(set(fixed) & {k for p in points for k in p})
    if clash:
        raise ValueError(f"`fixed` and `grid` both set {', '.join(map(repr, clash))}: give each parameter once")
    if rng_arg is not None and (rng_arg in fixed or any(rng_arg in p for p in points)):
        raise ValueError(f"`{rng_arg}` is given by sweep from the seeds; do not put it in `grid` or `fixed`")

    tasks = [(p, r) for p in points for r in range(n_rep)]
    children = root.spawn(len(tasks))
    desc = desc or getattr(fn, "__name__", "sweep")
    bar = progress_bar(total=len(tasks), desc=desc, progress=progress)
    rows: list[dict[str, Any]] = []
    try:
        if backend == "sequential":
            for (p, _), ss in zip(tasks, children, strict=True):
                rows.append(_run_one(fn, p, fixed, rng_arg, ss))
                bar.update()
        else:
            import joblib

            calls = (joblib.delayed(_run_one)(fn, p, fixed, rng_arg, ss)
                     for (p, _), ss in zip(tasks, children, strict=True))
            if backend == "dask":
                if client is None:
                    from distributed import get_client

                    try:
                        client = get_client()
                    except ValueError:
                        raise ValueError("backend='dask' needs a dask.distributed Client: pass `client=` or "
                                         "start one (Client(LocalCluster(...)))") from None
                config = _dask_config(client, n_jobs)
            else:
                config = joblib.parallel_config(backend="loky", n_jobs=n_jobs)
            with config:
                for row in joblib.Parallel(return_as="generator")(calls):
                    rows.append(row)
                    bar.update()
    finally:
        bar.close()

    records = [{**p, "replicate": r, **row} for (p, r), row in zip(tasks, rows, strict=True)]
    table = pd.DataFrame.from_records(records)
    # the error column last, the rest in first-seen order
    cols = [c for c in table.columns if c != "error"] + ["error"]
    table = table[cols]
    if on_error == "raise":
        raise_failed(table, desc)
    return table


def raise_failed(table, what: str = "sweep") -> None:
    """Raise a ``RuntimeError`` if any row of a :func:`sweep` table holds an error (what ``on_error="raise"`` does).

    Parameters
    ----------
    table : pandas.DataFrame
        A table returned by :func:`sweep` (its ``error`` column).
    what : str
        Names the sweep in the message.

    Returns
    -------
    None

    Raises
    ------
    RuntimeError
        "``n`` of ``N`` run(s) of ``what`` failed; first: ``<error>``".
    """
    failed = table["error"].notna()
    if failed.any():
        raise RuntimeError(f"{int(failed.sum())} of {len(table)} run(s) of {what} failed; "
                           f"first: {table['error'][failed].iloc[0]}")
