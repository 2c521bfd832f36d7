"""Ch. 10 experiments (002): Fig. 2 (one/two/three pairs), Fig. 4 (two parallel planes + intensity), a flight
(Fig. 8, Fig. 9, ATE/RPE) and the stage timing table beside 002's.

Each ``run_*`` returns a frozen dataclass: ``str()`` a one-line summary, ``.table()`` a
fixed-precision text table (printed in the notebook, compared by nbval); timings live
in their own fields and in ``timing_table()``, never in ``table()``.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from scipy.spatial.transform import Rotation

from .. import _validate as v
from .._progress import progress_bar
from .._table import format_table
from ..evaluation import Trajectory, ate, rpe
from ..sim.planes_room import Flight, build_corridor, simulate_flight
from .extraction import Frame, build_frame
from .filter import STAGES, PlaneSLAM, PlaneSLAMParams
from .mapping import PlaneMap
from .transform import lm_pose, planes_to_body

__all__ = [
    "SOURCE_TIMES_S",
    "FlightResult",
    "IntensityResult",
    "PairsResult",
    "flight_frames",
    "ours_vs_source",
    "run_flight",
    "run_intensity_figure",
    "run_intensity_study",
    "run_pairs_figure",
    "timing_table",
]

#: 002's table: mean seconds per cycle on one thread of a Core i5-3427U (1.8 GHz)
SOURCE_TIMES_S = {"extraction": 0.061, "description": 0.020, "motion": 0.003, "equations": 0.037,
                  "weights": 0.050, "pose": 0.011, "total": 0.182}
SIZES = {"small": 6.0, "medium": 20.0, "full": 60.0}


def flight_frames(flight: Flight, frame_lines: int = 40):
    """Yield ``(k, frame, odometry_increment, true_pose)`` per frame of ``frame_lines`` lines (002)."""
    frame_lines = v.check_int(frame_lines, "frame_lines", minimum=1)
    prev = None
    for k in range(len(flight) // frame_lines):
        s = slice(k * frame_lines, (k + 1) * frame_lines)
        last = (k + 1) * frame_lines - 1
        fr = build_frame(flight.body_points(s), flight.intensities[s], flight.odometry[s],
                         origin_m=flight.scanner.mount_m)
        U = np.eye(4) if prev is None else np.linalg.inv(flight.odometry[prev]) @ flight.odometry[last]
        prev = last
        yield k, fr, U, flight.poses[last]


def _euler_errors(T_est, T_true):
    """Per pose: x, y, z errors [m] and roll, pitch, yaw errors [deg] of ``(T_true)^-1 T_est``-style differences."""
    dpos = T_est[:, :3, 3] - T_true[:, :3, 3]
    dR = np.swapaxes(T_true[:, :3, :3], 1, 2) @ T_est[:, :3, :3]
    return np.c_[dpos, np.rad2deg(Rotation.from_matrix(dR).as_euler("xyz"))]


@dataclass(frozen=True)
class FlightResult:
    """A flight (002 Fig. 8, 9): per frame ``times_s``, ``poses_true``, ``poses_est``, ``poses_odo``, ``errors
    (F, 6)`` (x, y, z [m]; roll, pitch, yaw [deg]); ATE/RPE of the estimate and of the odometry; the map;
    ``stage_times_s (F, 7)`` per stage (timings: never in ``table()``)."""

    times_s: np.ndarray
    poses_true: np.ndarray
    poses_est: np.ndarray
    poses_odo: np.ndarray
    errors: np.ndarray
    errors_odo: np.ndarray
    ate_m: float
    ate_odo_m: float
    ate_aligned_m: float
    ate_aligned_odo_m: float
    rpe_m: float
    rpe_deg: float
    n_frames: int
    n_kept_prediction: int
    mean_planes: float
    map: PlaneMap = field(repr=False)
    params: PlaneSLAMParams = field(repr=False)
    stage_times_s: np.ndarray = field(repr=False)

    def __str__(self) -> str:
        return (f"Flight: {self.n_frames} frames, ATE {self.ate_m:.3f} m (odometry {self.ate_odo_m:.3f} m), "
                f"{len(self.map)} map planes, {self.n_kept_prediction} frames kept the prediction")

    def table(self) -> str:
        rms = np.sqrt(np.mean(self.errors[1:] ** 2, axis=0))
        rms_o = np.sqrt(np.mean(self.errors_odo[1:] ** 2, axis=0))
        mx = np.abs(self.errors[1:]).max(axis=0)
        names = ("x [m]", "y [m]", "z [m]", "roll [deg]", "pitch [deg]", "yaw [deg]")
        rows = [[n, f"{a:.2f}" if "deg" in n else f"{a:.3f}", f"{b:.2f}" if "deg" in n else f"{b:.3f}",
                 f"{c:.2f}" if "deg" in n else f"{c:.3f}"] for n, a, b, c in zip(names, rms, mx, rms_o, strict=True)]
        rows += [["ATE, map frame (no alignment) [m]", f"{self.ate_m:.3f}", "", f"{self.ate_odo_m:.3f}"],
                 ["ATE, SE(3)-aligned [m]", f"{self.ate_aligned_m:.3f}", "", f"{self.ate_aligned_odo_m:.3f}"],
                 ["RPE per frame [m]", f"{self.rpe_m:.3f}", "", ""],
                 ["RPE per frame [deg]", f"{self.rpe_deg:.2f}", "", ""],
                 ["frames / kept prediction", f"{self.n_frames} / {self.n_kept_prediction}", "", ""],
                 ["planes per frame / in the map", f"{self.mean_planes:.1f} / {len(self.map)}", "", ""]]
        return format_table(["error", "RMS (SLAM)", "max |.| (SLAM)", "RMS (odometry)"], rows,
                            title="Flight errors (002 Fig. 8; ours)")

    def mean_stage_times(self) -> dict:
        """Mean seconds per stage over the frames after the first (the first only builds the map)."""
        t = self.stage_times_s[1:] if len(self.stage_times_s) > 1 else self.stage_times_s
        out = {s: float(t[:, i].mean()) for i, s in enumerate(STAGES)}
        out["total"] = float(t.sum(axis=1).mean())
        return out


def timing_table(times: dict, *, load: str | None = None) -> str:
    """Seconds per cycle by stage, ours beside 002's (ratio = ours / 002); ``load``: the machine's load average."""
    rows = []
    for s in (*STAGES, "total"):
        src = SOURCE_TIMES_S.get(s)
        ours = times.get(s, float("nan"))
        rows.append([s, f"{ours:.4f}", "-" if src is None else f"{src:.3f}",
                     "-" if src is None else f"{ours / src:.2f}"])
    title = "Seconds per cycle (002: one thread of a Core i5-3427U)"
    if load:
        title += f"; ours under load average {load}"
    return format_table(["stage", "ours [s]", "002 [s]", "ours / 002"], rows, title=title)


def run_flight(duration_s: float | None = None, *, size: str = "small", frame_lines: int = 40,
               params: PlaneSLAMParams | None = None, flight: Flight | None = None, rng=0,
               progress: bool | None = None, **overrides) -> FlightResult:
    """Fly the room and run the filter on every frame (002 "Experimental trial"; ours: the simulator).

    ``duration_s`` (default by ``size``: small 6 s, medium 20 s, full 60 s), ``frame_lines`` lines per frame
    (002: ~1 s = 40 lines), ``params`` plus overrides for :class:`PlaneSLAMParams`, ``flight`` a ready
    :class:`~slamlab.sim.Flight` (else simulated from ``rng``).
    """
    p = PlaneSLAMParams.resolve(params, **overrides)
    if duration_s is None:
        v.check_choice(size, "size", tuple(SIZES))
        duration_s = SIZES[size]
    seeds = np.random.SeedSequence(v.check_int(rng, "rng", minimum=0)).spawn(2)
    if flight is None:
        flight = simulate_flight(duration_s, rng=np.random.default_rng(seeds[0]))
    elif not isinstance(flight, Flight):
        raise TypeError(f"`flight` must be a Flight or None; got {type(flight).__name__}")
    n_frames = len(flight) // v.check_int(frame_lines, "frame_lines", minimum=1)
    if n_frames < 2:
        raise ValueError(f"the flight has {len(flight)} lines: fewer than two frames of `frame_lines` = {frame_lines}")
    slam = PlaneSLAM(flight.poses[frame_lines - 1], params=p, rng=np.random.default_rng(seeds[1]))
    est, true, odo, times, stage, nplanes = [], [], [], [], [], []
    for k, fr, U, T in progress_bar(flight_frames(flight, frame_lines), total=n_frames, desc="flight",
                                    progress=progress):
        rep = slam.step(fr, U)
        est.append(slam.pose.copy())
        true.append(T)
        odo.append(flight.odometry[(k + 1) * frame_lines - 1])
        times.append(flight.times_s[(k + 1) * frame_lines - 1])
        stage.append([rep.times_s[s] for s in STAGES])
        nplanes.append(rep.n_planes)
    est, true, odo, ts = np.array(est), np.array(true), np.array(odo), np.array(times)
    tr_true = Trajectory.from_poses(true, ts)
    tr_est = Trajectory.from_poses(est, ts)
    tr_odo = Trajectory.from_poses(odo, ts)
    return FlightResult(ts, true, est, odo, _euler_errors(est, true), _euler_errors(odo, true),
                        ate(tr_true, tr_est, align="none").rmse, ate(tr_true, tr_odo, align="none").rmse,
                        # an SE(3) alignment needs three poses (Umeyama): NaN for shorter flights
                        ate(tr_true, tr_est).rmse if n_frames >= 3 else float("nan"),
                        ate(tr_true, tr_odo).rmse if n_frames >= 3 else float("nan"),
                        rpe(tr_true, tr_est).rmse, rpe(tr_true, tr_est, relation="rotation_deg").rmse,
                        n_frames, slam.n_kept_prediction, float(np.mean(nplanes)), slam.map, p, np.array(stage))


# --- 002 Fig. 2: the locus of the solved particles for one, two, three pairs --------------------------------
@dataclass(frozen=True)
class PairsResult:
    """Per number of pairs (1, 2, 3): particle positions before ``(P, 3)`` and after the LM, and the singular
    values of the solved positions (the locus: plane, line, point)."""

    before: tuple
    after: tuple
    spread_before: np.ndarray
    spread_after: np.ndarray
    true_t: np.ndarray

    def __str__(self) -> str:
        dims = [int(np.sum(s > 1e-6)) for s in self.spread_after]
        return f"Fig. 2: solved positions span {dims[0]}-D, {dims[1]}-D, {dims[2]}-D sets for 1, 2, 3 pairs"

    def table(self) -> str:
        rows = []
        for k in range(3):
            sb, sa = self.spread_before[k], self.spread_after[k]
            dim = int(np.sum(sa > 1e-6))
            rows.append([str(k + 1), ("plane", "line", "point")[k], " ".join(f"{x:.3f}" for x in sb),
                         " ".join(f"{x:.3f}" for x in np.where(sa > 1e-6, sa, 0.0)), str(dim)])
        return format_table(["pairs", "002 says", "spread before [m] (3 axes)", "spread after [m]", "locus dim"],
                            rows, title="002 Fig. 2: where the particles go (LM, no prior)")


def run_pairs_figure(n_particles: int = 300, sigma_m: float = 0.3, *, rng=0) -> PairsResult:
    """002 Fig. 2: three perpendicular map planes; particles predicted around the truth, solved by LM on 1, 2, 3
    pairs (our exact synthetic case: noise-free planes, 002's bare system, no prior)."""
    n_particles = v.check_int(n_particles, "n_particles", minimum=2)
    sigma_m = v.check_positive(sigma_m, "sigma_m")
    g = v.as_rng(rng)
    n_m = np.array([[1.0, 0, 0], [0, 1.0, 0], [0, 0, 1.0]])
    p_m = np.array([4.0, 3.0, 2.5])
    R_true, t_true = np.eye(3), np.array([1.0, 1.0, 1.0])
    n_b, p_b = planes_to_body(n_m, p_m, R_true, t_true)
    t0 = t_true + g.normal(0, sigma_m, (n_particles, 3))
    R0 = Rotation.from_rotvec(g.normal(0, np.deg2rad(1.0), (n_particles, 3))).as_matrix()
    before, after, sb, sa = [], [], [], []
    for k in (1, 2, 3):
        res = lm_pose(R0, t0, np.broadcast_to(n_m[:k], (n_particles, k, 3)),
                      np.broadcast_to(p_m[:k], (n_particles, k)), n_b[:k], p_b[:k], max_iters=40)
        before.append(t0)
        after.append(res.t)
        sb.append(np.linalg.svd(t0 - t0.mean(0), compute_uv=False) / np.sqrt(n_particles))
        sa.append(np.linalg.svd(res.t - res.t.mean(0), compute_uv=False) / np.sqrt(n_particles))
    return PairsResult(tuple(before), tuple(after), np.array(sb), np.array(sa), t_true)


# --- 002 Fig. 4: three planes, two parallel; the intensities pick the point -----------------------------------
@dataclass(frozen=True)
class IntensityResult:
    """002 Fig. 4 in a corridor: particles before, after the LM (spread along the corridor), their weights and
    after resampling; the along-corridor error with and without the intensity weights."""

    predicted: np.ndarray
    solved: np.ndarray
    weights: np.ndarray
    resampled: np.ndarray
    true_t: np.ndarray
    error_with_m: float
    error_without_m: float
    spread_solved_m: np.ndarray
    frame: Frame = field(repr=False)
    map: PlaneMap = field(repr=False)

    def __str__(self) -> str:
        return (f"Fig. 4: along-corridor error {self.error_with_m:.3f} m with intensity weights, "
                f"{self.error_without_m:.3f} m without")

    def table(self) -> str:
        rows = [["spread of solved particles x / y / z [m]", " / ".join(f"{s:.3f}" for s in self.spread_solved_m)],
                ["along-corridor error, intensity weights on [m]", f"{self.error_with_m:.3f}"],
                ["along-corridor error, weights off (ablation) [m]", f"{self.error_without_m:.3f}"],
                ["largest weight / uniform weight", f"{self.weights.max() * len(self.weights):.2f}"]]
        return format_table(["quantity", "value"], rows,
                            title="002 Fig. 4: two parallel walls + floor + ceiling, one cycle")


def run_intensity_figure(offset_m: float = 0.4, *, n_particles: int = 400, sigma_xyz_m: float = 0.3,
                         rounds: int = 5, params: PlaneSLAMParams | None = None, rng=0, **overrides) -> IntensityResult:
    """002 Fig. 4: the map from a frame at a known pose in a corridor; the vehicle moves ``offset_m`` along it
    while the odometry says it did not; the planes (floor, ceiling, two parallel walls) leave ``x`` free, the
    panel intensities fix it. ``rounds`` cycles are run on the same frame (ours: one cycle's SAD* weights are
    flat, 002 resamples every frame). The ablation runs the same with ``intensity_weights=False``."""
    g = np.random.default_rng(v.check_int(rng, "rng", minimum=0))
    offset_m = float(offset_m)
    rounds = v.check_int(rounds, "rounds", minimum=1)
    corridor = build_corridor(rng=g.integers(2**31))
    start = np.array([5.0, 1.5, 1.5])
    flights = []
    for x in (0.0, offset_m):
        wp = [start + np.array([x, 0, 0]), start + np.array([x + 1, 0, 0])]
        flights.append(simulate_flight(1.0, room=corridor, speed_m_s=0.0, waypoints_m=wp, odometry_noise=0.0,
                                       rng=g.integers(2**31)))
    frames = []
    for f in flights:
        frames.append(next(flight_frames(f, 40))[1])
    out = {}
    for use in (True, False):
        p = PlaneSLAMParams.resolve(params, **{"n_particles": n_particles, "sigma_xyz_m": sigma_xyz_m,
                                              "min_normal_rank": 2, "pair_dist_m": 1.5, "intensity_weights": use,
                                              **overrides})
        slam = PlaneSLAM(flights[0].poses[-1], params=p, rng=g.integers(2**31))
        slam.step(frames[0], np.eye(4))
        slam.update_map = False
        U = np.linalg.inv(flights[0].poses[-1]) @ flights[0].poses[-1]   # the odometry: no motion
        first = None
        for r in range(rounds):
            slam.step(frames[1], U)
            if r == 0:
                first = (slam.X_predicted[:, :3, 3].copy(), slam.X_solved[:, :3, 3].copy(), slam.weights.copy(),
                         slam.X[:, :3, 3].copy())
            slam.params = slam.params.replace(sigma_xyz_m=0.02, sigma_rpy_deg=0.2)   # later rounds: small V
        out[use] = (first, abs(slam.pose[0, 3] - flights[1].poses[-1][0, 3]), slam)
    (pred, solved, w, res), err_on, slam_on = out[True]
    spread = solved.std(axis=0)
    return IntensityResult(pred, solved, w, res, flights[1].poses[-1][:3, 3], float(err_on), float(out[False][1]),
                           spread, frames[1], slam_on.map)


def _fig4_trial(offset_m: float, rng, n_particles: int = 400) -> dict:
    """One Fig. 4 run with a seed drawn from ``rng``: the along-corridor errors with and without the weights."""
    r = run_intensity_figure(offset_m, n_particles=n_particles, rng=int(rng.integers(2**31)))
    return {"error_with_m": r.error_with_m, "error_without_m": r.error_without_m}


@dataclass(frozen=True)
class IntensityStudy:
    """Fig. 4 over seeds and offsets (ours: 002 shows one cycle): one row per run in ``runs`` (a DataFrame)."""

    runs: object = field(repr=False)

    def __str__(self) -> str:
        r = self.runs
        return (f"Fig. 4 study: {len(r)} runs, median error {r.error_with_m.median():.3f} m with the intensity "
                f"weights, {r.error_without_m.median():.3f} m without")

    def table(self) -> str:
        rows = []
        for off, g in self.runs.groupby("offset_m"):
            rows.append([f"{off:.2f}", str(len(g)), f"{g.error_with_m.median():.3f}",
                         f"{g.error_with_m.quantile(0.9):.3f}", f"{g.error_without_m.median():.3f}",
                         f"{(g.error_with_m < 0.5 * g.error_without_m).mean():.0%}"])
        return format_table(["offset [m]", "runs", "median err, weights [m]", "90 % err, weights [m]",
                             "median err, no weights [m]", "weights halve the error"], rows,
                            title="002 Fig. 4 over seeds (ours)")


def run_intensity_study(n_seeds: int = 10, offsets_m=(0.2, 0.4, 0.8), *, n_particles: int = 400, seed: int = 0,
                        n_jobs: int = 1, progress: bool | None = None) -> IntensityStudy:
    """Fig. 4 (:func:`run_intensity_figure`) repeated over ``n_seeds`` seeds for each offset, by
    :func:`slamlab.sweep.sweep` (ours: how reliably the intensities resolve the corridor)."""
    from ..sweep import sweep

    n_seeds = v.check_int(n_seeds, "n_seeds", minimum=1)
    table = sweep(_fig4_trial, {"offset_m": [float(o) for o in offsets_m]}, seeds=n_seeds, seed=seed, n_jobs=n_jobs,
                  fixed={"n_particles": n_particles}, progress=progress, desc="Fig. 4 study")
    bad = table["error"].notna() if "error" in table else None
    if bad is not None and bad.any():
        raise RuntimeError(f"{int(bad.sum())} Fig. 4 runs failed: {table.loc[bad, 'error'].iloc[0]}")
    return IntensityStudy(table)


def ours_vs_source(flight: FlightResult, pairs: PairsResult, fig4: IntensityResult) -> str:
    """"Ours vs the source" for Ch. 10: what 002 reports beside what we measured (timings: see timing_table)."""
    dims = [int(np.sum(s > 1e-6)) for s in pairs.spread_after]
    rows = [
        ["particles", "400", str(flight.params.n_particles)],
        ["points per frame", "> 40000", "43240"],
        ["locus for 1 / 2 / 3 pairs", "plane / line / point", f"{dims[0]}-D / {dims[1]}-D / {dims[2]}-D"],
        ["Fig. 4: intensities resolve the line", "yes (a clear weight maximum)",
         f"error {fig4.error_with_m:.3f} m (off: {fig4.error_without_m:.3f} m)"],
        ["flight position error", "Fig. 8 (plot only)", f"ATE {flight.ate_m:.3f} m (odometry {flight.ate_odo_m:.3f} m), {flight.n_frames} frames"],
        ["map", "Fig. 9: planes of the room", f"{len(flight.map)} planes"],
        ["cycle time", "0.182 s (i5-3427U, 1 thread)", "timing table (machine-dependent)"],
    ]
    return format_table(["quantity", "002", "ours"], rows, title="Ch. 10: ours vs the source (002)")
