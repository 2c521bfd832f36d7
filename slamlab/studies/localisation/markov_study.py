"""The Markov grid's two claims in 003 §2.2.1, measured: priors are easy, and it re-localises (kidnapped robot).

003: Markov localisation "can use prior knowledge" and, unlike a Kalman filter, "can re-localise"; its cost grows
with the number of cells (the cost table is :func:`~slamlab.studies.localisation.experiments.run_markov_vs_mcl` at
several grid sizes). Runs are paired (every variant sees the same simulated runs) and on
:func:`slamlab.sweep.sweep`.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..._validate import check_int, check_positive
from ...geometry import wrap_angle
from ...localisation.markov import MarkovGrid, MarkovParams
from ._tables import table
from .experiments import FAIL_DEG, FAIL_POS_CELLS, simulate_run

__all__ = ["MARKOV_PRIORS", "MARKOV_STUDY_PARAMS", "MarkovStudyResult", "run_markov_kidnap", "run_markov_prior"]

#: Priors of the prior experiment: (label, kind, offset of the prior's centre from the true start in cells).
MARKOV_PRIORS = (
    ("uniform on the free cells (003, no prior)", "uniform", 0.0),
    ("Gaussian at the true start (σ 10 cells, 20°)", "gaussian", 0.0),
    ("Gaussian 30 cells off the true start", "gaussian", 30.0),
)

#: The Markov studies' grid when no ``params`` is given: belief cells of 4 map cells, 36 headings (10°).
MARKOV_STUDY_PARAMS = MarkovParams(resolution=4, n_headings=36)


def _errors(est, true):
    e = np.hypot(*(est[:, :2] - true[:, :2]).T)
    h = np.degrees(np.abs(wrap_angle(est[:, 2] - true[:, 2])))
    return e, h


def _ok_bits(est, true) -> str:
    e, h = _errors(est, true)
    return "".join("1" if a else "0" for a in ((e < FAIL_POS_CELLS) & (h < FAIL_DEG)))


def _markov_task(rng, kind: str, offset: float, n_steps: int, kidnap_step: int | None, params: MarkovParams,
                 variant: str = "", uniform_floor: float | None = None):
    """One run of a Markov study: the grid of ``params`` (its floor replaced by ``uniform_floor`` when given, the
    kidnap study's axis) from a uniform or a Gaussian prior, on the run that ``rng`` simulates."""
    run = simulate_run(n_steps, start=None if kidnap_step is None else 0, kidnap_step=kidnap_step, rng=rng)
    p = params if uniform_floor is None else params.replace(uniform_floor=uniform_floor)
    g = MarkovGrid(run.grid, run.max_range, params=p)
    if kind == "gaussian":
        t = run.true_poses[0]
        a = float(rng.uniform(-np.pi, np.pi))  # the direction of the offset
        centre = t + np.array([offset * np.cos(a), offset * np.sin(a), 0.0])
        g.belief = g.gaussian_prior(centre, 10.0, np.radians(20))
    est = np.empty((run.n_steps, 3))
    for k in range(run.n_steps):
        prev, now = (run.odom_poses[k - 1], run.odom_poses[k]) if k else (None, None)
        est[k] = g.step(prev, now, run.scans[k])
    return {"ok": _ok_bits(est, run.true_poses), "final_err": float(_errors(est[-1:], run.true_poses[-1:])[0][0]),
            "err_cells": " ".join(f"{e:.2f}" for e in _errors(est, run.true_poses)[0])}


@dataclass(frozen=True)
class MarkovStudyResult:
    """A Markov-grid study: per variant, the share of runs within the bounds against the step.

    Parameters
    ----------
    table_df : pandas.DataFrame
        One row per (variant, run) of :func:`slamlab.sweep.sweep`: ``ok`` (one "1" or "0" per step: within the
        bounds), ``final_err`` (cells) and ``err_cells`` (the position error of every step, cells, as text).
    labels : tuple of str
        The variants, in table order.
    n_runs, n_steps : int
        Runs per variant, steps per run.
    resolution, n_headings : int
        The grid's map cells per belief cell and heading bins.
    kidnap_step : int or None
        The step of the kidnap (None: no kidnap).
    title : str
        The table's title.
    """

    table_df: object = field(repr=False)
    labels: tuple = ()
    n_runs: int = 0
    n_steps: int = 0
    resolution: int = 4
    n_headings: int = 36
    kidnap_step: int | None = None
    title: str = ""

    def success(self, label: str, step: int | None = None) -> float:
        """Share of runs of ``label`` within 3 cells and 5° at ``step`` (default: the last).

        Parameters
        ----------
        label : str
            A variant of ``labels``.
        step : int, optional
            The step, from 1 (default: the last).

        Returns
        -------
        float
        """
        g = self.table_df[self.table_df["variant"] == label]
        k = self.n_steps if step is None else step
        return float(np.mean([s[k - 1] == "1" for s in g["ok"]]))

    def table(self, steps=None) -> str:
        """The table: per variant, the success at some steps and the median final error.

        Parameters
        ----------
        steps : sequence of int, optional
            Steps to show (default: 1, 3, 5 and the last, or from the kidnap on).

        Returns
        -------
        str
        """
        ks = sorted(set(steps or ((1, 3, 5, self.n_steps) if self.kidnap_step is None else
                                  (self.kidnap_step, self.kidnap_step + 3, self.kidnap_step + 6, self.n_steps))))
        ks = [k for k in ks if 1 <= k <= self.n_steps]
        rows = []
        for lab in self.labels:
            g = self.table_df[self.table_df["variant"] == lab]
            rows.append([lab, *(f"{self.success(lab, k):.2f}" for k in ks), f"{g['final_err'].median():.2f}"])
        return table(["variant", *(f"success @{k}" if i == 0 else f"@{k}" for i, k in enumerate(ks)),
                      "final err [cells]"], rows,
                     title=f"{self.title}: belief cells of {self.resolution} map cells, {self.n_headings} "
                           f"headings, the same {self.n_runs} runs per variant, {self.n_steps} steps",
                     notes=[(f"success @k: share of runs within {FAIL_POS_CELLS:g} cells and {FAIL_DEG:g}° at step "
                            "k; final err: median position error at the last step")])

    def __str__(self) -> str:
        return f"{self.title}, {self.n_runs} runs per variant"


def _run(points, fixed, *, n_runs, rng, n_jobs, progress):
    """One sweep per point from a fresh copy of the same seed: run i of every point is the same simulated run."""
    import pandas as pd

    from ...sweep import fresh_seed_sequence, sweep

    frames = [sweep(_markov_task, [pt], seeds=n_runs, rng=fresh_seed_sequence(rng), n_jobs=n_jobs,
                    progress=progress, fixed=fixed, on_error="raise", desc="Markov grid study") for pt in points]
    return pd.concat(frames, ignore_index=True)


def _settings(params, overrides: dict) -> MarkovParams:
    """The studies' grid: ``params`` (default :data:`MARKOV_STUDY_PARAMS`) with ``overrides``."""
    return MarkovParams.resolve(MARKOV_STUDY_PARAMS if params is None else params, **overrides)


def _title_extra(params, overrides: dict) -> str:
    """The settings given to the prior study besides its grid, for its title (e.g. "max_beams 3")."""
    given = MarkovParams.as_overrides(params, **overrides)
    return ", ".join(f"{k} {val}" for k, val in given.items() if k not in ("resolution", "n_headings"))


def run_markov_prior(priors=MARKOV_PRIORS, *, n_runs: int = 5, n_steps: int = 10, params: MarkovParams | None = None, rng=5,
                     n_jobs: int = 1, progress=None, **overrides) -> MarkovStudyResult:
    """The Markov grid from a uniform prior and from Gaussian priors; the same runs for every prior (003 §2.2.1).

    Parameters
    ----------
    priors : sequence of (str, {"uniform", "gaussian"}, float)
        (label, kind, offset of the prior's centre from the true start [cells]).
    n_runs, n_steps : int
        Runs per prior, steps per run.
    params : MarkovParams, optional
        Settings of the grid (default: :data:`MARKOV_STUDY_PARAMS`, 4-cell belief cells and 36 headings).
    rng : int, SeedSequence or Generator
        Where every run's stream is spawned from (run ``i`` the same for every prior).
    n_jobs : int
        Parallel workers of :func:`slamlab.sweep.sweep`.
    progress : bool, callable or None
        See :mod:`slamlab._progress`.
    **overrides
        :class:`~slamlab.localisation.markov.MarkovParams` fields (e.g. fewer beams, ``max_beams=4``).

    Returns
    -------
    MarkovStudyResult
    """
    p = _settings(params, overrides)
    n_runs = check_int(n_runs, "n_runs", minimum=1)
    n_steps = check_int(n_steps, "n_steps", minimum=2)
    pts = []
    for item in priors:
        if not (isinstance(item, tuple) and len(item) == 3 and item[1] in ("uniform", "gaussian")):
            raise ValueError(f"`priors` must hold (label, 'uniform' or 'gaussian', offset) triples; got {item!r}")
        pts.append({"variant": item[0], "kind": item[1], "offset": float(item[2])})
    df = _run(pts, {"n_steps": n_steps, "kidnap_step": None, "params": p}, n_runs=n_runs, rng=rng, n_jobs=n_jobs,
              progress=progress)
    extra = _title_extra(params, overrides)
    return MarkovStudyResult(df, tuple(pt["variant"] for pt in pts), n_runs, n_steps, p.resolution, p.n_headings,
                             None, "Markov grid, priors" + (f" ({extra})" if extra else ""))


def run_markov_kidnap(floors=(0.0, 1e-6, 1e-3), *, n_runs: int = 5, n_steps: int = 24, kidnap_step: int = 8,
                      params: MarkovParams | None = None, rng=6, n_jobs: int = 1, progress=None, **overrides) -> MarkovStudyResult:
    """The kidnapped robot on the Markov grid: tracking from a prior at the true start, carried elsewhere at
    ``kidnap_step``; per uniform floor ε (0: PR Table 8.1 as it is; 003 §2.2.1).

    The study varies the floor itself (one variant per value of ``floors``): ``params`` and the overrides must
    leave ``uniform_floor`` at its default (a ``ValueError`` names it otherwise).

    Parameters
    ----------
    floors : sequence of float
        The uniform floors ε, one variant each (the study's own axis: not ``params.uniform_floor``).
    n_runs, n_steps, kidnap_step : int
        Runs per floor, steps per run, the step of the kidnap.
    params : MarkovParams, optional
        Settings of the grid (default: :data:`MARKOV_STUDY_PARAMS`, 4-cell belief cells and 36 headings), but for
        ``uniform_floor``.
    rng : int, SeedSequence or Generator
        Where every run's stream is spawned from (run ``i`` the same for every floor).
    n_jobs : int
        Parallel workers of :func:`slamlab.sweep.sweep`.
    progress : bool, callable or None
        See :mod:`slamlab._progress`.
    **overrides
        :class:`~slamlab.localisation.markov.MarkovParams` fields.

    Returns
    -------
    MarkovStudyResult
    """

    from ..._params import refuse_set_fields

    p = _settings(params, overrides)
    refuse_set_fields(p, ["uniform_floor"], "one variant per value of `floors`")
    n_runs = check_int(n_runs, "n_runs", minimum=1)
    pts = [{"variant": f"uniform floor ε = {check_positive(f, 'floors[]', allow_zero=True):g}", "kind": "gaussian",
            "offset": 0.0, "uniform_floor": float(f)} for f in floors]
    df = _run(pts, {"n_steps": n_steps, "kidnap_step": kidnap_step, "params": p}, n_runs=n_runs, rng=rng,
              n_jobs=n_jobs, progress=progress)
    return MarkovStudyResult(df, tuple(pt["variant"] for pt in pts), n_runs, n_steps, p.resolution, p.n_headings,
                             kidnap_step, f"Markov grid, kidnapped at step {kidnap_step}")
