"""MCL on real laser logs (the corrected CARMEN logs of the Radish repository, any CARMEN log by path): tracking and
global localisation on a stretch (:func:`run_log_mcl`); the success-rate protocol is in
:mod:`slamlab.studies.localisation.log_protocol`.

The corrected logs carry SLAM-corrected poses only: a stretch's map is built from the other scans at those poses
(:mod:`slamlab.studies.localisation.log_maps`: the stretch and ``leave_margin`` scans on either side left out, or
every scan with ``map_leave_out="none"``), the odometry is the corrected path with noise we add (ours), errors are
against the corrected poses.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np

from ..._table import format_table
from ..._validate import as_rng, check_choice, check_int, check_positive
from ...geometry import wrap_angle
from ...geometry.odometry import simulate_odometry
from ...localisation.mcl import MCL, MCLParams
from ...scans import log_counts
from .log_maps import MAP_LEAVE_OUT, read_log_counts, stretch_coverage, stretch_map

__all__ = []


# --- real data: the corrected CARMEN logs ----------------------------------------------------------------

#: Tracking and global success on a real log: within this distance [m] ...
REAL_POS_M = 0.2
#: ... and this heading error [deg] of the corrected pose.
REAL_DEG = 2.0


def log_settings(cell_m: float) -> dict:
    """The MCLParams overrides of every run on a real log (ours, set before issue 27 and kept): σ_hit 0.2 m,
    distance cap 1 m, KLD bins 0.5 m, the motion noise (0.05, 0.002, 0.05, 0.005) in cells, weights p^1, no
    jitter, 003's averages from 0 (so no injection while tracking with (0.001, 0.1)).

    Parameters
    ----------
    cell_m : float
        The map's cell size [m] (lengths are in cells).

    Returns
    -------
    dict
        :class:`MCLParams` fields.
    """
    return {"sigma_hit": 0.2 / cell_m, "max_dist": 1.0 / cell_m, "kld_bin": (0.5 / cell_m, 0.5 / cell_m, 0.174533),
            "alpha": (0.05, 0.002, 0.05, 0.005), "gamma": 1.0, "jitter": (0.0, 0.0), "averages": "003",
            "score": "geometric_mean"}


def global_log_settings(cell_m: float) -> dict:
    """The global run's MCLParams overrides on a real log (ours; issue 27's real-log ablation, tuned on fhw, intel
    and orebro, :data:`~slamlab.studies.localisation.log_maps.TUNED_LOGS`, on maps of all scans, not on csail and
    seattle): σ_hit 0.4 m, the z_hit = z_rand = 0.5 mixture of Nav2, α2 = 0.01 rad²/m² (rotation noise from
    translation; the tracking runs' 0.2 rad²/m², ROS's default, spreads the headings by ~15° per 0.6 m step) and
    injection (α_slow, α_fast) = (0.05, 0.5) on the bias-corrected averages (003's averages from 0 hardly inject
    within 30 steps). Before the ablation: z_hit 0.9, α2 0.2 rad²/m², 003's averages (:data:`GLOBAL_BEFORE`).

    Parameters
    ----------
    cell_m : float
        The map's cell size [m].

    Returns
    -------
    dict
        :class:`MCLParams` fields (on top of :func:`log_settings`).
    """
    a1, _, a3, a4 = log_settings(cell_m)["alpha"]
    return {"sigma_hit": 0.4 / cell_m, "z_hit": 0.5, "z_rand": 0.5, "alpha": (a1, round(0.01 * cell_m**2, 12), a3, a4),
            "alpha_slow": 0.05, "alpha_fast": 0.5, "averages": "debiased"}


def log_params(cell_m: float, run: str = "track") -> MCLParams:
    """The MCL settings of a run on a real log (ours): :func:`log_settings` for tracking, and
    :func:`global_log_settings` on top of them for a global run.

    Parameters
    ----------
    cell_m : float
        The map's cell size [m].
    run : {"track", "global"}
        Which run.

    Returns
    -------
    MCLParams
        The settings (the default particle count).
    """
    fields = log_settings(cell_m)
    if check_choice(run, "run", ("track", "global")) == "global":
        fields.update(global_log_settings(cell_m))
    return MCLParams(**fields)


#: The global runs' MCLParams overrides before issue 27's real-log ablation, at 0.1 m cells (on top of
#: :func:`log_settings` and :func:`global_log_settings`): success 0.68 against 0.74 after it (10 stretches of 30 scans
#: per log, 20 000 particles, ``rng=0``, on maps of all scans, as then).
GLOBAL_BEFORE = {"z_hit": 0.9, "z_rand": 0.1, "alpha": (0.05, 0.002, 0.05, 0.005), "averages": "003"}


@dataclass(frozen=True)
class LogMCLResult:
    """MCL on a stretch of a corrected CARMEN log: tracking and global localisation against the corrected poses.

    Parameters
    ----------
    name : str
        The log's name.
    scan_indices : ndarray of int, shape (n,)
        The scans of the stretch.
    true_m, track_m, global_m, odo_m : ndarray, shape (n, 3)
        Corrected poses, tracking and global estimates, and the noisy odometry we made (m, rad).
    cell_m : float
        The map's cell size [m].
    grid_shape : tuple of int
        The map's shape.
    n_particles_track, n_particles_global : int
        Particles of the two runs.
    odo_trans_frac, odo_rot_std_deg : float
        The odometry noise we added.
    grid : ndarray, optional
        The map.
    frame : GridFrame, optional
        The map's frame (cells ↔ metres).
    map_leave_out : str
        ``"stretch"``: the stretch and ``leave_margin`` scans on either side drew no part of the map; ``"none"``:
        every scan drew it.
    leave_margin : int
        Scans left out on either side of the stretch.
    coverage : float
        Mean over the stretch's scans of the share of their end points within 1 cell of an obstacle cell of the map
        at the corrected pose (:func:`slamlab.scans.map_coverage`).
    time_s : float
        Wall time of the two runs.
    """

    name: str
    scan_indices: np.ndarray = field(repr=False)
    true_m: np.ndarray = field(repr=False)  # (n, 3) corrected poses
    track_m: np.ndarray = field(repr=False)  # (n, 3) tracking estimates
    global_m: np.ndarray = field(repr=False)  # (n, 3) global estimates
    odo_m: np.ndarray = field(repr=False)  # (n, 3) the noisy odometry we made
    cell_m: float = 0.1
    grid_shape: tuple = (0, 0)
    n_particles_track: int = 0
    n_particles_global: int = 0
    odo_trans_frac: float = 0.0
    odo_rot_std_deg: float = 0.0
    grid: np.ndarray = field(default=None, repr=False)
    frame: object = field(default=None, repr=False)
    map_leave_out: str = "stretch"
    leave_margin: int = 2
    coverage: float = float("nan")
    time_s: float = field(default=0.0, compare=False)

    @staticmethod
    def _errors(est, true):
        return np.hypot(*(est[:, :2] - true[:, :2]).T), np.degrees(np.abs(wrap_angle(est[:, 2] - true[:, 2])))

    def within(self, which: str = "track") -> np.ndarray:
        """Per step: within 0.2 m and 2° of the corrected pose.

        Parameters
        ----------
        which : {"track", "global"}
            Which run.

        Returns
        -------
        ndarray of bool, shape (n,)
        """
        e, h = self._errors(self.track_m if which == "track" else self.global_m, self.true_m)
        return (e < REAL_POS_M) & (h < REAL_DEG)

    def row(self) -> dict:
        """The numbers of the table (also for tests)."""
        et, ht = self._errors(self.track_m, self.true_m)
        eg, _ = self._errors(self.global_m, self.true_m)
        eo, _ = self._errors(self.odo_m, self.true_m)
        wg = self.within("global")
        first = int(np.argmax(wg)) if wg.any() else -1
        return {"log": self.name, "steps": int(self.scan_indices.size), "odo_final_err_m": float(eo[-1]),
                "track_median_err_m": float(np.median(et)), "track_median_err_deg": float(np.median(ht)),
                "track_within": float(self.within("track").mean()), "global_within": float(wg.mean()),
                "global_first_step": first, "global_final_err_m": float(eg[-1]), "coverage": self.coverage}

    def __str__(self) -> str:
        r = self.row()
        return (f"{self.name}: tracking within {REAL_POS_M:g} m / {REAL_DEG:g}° at {r['track_within']:.2f} of "
                f"{r['steps']} steps; global {r['global_within']:.2f}; map {_map_words(self)}, coverage "
                f"{self.coverage:.2f}")


def _map_words(r) -> str:
    """The map of a run in words (for its one-line summary and the table's title)."""
    return "of all scans" if r.map_leave_out == "none" else f"without the stretch ±{r.leave_margin} scans"


def run_log_mcl(path, *, start: int = 0, n_scans: int = 60, cell_m: float = 0.1, max_range_m: float = 10.0,
                n_particles_track: int = 3000, n_particles_global: int = 20000, odo_trans_frac: float = 0.1,
                odo_rot_std_deg: float = 1.0, rng=0, params: MCLParams | None = None,
                global_params: MCLParams | None = None, map_leave_out: str = "stretch", leave_margin: int = 2,
                **overrides) -> LogMCLResult:
    """MCL on ``n_scans`` consecutive scans of a corrected CARMEN log (path: str / os.PathLike, or a log name; 003
    §2.2 on real data, ours).

    The map is the occupancy grid (``cell_m`` cells, ranges below ``max_range_m``) of the log's scans at their
    corrected poses but the stretch's own and ``leave_margin`` on either side of it (ours, as chapter 06 leaves a
    test scan and its ±2 neighbours out; :func:`~slamlab.studies.localisation.log_maps.stretch_map`), or of every
    scan with ``map_leave_out="none"``; the result's ``coverage`` says how much of the stretch that map knows
    (:func:`~slamlab.studies.localisation.log_maps.stretch_coverage`). The odometry is the corrected path with
    Gaussian noise, ``odo_trans_frac`` of each step's length and ``odo_rot_std_deg`` per step (ours: the corrected
    logs carry no raw odometry).
    Tracking starts from the corrected first pose (σ 0.1 m, 2°), global from particles uniform on
    the free cells. Tracking settings by default :func:`log_settings`: σ_hit 0.2 m, distance cap 1 m (ROS's σ_hit;
    ours otherwise); the motion noise α = (0.05, 0.002, 0.05, 0.005) in cells, weights p^1, no jitter and the
    averages from 0 (003: no injection while tracking). Global settings by default those and
    :func:`global_log_settings` (ours): σ_hit 0.4 m, z_hit = z_rand = 0.5, α2 0.01 rad²/m² and random injection
    with (α_slow, α_fast) = (0.05, 0.5) on the bias-corrected averages. Tracking, global and the odometry noise
    draw from three independent streams spawned from ``rng``. The particle counts are ``n_particles_track`` and
    ``n_particles_global``: the settings must leave ``n_particles`` at its default (a ``ValueError`` names it).

    Parameters
    ----------
    path : str, os.PathLike or CarmenLog
        A log name of :data:`~slamlab.studies.localisation.log_maps.CARMEN_LOGS`, the path of any CARMEN log, or a
        log already read.
    start, n_scans : int
        The first scan and the number of scans of the stretch.
    cell_m : float
        The map's cell size [m].
    max_range_m : float
        Ranges at or beyond this [m] are not used (map and weighting).
    n_particles_track, n_particles_global : int
        Particles of the tracking and the global run.
    odo_trans_frac, odo_rot_std_deg : float
        The odometry noise we add: share of each step's length, degrees per step.
    rng : int, SeedSequence or Generator
        Where the three streams are spawned from.
    params : MCLParams, optional
        Settings of the tracking run, lengths in cells (default: ``log_params(cell_m, "track")``).
    global_params : MCLParams, optional
        Settings of the global run (default: ``log_params(cell_m, "global")``).
    map_leave_out : {"stretch", "none"}
        ``"stretch"``: the stretch and ``leave_margin`` scans on either side do not draw the map (ours); ``"none"``:
        every scan draws it (the stretch is matched against a map drawn partly from itself).
    leave_margin : int
        Scans left out on either side of the stretch (≥ 0; chapter 06's ±2 by default).
    **overrides
        MCLParams fields for both runs.

    Returns
    -------
    LogMCLResult
    """
    from ..._params import refuse_set_fields
    from ...io import CarmenLog

    cell = check_positive(cell_m, "cell_m")
    settings = {"track": MCLParams.resolve(log_params(cell, "track") if params is None else params, **overrides),
                "global": MCLParams.resolve(log_params(cell, "global") if global_params is None else global_params,
                                            **overrides)}
    for p in settings.values():
        refuse_set_fields(p, ["n_particles"], "`n_particles_track` and `n_particles_global`")
    counts = {"track": check_int(n_particles_track, "n_particles_track", minimum=1),
              "global": check_int(n_particles_global, "n_particles_global", minimum=1)}
    check_choice(map_leave_out, "map_leave_out", MAP_LEAVE_OUT)
    margin = check_int(leave_margin, "leave_margin", minimum=0)
    if isinstance(path, CarmenLog):
        log = path
        frame, scans_c, Pc, full = log_counts(log, cell_m=cell, max_range_m=max_range_m)
    else:
        log, frame, scans_c, Pc, full = read_log_counts(path, cell, max_range_m)
    n = check_int(n_scans, "n_scans", minimum=2)
    if n > log.n_scans:
        raise ValueError(f"`n_scans` must be <= the {log.n_scans} scans of log {log.name!r}; got {n}")
    s0 = check_int(start, "start", minimum=0)
    if s0 + n > log.n_scans:
        raise ValueError(f"`start` + `n_scans` must be <= the {log.n_scans} scans of log {log.name!r}; got "
                         f"{s0} + {n} = {s0 + n}")
    idx = np.arange(s0, s0 + n)
    G, _ = stretch_map(full, scans_c, Pc, idx, map_leave_out, margin)
    rng_odo, rng_track, rng_global = as_rng(rng).spawn(3)
    t0 = time.perf_counter()
    true_c = Pc[idx]
    odo = simulate_odometry(true_c, trans_std_frac=odo_trans_frac, rot_std_rad=float(np.radians(odo_rot_std_deg)),
                            rng=rng_odo).poses
    zmax = max_range_m / cell
    est = {}
    for mode, r in (("track", rng_track), ("global", rng_global)):
        kw = {"init_pose": true_c[0], "init_std": (0.1 / cell, 0.1 / cell, float(np.radians(2)))} \
            if mode == "track" else {}
        est[mode] = localise_stretch(G, frame, scans_c, idx, odo, r,
                                     settings[mode].replace(n_particles=counts[mode]), zmax, **kw)
    return LogMCLResult(log.name, idx, log.poses[idx].copy(), est["track"], est["global"], frame.to_metres(odo), cell,
                        G.shape, counts["track"], counts["global"], float(odo_trans_frac),
                        float(odo_rot_std_deg), G, frame, map_leave_out, margin,
                        stretch_coverage(G, scans_c, Pc, idx), time.perf_counter() - t0)


def localise_stretch(G, frame, scans_cells, idx, odo, rng, params: MCLParams, z_max: float, **init) -> np.ndarray:
    """MCL with ``params`` on the map ``G`` over the scans ``idx`` of a log, one step per scan (003 §2.2; ours).

    Parameters
    ----------
    G : ndarray of int8, shape (H, W)
        The map.
    frame : GridFrame
        Its frame (cells ↔ metres).
    scans_cells : sequence of Scan
        Every scan of the log in cells.
    idx : ndarray of int, shape (n,)
        The scans of the stretch.
    odo : ndarray, shape (n, 3)
        The odometry poses at those scans [cells, rad].
    rng : Generator
        The filter's stream.
    params : MCLParams
        The settings (lengths in cells).
    z_max : float
        The range limit [cells].
    **init
        ``init_pose`` and ``init_std`` of a tracking run; none for a global run (uniform on the free cells).

    Returns
    -------
    ndarray, shape (n, 3)
        The filter's mean pose after each scan [m, rad].
    """
    f = MCL(G, z_max, params=params, rng=rng, **init)
    out = np.empty((idx.size, 3))
    for k, i in enumerate(idx):
        prev, now = (odo[k - 1], odo[k]) if k else (None, None)
        out[k] = f.step(prev, now, scans_cells[i]).mean
    return frame.to_metres(out)


def logs_table(results) -> str:
    """One row per log: odometry drift, tracking and global errors, the fractions within 0.2 m / 2°.

    Parameters
    ----------
    results : sequence of LogMCLResult
        One per log.

    Returns
    -------
    str
    """
    rows = []
    for r in results:
        d = r.row()
        rows.append([d["log"], d["steps"], f"{d['odo_final_err_m']:.2f}", f"{d['track_median_err_m']:.3f}",
                     f"{d['track_median_err_deg']:.2f}", f"{d['track_within']:.2f}", f"{d['global_within']:.2f}",
                     "never" if d["global_first_step"] < 0 else d["global_first_step"],
                     f"{d['global_final_err_m']:.2f}", f"{d['coverage']:.2f}"])
    r0 = results[0]
    return format_table(["log", "steps", "odometry drift [m]", "track med err [m]", "track med err [°]",
                         "track within", "global within", "global first ok step", "global final err [m]",
                         "coverage"], rows,
                        title=f"MCL on the corrected CARMEN logs: {r0.cell_m:g} m cells, map {_map_words(r0)}, "
                              f"odometry noise {100 * r0.odo_trans_frac:g} % of each step + "
                              f"{r0.odo_rot_std_deg:g}°/step; {r0.n_particles_track} particles tracking, "
                              f"{r0.n_particles_global} global; 'within' = fraction of steps within {REAL_POS_M:g} m "
                              f"and {REAL_DEG:g}°; coverage: mean share of a scan's end points within 1 cell of a "
                              f"map wall at the corrected pose")


__all__ += [
    "GLOBAL_BEFORE",
    "REAL_DEG",
    "REAL_POS_M",
    "LogMCLResult",
    "global_log_settings",
    "localise_stretch",
    "log_params",
    "log_settings",
    "logs_table",
    "run_log_mcl",
]
