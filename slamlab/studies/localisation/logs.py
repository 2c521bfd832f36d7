"""MCL on real laser logs (the corrected CARMEN logs of the Radish repository, any CARMEN log by path): tracking and
global localisation on a stretch (:func:`run_log_mcl`); the success-rate protocol is in
:mod:`slamlab.studies.localisation.log_protocol`.

The corrected logs carry SLAM-corrected poses only: the map is built from all scans at those poses, the odometry is
the corrected path with noise we add (ours), errors are against the corrected poses.
"""

from __future__ import annotations

import functools
import time
from dataclasses import dataclass, field

import numpy as np

from ..._table import format_table
from ..._validate import as_path, as_rng, check_choice, check_int, check_positive
from ...geometry import wrap_angle
from ...geometry.odometry import simulate_odometry
from ...localisation.mcl import MCL, MCLParams
from ...scans import log_grid

__all__ = []


# --- real data: the corrected CARMEN logs ----------------------------------------------------------------

#: The five corrected Radish logs of ``../shared/data/carmen-radish-corrected``.
CARMEN_LOGS = ("intel", "csail", "fhw", "orebro", "seattle")
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
    and orebro): σ_hit 0.4 m, the z_hit = z_rand = 0.5 mixture of Nav2, α2 = 0.01 rad²/m² (rotation noise from
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
#: :func:`log_settings` and :func:`global_log_settings`): success 0.68 against 0.74 now (10 stretches of 30 scans
#: per log, 20 000 particles, ``rng=0``).
GLOBAL_BEFORE = {"z_hit": 0.9, "z_rand": 0.1, "alpha": (0.05, 0.002, 0.05, 0.005), "averages": "003"}


def carmen_path(path):
    """Path of a CARMEN log: ``<path>-corrected.log.gz`` in the shared data for a name of :data:`CARMEN_LOGS`
    (via :func:`slamlab.data.find_data`), else ``path`` itself, which must be an existing file (ours).

    Parameters
    ----------
    path : str or os.PathLike
        One of :data:`CARMEN_LOGS`, or the path of any CARMEN log.

    Returns
    -------
    pathlib.Path
    """
    from ...data import find_data

    if isinstance(path, str) and path in CARMEN_LOGS:
        return find_data(f"carmen-radish-corrected/{path}-corrected.log.gz")
    return as_path(path, "path", kind="file")


def log_map(path, cell_m: float = 0.1, max_range_m: float = 10.0):
    """A CARMEN log read and its occupancy map built from all scans at the corrected poses, once per (file,
    cell size, range) (:func:`slamlab.scans.log_grid`; ours: the map of every run on the log).

    Parameters
    ----------
    path : str or os.PathLike
        One of :data:`CARMEN_LOGS`, or the path of any CARMEN log (see :func:`carmen_path`).
    cell_m : float
        The map's cell size [m].
    max_range_m : float
        Ranges at or beyond this [m] are not used.

    Returns
    -------
    log : CarmenLog
        The log.
    grid : ndarray of int, shape (H, W)
        The map.
    frame : GridFrame
        Cells ↔ metres.
    scans : list of Scan
        The scans in cells.
    poses : ndarray, shape (n, 3)
        The corrected poses in cells.
    """
    return _read_log_map(str(carmen_path(path)), check_positive(cell_m, "cell_m"),
                         check_positive(max_range_m, "max_range_m"))


@functools.lru_cache(maxsize=6)
def _read_log_map(path: str, cell_m: float, max_range_m: float):
    from ...io import read_carmen

    log = read_carmen(path)
    return (log, *log_grid(log, cell_m=cell_m, max_range_m=max_range_m))


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
                "global_first_step": first, "global_final_err_m": float(eg[-1])}

    def __str__(self) -> str:
        r = self.row()
        return (f"{self.name}: tracking within {REAL_POS_M:g} m / {REAL_DEG:g}° at {r['track_within']:.2f} of "
                f"{r['steps']} steps; global {r['global_within']:.2f}")


def run_log_mcl(path, *, start: int = 0, n_scans: int = 60, cell_m: float = 0.1, max_range_m: float = 10.0,
                n_particles_track: int = 3000, n_particles_global: int = 20000, odo_trans_frac: float = 0.1,
                odo_rot_std_deg: float = 1.0, rng=0, params: MCLParams | None = None,
                global_params: MCLParams | None = None, **overrides) -> LogMCLResult:
    """MCL on ``n_scans`` consecutive scans of a corrected CARMEN log (path: str / os.PathLike, or a log name; 003
    §2.2 on real data, ours).

    The map is the occupancy grid of all the log's scans at their corrected poses
    (:func:`slamlab.scans.log_grid`, ``cell_m`` cells, ranges below ``max_range_m``);
    the odometry is the corrected path with Gaussian noise, ``odo_trans_frac`` of each step's
    length and ``odo_rot_std_deg`` per step (ours: the corrected logs carry no raw odometry).
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
        A log name of :data:`CARMEN_LOGS`, the path of any CARMEN log, or a log already read.
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
    if isinstance(path, CarmenLog):
        log = path
        G, frame, scans_c, Pc = log_grid(log, cell_m=cell, max_range_m=max_range_m)
    else:
        log, G, frame, scans_c, Pc = log_map(path, cell, max_range_m)
    n = check_int(n_scans, "n_scans", minimum=2)
    if n > log.n_scans:
        raise ValueError(f"`n_scans` must be <= the {log.n_scans} scans of log {log.name!r}; got {n}")
    s0 = check_int(start, "start", minimum=0)
    if s0 + n > log.n_scans:
        raise ValueError(f"`start` + `n_scans` must be <= the {log.n_scans} scans of log {log.name!r}; got "
                         f"{s0} + {n} = {s0 + n}")
    rng_odo, rng_track, rng_global = as_rng(rng).spawn(3)
    t0 = time.perf_counter()
    idx = np.arange(s0, s0 + n)
    true_c = Pc[idx]
    odo = simulate_odometry(true_c, trans_std_frac=odo_trans_frac, rot_std_rad=float(np.radians(odo_rot_std_deg)),
                            rng=rng_odo).poses
    zmax = max_range_m / cell
    est = {}
    for mode, r in (("track", rng_track), ("global", rng_global)):
        kw = {"init_pose": true_c[0], "init_std": (0.1 / cell, 0.1 / cell, float(np.radians(2)))} \
            if mode == "track" else {}
        f = MCL(G, zmax, params=settings[mode].replace(n_particles=counts[mode]), rng=r, **kw)
        out = np.empty((n, 3))
        for k, i in enumerate(idx):
            prev, now = (odo[k - 1], odo[k]) if k else (None, None)
            out[k] = f.step(prev, now, scans_c[i]).mean
        est[mode] = frame.to_metres(out)
    return LogMCLResult(log.name, idx, log.poses[idx].copy(), est["track"], est["global"], frame.to_metres(odo), cell,
                        G.shape, counts["track"], counts["global"], float(odo_trans_frac),
                        float(odo_rot_std_deg), G, frame, time.perf_counter() - t0)


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
                     f"{d['global_final_err_m']:.2f}"])
    r0 = results[0]
    return format_table(["log", "steps", "odometry drift [m]", "track med err [m]", "track med err [°]",
                         "track within", "global within", "global first ok step", "global final err [m]"], rows,
                        title=f"MCL on the corrected CARMEN logs: {r0.cell_m:g} m cells, odometry noise "
                              f"{100 * r0.odo_trans_frac:g} % of each step + {r0.odo_rot_std_deg:g}°/step; "
                              f"{r0.n_particles_track} particles tracking, {r0.n_particles_global} global; "
                              f"'within' = fraction of steps within {REAL_POS_M:g} m and {REAL_DEG:g}°")


__all__ += ["CARMEN_LOGS", "GLOBAL_BEFORE", "REAL_DEG", "REAL_POS_M", "LogMCLResult", "carmen_path",
            "global_log_settings", "log_map", "log_params", "log_settings", "logs_table", "run_log_mcl"]
