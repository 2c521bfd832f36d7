"""Stereo SLAM on rendered arena runs (000 §3.7): the result, the runner, 000's turn in place and closed loop."""

from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np

from ... import _validate as v
from ..._progress import progress_bar
from ..._table import format_table
from ...geometry import wrap_angle
from ...geometry.camera import StereoRig
from ...geometry.se3 import planar_from_se3, se3_from_planar, se3_inverse
from ...kdtree.stores import LandmarkStore
from ...sim.arena import StereoArena, StereoSim
from ...sim.stereo_paths import rectangular_loop, turn_in_place
from ..params import RenderParams, StereoParams
from ..slam import STAGES, StereoSLAM

#: frame steps per size: (turn step deg, loop step m, loop turn step deg)
SIZES = {"small": (10.0, 0.5, 20.0), "full": (5.0, 0.25, 15.0)}


@dataclass(frozen=True)
class StereoRunResult:
    """One stereo SLAM run on a rendered trajectory, errors against the ground truth (000 §3.7).

    Attributes
    ----------
    name : str
        Run label.
    params : StereoParams
        Pipeline settings.
    n_frames : int
        Frames processed.
    truth, estimate : numpy.ndarray, shape (N, 3)
        ``(x_m, y_m, yaw_rad)`` in the map frame (yaw unwrapped).
    pos_err_m : numpy.ndarray, shape (N,)
        Position errors [m].
    yaw_err_rad : numpy.ndarray, shape (N,)
        Wrapped yaw errors, estimate minus truth [rad].
    counts : dict
        Per-frame counts of :meth:`StereoSLAM.process` (``n_inliers``, ``n_new``...), as arrays (:meth:`StereoSLAM.counts`).
    landmarks_xy : numpy.ndarray, shape (K, 2)
        Base landmarks in the map frame [m].
    degenerate : numpy.ndarray of int
        Frames that kept the last pose.
    stage_time_s : dict
        Per-frame stage times [s] (not compared).
    fps : float
        SLAM frames per second, rendering excluded (not compared).
    """

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
        """First frame whose true turned angle reaches ``angle_rad``.

        Parameters
        ----------
        angle_rad : float
            Turned angle [rad].

        Returns
        -------
        int
            Frame index (the last frame when the angle is never reached).
        """
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
        """Our errors beside 000's figures and requirements (fixed precision).

        Returns
        -------
        str
        """
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
        """Mean time per stage in ms and frames per second (volatile: not for nbval).

        Returns
        -------
        str
        """
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

    Parameters
    ----------
    poses : array_like, shape (N, 3)
        Body poses ``(x_m, y_m, yaw_rad)``, N ≥ 2.
    name : str, default "run"
        Run label.
    params : StereoParams, optional
        Pipeline settings (default :class:`StereoParams`).
    store : LandmarkStore or callable, optional
        Landmark store or a factory (default :func:`~slamlab.stereo.slam.default_store`).
    render : RenderParams, optional
        Renderer settings (``arena_seed``, ``camera_height_m``, ``noise_std``, ``drift_std_rad``).
    arena : StereoArena, optional
        Scene (default from ``render.arena_seed``).
    rig : StereoRig, optional
        Camera pair (default 768×576, 40°, 0.2 m baseline).
    progress : bool, None or callable
        A bar over the frames (None: on unless ``$SLAMLAB_PROGRESS=0``), or ``progress(i)`` after frame ``i``.
    rng : int or numpy.random.Generator, default 0
        Seed of the RANSAC stream (and the image noise).
    **overrides
        :class:`StereoParams` fields to change.

    Returns
    -------
    StereoRunResult
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

    Parameters
    ----------
    poses : array_like, shape (N, 3)
        Body poses ``(x_m, y_m, yaw_rad)``, N ≥ 2.
    variants : dict
        Label -> :class:`StereoParams` or dict of overrides of ``params``.
    name : str, default "run"
        Run label.
    params : StereoParams, optional
        Pipeline settings (default :class:`StereoParams`).
    store : LandmarkStore or callable, optional
        Landmark store or a factory (default :func:`~slamlab.stereo.slam.default_store`).
    render : RenderParams, optional
        Renderer settings (``arena_seed``, ``camera_height_m``, ``noise_std``, ``drift_std_rad``).
    arena : StereoArena, optional
        Scene.
    rig : StereoRig, optional
        Camera pair.
    progress : bool, None or callable
        A bar over the frames (None: on unless ``$SLAMLAB_PROGRESS=0``), or ``progress(i)`` after frame ``i``.
    rng : int or numpy.random.Generator, default 0
        Seed of the RANSAC stream (and the image noise).

    Returns
    -------
    dict
        Label -> :class:`StereoRunResult`.
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
    from ...sweep import fresh_seed_sequence

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
    """Body poses ``(N, 3)`` of the turn in place or the closed loop at ``size`` (000 §3.7).

    Parameters
    ----------
    experiment : {"turn in place", "closed loop"}
        The trajectory.
    size : {"small", "full"}
        Frame step (see :func:`run_turn_in_place`, :func:`run_closed_loop`).

    Returns
    -------
    numpy.ndarray, shape (N, 3)
        ``(x_m, y_m, yaw_rad)``.
    """
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

    Parameters
    ----------
    size : {"small", "full"}
        Frame step: see above.
    n_frames : int, optional
        Keep only the first frames.
    params : StereoParams, optional
        Pipeline settings (default :class:`StereoParams`).
    store : LandmarkStore or callable, optional
        Landmark store or a factory (default :func:`~slamlab.stereo.slam.default_store`).
    render : RenderParams, optional
        Renderer settings (``arena_seed``, ``camera_height_m``, ``noise_std``, ``drift_std_rad``).
    progress : bool, None or callable
        A bar over the frames (None: on unless ``$SLAMLAB_PROGRESS=0``), or ``progress(i)`` after frame ``i``.
    rng : int or numpy.random.Generator, default 0
        Seed of the RANSAC stream (and the image noise).
    **overrides
        :class:`StereoParams` fields to change.

    Returns
    -------
    StereoRunResult
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

    Parameters
    ----------
    size : {"small", "full"}
        Frame step: see above.
    n_frames : int, optional
        Keep only the first frames.
    params : StereoParams, optional
        Pipeline settings (default :class:`StereoParams`).
    store : LandmarkStore or callable, optional
        Landmark store or a factory (default :func:`~slamlab.stereo.slam.default_store`).
    render : RenderParams, optional
        Renderer settings (``arena_seed``, ``camera_height_m``, ``noise_std``, ``drift_std_rad``).
    progress : bool, None or callable
        A bar over the frames (None: on unless ``$SLAMLAB_PROGRESS=0``), or ``progress(i)`` after frame ``i``.
    rng : int or numpy.random.Generator, default 0
        Seed of the RANSAC stream (and the image noise).
    **overrides
        :class:`StereoParams` fields to change.

    Returns
    -------
    StereoRunResult
    """
    v.check_choice(size, "size", SIZES)
    poses = _first(experiment_poses("closed loop", size), n_frames)
    return run_stereo_slam(poses, name="closed loop", params=params, store=store, render=render, progress=progress, rng=rng,
                           **overrides)
