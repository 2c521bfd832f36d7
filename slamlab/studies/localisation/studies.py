"""Monte Carlo studies of MCL in the simulated test room (003 §2.2): global localisation against the step and the
particle count, the ablation that finds what global localisation depends on, the kidnapped robot, and the
observation score compared on both.

Every study runs on :func:`slamlab.sweep.sweep` with one seeded stream per run. Variants of a study are run as one
sweep each from the same seed, so run ``i`` of every variant is the same simulated run (path, scans, odometry)
and the comparison is paired. Success at step ``k``: the estimate within 3 cells and 5° of the truth at that step
(ours). AMCL's convergence test (ROS 1 amcl ``pf_update_converged``: every particle within ``converged_dist`` of
the particles' mean in x and y) is reported beside it: "converged" says nothing about *where*, so a run can be
converged and wrong.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..._table import format_table
from ..._validate import check_choice, check_int
from ...localisation.mcl import MCLParams
from ._tables import fmt, params_line, table
from .experiments import FAIL_DEG, FAIL_POS_CELLS, run_filter, simulate_run
from .kidnap import (
    KIDNAP_VARIANTS,
    RESAMPLING_COLUMNS,
    KidnapResult,
    resampling_stats,
    resampling_table,
    run_kidnapped,
)
from .variants import ABLATION, ABLATION_MORE, CHAPTER_BEFORE, PLAIN_SETUP, SCORE_VARIANTS

__all__ = [
    "ABLATION",
    "ABLATION_MORE",
    "CHAPTER_BEFORE",
    "PLAIN_SETUP",
    "SCORE_VARIANTS",
    "AblationResult",
    "GlobalResult",
    "KidnapResult",
    "ScoreComparison",
    "run_global_ablation",
    "run_global_localisation",
    "run_kidnapped",
    "run_score_comparison",
]

def _bits(flags) -> str:
    return "".join("1" if f else "0" for f in flags)


def _on_turn(run) -> bool:
    """Whether the run starts in one of the path's turns on the spot (the first two poses at one place)."""
    return bool(np.hypot(*(run.true_poses[1, :2] - run.true_poses[0, :2])) < 1e-9)


def _global_task(rng, params: MCLParams, n_steps: int, variant: str = "", world: str = "map", n_particles=None):
    """One global run from no prior: ``params`` (its count replaced by ``n_particles`` when given, the particle
    count study's axis) on the run that ``rng`` simulates."""
    run = simulate_run(n_steps, world=world, rng=rng)
    p = params if n_particles is None else params.replace(n_particles=n_particles)
    r = run_filter(run, params=p, rng=rng)
    return {"ok": _bits(r.ok), "conv": _bits(x.converged for x in r.records), "on_turn": _on_turn(run),
            **resampling_stats(r.records, p), "time_per_step_s": r.time_s / run.n_steps}


def _per_step(df, col: str) -> np.ndarray:
    """(runs, steps) 0/1 array of a bit-string column."""
    return np.array([[c == "1" for c in s] for s in df[col]], dtype=bool)


def _stays_from(ok: np.ndarray) -> np.ndarray:
    """Per run, the first step from which the estimate stays within the bounds to the end (-1: never)."""
    out = np.full(ok.shape[0], -1)
    for i, row in enumerate(ok):
        bad = np.flatnonzero(~row)
        k = 0 if bad.size == 0 else int(bad[-1]) + 1
        out[i] = k if k < row.size else -1
    return out


def _group_stats(g, steps) -> dict:
    ok, conv = _per_step(g, "ok"), _per_step(g, "conv")
    n = ok.shape[1]
    stays = _stays_from(ok)
    turn = g["on_turn"].to_numpy(bool)
    return {"runs": len(g), **{f"success@{k}": float(ok[:, k - 1].mean()) for k in steps if k <= n},
            "amcl_converged": float(conv[:, -1].mean()), "converged_wrong": float((conv[:, -1] & ~ok[:, -1]).mean()),
            "median_step": float(np.median(stays[stays >= 0])) if (stays >= 0).any() else float("nan"),
            "success_turn_start": float(ok[turn, -1].mean()) if turn.any() else float("nan"),
            "n_turn_start": int(turn.sum()),
            "success_leg_start": float(ok[~turn, -1].mean()) if (~turn).any() else float("nan"),
            **{k: float(g[k].mean()) for k in RESAMPLING_COLUMNS},
            "time_per_step_s": float(g["time_per_step_s"].median())}


# --- global localisation: success against the step and the particle count -----------------------------------


@dataclass(frozen=True)
class GlobalResult:
    """Global localisation from no prior: per particle count and step, the share of runs within the bounds,
    and AMCL's convergence test at the last step.

    Parameters
    ----------
    table_df : pandas.DataFrame
        One row per (particle count, run).
    n_runs, n_steps : int
        Runs per count, steps per run.
    params : MCLParams
        The settings of every run (its ``n_particles`` replaced by each count).
    """

    table_df: object = field(repr=False)
    n_runs: int = 0
    n_steps: int = 0
    params: MCLParams = field(default_factory=MCLParams)

    def success(self, n_particles: int | None = None, step: int | None = None) -> float:
        """Share of runs within 3 cells and 5° at ``step`` (default: the last) for one count (default: the
        largest).

        Parameters
        ----------
        n_particles : int, optional
            The particle count (default: the largest).
        step : int, optional
            The step, from 1 (default: the last).

        Returns
        -------
        float
        """
        n = int(self.table_df["n_particles"].max()) if n_particles is None else int(n_particles)
        return float(self.step_shares(n)[0][(self.n_steps if step is None else step) - 1])

    def step_shares(self, n_particles: int) -> tuple[np.ndarray, np.ndarray]:
        """Per step, the share of runs within 3 cells and 5° and the share that pass amcl's convergence test.

        Parameters
        ----------
        n_particles : int
            The particle count.

        Returns
        -------
        ok, converged : ndarray, shape (n_steps,)
            Shares of the runs of that count, step 1 first.
        """
        g = self.table_df[self.table_df["n_particles"] == n_particles]
        return _per_step(g, "ok").mean(axis=0), _per_step(g, "conv").mean(axis=0)

    def summary(self):
        """One row per particle count (pandas): success at steps 5, 10, 20, 30 and the last, AMCL's test…"""
        import pandas as pd

        steps = sorted({5, 10, 20, 30, self.n_steps})
        rows = {int(n): _group_stats(g, steps) for n, g in self.table_df.groupby("n_particles")}
        out = pd.DataFrame.from_dict(rows, orient="index")
        out["success"] = out[f"success@{self.n_steps}"]
        return out

    def table(self) -> str:
        s = self.summary()
        steps = [k for k in (5, 10, 20, 30) if k <= self.n_steps]
        if self.n_steps not in steps:
            steps.append(self.n_steps)
        rows = [[int(n), *(fmt(r[f"success@{k}"]) for k in steps), fmt(r.amcl_converged),
                 fmt(r.converged_wrong), fmt(r.median_step, 0)] for n, r in s.iterrows()]
        return table(["particles", *(f"success @{k}" if i == 0 else f"@{k}" for i, k in enumerate(steps)),
                      "amcl converged", "converged, wrong", "step localised"], rows,
                     title=f"Global localisation from no prior, {self.n_runs} runs per count (the same runs), "
                           f"{self.n_steps} steps\nsettings: {params_line(self.params)}",
                     notes=[(f"success @k: share of runs within {FAIL_POS_CELLS:g} cells and {FAIL_DEG:g}° of the "
                            f"truth at step k; amcl converged: AMCL's test at step {self.n_steps} (every particle "
                            f"within {self.params.converged_dist:g} cells of the mean); converged, wrong: converged "
                            f"and not within the bounds; step localised: median step from which a run stays within "
                            f"the bounds")])

    def step_table(self, every: int = 5) -> str:
        """Success against the step, one column per particle count.

        Parameters
        ----------
        every : int
            Show every ``every``-th step.

        Returns
        -------
        str
        """
        counts = sorted(int(n) for n in self.table_df["n_particles"].unique())
        oks, convs = {}, {}
        for n in counts:
            oks[n], convs[n] = self.step_shares(n)
        ks = sorted({1, *range(every, self.n_steps + 1, every), self.n_steps})
        rows = [[k, *(f"{oks[n][k - 1]:.2f} / {convs[n][k - 1]:.2f}" for n in counts)] for k in ks]
        return format_table(["step", *(f"{n} particles" for n in counts)], rows,
                            title="Success / amcl-converged share against the step")

    def timing_table(self) -> str:
        s = self.summary()
        rows = [[int(n), f"{1e3 * r.time_per_step_s:.2f}"] for n, r in s.iterrows()]
        return format_table(["particles", "median ms per step"], rows, title="Time per MCL step (wall clock)")

    def __str__(self) -> str:
        s = self.summary()
        return "Global localisation: success " + ", ".join(f"{r.success:.2f} at {int(n)}" for n, r in s.iterrows())


def _paired_sweep(points, *, n_runs, rng, n_jobs, progress, fixed):
    """One sweep per point from a fresh copy of the same seed: run i of every point is the same simulated run."""
    import pandas as pd

    from ...sweep import fresh_seed_sequence, sweep

    frames = [sweep(_global_task, [pt], seeds=n_runs, rng=fresh_seed_sequence(rng), n_jobs=n_jobs,
                    progress=progress, fixed=fixed, on_error="raise", desc="global localisation")
              for pt in points]
    return pd.concat(frames, ignore_index=True)


def run_global_localisation(particle_counts=(500, 1000, 2500), *, n_runs: int = 50, n_steps: int = 30,
                            params: MCLParams | None = None, rng=0, n_jobs: int = 1, progress=None,
                            **overrides) -> GlobalResult:
    """Global localisation in the test room from no prior: ``n_runs`` seeded runs per particle count (the same
    runs for every count), each from a random place on 004's path (003 §2.2).

    The study varies the particle count itself (one variant per count of ``particle_counts``): ``params`` and the
    overrides must leave ``n_particles`` at its default (a ``ValueError`` names it otherwise).

    Parameters
    ----------
    particle_counts : sequence of int
        Particle counts, one variant each (the study's own axis: not ``params.n_particles``).
    n_runs, n_steps : int
        Runs per count, and steps per run.
    params : MCLParams, optional
        Settings of MCL (default: the defaults), but for ``n_particles``.
    rng : int, SeedSequence or Generator
        Where every run's stream is spawned from (run ``i`` the same for every count).
    n_jobs : int
        Parallel workers of :func:`slamlab.sweep.sweep`.
    progress : bool, callable or None
        See :mod:`slamlab._progress`.
    **overrides
        :class:`MCLParams` fields.

    Returns
    -------
    GlobalResult
    """

    from ..._params import refuse_set_fields

    p = MCLParams.resolve(params, **overrides)
    refuse_set_fields(p, ["n_particles"], "one variant per count of `particle_counts`")
    counts = [check_int(c, "particle_counts[]", minimum=1) for c in particle_counts]
    n_runs = check_int(n_runs, "n_runs", minimum=1)
    n_steps = check_int(n_steps, "n_steps", minimum=2)
    df = _paired_sweep([{"n_particles": c} for c in counts], n_runs=n_runs, rng=rng, n_jobs=n_jobs,
                       progress=progress, fixed={"n_steps": n_steps, "params": p})
    return GlobalResult(df, n_runs, n_steps, p)


# --- the ablation -------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class AblationResult:
    """Global localisation with one factor changed at a time (the same runs for every variant).

    Parameters
    ----------
    table_df : pandas.DataFrame
        One row per (variant, run).
    labels : tuple of str
        The variants, in table order.
    n_runs, n_steps, n_particles : int
        Runs per variant, steps per run, particles.
    world : str
        What the scans see ("map" or "cluttered").
    base : MCLParams
        The settings every variant changes.
    """

    table_df: object = field(repr=False)
    labels: tuple = ()
    n_runs: int = 0
    n_steps: int = 0
    n_particles: int = 0
    world: str = "map"
    base: MCLParams = field(default_factory=MCLParams)

    @property
    def mid_step(self) -> int:
        """The earlier step of the table: 20, or half the run when it is shorter."""
        return 20 if self.n_steps > 20 else max(1, self.n_steps // 2)

    def summary(self):
        """One row per variant (pandas), in the order of the study."""
        import pandas as pd

        steps = sorted({self.mid_step, self.n_steps})
        rows = [{"variant": lab, **_group_stats(self.table_df[self.table_df["variant"] == lab], steps)}
                for lab in self.labels]
        return pd.DataFrame(rows).set_index("variant")

    def table(self) -> str:
        s = self.summary()
        rows = [[lab, fmt(r[f"success@{self.mid_step}"]), fmt(r[f"success@{self.n_steps}"]), fmt(r.amcl_converged),
                 fmt(r.converged_wrong), f"{fmt(r.success_turn_start)} ({int(r.n_turn_start)})",
                 fmt(r.success_leg_start)] for lab, r in s.iterrows()]
        return table(["variant", f"success @{self.mid_step}", f"@{self.n_steps}", "amcl conv.", "conv., wrong",
                      "turn start", "leg start"], rows,
                     title=f"Global localisation{' among unmapped clutter' if self.world != 'map' else ''}: "
                           f"{self.n_particles} particles, the same {self.n_runs} runs for every variant, "
                           f"{self.n_steps} steps\ndefaults: {params_line(self.base)}",
                     notes=[(f"success @k: share of runs within {FAIL_POS_CELLS:g} cells and {FAIL_DEG:g}° at step k; "
                            f"the other columns at step {self.n_steps}: amcl conv.: AMCL's convergence test passed; "
                            f"conv., wrong: passed and not within the bounds; turn start (runs) / leg start: success "
                            f"of the runs that start in one of the path's turns on the spot / on a straight leg")])

    def resampling_table(self) -> str:
        """Per variant, how often the set was resampled and why: N_eff against the threshold, and injection."""
        return resampling_table(self.summary(), self.labels, self.base,
                                f"Resampling in the global runs ({self.n_particles} particles, {self.n_runs} runs "
                                f"of {self.n_steps} steps per variant)")

    def __str__(self) -> str:
        return f"Ablation of global localisation, {len(self.labels)} variants × {self.n_runs} runs"


#: Runs per variant of each ``size`` of :func:`run_global_ablation`.
_SIZES = {"small": 8, "full": 50}
#: The ablation's settings when no ``params`` is given: the defaults with 2500 particles.
_ABLATION_PARAMS = MCLParams(n_particles=2500)


def run_global_ablation(variants=ABLATION, *, size: str = "small", n_runs: int | None = None, n_steps: int = 30,
                        world: str = "map", params: MCLParams | None = None, rng=0, n_jobs: int = 1, progress=None,
                        **overrides) -> AblationResult:
    """Global localisation with one factor changed at a time (``variants``: (label, MCLParams overrides); 003 §2.2).

    Parameters
    ----------
    variants : sequence of (str, dict)
        (label, :class:`MCLParams` overrides) pairs, applied on top of ``params`` and ``overrides``.
    size : {"small", "full"}
        "small" (8 runs per variant, the notebook) or "full" (50 runs).
    n_runs : int, optional
        Replaces the size's runs per variant.
    n_steps : int
        Steps per run.
    world : {"map", "cluttered"}
        See :func:`~slamlab.studies.localisation.experiments.simulate_run` ("cluttered": scans with unmapped objects).
    params : MCLParams, optional
        The settings every variant changes (default: the defaults with ``n_particles=2500``).
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
    AblationResult
    """
    base = MCLParams.resolve(_ABLATION_PARAMS if params is None else params, **overrides)
    check_choice(size, "size", tuple(_SIZES))
    n_runs = check_int(_SIZES[size] if n_runs is None else n_runs, "n_runs", minimum=1)
    labels, points = [], []
    for item in variants:
        if not (isinstance(item, tuple) and len(item) == 2 and isinstance(item[0], str) and isinstance(item[1], dict)):
            raise TypeError(f"`variants` must hold (label, overrides dict) pairs; got {item!r}")
        labels.append(item[0])
        points.append({"variant": item[0], "params": base.replace(**item[1])})
    if len(set(labels)) != len(labels):
        raise ValueError("`variants` labels must be distinct")
    df = _paired_sweep(points, n_runs=n_runs, rng=rng, n_jobs=n_jobs, progress=progress,
                       fixed={"n_steps": n_steps, "world": check_choice(world, "world", ("map", "cluttered"))})
    return AblationResult(df, tuple(labels), n_runs, n_steps, base.n_particles, world, base)


@dataclass(frozen=True)
class ScoreComparison:
    """Each observation score: global success (the ablation's runs) and kidnap recovery.

    Parameters
    ----------
    global_ : AblationResult
        Global success per score.
    kidnap : KidnapResult
        Kidnap recovery per score.
    """

    global_: AblationResult
    kidnap: KidnapResult

    def table(self) -> str:
        g = self.global_.summary()
        k = {r[0]: r for r in self.kidnap.rows()}
        rows = [[lab, fmt(g.loc[lab, f"success@{self.global_.n_steps}"]), fmt(g.loc[lab, "amcl_converged"]),
                 k[lab][2], k[lab][3], k[lab][4], k[lab][1]] for lab in self.global_.labels]
        return table(["score ω that eq 2.8 averages", f"global @{self.global_.n_steps}", "amcl conv.",
                      "recovered", "steps", "% injected", "tracked"], rows,
                     title=f"The observation score: global localisation ({self.global_.n_particles} particles, "
                           f"{self.global_.n_runs} runs) and kidnap ({self.kidnap.n_particles} particles, "
                           f"{self.kidnap.n_runs} runs); weights p(z | x)^{self.global_.base.gamma:g} in every row, "
                           f"other settings the defaults",
                     notes=[(f"global @{self.global_.n_steps}: share of the global runs within {FAIL_POS_CELLS:g} "
                            f"cells and {FAIL_DEG:g}° at step {self.global_.n_steps}; amcl conv.: AMCL's convergence "
                            f"test passed there; recovered, steps: share of the kidnap runs that recover, median "
                            f"steps to recover; % injected: particles injected per step while tracking (before the "
                            f"kidnap); tracked: share within the bounds before the kidnap")])

    def __str__(self) -> str:
        return f"Observation scores compared: {len(self.global_.labels)} scores"


def run_score_comparison(variants=SCORE_VARIANTS, *, n_runs: int = 20, kidnap_particles: int = 1000,
                         global_particles: int = 2500, params: MCLParams | None = None, rng=0, n_jobs: int = 1,
                         progress=None, **overrides) -> ScoreComparison:
    """Each score variant on the global study (``global_particles``) and the kidnap study (``kidnap_particles``),
    ``n_runs`` runs each (003 §2.2, eq 2.8).

    The study sets the particle count of each part itself: ``params`` and the overrides must leave
    ``n_particles`` at its default (a ``ValueError`` names it otherwise).

    Parameters
    ----------
    variants : sequence of (str, dict)
        (label, :class:`MCLParams` overrides) pairs.
    n_runs : int
        Runs per variant.
    kidnap_particles, global_particles : int
        Particles of the kidnap study and of the global study.
    params : MCLParams, optional
        The settings every variant changes (default: the defaults), but for ``n_particles``.
    rng : int, SeedSequence or Generator
        An int seed ``s`` runs the global study from ``s`` and the kidnap study from ``s + 1``; otherwise the
        two studies draw from two children spawned from ``rng``.
    n_jobs : int
        Parallel workers of :func:`slamlab.sweep.sweep`.
    progress : bool, callable or None
        See :mod:`slamlab._progress`.
    **overrides
        :class:`MCLParams` fields under every variant.

    Returns
    -------
    ScoreComparison
    """
    import numbers

    from ..._params import refuse_set_fields
    from ...sweep import root_seed_sequence

    p = MCLParams.resolve(params, **overrides)
    refuse_set_fields(p, ["n_particles"], "`kidnap_particles` and `global_particles`")
    g_particles = check_int(global_particles, "global_particles", minimum=1)
    k_particles = check_int(kidnap_particles, "kidnap_particles", minimum=1)
    # The kidnap half's stream is the next int seed, not a spawned one (the table notebook 08 prints was first stored
    # so). The table once differed between numpy with and without its AVX-512 kernels: the injection step drew from
    # the stream or not as p_inj rounded to 0 or 1e-16 (fixed in slamlab.localisation.mcl, LOG_AVERAGE_TIE).
    if isinstance(rng, numbers.Integral) and not isinstance(rng, bool):
        rng_g, rng_k = rng, rng + 1
    else:
        rng_g, rng_k = root_seed_sequence(rng, "rng").spawn(2)
    g = run_global_ablation(variants, n_runs=n_runs, params=p.replace(n_particles=g_particles), rng=rng_g,
                            n_jobs=n_jobs, progress=progress)
    k = run_kidnapped(variants, n_runs=n_runs, params=p.replace(n_particles=k_particles), rng=rng_k, n_jobs=n_jobs,
                      progress=progress)
    return ScoreComparison(g, k)


__all__ += ["KIDNAP_VARIANTS"]
