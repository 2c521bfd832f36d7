"""The kidnapped robot in the simulated test room (003 §1.2.4, §2.2): tracking from the known start, the robot
carried elsewhere, and whether MCL recovers; per variant of how w_slow / w_fast start (:data:`KIDNAP_VARIANTS`).

Moved unchanged from :mod:`slamlab.studies.localisation.studies` (which re-exports every name), with the two table helpers
the studies share.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ... import _validate as v
from ..._table import format_table
from ...localisation.mcl import MCLParams
from .experiments import FAIL_DEG, FAIL_POS_CELLS, run_filter, simulate_run

__all__ = ["KIDNAP_VARIANTS", "KidnapResult", "run_kidnapped"]


def _fmt(x, p=2):
    return "-" if x is None or (isinstance(x, float) and np.isnan(x)) else f"{x:.{p}f}"


def _params_line(overrides: dict | None = None) -> str:
    p = MCLParams(**(overrides or {}))
    return (f"score {p.score}, σ_hit {p.sigma_hit:g} cells, max_dist {p.max_dist:g}, {p.max_beams} beams, "
            f"α1…α4 = ({', '.join(f'{a:g}' for a in p.alpha)}), jitter ({p.jitter[0]:g}, {p.jitter[1]:g}), "
            f"weights p^{p.gamma:g}, averages {p.averages}, "
            f"(α_slow, α_fast) = ({p.alpha_slow:g}, {p.alpha_fast:g}), resample when N_eff < "
            f"{p.resample_threshold:g}·M{' (every step)' if p.resample_threshold >= 1 else ''}")


# --- the kidnapped robot --------------------------------------------------------------------------------------

#: Kidnap variants (label, overrides of the defaults): how w_slow/w_fast start decides whether injection fires.
KIDNAP_VARIANTS = (
    ("averages from 0 (003)", {"averages": "003"}),
    ("from the first w_avg, restart after injecting (amcl)", {"averages": "amcl"}),
    ("from the first w_avg, no restart (ours)", {"averages": "first"}),
    ("from 0, bias-corrected (defaults)", {}),
)


def _kidnap_task(rng, overrides: dict, n_particles: int, n_steps: int, kidnap_step: int, variant: str = "",
                 world: str = "map"):
    run = simulate_run(n_steps, start=0, kidnap_step=kidnap_step, world=world, rng=rng)
    r = run_filter(run, init="tracking", n_particles=n_particles, rng=rng, **overrides)
    k = r.converged_at(kidnap_step)
    inj = np.array([x.n_injected for x in r.records])
    return {"tracked_before": bool(r.ok[kidnap_step - 1]), "recovered": k is not None,
            "recovery_steps": -1 if k is None else k - kidnap_step,
            "injected_before": float(inj[1:kidnap_step].mean()) / n_particles,
            "injected_after": float(inj[kidnap_step:].mean()) / n_particles,
            "err_before": float(np.median(r.err_pos[1:kidnap_step]))}


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
    base : dict
        MCLParams fields under every variant's.
    """

    table_df: object = field(repr=False)
    labels: tuple = ()
    n_runs: int = 0
    kidnap_step: int = 0
    n_steps: int = 0
    n_particles: int = 0
    world: str = "map"
    base: dict = field(default_factory=dict)  # MCLParams overrides under every variant's (params=, **overrides)

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
            out.append([lab, _fmt(g["tracked_before"].mean()), _fmt(g["recovered"].mean()),
                        "-" if rec.empty else f"{rec.median():.0f}", f"{100 * g['injected_before'].mean():.1f}",
                        f"{100 * g['injected_after'].mean():.1f}", _fmt(g["err_before"].median())])
        return out

    def table(self) -> str:
        return format_table(["variant", "tracked before", "recovered", "median steps to recover",
                             "% injected per step before", "% after", "median err before [cells]"], self.rows(),
                            title=f"Kidnapped robot{' among unmapped clutter' if self.world != 'map' else ''}: "
                                  f"{self.n_particles} particles, the same {self.n_runs} runs per "
                                  f"variant, kidnapped at step {self.kidnap_step} of {self.n_steps}; recovered: "
                                  f"within {FAIL_POS_CELLS:g} cells and {FAIL_DEG:g}° from some step to the end\n"
                                  f"defaults: {_params_line(self.base)}")

    def __str__(self) -> str:
        return f"Kidnapped robot, {self.n_runs} runs per variant"


def run_kidnapped(variants=KIDNAP_VARIANTS, *, n_runs: int = 20, n_particles: int = 1000, n_steps: int = 40,
                  kidnap_step: int = 20, world: str = "map", params: MCLParams | None = None, rng=1,
                  n_jobs: int = 1, progress=None, **overrides) -> KidnapResult:
    """Track from the known start, kidnap at ``kidnap_step``; recovery per variant (the same runs for every
    variant; on sweep).

    Parameters
    ----------
    variants : sequence of (str, dict)
        (label, :class:`MCLParams` overrides) pairs, applied on top of ``params`` and ``overrides``.
    n_runs, n_particles, n_steps, kidnap_step : int
        Runs per variant, particles, steps per run, the step of the kidnap.
    world : {"map", "cluttered"}
        See :func:`~slamlab.studies.localisation.experiments.simulate_run`.
    params : MCLParams, optional
        The settings every variant changes (default: the defaults).
    rng : int, SeedSequence or Generator
        Where every run's stream is spawned from (run ``i`` the same for every variant).
    n_jobs : int
        Parallel workers of :func:`slamlab.sweep.sweep`.
    progress : bool, callable or None
        See :mod:`slamlab._progress`.
    **overrides
        :class:`MCLParams` fields under every variant.

    Returns
    -------
    KidnapResult
    """
    import pandas as pd

    from ...sweep import fresh_seed_sequence, sweep

    base = MCLParams.as_overrides(params, **overrides)
    base.pop("n_particles", None)  # the particle count is `n_particles`

    n_runs = v.check_int(n_runs, "n_runs", minimum=1)
    n_steps = v.check_int(n_steps, "n_steps", minimum=3)
    kidnap_step = v.check_int(kidnap_step, "kidnap_step", minimum=2, maximum=n_steps - 1)
    labels = []
    frames = []
    for item in variants:
        if not (isinstance(item, tuple) and len(item) == 2 and isinstance(item[1], dict)):
            raise TypeError(f"`variants` must hold (label, overrides dict) pairs; got {item!r}")
        MCLParams.resolve(None, **{**base, **item[1]})
        labels.append(item[0])
        df = sweep(_kidnap_task, [{"variant": item[0], "overrides": {**base, **item[1]}}], seeds=n_runs,
                   rng=fresh_seed_sequence(rng), n_jobs=n_jobs, progress=progress, on_error="raise",
                   desc="kidnapped robot",
                   fixed={"n_particles": n_particles, "n_steps": n_steps, "kidnap_step": kidnap_step,
                          "world": v.check_choice(world, "world", ("map", "cluttered"))})
        frames.append(df)
    return KidnapResult(pd.concat(frames, ignore_index=True), tuple(labels), n_runs, kidnap_step, n_steps,
                        int(n_particles), world, base)


# --- the observation score on both -------------------------------------------------------------------------------
