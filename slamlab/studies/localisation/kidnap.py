"""The kidnapped robot in the simulated test room (003 §1.2.4, §2.2): tracking from the known start, the robot
carried elsewhere, and whether MCL recovers; per variant of how w_slow / w_fast start (:data:`KIDNAP_VARIANTS`).

:mod:`slamlab.studies.localisation.studies` re-exports every name.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..._validate import check_choice, check_int
from ...localisation.mcl import MCLParams
from ._tables import fmt, params_line, table
from .experiments import FAIL_DEG, FAIL_POS_CELLS, run_filter, simulate_run

__all__ = ["KIDNAP_VARIANTS", "RESAMPLING_COLUMNS", "KidnapResult", "resampling_stats", "resampling_table",
           "run_kidnapped"]

#: The per-run resampling figures of :func:`resampling_stats` (each a share of the run's steps, or a median).
RESAMPLING_COLUMNS = ("resampled", "neff_low", "neff_frac", "injecting")


def resampling_stats(records, params: MCLParams) -> dict:
    """How often one run resampled, and why: the shares of its steps that resampled, that had
    ``N_eff < resample_threshold·M`` before resampling, that injected particles, and the median ``N_eff/M``.

    Parameters
    ----------
    records : sequence of StepRecord
        The run's step records (the ``records`` of a :class:`slamlab.localisation.MCL`).
    params : MCLParams
        The run's settings (its ``resample_threshold``).

    Returns
    -------
    dict
        ``resampled``, ``neff_low``, ``injecting`` (shares of the steps) and ``neff_frac`` (median N_eff/M).
    """
    frac = np.array([r.n_eff / max(1, r.n_particles) for r in records])
    return {"resampled": float(np.mean([r.resampled for r in records])),
            "neff_low": float(np.mean(frac < params.resample_threshold)),
            "neff_frac": float(np.median(frac)),
            "injecting": float(np.mean([r.n_injected > 0 for r in records]))}


def resampling_table(summary, labels, base: MCLParams, title: str) -> str:
    """The resampling figures of a study, one row per variant (``summary``: one row per label with the means over
    the runs of :data:`RESAMPLING_COLUMNS`).

    Parameters
    ----------
    summary : pandas.DataFrame
        Indexed by the labels, with the columns of :data:`RESAMPLING_COLUMNS`.
    labels : sequence of str
        The variants, in table order.
    base : MCLParams
        The settings every variant changes (for the notes).
    title : str
        The table's title.

    Returns
    -------
    str
    """
    rows = [[lab, *(fmt(summary.loc[lab, c]) for c in RESAMPLING_COLUMNS)] for lab in labels]
    return table(["variant", "steps resampled", "N_eff < thr·M", "median N_eff/M", "steps injecting"], rows,
                 title=title,
                 notes=[("steps resampled: share of the steps at which the set was resampled; N_eff < thr·M: share "
                        "of the steps whose effective sample size N_eff = 1/Σw², before resampling, was below the "
                        f"variant's resample_threshold (defaults {base.resample_threshold:g}) times the count M; "
                        "median N_eff/M: over the steps of a run; steps injecting: share of the steps at which "
                        "particles were injected (injection happens inside a resampling, never causes one); all "
                        "averaged over the runs")])


# --- the kidnapped robot --------------------------------------------------------------------------------------

#: Kidnap variants (label, overrides of the defaults): how w_slow/w_fast start decides whether injection fires.
KIDNAP_VARIANTS = (
    ("from 0 (003)", {"averages": "003"}),
    ("first w_avg, restarted (amcl)", {"averages": "amcl"}),
    ("first w_avg, no restart (ours)", {"averages": "first"}),
    ("from 0, bias-corrected (defaults)", {}),
)


def _kidnap_task(rng, params: MCLParams, n_steps: int, kidnap_step: int, variant: str = "", world: str = "map"):
    """One kidnap run: tracking with ``params`` from the true start of the run that ``rng`` simulates."""
    run = simulate_run(n_steps, start=0, kidnap_step=kidnap_step, world=world, rng=rng)
    r = run_filter(run, init="tracking", params=params, rng=rng)
    k = r.converged_at(kidnap_step)
    inj = np.array([x.n_injected for x in r.records])
    return {"tracked_before": bool(r.ok[kidnap_step - 1]), "recovered": k is not None,
            "recovery_steps": -1 if k is None else k - kidnap_step,
            "injected_before": float(inj[1:kidnap_step].mean()) / params.n_particles,
            "injected_after": float(inj[kidnap_step:].mean()) / params.n_particles,
            "err_before": float(np.median(r.err_pos[1:kidnap_step])), **resampling_stats(r.records, params)}


@dataclass(frozen=True)
class KidnapResult:
    """Kidnapped robot: tracking from the known start, carried elsewhere at ``kidnap_step``; per variant.

    Parameters
    ----------
    table_df : pandas.DataFrame
        One row per (variant, run).
    labels : tuple of str
        The variants, in table order.
    n_runs, kidnap_step, n_steps, n_particles : int
        Runs per variant, the kidnap's step, steps per run, particles.
    world : str
        What the scans see ("map" or "cluttered").
    base : MCLParams
        The settings every variant changes.
    """

    table_df: object = field(repr=False)
    labels: tuple = ()
    n_runs: int = 0
    kidnap_step: int = 0
    n_steps: int = 0
    n_particles: int = 0
    world: str = "map"
    base: MCLParams = field(default_factory=MCLParams)

    def recovered(self, label: str | None = None) -> float:
        """Share of runs that recover (within the bounds from some step after the kidnap to the end).

        Parameters
        ----------
        label : str, optional
            A variant (default: the first).

        Returns
        -------
        float
        """
        df = self.table_df
        return float(df[df["variant"] == (self.labels[-1] if label is None else label)]["recovered"].mean())

    def rows(self) -> list:
        out = []
        for lab in self.labels:
            g = self.table_df[self.table_df["variant"] == lab]
            rec = g[g["recovery_steps"] >= 0]["recovery_steps"]
            out.append([lab, fmt(g["tracked_before"].mean()), fmt(g["recovered"].mean()),
                        "-" if rec.empty else f"{rec.median():.0f}", f"{100 * g['injected_before'].mean():.1f}",
                        f"{100 * g['injected_after'].mean():.1f}", fmt(g["err_before"].median())])
        return out

    def table(self) -> str:
        return table(["variant", "tracked", "recovered", "steps", "% inj. before", "% inj. after", "err before"],
                     self.rows(),
                     title=f"Kidnapped robot{' among unmapped clutter' if self.world != 'map' else ''}: "
                           f"{self.n_particles} particles, the same {self.n_runs} runs per variant, kidnapped at "
                           f"step {self.kidnap_step} of {self.n_steps}\ndefaults: {params_line(self.base)}",
                     notes=[(f"tracked: share of runs within {FAIL_POS_CELLS:g} cells and {FAIL_DEG:g}° at the step "
                            "before the kidnap; recovered: share within them from some step after it to the end; "
                            "steps: median steps to recover; % inj. before / after: particles injected per step, "
                            "in % of the count, before / after the kidnap; err before: median position error "
                            "before the kidnap [cells]")])

    def resampling_table(self) -> str:
        """Per variant, how often the set was resampled and why: N_eff against the threshold, and injection."""
        summary = self.table_df.groupby("variant")[list(RESAMPLING_COLUMNS)].mean()
        return resampling_table(summary, self.labels, self.base,
                                f"Resampling in the kidnap runs{' among unmapped clutter' if self.world != 'map' else ''}"
                                f" ({self.n_particles} particles, {self.n_runs} runs of {self.n_steps} steps per "
                                f"variant)")

    def __str__(self) -> str:
        return f"Kidnapped robot, {self.n_runs} runs per variant"


#: The kidnap study's settings when no ``params`` is given: the defaults with 1000 particles.
_KIDNAP_PARAMS = MCLParams(n_particles=1000)


def run_kidnapped(variants=KIDNAP_VARIANTS, *, n_runs: int = 20, n_steps: int = 40, kidnap_step: int = 20,
                  world: str = "map", params: MCLParams | None = None, rng=1, n_jobs: int = 1, progress=None,
                  **overrides) -> KidnapResult:
    """Track from the known start, kidnap at ``kidnap_step``; recovery per variant (the same runs for every
    variant; on sweep; 003 §1.2.4, §2.2).

    Parameters
    ----------
    variants : sequence of (str, dict)
        (label, :class:`MCLParams` overrides) pairs, applied on top of ``params`` and ``overrides``.
    n_runs, n_steps, kidnap_step : int
        Runs per variant, steps per run, the step of the kidnap.
    world : {"map", "cluttered"}
        See :func:`~slamlab.studies.localisation.experiments.simulate_run`.
    params : MCLParams, optional
        The settings every variant changes (default: the defaults with ``n_particles=1000``).
    rng : int, SeedSequence or Generator
        Where every run's stream is spawned from (run ``i`` the same for every variant).
    n_jobs : int
        Parallel workers of :func:`slamlab.sweep.sweep`.
    progress : bool, callable or None
        See :mod:`slamlab._progress`.
    **overrides
        :class:`MCLParams` fields under every variant (e.g. ``n_particles``).

    Returns
    -------
    KidnapResult
    """
    import pandas as pd

    from ...sweep import fresh_seed_sequence, sweep

    base = MCLParams.resolve(_KIDNAP_PARAMS if params is None else params, **overrides)
    n_runs = check_int(n_runs, "n_runs", minimum=1)
    n_steps = check_int(n_steps, "n_steps", minimum=3)
    kidnap_step = check_int(kidnap_step, "kidnap_step", minimum=2, maximum=n_steps - 1)
    world = check_choice(world, "world", ("map", "cluttered"))
    labels, points = [], []
    for item in variants:
        if not (isinstance(item, tuple) and len(item) == 2 and isinstance(item[1], dict)):
            raise TypeError(f"`variants` must hold (label, overrides dict) pairs; got {item!r}")
        labels.append(item[0])
        points.append({"variant": item[0], "params": base.replace(**item[1])})
    frames = [sweep(_kidnap_task, [pt], seeds=n_runs, rng=fresh_seed_sequence(rng), n_jobs=n_jobs,
                    progress=progress, on_error="raise", desc="kidnapped robot",
                    fixed={"n_steps": n_steps, "kidnap_step": kidnap_step, "world": world}) for pt in points]
    return KidnapResult(pd.concat(frames, ignore_index=True), tuple(labels), n_runs, kidnap_step, n_steps,
                        base.n_particles, world, base)
