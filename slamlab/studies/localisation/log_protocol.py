"""The success-rate protocol of global localisation on real logs (issue 27; ours: Beluga's and IR-MCL's reports give
the error after convergence only): seeded global runs from no prior on stretches spread over each log, with the
success rate, the step of convergence and the error after it, against the particle count.

Each stretch is localised on a map its own scans did not draw: the log's other scans but ``leave_margin`` on either
side of the stretch (:func:`~slamlab.studies.localisation.log_maps.stretch_map`; ``map_leave_out="none"``: every
scan), with its coverage by that map printed (:func:`~slamlab.studies.localisation.log_maps.stretch_coverage`). The
logs the global settings were tuned on (:data:`~slamlab.studies.localisation.log_maps.TUNED_LOGS`) and the others
are pooled apart.

Success is the chapter's one criterion (:data:`~slamlab.localisation.particles.FAIL_POS_CELLS` map cells and
:data:`~slamlab.localisation.particles.FAIL_DEG` degrees at the last scan, as the simulated study); the share within
the tracking bound (:data:`~slamlab.studies.localisation.logs.REAL_POS_M`,
:data:`~slamlab.studies.localisation.logs.REAL_DEG`) is printed beside it, and so is the ceiling: tracking from the
corrected start pose on the same stretch and odometry.
"""

from __future__ import annotations

import time
import zlib
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..._validate import check_choice, check_int
from ...geometry import wrap_angle
from ...geometry.odometry import simulate_odometry
from ...localisation.mcl import MCLParams
from ...localisation.particles import FAIL_DEG, FAIL_POS_CELLS
from ._tables import fmt, table
from .log_maps import (
    CARMEN_LOGS,
    MAP_LEAVE_OUT,
    TUNED_LOGS,
    carmen_path,
    is_tuned_log,
    read_log_counts,
    stretch_coverage,
    stretch_map,
)
from .logs import REAL_DEG, REAL_POS_M, localise_stretch, log_params

__all__ = ["GROUPS", "LogProtocolResult", "maps_table", "run_log_protocol"]


def _stream(seed: int, log: str, start: int, *tail: int) -> np.random.Generator:
    """A stream keyed by (seed, the log's file name, the stretch's first scan, …): a stretch's run is the same
    whichever logs, stretches and counts share the call."""
    return np.random.default_rng([seed, zlib.crc32(Path(log).name.encode()), start, *tail])


def _final_errors(est_m, true_m):
    e = np.hypot(*(est_m[:, :2] - true_m[:, :2]).T)
    h = np.degrees(np.abs(wrap_angle(est_m[:, 2] - true_m[:, 2])))
    return e, h


def _protocol_task(log: str, run: int, n_particles: int, n_runs: int, n_scans: int, cell_m: float,
                   max_range_m: float, odo_trans_frac: float, odo_rot_std_deg: float, seed: int, params: MCLParams,
                   track_particles: int, track_params: MCLParams, map_leave_out: str = "stretch",
                   leave_margin: int = 2):
    """One stretch of ``log``: a global run with ``params`` and ``n_particles`` (and the tracking ceiling with
    ``track_particles`` when > 0) on the stretch's map."""
    lg, frame, scans_c, Pc, counts = read_log_counts(log, cell_m, max_range_m)
    if lg.n_scans < n_scans:
        raise ValueError(f"`n_scans` must be <= the {lg.n_scans} scans of log {lg.name!r}; got {n_scans}")
    s0 = round(run * (lg.n_scans - n_scans) / max(1, n_runs - 1)) if n_runs > 1 else 0
    idx = np.arange(s0, s0 + n_scans)
    G, left = stretch_map(counts, scans_c, Pc, idx, map_leave_out, leave_margin)
    # the same stretch and odometry noise for every particle count
    odo = simulate_odometry(Pc[idx], trans_std_frac=odo_trans_frac, rot_std_rad=float(np.radians(odo_rot_std_deg)),
                            rng=_stream(seed, log, s0, 0)).poses
    true = lg.poses[idx]
    z_max = max_range_m / cell_m
    t0 = time.perf_counter()
    est = localise_stretch(G, frame, scans_c, idx, odo, _stream(seed, log, s0, 1, n_particles),
                       params.replace(n_particles=n_particles), z_max)
    dt = time.perf_counter() - t0
    e, h = _final_errors(est, true)
    ok = (e < FAIL_POS_CELLS * cell_m) & (h < FAIL_DEG)
    bad = np.flatnonzero(~ok)
    conv = 0 if bad.size == 0 else int(bad[-1]) + 1
    conv = conv if conv < n_scans else -1
    row = {"name": lg.name, "tuned": is_tuned_log(log), "start": s0, "left_out": len(left),
           "coverage": stretch_coverage(G, scans_c, Pc, idx), "success": bool(ok[-1]),
           "within_tracking_bound": bool(e[-1] < REAL_POS_M and h[-1] < REAL_DEG), "converged_step": conv,
           "err_after_m": float(np.median(e[conv:])) if conv >= 0 else float("nan"),
           "final_err_m": float(e[-1]), "final_err_deg": float(h[-1]), "time_per_step_s": dt / n_scans,
           "track_success": float("nan"), "track_within_tracking_bound": float("nan")}
    if track_particles:
        tr = localise_stretch(G, frame, scans_c, idx, odo, _stream(seed, log, s0, 2),
                          track_params.replace(n_particles=track_particles), z_max,
                          init_pose=Pc[idx[0]], init_std=(0.1 / cell_m, 0.1 / cell_m, float(np.radians(2))))
        te, th = _final_errors(tr, true)
        row["track_success"] = float(te[-1] < FAIL_POS_CELLS * cell_m and th[-1] < FAIL_DEG)
        row["track_within_tracking_bound"] = float(te[-1] < REAL_POS_M and th[-1] < REAL_DEG)
    return row


def _short(name: str) -> str:
    """A log's name for a table: its file name without ``.log`` / ``.gz`` and ``-corrected``."""
    for ext in (".gz", ".log", "-corrected"):
        name = name.removesuffix(ext)
    return name


def _sweep_task(rng, **kw):
    """:func:`_protocol_task` on :func:`slamlab.sweep.sweep` (its stream unused: each stretch keys its own)."""
    return _protocol_task(**kw)


#: The groups of logs the table pools apart: label → ``tuned`` (None: every log).
GROUPS = (("tuned logs", True), ("untuned logs", False), ("all logs", None))


@dataclass(frozen=True)
class LogProtocolResult:
    """Global localisation from no prior on stretches of real logs: success, steps to converge and error after
    convergence against the particle count (per log, per group of logs: tuned or not).

    Parameters
    ----------
    table_df : pandas.DataFrame
        One row per (log, stretch, particle count): ``name``, ``tuned`` (a log of
        :data:`~slamlab.studies.localisation.log_maps.TUNED_LOGS`), ``start``, ``left_out`` (scans left out of the
        stretch's map), ``coverage`` (:func:`~slamlab.studies.localisation.log_maps.stretch_coverage` on that map),
        ``success`` (the chapter's criterion at the last scan), ``within_tracking_bound`` (within 0.2 m and 2°
        there), ``converged_step`` (success from that step on; −1: never), ``err_after_m``, ``final_err_m``,
        ``final_err_deg``, ``time_per_step_s``, ``track_success`` (tracking from the corrected start pose: 1.0 /
        0.0; NaN when not run), ``track_within_tracking_bound`` (the same run within 0.2 m and 2°).
    n_runs, n_scans : int
        Stretches per log, scans per stretch.
    params : MCLParams
        The settings of the global runs (their ``n_particles`` replaced by each count).
    cell_m : float
        The map's cell size [m].
    track_particles : int
        Particles of the tracking run (0: not run).
    map_leave_out : str
        ``"stretch"``: each stretch's map leaves it and ``leave_margin`` scans on either side out; ``"none"``: every
        scan draws it.
    leave_margin : int
        Scans left out on either side of a stretch.
    """

    table_df: object = field(repr=False)
    n_runs: int = 0
    n_scans: int = 0
    params: MCLParams = field(default_factory=MCLParams)
    cell_m: float = 0.1
    track_particles: int = 0
    map_leave_out: str = "stretch"
    leave_margin: int = 2

    def summary(self):
        """One row per (log, particle count) (pandas)."""
        g = self.table_df.groupby(["name", "n_particles"], sort=False)
        out = g.agg(tuned=("tuned", "first"), success=("success", "mean"),
                    within_tracking_bound=("within_tracking_bound", "mean"), track_success=("track_success", "mean"),
                    track_within=("track_within_tracking_bound", "mean"), runs=("success", "size"),
                    coverage=("coverage", "mean"), time_per_step_s=("time_per_step_s", "median"))
        conv = self.table_df[self.table_df["converged_step"] >= 0].groupby(["name", "n_particles"], sort=False)
        out["median_converged_step"] = conv["converged_step"].median()
        out["median_err_after_m"] = conv["err_after_m"].median()
        return out

    def _rows(self, n_particles: int | None, tuned: bool | None):
        df = self.table_df
        n = int(df["n_particles"].max()) if n_particles is None else int(n_particles)
        df = df[df["n_particles"] == n]
        return df if tuned is None else df[df["tuned"] == bool(tuned)]

    def success(self, n_particles: int | None = None, tuned: bool | None = None) -> float:
        """Success rate over the runs of every log (or of the tuned or untuned ones) for one particle count.

        Parameters
        ----------
        n_particles : int, optional
            The particle count (default: the largest).
        tuned : bool, optional
            True: the logs of :data:`~slamlab.studies.localisation.log_maps.TUNED_LOGS` only; False: the others;
            None: every log.

        Returns
        -------
        float
            NaN when no log of the group ran.
        """
        return float(self._rows(n_particles, tuned)["success"].mean())

    def within_tracking_bound(self, n_particles: int | None = None, tuned: bool | None = None) -> float:
        """Share of the runs within 0.2 m and 2° at the last scan for one particle count (as :meth:`success`).

        Parameters
        ----------
        n_particles : int, optional
            The particle count (default: the largest).
        tuned : bool, optional
            The group of logs, as in :meth:`success`.

        Returns
        -------
        float
        """
        return float(self._rows(n_particles, tuned)["within_tracking_bound"].mean())

    def track_success(self, column: str = "track_success", tuned: bool | None = None) -> float:
        """Success rate of tracking from the corrected start pose over every stretch (NaN if not run).

        Parameters
        ----------
        column : str
            ``"track_success"`` (the chapter's criterion) or ``"track_within_tracking_bound"`` (0.2 m and 2°).
        tuned : bool, optional
            The group of logs, as in :meth:`success`.

        Returns
        -------
        float
        """
        return float(self._rows(None, tuned)[column].mean())

    def coverage(self, tuned: bool | None = None) -> float:
        """Mean coverage of the stretches by their maps (a stretch's scans' end points within 1 cell of a wall).

        Parameters
        ----------
        tuned : bool, optional
            The group of logs, as in :meth:`success`.

        Returns
        -------
        float
        """
        return float(self._rows(None, tuned)["coverage"].mean())

    def _map_words(self) -> str:
        if self.map_leave_out == "none":
            return "every scan of the log (the stretch's own too)"
        return f"every scan of the log but the stretch's own and {self.leave_margin} on either side"

    def table(self) -> str:
        s = self.summary()
        counts = sorted(self.table_df["n_particles"].unique())
        top = counts[-1]
        rows = []
        for label, tuned in GROUPS:
            if tuned is not None:
                part = s[s["tuned"] == tuned]
                if part.empty:
                    continue
                rows += [[_short(name), int(n), f"{r.success:.2f}", f"{r.within_tracking_bound:.2f}",
                          fmt(r.track_success), fmt(r.track_within), fmt(r.median_converged_step, 0),
                          fmt(r.median_err_after_m, 3), f"{r.coverage:.2f}"] for (name, n), r in part.iterrows()]
            for n in counts:  # the ceiling is run once, with the largest count
                track = [fmt(self.track_success(tuned=tuned)),
                         fmt(self.track_success("track_within_tracking_bound", tuned))] if n == top else ["-", "-"]
                rows.append([label, int(n), f"{self.success(n, tuned):.2f}",
                             f"{self.within_tracking_bound(n, tuned):.2f}", *track, "", "",
                             f"{self.coverage(tuned):.2f}"])
        p = self.params
        track = (f"; tracking: {self.track_particles} particles from the corrected start pose, same odometry"
                 if self.track_particles else "")
        return table(
            ["log", "particles", "success", f"within {REAL_POS_M:g} m/{REAL_DEG:g}°", "track", "track within",
             "conv. step", "err after [m]", "coverage"], rows,
            title=f"Global localisation on real logs: {self.n_runs} stretches of {self.n_scans} scans per log, spread "
                  f"over the log, one seeded run each{track}\n"
                  f"map of a stretch: {self._map_words()}\n"
                  f"settings (tuned on {', '.join(TUNED_LOGS)}): {self.cell_m:g} m cells, odometry noise 10 % + "
                  f"1°/step, σ_hit {p.sigma_hit * self.cell_m:g} m, (z_hit, z_rand) = ({p.z_hit:g}, {p.z_rand:g}), "
                  f"α2 {p.alpha[1] / self.cell_m**2:g} rad²/m², (α_slow, α_fast) = ({p.alpha_slow:g}, "
                  f"{p.alpha_fast:g}), averages {p.averages}",
            notes=[(f"success: share of runs within {FAIL_POS_CELLS:g} cells ({FAIL_POS_CELLS * self.cell_m:g} m) and "
                   f"{FAIL_DEG:g}° of the corrected pose at the last scan (the simulated study's criterion); within "
                   f"{REAL_POS_M:g} m/{REAL_DEG:g}°: the tracking bound there; track / track within: the same two "
                   f"for tracking from the corrected start pose; conv. step: median step from which a run stays a "
                   f"success; err after: median position error after that step; coverage: mean share of the "
                   f"stretch's end points within 1 cell of a wall of its map at the corrected poses; tuned / "
                   f"untuned / all logs: the runs of those logs pooled")])

    def stretches_table(self) -> str:
        """One row per stretch: its first scan, the scans its map left out, its coverage, whether tracking from the
        corrected start pose succeeded and, per particle count, whether the global run did (the chapter's criterion)
        and its final error."""
        import pandas as pd

        df = self.table_df
        counts = sorted(df["n_particles"].unique())
        wide = df.pivot_table(index=["name", "start"], columns="n_particles", values=["success", "final_err_m"],
                              sort=False)
        first = df.groupby(["name", "start"], sort=False)[["tuned", "left_out", "coverage"]].first()
        track = df[df["n_particles"] == counts[-1]].set_index(["name", "start"])["track_success"]

        def yes(x) -> str:
            return "-" if x is None or pd.isna(x) else ("yes" if x else "no")  # NaN: not run

        rows = []
        for (name, start), r in first.iterrows():
            rows.append([_short(name), yes(r.tuned), int(start), int(r.left_out), f"{r.coverage:.2f}",
                         yes(track[(name, start)]),
                         *[c for n in counts for c in (yes(wide.loc[(name, start), ("success", n)]),
                                                       f"{wide.loc[(name, start), ('final_err_m', n)]:.2f}")]])
        return table(["log", "tuned", "first scan", "left out", "coverage", "track ok",
                      *[c for n in counts for c in (f"ok @{n}", f"err @{n} [m]")]], rows,
                     title=f"The stretches of the protocol ({self.n_scans} scans each), their maps and runs",
                     notes=[("left out: scans that drew no part of the stretch's map; track ok: tracking from the "
                             "corrected start pose succeeded (-: not run); ok @N: the global run with N particles "
                             "succeeded (the chapter's criterion); err: its final position error")])

    def __str__(self) -> str:
        return (f"Real-log protocol: success {self.success():.2f} (tuned logs {fmt(self.success(tuned=True))}, "
                f"untuned {fmt(self.success(tuned=False))}; {self.n_runs} runs per log)")


def maps_table(leave_out: LogProtocolResult, all_scans: LogProtocolResult) -> str:
    """The same protocol on two maps side by side, pooled over the tuned logs, the untuned ones and every log: the
    success (the chapter's criterion), the share within 0.2 m and 2° and the coverage (ours).

    Parameters
    ----------
    leave_out, all_scans : LogProtocolResult
        The protocol with ``map_leave_out="stretch"`` and with ``"none"`` (the same logs, stretches and counts).

    Returns
    -------
    str
    """
    for name, r in (("leave_out", leave_out), ("all_scans", all_scans)):
        if not isinstance(r, LogProtocolResult):
            raise TypeError(f"`{name}` must be a LogProtocolResult; got {type(r).__name__}")
    counts = sorted(leave_out.table_df["n_particles"].unique())
    if counts != sorted(all_scans.table_df["n_particles"].unique()):
        raise ValueError(f"`all_scans` must have the particle counts of `leave_out` ({counts}); got "
                         f"{sorted(all_scans.table_df['n_particles'].unique())}")
    rows = []
    for label, tuned in GROUPS:
        if leave_out._rows(None, tuned).empty:
            continue
        for n in counts:
            rows.append([label, int(n), *[f"{r.success(n, tuned):.2f}" for r in (all_scans, leave_out)],
                         *[f"{r.within_tracking_bound(n, tuned):.2f}" for r in (all_scans, leave_out)],
                         *[f"{r.coverage(tuned):.2f}" for r in (all_scans, leave_out)]])
    return table(["logs", "particles", "success: all", "leave-out", f"within {REAL_POS_M:g} m/{REAL_DEG:g}°: all",
                  "leave-out", "coverage: all", "leave-out"], rows,
                 title=f"The protocol on two maps: all, every scan of the log; leave-out, every scan but the "
                       f"stretch's and {leave_out.leave_margin} on either side ({leave_out.n_runs} stretches of "
                       f"{leave_out.n_scans} scans per log, the same runs' streams)",
                 notes=["success, within, coverage: as in the protocol's table"])


def run_log_protocol(logs=CARMEN_LOGS, particle_counts=(5000, 20000), *, n_runs: int = 10, n_scans: int = 30,
                     odo_trans_frac: float = 0.1, odo_rot_std_deg: float = 1.0, track_particles: int = 3000,
                     params: MCLParams | None = None, track_params: MCLParams | None = None, rng=0,
                     n_jobs: int = 1, progress=None, map_leave_out: str = "stretch", leave_margin: int = 2,
                     **overrides) -> LogProtocolResult:
    """Global localisation from no prior on ``n_runs`` stretches of ``n_scans`` scans of every log, spread evenly
    over the log, for every particle count (the same stretches and odometry noise for every count), beside
    tracking from the corrected start pose (the ceiling); on :func:`slamlab.sweep.sweep`. Settings as the global
    run of :func:`~slamlab.studies.localisation.logs.run_log_mcl`, and so is the map of a stretch: by default every
    scan of the log but the stretch's and ``leave_margin`` on either side (ours; its coverage is in the table).

    Every stretch's odometry noise and filter stream are keyed by (seed, the log's file name, the stretch's first
    scan, the particle count): a stretch gives the same run whichever logs, stretches and counts share the call.
    The study varies the particle count itself: ``params`` and the overrides must leave ``n_particles`` at its
    default (a ``ValueError`` names it otherwise).

    Parameters
    ----------
    logs : str, os.PathLike or a sequence of them
        Names of :data:`~slamlab.studies.localisation.log_maps.CARMEN_LOGS` or paths of any CARMEN log.
    particle_counts : sequence of int
        Particle counts of the global runs, one variant each (the study's own axis: not ``params.n_particles``).
    n_runs, n_scans : int
        Stretches per log, scans per stretch.
    odo_trans_frac, odo_rot_std_deg : float
        The odometry noise we add: share of each step's length, degrees per step.
    track_particles : int
        Particles of the tracking run from the corrected start pose (σ 0.1 m, 2°) with ``track_params``;
        0: no tracking run.
    params : MCLParams, optional
        Settings of the global runs, lengths in 0.1 m cells (default:
        :func:`log_params(0.1, "global") <slamlab.studies.localisation.logs.log_params>`), but for ``n_particles``.
    track_params : MCLParams, optional
        Settings of the tracking runs (default: ``log_params(0.1, "track")``), but for ``n_particles``
        (``track_particles``); the overrides do not apply to them.
    rng : int, SeedSequence or Generator
        The seed of every stream (a SeedSequence or Generator gives it as its first generated word).
    n_jobs : int
        Parallel workers of :func:`slamlab.sweep.sweep`.
    progress : bool, callable or None
        See :mod:`slamlab._progress`.
    map_leave_out : {"stretch", "none"}
        ``"stretch"``: a stretch and ``leave_margin`` scans on either side do not draw its map (ours); ``"none"``:
        every scan draws it.
    leave_margin : int
        Scans left out on either side of a stretch (≥ 0; chapter 06's ±2 by default).
    **overrides
        :class:`MCLParams` fields (global runs).

    Returns
    -------
    LogProtocolResult
    """
    import numbers

    from ..._params import refuse_set_fields
    from ...sweep import root_seed_sequence, sweep

    cell_m = 0.1
    map_leave_out = check_choice(map_leave_out, "map_leave_out", MAP_LEAVE_OUT)
    leave_margin = check_int(leave_margin, "leave_margin", minimum=0)
    root = root_seed_sequence(rng, "rng")
    key = int(rng) if isinstance(rng, numbers.Integral) else int(root.generate_state(1, np.uint64)[0])
    p = MCLParams.resolve(log_params(cell_m, "global") if params is None else params, **overrides)
    refuse_set_fields(p, ["n_particles"], "one variant per count of `particle_counts`")
    tp = MCLParams.resolve(log_params(cell_m, "track") if track_params is None else track_params)
    refuse_set_fields(tp, ["n_particles"], "the tracking runs use `track_particles`")
    if isinstance(logs, (str, bytes)) or not hasattr(logs, "__iter__"):
        logs = [logs]
    paths = [str(carmen_path(path)) for path in logs]
    counts = [check_int(c, "particle_counts[]", minimum=1) for c in particle_counts]
    n_runs = check_int(n_runs, "n_runs", minimum=1)
    n_scans = check_int(n_scans, "n_scans", minimum=2)
    track_particles = check_int(track_particles, "track_particles", minimum=0)
    # the tracking run (the ceiling) once per stretch: with the largest count's row
    pts = [{"log": path, "run": r, "n_particles": c, "track_particles": track_particles if c == max(counts) else 0}
           for path in paths for c in counts for r in range(n_runs)]
    df = sweep(_sweep_task, pts, seeds=1, rng=root, n_jobs=n_jobs, progress=progress,
               on_error="raise", desc="MCL log protocol",
               fixed={"n_runs": n_runs, "n_scans": n_scans, "cell_m": cell_m, "max_range_m": 10.0,
                      "odo_trans_frac": odo_trans_frac, "odo_rot_std_deg": odo_rot_std_deg, "seed": key,
                      "params": p, "track_params": tp, "map_leave_out": map_leave_out,
                      "leave_margin": leave_margin})
    return LogProtocolResult(df, n_runs, n_scans, p, cell_m, track_particles, map_leave_out, leave_margin)
