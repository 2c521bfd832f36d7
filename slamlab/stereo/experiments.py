"""Ch. 4 experiments (000 §3.7): the stereo SLAM loop on rendered arena runs, against ground truth (KITTI and the
closing table: :mod:`.kitti_experiments`).

``run_turn_in_place`` (000 §3.7.1) and ``run_closed_loop`` (000 §3.7.2) return a
frozen :class:`StereoRunResult`; ``str(result)`` is a one-line summary and
``result.table()`` prints our figures beside 000's. Timings live in ``stage_time_s``
and ``fps`` only, never in the table.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np

from .. import _validate as v
from .._progress import progress_bar
from .._table import format_table
from ..geometry import wrap_angle
from ..geometry.camera import StereoRig
from ..geometry.se3 import planar_from_se3, se3_from_planar, se3_inverse
from ..kdtree.stores import ExactStore, LandmarkStore
from ..kdtree.workloads import RecordingStore, Workload
from ..sim.arena import StereoArena, StereoSim
from ..sim.stereo_paths import rectangular_loop, turn_in_place
from .params import RenderParams, StereoParams
from .slam import STAGES, StereoSLAM

__all__ = [
    "COMPARISON",
    "SIZES",
    "DriftStudy",
    "StereoRunResult",
    "comparison_table",
    "disparity_errors",
    "experiment_poses",
    "record_stereo_stream",
    "run_closed_loop",
    "run_comparison",
    "run_drift_study",
    "run_stereo_slam",
    "run_stereo_slam_variants",
    "run_turn_in_place",
]

#: frame steps per size: (turn step deg, loop step m, loop turn step deg)
SIZES = {"small": (10.0, 0.5, 20.0), "full": (5.0, 0.25, 15.0)}


@dataclass(frozen=True)
class StereoRunResult:
    """One stereo SLAM run on a rendered trajectory, errors against the ground truth (000 §3.7)."""

    name: str
    params: StereoParams = field(repr=False)
    n_frames: int
    truth: np.ndarray = field(repr=False)  # (N, 3) x, y, yaw (unwrapped) in the map frame
    estimate: np.ndarray = field(repr=False)  # (N, 3)
    pos_err_m: np.ndarray = field(repr=False)  # (N,)
    yaw_err_rad: np.ndarray = field(repr=False)  # (N,) wrapped estimate - truth
    counts: dict = field(repr=False)
    landmarks_xy: np.ndarray = field(repr=False)  # (K, 2) base landmarks in the map frame
    degenerate: np.ndarray = field(repr=False)  # indices of frames that kept the last pose
    stage_time_s: dict = field(repr=False, compare=False)  # per-frame stage times
    fps: float = field(compare=False)  # SLAM frames per second (rendering excluded)

    @property
    def detector(self) -> str:
        return self.params.detector

    @property
    def policy(self) -> str:
        return self.params.policy

    def __str__(self) -> str:
        return (
            f"{self.name}: {self.n_frames} frames, {self.detector}/{self.policy}, max position error "
            f"{self.pos_err_m.max():.2f} m, max heading error {np.rad2deg(np.abs(self.yaw_err_rad).max()):.1f} deg, "
            f"{len(self.degenerate)} degenerate frames"
        )

    # -- figures of 000 §3.7 -------------------------------------------------------------------------
    def frame_at_turn(self, angle_rad: float) -> int:
        """First frame whose true turned angle reaches ``angle_rad``."""
        turned = np.abs(self.truth[:, 2] - self.truth[0, 2])
        return int(np.argmax(turned >= angle_rad - 1e-9)) if np.any(turned >= angle_rad - 1e-9) else len(turned) - 1

    @property
    def position_spread_m(self) -> float:
        """Largest distance between two estimated positions (000 §3.7.1: ~20 cm in the turn)."""
        p = self.estimate[:, :2]
        return float(np.max(np.linalg.norm(p[:, None] - p[None], axis=2)))

    @property
    def heading_error_ratio(self) -> float:
        """Largest ``|heading error| / |turned angle|`` over frames turned at least 90° (000 §3.1: ≤ 10 %)."""
        turned = np.abs(self.truth[:, 2] - self.truth[0, 2])
        m = turned >= np.pi / 2 - 1e-9
        return float(np.max(np.abs(self.yaw_err_rad[m]) / turned[m])) if m.any() else float("nan")

    @property
    def revisit_difference(self) -> tuple[float, float]:
        """Estimated pose at the last frame minus at the first (same true place and heading): (m, rad)."""
        d = self.estimate[-1] - self.estimate[0]
        return float(np.hypot(d[0], d[1])), float(wrap_angle(d[2]))

    def table(self) -> str:
        """Our errors beside 000's figures and requirements (fixed precision)."""
        deg = np.rad2deg
        rows = [
            ["frames (degenerate)", f"{self.n_frames} ({len(self.degenerate)})", ""],
            ["max position error, m", f"{self.pos_err_m.max():.2f}", "<= 0.5 (req.)" if self.name == "closed loop" else "<= 0.15"],
        ]
        if self.name == "turn in place":
            rows.append(["spread of positions, m", f"{self.position_spread_m:.2f}", "~0.20"])
            i180 = self.frame_at_turn(np.pi)
            rows.append(["heading error at 180 deg, deg", f"{deg(abs(self.yaw_err_rad[i180])):.1f}", "<= 5"])
            rows.append(["heading error back at 0 deg, deg", f"{deg(abs(self.yaw_err_rad[-1])):.1f}", "2-3"])
        else:
            rows.append(["max heading error / turned angle, %", f"{100 * self.heading_error_ratio:.1f}", "<= 10 (req.; 000: 10)"])
            dp, dyaw = self.revisit_difference
            rows.append(["revisit: pose change, m", f"{dp:.2f}", "same pose (req.)"])
            rows.append(["revisit: heading change, deg", f"{deg(abs(dyaw)):.1f}", "same pose (req.)"])
        c = self.counts
        rows.append(["stereo matches per frame (median)", f"{np.median(c['n_stereo']):.0f}", "~500 (<100 bad)"])
        rows.append(["RANSAC inliers per frame (median)", f"{np.median(c['n_inliers'][1:]):.0f}", ""])
        return format_table(["quantity", "ours", "000"], rows, title=f"{self.name} ({self.detector}, policy {self.policy})")

    def timing_table(self) -> str:
        """Mean time per stage in ms and frames per second (volatile: not for nbval)."""
        rows = [[s, f"{1000 * np.mean(self.stage_time_s[s]):.1f}"] for s in STAGES]
        rows.append(["frames/s", f"{self.fps:.2f}"])
        return format_table(["stage", "ms/frame"], rows)


def run_stereo_slam(poses, *, name: str = "run", params: StereoParams | None = None, store=None,
                    render: RenderParams | None = None, arena: StereoArena | None = None, rig: StereoRig | None = None,
                    progress=None, rng=0, **overrides) -> StereoRunResult:
    """Render ``poses`` (N, 3) in an arena and run :class:`StereoSLAM` on them (000 §3.7).

    The map frame is the first body pose; truth is expressed in it. ``params`` plus ``overrides``
    set the pipeline (:class:`StereoParams`), ``store`` its landmark store (or a factory),
    ``render`` / ``arena`` / ``rig`` / ``progress`` the renderer (see :func:`run_stereo_slam_variants`).
    """
    p = StereoParams.resolve(params, **overrides)
    return run_stereo_slam_variants(poses, {name: p}, name=name, store=store, render=render, arena=arena, rig=rig,
                                    progress=progress, rng=rng)[name]


def run_stereo_slam_variants(
    poses,
    variants: dict,
    *,
    name: str = "run",
    params: StereoParams | None = None,
    store=None,
    render: RenderParams | None = None,
    arena: StereoArena | None = None,
    rig: StereoRig | None = None,
    progress=None,
    rng=0,
) -> dict:
    """Like :func:`run_stereo_slam`, for several pipeline settings on the same rendered frames.

    ``variants`` maps a label to a :class:`StereoParams` or to a dict of overrides of ``params``
    (default ``StereoParams()``); every run gets the same RANSAC seed, so each result equals a
    separate :func:`run_stereo_slam` call. The frames are rendered once (rendering costs about as
    much as our SURF). ``store``: a landmark store (one variant only) or a factory (default: each
    run's :func:`~slamlab.stereo.slam.default_store`).

    Renderer: ``render`` (:class:`RenderParams`: ``camera_height_m``, ``noise_std`` in grey levels,
    ``drift_std_rad`` = random-walk step of the right camera's orientation per frame,
    ``arena_seed``), ``arena`` (default the 6×8 m :class:`~slamlab.sim.arena.StereoArena` of
    ``render.arena_seed``), ``rig`` (default the 768×576, 40° pair with a 0.2 m baseline).
    ``progress``: True/False/None for a bar over the frames, or a callable ``progress(i)`` called after
    frame ``i`` (the one contract of :mod:`slamlab._progress`).
    """
    poses = v.as_finite_array(poses, "poses", ndim=2)
    if poses.shape[1] != 3 or len(poses) < 2:
        raise ValueError(f"`poses` must have shape (N, 3) with N >= 2; got {poses.shape}")
    if not isinstance(variants, dict) or not variants:
        raise TypeError("`variants` must be a non-empty dict of label -> StereoParams or dict of overrides")
    base = StereoParams.resolve(params)
    settings = {}
    for label, var in variants.items():
        if isinstance(var, StereoParams):
            settings[label] = var
        elif isinstance(var, dict):
            settings[label] = base.replace(**var)
        else:
            raise TypeError(f"`variants[{label!r}]` must be a StereoParams or a dict of overrides; got {type(var).__name__}")
    if isinstance(store, LandmarkStore) and len(settings) > 1:
        raise ValueError("a `store` instance serves one run; give a factory for several variants")
    bar = progress_bar(total=len(poses), desc=f"stereo SLAM: {name}", progress=progress)
    render = RenderParams.resolve(render)
    from ..sweep import fresh_seed_sequence

    r_sim, r_slam = fresh_seed_sequence(rng).spawn(2)  # an int seed: SeedSequence(seed)'s children as before
    arena = StereoArena(seed=render.arena_seed) if arena is None else arena
    sim = StereoSim(arena, rig, camera_height_m=render.camera_height_m, noise_std=render.noise_std,
                    drift_std_rad=render.drift_std_rad, rng=np.random.default_rng(r_sim))
    slams = {k: StereoSLAM(sim.rig, sim.T_body_left, params=p, store=store, rng=np.random.default_rng(r_slam))
             for k, p in settings.items()}
    T0_inv = se3_inverse(se3_from_planar(*poses[0]))
    truth = np.array([planar_from_se3(T0_inv @ se3_from_planar(*p)) for p in poses])
    truth[:, 2] = poses[:, 2] - poses[0, 2]
    t_slam = dict.fromkeys(slams, 0.0)
    for p in poses:
        left, right = sim.render_pair(p)
        for k, slam in slams.items():
            t = time.perf_counter()
            slam.process(left, right)
            t_slam[k] += time.perf_counter() - t
        bar.update()
    bar.close()
    out = {}
    for k, slam in slams.items():
        est = slam.planar_trajectory
        out[k] = StereoRunResult(
            name=name, params=slam.params, n_frames=len(poses), truth=truth, estimate=est,
            pos_err_m=np.hypot(*(est[:, :2] - truth[:, :2]).T), yaw_err_rad=np.asarray(wrap_angle(est[:, 2] - truth[:, 2])),
            counts=slam.counts(), landmarks_xy=slam.landmark_map()[:, :2], degenerate=slam.degenerate_frames,
            stage_time_s=slam.stage_times(), fps=len(poses) / t_slam[k],
        )  # fmt: skip
    return out


def _first(poses, n_frames):
    return poses if n_frames is None else poses[: v.check_int(n_frames, "n_frames", minimum=2)]


def experiment_poses(experiment: str, size: str = "small") -> np.ndarray:
    """Body poses ``(N, 3)`` of the turn in place or the closed loop at ``size`` (000 §3.7)."""
    v.check_choice(experiment, "experiment", ("turn in place", "closed loop"))
    v.check_choice(size, "size", SIZES)
    turn_deg, step_m, loop_turn_deg = SIZES[size]
    if experiment == "turn in place":
        return turn_in_place(np.deg2rad(turn_deg), center_m=(3.0, 4.0), start_yaw_rad=np.pi / 2)
    return rectangular_loop(step_m, np.deg2rad(loop_turn_deg))


def run_turn_in_place(size: str = "small", *, n_frames: int | None = None, params: StereoParams | None = None,
                    store=None, render: RenderParams | None = None, progress=None, rng=0, **overrides) -> StereoRunResult:
    """360° turn in place in the 6×8 m arena, facing a wall at the start (000 §3.7.1).

    ``size="small"``: 10° per frame (37 frames); ``"full"``: 5° per frame (73 frames);
    ``n_frames`` keeps only the first frames (for quick checks). ``params`` + ``overrides``:
    :class:`StereoParams`; ``render``: :class:`RenderParams`.
    """
    v.check_choice(size, "size", SIZES)
    poses = _first(experiment_poses("turn in place", size), n_frames)
    return run_stereo_slam(poses, name="turn in place", params=params, store=store, render=render, progress=progress, rng=rng,
                           **overrides)


def run_closed_loop(size: str = "small", *, n_frames: int | None = None, params: StereoParams | None = None,
                    store=None, render: RenderParams | None = None, progress=None, rng=0, **overrides) -> StereoRunResult:
    """The closed, roughly rectangular 4×5 m loop in the 6×8 m arena, back to the start pose (000 §3.7.2).

    ``size="small"``: 0.5 m and 20° per frame (57 frames); ``"full"``: 0.25 m and 15° per frame;
    ``n_frames`` keeps only the first frames (for quick checks). ``params`` + ``overrides``:
    :class:`StereoParams`; ``render``: :class:`RenderParams`.
    """
    v.check_choice(size, "size", SIZES)
    poses = _first(experiment_poses("closed loop", size), n_frames)
    return run_stereo_slam(poses, name="closed loop", params=params, store=store, render=render, progress=progress, rng=rng,
                           **overrides)


#: the default comparison of :func:`run_comparison`: 000's pipeline, and ORB with and without §3.5's policy
COMPARISON = {
    "SURF, oldest": {},
    "ORB, oldest": {"detector": "orb"},
    "ORB, all": {"detector": "orb", "policy": "all"},
}


def run_comparison(
    experiment: str = "closed loop", size: str = "small", variants: dict | None = None, *, n_frames: int | None = None,
    params: StereoParams | None = None, render: RenderParams | None = None, progress=None, rng=0,
) -> dict:
    """The turn or the loop once per pipeline setting, on the same rendered frames (000 §3.5, §3.7).

    ``variants`` maps a label to a :class:`StereoParams` or to overrides of ``params`` (default
    :data:`COMPARISON`); ``render``: :class:`RenderParams` (``noise_std``, ``drift_std_rad``, ...).
    Returns label -> :class:`StereoRunResult`; :func:`comparison_table` prints them side by side.
    """
    v.check_choice(size, "size", SIZES)
    v.check_choice(experiment, "experiment", ("turn in place", "closed loop"))
    poses = _first(experiment_poses(experiment, size), n_frames)
    return run_stereo_slam_variants(poses, COMPARISON if variants is None else variants, name=experiment,
                                    params=params, render=render, progress=progress, rng=rng)


def comparison_table(results: dict) -> str:
    """000's figures for the turn or the loop, one column per run of :func:`run_comparison`."""
    runs = list(results.values())
    if not runs:
        raise ValueError("`results` is empty")
    deg = np.rad2deg
    rows = [["max position error, m", *(f"{r.pos_err_m.max():.2f}" for r in runs)]]
    if runs[0].name == "turn in place":
        rows.append(["spread of positions, m", *(f"{r.position_spread_m:.2f}" for r in runs)])
        rows.append(["heading error at 180 deg, deg", *(f"{deg(abs(r.yaw_err_rad[r.frame_at_turn(np.pi)])):.1f}" for r in runs)])
        rows.append(["heading error back at 0 deg, deg", *(f"{deg(abs(r.yaw_err_rad[-1])):.1f}" for r in runs)])
    else:
        rows.append(["max heading error / turned angle, %", *(f"{100 * r.heading_error_ratio:.1f}" for r in runs)])
        rows.append(["revisit: pose change, m", *(f"{r.revisit_difference[0]:.2f}" for r in runs)])
        rows.append(["revisit: heading change, deg", *(f"{deg(abs(r.revisit_difference[1])):.1f}" for r in runs)])
    rows.append(["degenerate frames", *(f"{len(r.degenerate)}" for r in runs)])
    rows.append(["RANSAC inliers per frame (median)", *(f"{np.median(r.counts['n_inliers'][1:]):.0f}" for r in runs)])
    return format_table(["quantity", *results], rows, title=f"{runs[0].name}, {runs[0].n_frames} frames")


@dataclass(frozen=True)
class DriftStudy:
    """Runs of one experiment at several calibration-drift levels (000 §3.2; our experiment)."""

    experiment: str
    drift_std_rad: tuple
    runs: tuple = field(repr=False)  # StereoRunResult per level

    def table(self) -> str:
        """Errors, stereo matches and inliers per drift level (fixed precision)."""
        rows = []
        for d, r in zip(self.drift_std_rad, self.runs, strict=True):
            c = r.counts
            # the random walk's typical accumulated angle at the last frame: sqrt(N) sigma per axis
            rows.append([f"{1e3 * d:.1f}", f"{1e3 * d * np.sqrt(r.n_frames):.1f}", f"{r.pos_err_m.max():.2f}",
                         f"{np.rad2deg(np.abs(r.yaw_err_rad).max()):.1f}", f"{np.median(c['n_stereo']):.0f}",
                         f"{np.min(c['n_stereo']):.0f}", f"{np.median(c['n_inliers'][1:]):.0f}", f"{len(r.degenerate)}"])  # fmt: skip
        head = ["drift, mrad/frame", "~drift at end, mrad", "max pos. err, m", "max heading err, deg",
                "stereo matches (median)", "(min)", "inliers (median)", "degenerate"]  # fmt: skip
        return format_table(head, rows, title=f"calibration drift of the right camera: {self.experiment} ({self.runs[0].detector})")


_RUNNERS = {"turn in place": "run_turn_in_place", "closed loop": "run_closed_loop"}


def drift_level(*, drift_std_rad: float, experiment: str, size: str, n_frames, params: StereoParams,
                render: RenderParams, seed) -> dict:
    """One task of :func:`run_drift_study`: the experiment at one drift level (deterministic from ``seed``)."""
    runner = globals()[_RUNNERS[experiment]]
    return {"run": runner(size, n_frames=n_frames, params=params, render=render.replace(drift_std_rad=drift_std_rad),
                          progress=False, rng=seed)}


def run_drift_study(
    drift_std_rad=(0.0, 0.5e-3, 1e-3, 2e-3), experiment: str = "turn in place", size: str = "small", *,
    n_frames: int | None = None, params: StereoParams | None = None, render: RenderParams | None = None, rng=0,
    n_jobs: int = 1, progress: bool | None = None, **overrides,
) -> DriftStudy:
    """The same run at several calibration-drift levels (our experiment for 000 §3.2), on :func:`slamlab.sweep.sweep`.

    The right camera's orientation takes a random-walk step of ``drift_std_rad`` per axis and
    frame while the pipeline keeps the nominal calibration; ``params`` + ``overrides`` set the
    pipeline (``detector``, ``policy``, ...), ``render`` the rest of the renderer. Every level uses
    the same seed ``rng`` (common random numbers: the level is the only change), so each task is
    deterministic and the sweep gives it no stream of its own (``rng_arg=None``); the study is
    the same for any ``n_jobs``. ``progress``: a bar over the levels (default: on unless
    ``$SLAMLAB_PROGRESS=0``).
    """
    from ..sweep import fresh_seed_sequence, sweep

    v.check_choice(experiment, "experiment", _RUNNERS)
    v.check_choice(size, "size", SIZES)
    levels = tuple(float(d) for d in np.atleast_1d(v.as_finite_array(drift_std_rad, "drift_std_rad", ndim=1)))
    if min(levels) < 0:
        raise ValueError(f"`drift_std_rad` must be >= 0; got {levels}")
    seed = fresh_seed_sequence(rng)  # every level's run from the same (fresh) SeedSequence
    p = StereoParams.resolve(params, **overrides)
    render = RenderParams.resolve(render)
    table = sweep(drift_level, {"drift_std_rad": levels}, rng_arg=None, n_jobs=n_jobs, progress=progress,
                  on_error="raise", desc=f"calibration drift study ({experiment})",
                  fixed={"experiment": experiment, "size": size, "n_frames": n_frames, "params": p, "render": render,
                         "seed": seed})
    return DriftStudy(experiment, levels, tuple(table["run"]))


def record_stereo_stream(n_frames: int | None = None, *, detector: str = "sift", rng: int = 0,
                         progress: bool | None = None) -> Workload:
    """Record the landmark-store calls of the stereo pipeline on 000's closed loop (our addition).

    Runs the closed loop (small size: 57 frames; ``n_frames`` keeps the first frames only) with an
    :class:`~slamlab.kdtree.ExactStore` wrapped in a :class:`~slamlab.kdtree.workloads.RecordingStore`,
    and returns the recorded :class:`~slamlab.kdtree.workloads.Workload` for
    :func:`slamlab.kdtree.experiments.run_store_comparison`. ``detector="sift"`` gives 128-d float
    descriptors (OpenCV); ``"surf"`` the 64-d SURF of the features chapter. The map search is 000's
    global one for every detector (ORB's window search would leave the store almost no queries).
    ``progress``: a bar over the frames (None: on unless ``$SLAMLAB_PROGRESS=0``).
    """
    p = StereoParams(detector=detector, map_search="global")
    rec = RecordingStore(ExactStore(p.base_seen_times, p.max_non_base_time))
    run_closed_loop("small", n_frames=n_frames, params=p, store=rec, progress=progress, rng=rng)
    n = len(rec.iterations)
    return rec.workload(f"stereo closed loop, {n} frames ({detector.upper()}, recorded)",
                        base_seen_times=p.base_seen_times, max_non_base_time=p.max_non_base_time)


def disparity_errors(pose=(3.0, 4.0, 1.2), *, arena: StereoArena | None = None, params: StereoParams | None = None,
                     rng=0, **overrides) -> str:
    """Stereo disparity errors against the renderer's depth, per ORB pyramid level, before and after
    :func:`~slamlab.stereo.subpixel_disparity` (our addition to 000 §3.3).

    One rendered pair at ``pose`` in ``arena`` (default the 6×8 m arena): keypoints (``params`` +
    ``overrides``, default ORB), stereo matches, and for each match the disparity minus the true one
    ``f b / z`` (``z``: the renderer's depth at the left keypoint's pixel). Returns a table of the
    median absolute error and the share above 1 px per level.
    """
    from .local_stages import _stereo_match, detect_features, subpixel_disparity

    p = StereoParams.resolve(params, **({"detector": "orb"} | overrides))
    arena = StereoArena(seed=0) if arena is None else arena
    sim = StereoSim(arena, rng=rng)
    pose = v.as_vector(pose, "pose", 3)
    left, right = sim.render_pair(pose)
    fl, fr = detect_features(left, params=p), detect_features(right, params=p)
    sm = _stereo_match(fl, fr, sim.rig.F, p.ratio, p.epi_tol_px)
    _, depth, _ = arena.cast(sim.rig.left, se3_from_planar(*pose) @ sim.T_body_left)
    fb = sim.rig.left.fx * sim.rig.baseline_m

    def errors(uvl, uvr):
        c, r = np.rint(uvl).astype(int).T
        return (uvl[:, 0] - uvr[:, 0]) - fb / depth[r, c]

    uvl, uvr = fl.uv[sm.left], fr.uv[sm.right]
    raw = errors(uvl, uvr)
    ref_l, ref_r, ok = subpixel_disparity(left, right, uvl, uvr, half_px=p.subpixel_half_px, search_px=p.subpixel_search_px)
    ref = np.full(len(raw), np.nan)
    ref[ok] = errors(ref_l[ok], ref_r[ok])
    level = fl.octave[sm.left]
    rows = []
    for lv in np.unique(level):
        m = (level == lv) & np.isfinite(raw)
        mr = m & ok
        rows.append([f"{lv}", f"{m.sum()}", f"{np.median(np.abs(raw[m])):.2f}", f"{100 * np.mean(np.abs(raw[m]) > 1):.0f}",
                     f"{np.median(np.abs(ref[mr])):.2f}", f"{100 * np.mean(np.abs(ref[mr]) > 1):.0f}", f"{100 * mr.sum() / max(m.sum(), 1):.0f}"])
    head = ["level", "matches", "keypoints: median |err|, px", "> 1 px, %", "refined: median |err|, px", "> 1 px, %",
            "refined, %"]
    return format_table(head, rows, title=f"disparity error against the renderer ({p.detector.upper()}, one frame)")
