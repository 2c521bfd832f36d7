"""Ch. 9 experiments (003 §4, §5): monocular runs on rendered arena sequences and KITTI frames.

Rendered sequences use the stereo chapter's arena (:class:`slamlab.sim.StereoArena`) and
its left camera only. ``run_mono_sequence`` returns a frozen :class:`MonoRunResult`
(``str`` a one-line summary, ``.table()`` fixed precision; timings in their own field).
"""

from __future__ import annotations

import numpy as np

from ..._params import refuse_set_fields
from ..._progress import progress_bar
from ..._table import format_table
from ..._validate import as_finite_array, check_choice, check_int, check_positive
from ...geometry.camera import StereoRig
from ...geometry.se3 import se3_compose, se3_from_planar
from ...mono.params import MonoParams
from ...mono.slam import STAGES
from ...sim.arena import StereoArena, StereoSim
from .convergence import ConvergenceStudy, run_depth_filter_convergence
from .runs import MonoRunResult, run_mono, trajectory_errors

__all__ = [
    "CASE_ORDER",
    "FAILURE_CASES",
    "FAILURE_CONSTRUCTIONS",
    "FAILURE_SETTINGS",
    "SEQUENCES",
    "SWEPT_FIELDS",
    "ConvergenceStudy",
    "MonoRunResult",
    "case_seed",
    "failure_case_frames",
    "failure_table",
    "mono_sim",
    "render_sequence",
    "run_depth_filter_convergence",
    "run_failure_cases",
    "run_mono",
    "run_mono_sequence",
    "run_parameter_sweep",
    "sequence_poses",
    "trajectory_errors",
]

#: image sizes per run size (width, height); "full" is the 768×576 of 000's robot's stereo cameras (000 §3: 40° view),
#: which Ch. 5 renders (003 used a camera it calls "Kinetic" and the ICL-NUIM scenes; it states no image size)
SIZES = {"tiny": (192, 144), "small": (320, 240), "full": (768, 576)}

SEQUENCES = ("strafe", "arc")
#: 003 §5.3's failure cases, rendered (our constructions)
FAILURE_CASES = ("little_texture", "fast_motion", "pure_rotation", "distant_points", "kidnap", "bad_initial_map")
#: how each case is made (ours), printed with the table
FAILURE_CONSTRUCTIONS = {
    "normal": "strafe, 2 cm per frame",
    "little_texture": "blur 2.5 px, contrast 12 %",
    "fast_motion": "strafe, 15 cm per frame",
    "pure_rotation": "2 deg per frame in place",
    "distant_points": "strafe in a 60 x 60 m arena",
    "kidnap": "2 m, 0.6 rad jump at mid-run",
    "bad_initial_map": "initialised after 2 px",
}
#: the settings a failure case makes itself (ours): :class:`MonoParams` overrides of its run
FAILURE_SETTINGS = {"bad_initial_map": {"init_disparity_px": 2.0, "init_min_parallax_deg": 0.0}}
#: every case in the order of its random stream: stream i of ``SeedSequence(rng)`` renders case i, whichever
#: cases a study runs, so that one case gives the same frames in every table and widget of the chapter
CASE_ORDER = ("normal", *FAILURE_CASES)


def case_seed(rng, case: str) -> np.random.SeedSequence:
    """The random stream that renders ``case`` (ours): child ``CASE_ORDER.index(case)`` of ``rng``'s SeedSequence.

    The failure table, the ablation, the parameter sweep and the widgets all render a case from it, so the
    same ``rng`` gives the same frames of a case wherever it is run.

    Parameters
    ----------
    rng : int, SeedSequence, Generator or None
        The study's seed.
    case : str
        ``"normal"`` or one of :data:`FAILURE_CASES`.

    Returns
    -------
    numpy.random.SeedSequence

    Examples
    --------
    >>> case_seed(0, "fast_motion").spawn_key
    (2,)
    """
    from ...sweep import fresh_seed_sequence

    check_choice(case, "case", CASE_ORDER)
    return fresh_seed_sequence(rng).spawn(len(CASE_ORDER))[CASE_ORDER.index(case)]


def sequence_poses(name: str, n_frames: int = 60, *, step_m: float = 0.02) -> np.ndarray:
    """Body poses ``(N, 3)`` ``(x_m, y_m, yaw_rad)`` of a rendered sequence (ours).

    ``"strafe"``: sideways along the fence at y = 0, 2.5 m from it, looking at it, with a slow
    yaw sway (the easy case for a monocular camera: parallax from translation across the view).
    ``"arc"``: forward on a circle of 2.5 m radius about the arena centre (parallax mostly
    along the optical axis). ``"turn"``: rotation in place (003 §5.3's pure rotation).

    Parameters
    ----------
    name : str
        ``"strafe"``, ``"arc"`` or ``"turn"``.
    n_frames : int
        Number of poses, at least 2 (default 60).
    step_m : float
        Distance between frames [m] (default 0.02; ``"turn"`` ignores it).

    Returns
    -------
    poses : ndarray, shape (n_frames, 3)
        ``(x_m, y_m, yaw_rad)`` per frame.
    """
    check_choice(name, "name", (*SEQUENCES, "turn"))
    n = check_int(n_frames, "n_frames", minimum=2)
    step_m = check_positive(step_m, "step_m")
    k = np.arange(n)
    if name == "strafe":
        x = 1.5 + step_m * k
        return np.column_stack([x, np.full(n, 2.5), -np.pi / 2 + 0.05 * np.sin(2 * np.pi * k / 80)])
    if name == "arc":
        ang = -np.pi / 2 + step_m * k / 2.5
        return np.column_stack([3.0 + 2.5 * np.cos(ang), 4.0 + 2.5 * np.sin(ang), ang + np.pi / 2])
    yaw = -np.pi / 2 + np.deg2rad(2.0) * k * step_m / 0.02
    return np.column_stack([np.full(n, 3.0), np.full(n, 3.0), yaw])


def mono_sim(size: str = "small", *, arena: StereoArena | None = None, noise_std: float = 1.0,
             camera_height_m: float = 0.6, rng=0) -> StereoSim:
    """The stereo chapter's arena simulator (000's robot's 40° stereo rig, left camera used) at the size of ``size``.

    Default arena: seed 0 with the floor texture at full contrast (ours: a monocular camera
    needs points off the fence's plane; with the fence alone, a thin band of coplanar points,
    vertical translation and pitch are nearly indistinguishable).

    Parameters
    ----------
    size : str
        Image size: ``"tiny"`` (192×144), ``"small"`` (320×240, default) or ``"full"`` (768×576).
    arena : StereoArena, optional
        The scene; ``None`` = seed 0 with a full-contrast floor.
    noise_std : float
        Image noise [grey levels] (default 1).
    camera_height_m : float
        Height of the camera above the floor [m] (default 0.6).
    rng : Generator, int or None
        Randomness of the image noise (default 0).

    Returns
    -------
    StereoSim
        The simulator (its ``rig.left`` is the monocular camera).
    """
    w, h = SIZES[check_choice(size, "size", tuple(SIZES))]
    return StereoSim(StereoArena(texture_seed=0, floor_contrast=1.0) if arena is None else arena,
                     StereoRig.parallel(0.2, w, h), noise_std=noise_std, camera_height_m=camera_height_m, rng=rng)


#: the monocular camera looks down by this much (ours: more floor in view, as a hand-held camera would)
PITCH_DOWN_RAD = np.deg2rad(20.0)


def render_sequence(sim: StereoSim, poses, *, blur_px: float = 0.0, contrast: float = 1.0,
                    pitch_down_rad: float = PITCH_DOWN_RAD, progress=None):
    """Left-camera images ``(N, H, W)`` uint8 and true camera poses ``(N, 4, 4)`` (world ← camera).

    ``contrast`` < 1 and ``blur_px`` > 0 turn a scene into a low-texture one (ours, for 003 §5.3).

    Parameters
    ----------
    sim : StereoSim
        The simulator (:func:`mono_sim`).
    poses : array_like, shape (N, 3)
        Body poses ``(x_m, y_m, yaw_rad)`` (:func:`sequence_poses`).
    blur_px : float
        Gaussian blur σ [px] (default 0: none).
    contrast : float
        Contrast factor about mid-grey (default 1).
    pitch_down_rad : float
        Downward tilt of the camera [rad] (default 20°).
    progress : bool, callable or None
        Progress display (``slamlab._progress``).

    Returns
    -------
    images : ndarray of uint8, shape (N, H, W)
        Left-camera images.
    T_wc : ndarray, shape (N, 4, 4)
        True camera poses (camera to world).
    """
    import cv2

    poses = as_finite_array(poses, "poses", ndim=2)
    cam = sim.rig.left
    c, s_ = np.cos(pitch_down_rad), np.sin(pitch_down_rad)
    tilt = np.eye(4)
    tilt[1:3, 1:3] = [[c, s_], [-s_, c]]  # about the camera x axis: the optical axis dips (y is down)
    imgs, Ts = [], []
    for pose in progress_bar(poses, desc="render", progress=progress):
        T = se3_compose(se3_compose(se3_from_planar(*pose), sim.T_body_left), tilt)
        img = sim.arena.render(cam, T) * 255.0
        if blur_px > 0:
            img = cv2.GaussianBlur(img.astype(np.float32), (0, 0), blur_px)
        if contrast != 1.0:
            img = 128.0 + contrast * (img - 128.0)
        if sim.noise_std > 0:
            img = img + sim.rng.normal(0.0, sim.noise_std, img.shape)
        imgs.append(np.clip(np.rint(img), 0, 255).astype(np.uint8))
        Ts.append(T)
    return np.array(imgs), np.array(Ts)


def run_mono_sequence(sequence: str = "strafe", *, n_frames: int = 60, size: str = "small", step_m: float = 0.02,
                      noise_std: float = 1.0, params: MonoParams | None = None, progress=None, rng=0,
                      **overrides) -> MonoRunResult:
    """Render a sequence of the arena with the left camera and run the monocular pipeline on it.

    Parameters
    ----------
    sequence : str
        ``"strafe"``, ``"arc"`` or ``"turn"`` (:func:`sequence_poses`; default ``"strafe"``).
    n_frames : int
        Number of frames (default 60).
    size : str
        Image size (:func:`mono_sim`; default ``"small"``).
    step_m : float
        Distance between frames [m] (default 0.02).
    noise_std : float
        Image noise [grey levels] (default 1).
    params : MonoParams, optional
        Settings (default values).
    progress : bool, callable or None
        Progress display.
    rng : Generator, int or None
        Randomness of the image noise (default 0).
    **overrides
        Fields of :class:`MonoParams` to change.

    Returns
    -------
    MonoRunResult
    """
    sim = mono_sim(size, noise_std=noise_std, rng=rng)
    poses = sequence_poses(sequence, n_frames, step_m=step_m)
    imgs, Ts = render_sequence(sim, poses, progress=progress)
    return run_mono(imgs, Ts, sim.rig.left.K, name=sequence, params=params, progress=progress, **overrides)


STAGE_NAMES = STAGES


# -- failure cases (003 §5.3) as rendered sequences ---------------------------------------------
def failure_case_frames(case: str, size: str = "tiny", n_frames: int = 30, *, rng=0):
    """The rendered frames of one of 003 §5.3's failure cases (our constructions, :data:`FAILURE_CONSTRUCTIONS`).

    Parameters
    ----------
    case : str
        ``"normal"`` or one of :data:`FAILURE_CASES`.
    size : str
        Image size (:func:`mono_sim`; default ``"tiny"``).
    n_frames : int
        Frames (default 30).
    rng : Generator, int or None
        Randomness of the image noise (default 0).

    Returns
    -------
    images : ndarray, shape (n_frames, H, W)
        Grey frames.
    truth_T_wc : ndarray, shape (n_frames, 4, 4)
        True camera poses.
    K : ndarray, shape (3, 3)
        Intrinsic matrix.
    overrides : dict
        The :class:`MonoParams` fields the case sets itself (:data:`FAILURE_SETTINGS`).
    """
    render = {}
    arena = None
    if case == "normal":
        poses = sequence_poses("strafe", n_frames)
    elif case == "little_texture":
        poses = sequence_poses("strafe", n_frames)
        render = {"blur_px": 2.5, "contrast": 0.12}
    elif case == "fast_motion":
        poses = sequence_poses("strafe", n_frames, step_m=0.15)
        poses[:, 0] = 0.6 + (poses[:, 0] - 1.5) % 4.8  # stay inside the arena
    elif case == "pure_rotation":
        poses = sequence_poses("turn", n_frames)
    elif case == "distant_points":
        arena = StereoArena(60.0, 60.0, floor_contrast=1.0, floor_texel_m=0.05, texture_seed=0)
        poses = sequence_poses("strafe", n_frames)
        poses[:, 0] += 28.5
        poses[:, 1] = 30.0
        render = {"pitch_down_rad": -np.deg2rad(8.0)}
    elif case == "kidnap":
        poses = sequence_poses("strafe", n_frames)
        half = n_frames // 2
        poses[half:, 0] += 2.0  # carried 2 m sideways between two frames
        poses[half:, 2] += 0.6
    elif case == "bad_initial_map":
        poses = sequence_poses("strafe", n_frames)
    else:
        raise ValueError(f"`case` must be one of {('normal', *FAILURE_CASES)}; got {case!r}")
    sim = mono_sim(size, arena=arena, rng=rng)
    imgs, Ts = render_sequence(sim, poses, progress=False, **render)
    return imgs, Ts, sim.rig.left.K, dict(FAILURE_SETTINGS.get(case, {}))


def run_failure_cases(cases=("normal", *FAILURE_CASES), *, size: str = "tiny", n_frames: int = 30,
                      params: MonoParams | None = None, progress=None, rng=0, **overrides) -> dict:
    """003 §5.3's failure cases rendered in the arena (our constructions), each run with MonoSLAM.

    ``normal`` strafe; ``little_texture`` blurred, low-contrast images; ``fast_motion`` 15 cm per
    frame; ``pure_rotation`` 2° per frame in place; ``distant_points`` a 60×60 m arena seen from
    its middle; ``kidnap`` carried 2 m between two frames; ``bad_initial_map`` initialised after
    2 px of displacement (it sets ``init_disparity_px`` and ``init_min_parallax_deg`` itself,
    :data:`FAILURE_SETTINGS`: ``params`` may not set them when it runs). Returns ``{case: MonoRunResult}``.

    Parameters
    ----------
    cases : sequence of str
        Cases to run (default ``"normal"`` and every one of ``FAILURE_CASES``).
    size : str
        Image size (:func:`mono_sim`; default ``"tiny"``).
    n_frames : int
        Frames per case (default 30).
    params : MonoParams, optional
        Settings (default values).
    progress : bool, callable or None
        Progress display.
    rng : Generator, int or None
        Randomness; each case renders from its own stream, :func:`case_seed` (default 0).
    **overrides
        Fields of :class:`MonoParams` to change.

    Returns
    -------
    dict
        Case → :class:`MonoRunResult`.
    """
    p = MonoParams.resolve(params, **overrides)
    for case in cases:
        check_choice(case, "case", CASE_ORDER)
        refuse_set_fields(p, list(FAILURE_SETTINGS.get(case, {})), f"the failure case {case!r} sets it")
    out = {}
    for case in progress_bar(cases, desc="failure cases", progress=progress):
        imgs, Ts, K, ov = failure_case_frames(case, size, n_frames, rng=np.random.default_rng(case_seed(rng, case)))
        out[case] = run_mono(imgs, Ts, K, name=case, params=p, progress=False, **ov)
    return out


def failure_table(results: dict) -> str:
    """003 §5.5.1's table layout: the correctly tracked share with its mark (X < 30 %, * 30-70 %) and the ATE.

    Columns: the case, its construction, the claimed and the correct share, the mark, the ATE after Sim(3) over
    all frames, the frames the tracker reported lost and the kinds of initialisation failure met.

    Parameters
    ----------
    results : dict
        Case → :class:`MonoRunResult` (:func:`run_failure_cases`).

    Returns
    -------
    str
        The printed table.
    """
    rows = []
    for name, r in results.items():
        ate_txt = f"{r.ate_m:.3f}" if np.isfinite(r.ate_m) else "-"
        rows.append([name, FAILURE_CONSTRUCTIONS.get(name, "-"), f"{100 * r.fraction_claimed:.0f}", f"{100 * r.fraction_tracked:.0f}", r.verdict, ate_txt,
                     f"{r.counts.get('lost', 0)}",
                     f"{sum(k.startswith('init_') and k not in ('init_done', 'init_tracking', 'init_first_frame') for k in r.counts)}"])
    tol = next(iter(results.values())).score.tol_frac if results else 0.05
    return format_table(["case", "construction (ours)", "claimed, %", "correct, %", "mark", "ATE, m", "lost frames",
                         "init fails"], rows,
                        title=(f"003 §5.3's failure cases, rendered (correct: error <= {100 * tol:.0f} % of the path; "
                               "ATE: Sim(3), all frames)"))


# -- the parameters 003 tuned (003 §5.1.1) on slamlab.sweep ---------------------------------------
#: the fields :func:`run_parameter_sweep` sets itself: 003 §5.1.1's four (its grid) and ``kf_min_frames`` (10)
SWEPT_FIELDS = ("init_disparity_px", "max_keyframes", "kf_max_lost_ratio", "max_matches", "kf_min_frames")


def _sweep_run(init_disparity_px, max_keyframes, kf_max_lost_ratio, max_matches, frames_seed, size="tiny",
               n_frames=30, params=None):
    imgs, Ts, K, _ = failure_case_frames("normal", size, n_frames, rng=np.random.default_rng(frames_seed))
    r = run_mono(imgs, Ts, K, name="sweep", params=params, progress=False, init_disparity_px=init_disparity_px,
                 max_keyframes=max_keyframes, kf_max_lost_ratio=kf_max_lost_ratio, max_matches=max_matches,
                 kf_min_frames=10)
    first_map = r.status.index("initialised") if "initialised" in r.status else -1
    return {"claimed_pct": round(100 * r.fraction_claimed), "correct_pct": round(100 * r.fraction_tracked),
            "first_map": first_map, "ate_mm": round(1000 * r.ate_m), "keyframes": r.n_keyframes,
            "tracking_ms": round(1000 * sum(r.stage_time_s[k] for k in ("align", "match", "refine")), 1)}


def run_parameter_sweep(grid=None, *, n_jobs: int = 1, size: str = "tiny", n_frames: int = 30,
                        params: MonoParams | None = None, rng=0, progress=None, **overrides):
    """003 §5.1.1's four tuning parameters on the rendered strafe, via :func:`slamlab.sweep.sweep`.

    Every row tracks the same frames (the ``"normal"`` case rendered from :func:`case_seed`), so the rows differ
    by their settings only. Columns: ``claimed_pct`` the frames the tracker claims, ``correct_pct`` the correctly
    tracked ones (claimed and within 5 % of the path after Sim(3)), ``first_map`` the frame at which the
    first map was made (-1: never), ``ate_mm`` the ATE over all frames, ``keyframes`` and ``tracking_ms``.

    Parameters
    ----------
    grid : mapping or sequence of points, optional
        Points of ``init_disparity_px``, ``max_keyframes``, ``kf_max_lost_ratio``, ``max_matches``
        (default: one parameter at a time around the defaults).
    n_jobs : int
        Parallel workers of :func:`slamlab.sweep.sweep`.
    size : str
        Render size of the strafe.
    n_frames : int
        Frames per run.
    params : MonoParams, optional
        The settings the grid changes (default: the defaults). The sweep sets :data:`SWEPT_FIELDS` itself
        (``kf_min_frames`` is 10 in these runs): ``params`` and ``overrides`` may not set them.
    rng : int, SeedSequence or Generator
        The seed of the rendered frames (one rendering for every row).
    progress : bool, callable or None
        See :mod:`slamlab._progress`.
    **overrides
        :class:`MonoParams` fields under the grid's.

    Returns
    -------
    pandas.DataFrame
        The sweep's table (``tracking_ms`` is a timing: print it only where timings are allowed).
    """
    from ...sweep import root_seed_sequence, sweep

    p = MonoParams.resolve(params, **overrides)
    refuse_set_fields(p, SWEPT_FIELDS, "the sweep's grid sets it")
    if params is None and not overrides:
        p = None
    base = {"init_disparity_px": 15.0, "max_keyframes": 10, "kf_max_lost_ratio": 0.3, "max_matches": 120}
    if grid is None:
        grid = [base, {**base, "init_disparity_px": 5.0}, {**base, "init_disparity_px": 30.0},
                {**base, "max_keyframes": 3}, {**base, "kf_max_lost_ratio": 0.1}, {**base, "max_matches": 30}]
    frames_seed = case_seed(root_seed_sequence(rng, "rng"), "normal")
    return sweep(_sweep_run, grid, rng_arg=None, n_jobs=n_jobs, progress=progress,
                 fixed={"size": size, "n_frames": n_frames, "params": p, "frames_seed": frames_seed})
