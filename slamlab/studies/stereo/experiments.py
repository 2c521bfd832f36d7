"""Ch. 4 experiments (000 §3.7): the stereo SLAM loop on rendered arena runs, against ground truth (KITTI and the
closing table: :mod:`~slamlab.studies.stereo.kitti_experiments`).

``run_experiment`` (the turn in place of 000 §3.7.1, the closed loop of 000 §3.7.2) returns a
frozen :class:`StereoRunResult`; ``str(result)`` is a one-line summary and
``result.table()`` prints our figures beside 000's. Timings live in ``stage_time_s``
and ``fps`` only, never in the table.

This module renders the arena and runs the pipeline on it (the runner, the two experiments, the comparison, the
drift study, the recorded store calls, the disparity check); the result dataclasses and
tables live in :mod:`~slamlab.studies.stereo.run_results`, the disparity error table in :mod:`~slamlab.studies.stereo.disparity_check` (re-exported here).
"""

from __future__ import annotations

import time

import numpy as np

from ..._params import refuse_set_fields
from ..._progress import progress_bar
from ..._validate import as_finite_array, as_vector, check_choice, check_int
from ...geometry import wrap_angle
from ...geometry.camera import StereoRig
from ...geometry.se3 import planar_from_se3, se3_from_planar, se3_inverse
from ...kdtree.stores import ExactStore, LandmarkStore
from ...sim.arena import StereoArena, StereoSim
from ...sim.stereo_paths import rectangular_loop, turn_in_place
from ...stereo.params import RenderParams, StereoParams
from ...stereo.slam import StereoSLAM
from ..kdtree.workloads import RecordingStore, Workload
from .disparity_check import disparity_error_table
from .run_results import COMPARISON, SIZES, DriftStudy, StereoRunResult, comparison_table

__all__ = [
    "COMPARISON",
    "DISPARITY_PARAMS",
    "EXPERIMENTS",
    "SIZES",
    "DriftStudy",
    "StereoRunResult",
    "comparison_table",
    "disparity_error_table",
    "disparity_errors",
    "experiment_poses",
    "record_stereo_stream",
    "run_comparison",
    "run_drift_study",
    "run_experiment",
    "run_stereo_slam",
    "run_stereo_slam_variants",
]

#: the rendered experiments of 000 §3.7: the turn in place (§3.7.1) and the closed loop (§3.7.2)
EXPERIMENTS = ("turn in place", "closed loop")

#: the settings of :func:`disparity_errors` (ORB: its pyramid levels are the table's rows)
DISPARITY_PARAMS = StereoParams(detector="orb")


def _first(poses, n_frames):
    return poses if n_frames is None else poses[: check_int(n_frames, "n_frames", minimum=2)]


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
    separate :func:`run_stereo_slam` call. A field is set by one route: ``params`` may not set a field a
    variant sets, nor come with a variant that is a whole :class:`StereoParams` (``ValueError`` naming it). The frames are rendered once (rendering costs about as
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
    poses = as_finite_array(poses, "poses", ndim=2)
    if poses.shape[1] != 3 or len(poses) < 2:
        raise ValueError(f"`poses` must have shape (N, 3) with N >= 2; got {poses.shape}")
    if not isinstance(variants, dict) or not variants:
        raise TypeError("`variants` must be a non-empty dict of label -> StereoParams or dict of overrides")
    base = StereoParams.resolve(params)
    settings = {}
    for label, var in variants.items():
        if isinstance(var, StereoParams):
            if params is not None:
                raise ValueError(f"`variants[{label!r}]` is a StereoParams, which replaces `params`: give a dict of "
                                 "overrides of `params` instead, or leave `params` out")
            settings[label] = var
        elif isinstance(var, dict):
            settings[label] = base.replace(**var)
            if params is not None:
                refuse_set_fields(params, sorted(var), f"`variants[{label!r}]` sets it")
        else:
            raise TypeError(f"`variants[{label!r}]` must be a StereoParams or a dict of overrides; got {type(var).__name__}")
    if isinstance(store, LandmarkStore) and len(settings) > 1:
        raise ValueError("a `store` instance serves one run; give a factory for several variants")
    bar = progress_bar(total=len(poses), desc=f"stereo SLAM: {name}", progress=progress)
    render = RenderParams.resolve(render)
    from ...sweep import fresh_seed_sequence

    r_sim, r_slam = fresh_seed_sequence(rng).spawn(2)  # an int seed: SeedSequence(seed)'s children as before
    arena = StereoArena(texture_seed=render.arena_seed) if arena is None else arena
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


def experiment_poses(experiment: str, size: str = "small") -> np.ndarray:
    """Body poses ``(N, 3)`` of the turn in place or the closed loop at ``size`` (000 §3.7).

    Parameters
    ----------
    experiment : {"turn in place", "closed loop"}
        The trajectory.
    size : {"small", "full"}
        Frame step (see :func:`run_experiment`).

    Returns
    -------
    numpy.ndarray, shape (N, 3)
        ``(x_m, y_m, yaw_rad)``.
    """
    check_choice(experiment, "experiment", EXPERIMENTS)
    check_choice(size, "size", SIZES)
    turn_deg, step_m, loop_turn_deg = SIZES[size]
    if experiment == "turn in place":
        return turn_in_place(np.deg2rad(turn_deg), center_m=(3.0, 4.0), start_yaw_rad=np.pi / 2)
    return rectangular_loop(step_m, np.deg2rad(loop_turn_deg))


def run_experiment(experiment: str, size: str = "small", *, n_frames: int | None = None,
                   params: StereoParams | None = None, store=None, render: RenderParams | None = None, progress=None,
                   rng=0, **overrides) -> StereoRunResult:
    """One of 000 §3.7's rendered experiments in the 6×8 m arena: the turn in place or the closed loop.

    ``"turn in place"`` (000 §3.7.1): a 360° turn in place, facing a wall at the start; ``size="small"``:
    10° per frame (37 frames), ``"full"``: 5° per frame (73 frames). ``"closed loop"`` (000 §3.7.2): the
    closed, roughly rectangular 4×5 m loop back to the start pose; ``"small"``: 0.5 m and 20° per frame
    (57 frames), ``"full"``: 0.25 m and 15° per frame. ``n_frames`` keeps only the first frames (for
    quick checks). ``params`` + ``overrides``: :class:`StereoParams`; ``render``: :class:`RenderParams`.

    Parameters
    ----------
    experiment : {"turn in place", "closed loop"}
        The trajectory.
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
        Named after the experiment.
    """
    check_choice(experiment, "experiment", EXPERIMENTS)
    check_choice(size, "size", SIZES)
    poses = _first(experiment_poses(experiment, size), n_frames)
    return run_stereo_slam(poses, name=experiment, params=params, store=store, render=render, progress=progress,
                           rng=rng, **overrides)


def run_comparison(
    experiment: str = "closed loop", size: str = "small", variants: dict | None = None, *, n_frames: int | None = None,
    params: StereoParams | None = None, render: RenderParams | None = None, progress=None, rng=0,
) -> dict:
    """The turn or the loop once per pipeline setting, on the same rendered frames (000 §3.5, §3.7).

    ``variants`` maps a label to a :class:`StereoParams` or to overrides of ``params`` (default
    :data:`COMPARISON`, which sets ``detector`` and ``policy`` itself: ``params`` may not set them);
    ``render``: :class:`RenderParams` (``noise_std``, ``drift_std_rad``, ...).
    Returns label -> :class:`StereoRunResult`; :func:`comparison_table` prints them side by side.

    Parameters
    ----------
    experiment : {"closed loop", "turn in place"}
        The trajectory.
    size : {"small", "full"}
        Frame step.
    variants : dict, optional
        Label -> :class:`StereoParams` or overrides of ``params`` (default ``COMPARISON``).
    n_frames : int, optional
        Keep only the first frames.
    params : StereoParams, optional
        Pipeline settings (default :class:`StereoParams`).
    render : RenderParams, optional
        Renderer settings (``arena_seed``, ``camera_height_m``, ``noise_std``, ``drift_std_rad``).
    progress : bool, None or callable
        A bar over the frames (None: on unless ``$SLAMLAB_PROGRESS=0``), or ``progress(i)`` after frame ``i``.
    rng : int or numpy.random.Generator, default 0
        Seed of the RANSAC stream (and the image noise).

    Returns
    -------
    dict
        Label -> :class:`StereoRunResult`.
    """
    check_choice(size, "size", SIZES)
    check_choice(experiment, "experiment", EXPERIMENTS)
    poses = _first(experiment_poses(experiment, size), n_frames)
    return run_stereo_slam_variants(poses, COMPARISON if variants is None else variants, name=experiment,
                                    params=params, render=render, progress=progress, rng=rng)


def drift_level(*, drift_std_rad: float, experiment: str, size: str, n_frames, params: StereoParams,
                render: RenderParams, rng) -> dict:
    """One task of :func:`run_drift_study`: the experiment at one drift level (deterministic from ``rng``).

    Parameters
    ----------
    drift_std_rad : float
        Drift level [rad per axis and frame].
    experiment : {"turn in place", "closed loop"}
        The run.
    size : {"small", "full"}
        Frame step.
    n_frames : int or None
        Keep only the first frames.
    params : StereoParams
        Pipeline settings.
    render : RenderParams
        Renderer settings (its ``drift_std_rad`` is replaced).
    rng : int or SeedSequence
        The run's seed, the same for every level.

    Returns
    -------
    dict
        ``{"run": StereoRunResult}``.
    """
    return {"run": run_experiment(experiment, size, n_frames=n_frames, params=params,
                                  render=render.replace(drift_std_rad=drift_std_rad), progress=False, rng=rng)}


def run_drift_study(
    drift_std_rad=(0.0, 0.5e-3, 1e-3, 2e-3), experiment: str = "turn in place", size: str = "small", *,
    n_frames: int | None = None, params: StereoParams | None = None, render: RenderParams | None = None, rng=0,
    n_jobs: int = 1, progress: bool | None = None, **overrides,
) -> DriftStudy:
    """The same run at several calibration-drift levels (our experiment for 000 §3.2), on :func:`slamlab.sweep.sweep`.

    The right camera's orientation takes a random-walk step of ``drift_std_rad`` per axis and
    frame while the pipeline keeps the nominal calibration; ``params`` + ``overrides`` set the
    pipeline (``detector``, ``policy``, ...), ``render`` the rest of the renderer (the study sets its
    ``drift_std_rad`` itself: a ``render`` that sets it is a ``ValueError``). Every level uses
    the same seed ``rng`` (common random numbers: the level is the only change), so each task is
    deterministic and the sweep gives it no stream of its own (``rng_arg=None``); the study is
    the same for any ``n_jobs``. ``progress``: a bar over the levels (default: on unless
    ``$SLAMLAB_PROGRESS=0``).

    Parameters
    ----------
    drift_std_rad : sequence of float
        Drift levels [rad per axis and frame], ≥ 0.
    experiment : {"turn in place", "closed loop"}
        The run.
    size : {"small", "full"}
        Frame step.
    n_frames : int, optional
        Keep only the first frames.
    params : StereoParams, optional
        Pipeline settings (default :class:`StereoParams`).
    render : RenderParams, optional
        Renderer settings (``arena_seed``, ``camera_height_m``, ``noise_std``; not ``drift_std_rad``).
    rng : int, numpy.random.Generator or SeedSequence, default 0
        Seed shared by every level.
    n_jobs : int, default 1
        Worker processes.
    progress : bool or None
        A bar over the levels.
    **overrides
        :class:`StereoParams` fields to change.

    Returns
    -------
    DriftStudy
    """
    from ...sweep import fresh_seed_sequence, sweep

    check_choice(experiment, "experiment", EXPERIMENTS)
    check_choice(size, "size", SIZES)
    levels = tuple(float(d) for d in np.atleast_1d(as_finite_array(drift_std_rad, "drift_std_rad", ndim=1)))
    if min(levels) < 0:
        raise ValueError(f"`drift_std_rad` must be >= 0; got {levels}")
    root = fresh_seed_sequence(rng)  # every level's run from the same (fresh) SeedSequence
    p = StereoParams.resolve(params, **overrides)
    render = RenderParams.resolve(render)
    if render.drift_std_rad != RenderParams().drift_std_rad:
        raise ValueError(f"`render` sets 'drift_std_rad' = {render.drift_std_rad}, which run_drift_study varies itself "
                         "(its first argument); leave it at the default in `render`")
    table = sweep(drift_level, {"drift_std_rad": levels}, rng_arg=None, n_jobs=n_jobs, progress=progress,
                  on_error="raise", desc=f"calibration drift study ({experiment})",
                  fixed={"experiment": experiment, "size": size, "n_frames": n_frames, "params": p, "render": render,
                         "rng": root})
    return DriftStudy(experiment, levels, tuple(table["run"]))


def record_stereo_stream(n_frames: int | None = None, *, detector: str = "sift", rng: int = 0,
                         progress: bool | None = None) -> Workload:
    """Record the landmark-store calls of the stereo pipeline on 000's closed loop (our addition).

    Runs the closed loop (small size: 57 frames; ``n_frames`` keeps the first frames only) with an
    :class:`~slamlab.kdtree.ExactStore` wrapped in a :class:`~slamlab.studies.kdtree.workloads.RecordingStore`,
    and returns the recorded :class:`~slamlab.studies.kdtree.workloads.Workload` for
    :func:`slamlab.studies.kdtree.experiments.run_store_comparison`. ``detector="sift"`` gives 128-d float
    descriptors (OpenCV); ``"surf"`` the 64-d SURF of the features chapter. The map search is 000's
    global one for every detector (ORB's window search would leave the store almost no queries). The two
    images of a pair are detected one after the other (``parallel_detect=False``: the same features; memory,
    issue 45). ``progress``: a bar over the frames (None: on unless ``$SLAMLAB_PROGRESS=0``).

    Parameters
    ----------
    n_frames : int, optional
        Keep only the first frames.
    detector : str, default "sift"
        Detector of the run ("sift", "surf").
    rng : int, default 0
        RANSAC seed.
    progress : bool or None
        A bar over the frames.

    Returns
    -------
    Workload
    """
    # the two images detected one after the other (the same features): the recording is not timed, and SIFT's
    # scale space of one image takes about 100 MiB, held twice when both images are detected at once (ours)
    p = StereoParams(detector=detector, map_search="global", parallel_detect=False)
    rec = RecordingStore(ExactStore(p.base_seen_times, p.max_non_base_time))
    run_experiment("closed loop", "small", n_frames=n_frames, params=p, store=rec, progress=progress, rng=rng)
    n = len(rec.iterations)
    return rec.workload(f"stereo loop ({detector.upper()}, {n} frames)",
                        base_seen_times=p.base_seen_times, max_non_base_time=p.max_non_base_time)


def disparity_errors(pose=(3.0, 4.0, 1.2), *, arena: StereoArena | None = None, params: StereoParams | None = None,
                     rng=0, **overrides) -> str:
    """Stereo disparity errors against the renderer's depth, per ORB pyramid level, before and after
    :func:`~slamlab.stereo.subpixel_disparity` (our addition to 000 §3.3).

    One rendered pair at ``pose`` in ``arena`` (default the 6×8 m arena): keypoints (``params``, default
    :data:`DISPARITY_PARAMS`, i.e. ORB, + ``overrides``), stereo matches, and for each match the disparity minus the true one
    ``f b / z`` (``z``: the renderer's depth at the left keypoint's pixel). Returns a table of the
    median absolute error and the share above 1 px per level.

    Parameters
    ----------
    pose : array_like, shape (3,)
        Body pose ``(x_m, y_m, yaw_rad)``.
    arena : StereoArena, optional
        Scene (default the 6×8 m arena, seed 0).
    params : StereoParams, optional
        Pipeline settings (default :data:`DISPARITY_PARAMS`: ORB).
    rng : int or numpy.random.Generator, default 0
        Seed of the simulator.
    **overrides
        :class:`StereoParams` fields to change.

    Returns
    -------
    str
    """
    p = StereoParams.resolve(DISPARITY_PARAMS if params is None else params, **overrides)
    arena = StereoArena(texture_seed=0) if arena is None else arena
    sim = StereoSim(arena, rng=rng)
    pose = as_vector(pose, "pose", 3)
    left, right = sim.render_pair(pose)
    _, depth, _ = arena.cast(sim.rig.left, se3_from_planar(*pose) @ sim.T_body_left)
    return disparity_error_table(left, right, depth, sim.rig, params=p)
