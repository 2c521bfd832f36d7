"""Ch. 9 experiments (003 §4, §5): monocular runs on rendered arena sequences and KITTI frames.

Rendered sequences use the stereo chapter's arena (:class:`slamlab.sim.StereoArena`) and
its left camera only. ``run_mono_sequence`` returns a frozen :class:`MonoRunResult`
(``str`` a one-line summary, ``.table()`` fixed precision; timings in their own field).
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np

from .. import _validate as v
from .._progress import progress_bar
from .._table import format_table
from ..geometry.camera import StereoRig
from ..geometry.se3 import se3_compose, se3_from_planar, se3_inverse
from ..sim.arena import StereoArena, StereoSim
from .params import MonoParams
from .slam import STAGES, MonoSLAM

__all__ = [
    "FAILURE_CASES",
    "SEQUENCES",
    "ConvergenceStudy",
    "MonoRunResult",
    "MonoVsStereo",
    "compare_init_methods",
    "epipolar_demo",
    "failure_table",
    "mono_sim",
    "ours_vs_source",
    "render_sequence",
    "run_depth_filter_convergence",
    "run_failure_cases",
    "run_kitti_mono",
    "run_mono",
    "run_mono_sequence",
    "run_mono_vs_stereo",
    "run_parameter_sweep",
    "sequence_poses",
    "trajectory_errors",
]

#: image sizes per run size (width, height) - the benchmark uses 003's 768×576 rig
SIZES = {"tiny": (192, 144), "small": (320, 240), "full": (768, 576)}

SEQUENCES = ("strafe", "arc")
#: 003 §5.3's failure cases, rendered (our constructions)
FAILURE_CASES = ("little_texture", "fast_motion", "pure_rotation", "distant_points", "kidnap", "bad_initial_map")


def sequence_poses(name: str, n_frames: int = 60, *, step_m: float = 0.02) -> np.ndarray:
    """Body poses ``(N, 3)`` ``(x_m, y_m, yaw_rad)`` of a rendered sequence (ours).

    ``"strafe"``: sideways along the fence at y = 0, 2.5 m from it, looking at it, with a slow
    yaw sway (the easy case for a monocular camera: parallax from translation across the view).
    ``"arc"``: forward on a circle of 2.5 m radius about the arena centre (parallax mostly
    along the optical axis). ``"turn"``: rotation in place (003 §5.3's pure rotation).
    """
    v.check_choice(name, "name", (*SEQUENCES, "turn"))
    n = v.check_int(n_frames, "n_frames", minimum=2)
    step_m = v.check_positive(step_m, "step_m")
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
    """The stereo chapter's arena simulator with 003's 40° rig at the image size of ``size``.

    Default arena: seed 0 with the floor texture at full contrast (ours: a monocular camera
    needs points off the fence's plane; with the fence alone, a thin band of coplanar points,
    vertical translation and pitch are nearly indistinguishable).
    """
    w, h = SIZES[v.check_choice(size, "size", tuple(SIZES))]
    return StereoSim(StereoArena(seed=0, floor_contrast=1.0) if arena is None else arena,
                     StereoRig.parallel(0.2, w, h), noise_std=noise_std, camera_height_m=camera_height_m, rng=rng)


#: the monocular camera looks down by this much (ours: more floor in view, as a hand-held camera would)
PITCH_DOWN_RAD = np.deg2rad(20.0)


def render_sequence(sim: StereoSim, poses, *, blur_px: float = 0.0, contrast: float = 1.0,
                    pitch_down_rad: float = PITCH_DOWN_RAD, progress=None):
    """Left-camera images ``(N, H, W)`` uint8 and true camera poses ``(N, 4, 4)`` (world ← camera).

    ``contrast`` < 1 and ``blur_px`` > 0 turn a scene into a low-texture one (ours, for 003 §5.3).
    """
    import cv2

    poses = v.as_finite_array(poses, "poses", ndim=2)
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


def trajectory_errors(truth, estimate, tracked):
    """ATE (Sim(3), m) and RPE (1-frame translation, m) over the tracked frames, via :mod:`slamlab.evaluation`.

    ``truth``/``estimate`` (N, 4, 4). Returns ``(ate_m, rpe_m)``; NaN-free: ``inf`` when fewer
    than 3 frames were tracked.
    """
    from ..evaluation import Trajectory, ate, rpe

    idx = np.flatnonzero(np.asarray(tracked, bool))
    if idx.size < 3:
        return float("inf"), float("inf")
    ts = idx * 0.1
    ref = Trajectory(truth[idx, :3, 3], truth[idx, :3, :3], ts)
    est = Trajectory(estimate[idx, :3, 3], estimate[idx, :3, :3], ts)
    a = float(ate(ref, est, align="sim3").rmse)
    # RPE after the Sim(3) scale: the monocular map has no metric scale
    from ..evaluation.metrics import align_trajectory

    est_al, _ = align_trajectory(est, ref, "sim3")
    r = float(rpe(ref, est_al, delta=1).rmse)
    return a, r


@dataclass(frozen=True)
class MonoRunResult:
    """A monocular run against ground truth (003 §5.2: ATE after alignment; ours: Sim(3), RPE)."""

    name: str
    truth: np.ndarray = field(repr=False)  # (N, 4, 4) camera poses in the first frame's camera frame
    estimate: np.ndarray = field(repr=False)  # (N, 4, 4)
    tracked: np.ndarray = field(repr=False)  # (N,)
    status: tuple = field(repr=False)
    ate_m: float
    rpe_m: float
    n_keyframes: int
    n_points: int
    counts: dict = field(repr=False, compare=False)
    stage_time_s: dict = field(repr=False, compare=False)
    fps: float = field(compare=False)
    points: np.ndarray = field(repr=False, compare=False, default=None)
    seed_snapshots: dict = field(repr=False, compare=False, default=None)  # frame -> σ_ρ/ρ_range of the seeds

    @property
    def fraction_tracked(self) -> float:
        return float(np.mean(self.tracked)) if len(self.tracked) else 0.0

    @property
    def verdict(self) -> str:
        """003 §5.5.1's marks: 'X' tracked < 30 % of the time, '*' 30-70 %, 'ok' > 70 %."""
        f = self.fraction_tracked
        return "X" if f < 0.3 else ("*" if f <= 0.7 else "ok")

    def __str__(self) -> str:
        return (f"{self.name}: {len(self.tracked)} frames, tracked {100 * self.fraction_tracked:.0f} %, "
                f"ATE (Sim(3)) {self.ate_m:.3f} m, {self.n_keyframes} keyframes, {self.n_points} points")

    def table(self) -> str:
        rows = [["frames", f"{len(self.tracked)}"],
                ["tracked, %", f"{100 * self.fraction_tracked:.0f}"],
                ["ATE RMSE after Sim(3), m", f"{self.ate_m:.3f}"],
                ["RPE RMSE (1 frame, Sim(3) scale), m", f"{self.rpe_m:.3f}"],
                ["keyframes / map points", f"{self.n_keyframes} / {self.n_points}"]]
        return format_table(["quantity", "value"], rows, title=self.name)


def _check_frames(images) -> list:
    """``images`` as a list of grey frames of one size, or a ValueError/TypeError naming ``images``."""
    if isinstance(images, np.ndarray) and images.ndim == 3:
        images = list(images)
    try:
        images = list(images)
    except TypeError:
        raise TypeError(f"`images` must be a sequence of grey images; got {type(images).__name__}") from None
    if not images:
        raise ValueError("`images` must hold at least one frame; got none")
    out = [v.as_image(img, f"images[{i}]") for i, img in enumerate(images)]
    shape0 = out[0].shape
    for i, img in enumerate(out):
        if img.shape != shape0:
            raise ValueError(f"`images` must all have one size; images[0] is {shape0} (H, W) but images[{i}] is "
                             f"{img.shape}")
    return out


def _check_truth(truth_T_wc, n: int) -> np.ndarray:
    """``truth_T_wc`` as an (n, 4, 4) array, or a ValueError naming ``truth_T_wc``."""
    T = v.as_finite_array(truth_T_wc, "truth_T_wc", ndim=3)
    if T.shape[1:] != (4, 4):
        raise ValueError(f"`truth_T_wc` must have shape (N, 4, 4); got {T.shape}")
    if T.shape[0] != n:
        raise ValueError(f"`truth_T_wc` must hold one pose per frame: {n} frames in `images`, {T.shape[0]} poses "
                         "in `truth_T_wc`")
    return T


def run_mono(images, truth_T_wc, K, *, name: str = "run", params: MonoParams | None = None, progress=None,
             snapshot_frames=(), **overrides) -> MonoRunResult:
    """Run :class:`MonoSLAM` on images with ground truth ``(N, 4, 4)`` and score it (003 §5.2).

    ``snapshot_frames``: frames after which the seeds' ``σ_ρ / ρ_range`` are kept (for histograms).
    Raises ``ValueError`` naming the argument when the frames differ in size or ``truth_T_wc``
    does not hold one pose per frame.
    """
    images = _check_frames(images)
    truth_T_wc = _check_truth(truth_T_wc, len(images))
    p = MonoParams.resolve(params, **overrides)
    slam = MonoSLAM(K, params=p)
    snaps = {}
    dt = 0.0
    for i, img in enumerate(progress_bar(images, desc=name, progress=progress)):
        t = time.perf_counter()
        slam.process(img)
        dt += time.perf_counter() - t
        if i in snapshot_frames:
            snaps[i] = np.sqrt(slam.seeds.sigma2) / slam.seeds.rho_range
    T0 = se3_inverse(truth_T_wc[0])
    truth = np.einsum("ij,njk->nik", T0, truth_T_wc)
    est = slam.trajectory
    tr = slam.tracked
    ate_m, rpe_m = trajectory_errors(truth, est, tr)
    return MonoRunResult(name, truth, est, tr, tuple(r["status"] for r in slam.records), ate_m, rpe_m,
                         len(slam.keyframes), len(slam.points), dict(slam.counts), slam.stage_times(),
                         len(images) / dt if dt > 0 else float("inf"), slam.points.copy(), snaps)


def run_mono_sequence(sequence: str = "strafe", *, n_frames: int = 60, size: str = "small", step_m: float = 0.02,
                      noise_std: float = 1.0, params: MonoParams | None = None, progress=None, rng=0,
                      **overrides) -> MonoRunResult:
    """Render a sequence of the arena with the left camera and run the monocular pipeline on it."""
    sim = mono_sim(size, noise_std=noise_std, rng=rng)
    poses = sequence_poses(sequence, n_frames, step_m=step_m)
    imgs, Ts = render_sequence(sim, poses, progress=progress)
    return run_mono(imgs, Ts, sim.rig.left.K, name=sequence, params=params, progress=progress, **overrides)


STAGE_NAMES = STAGES


# -- depth-filter convergence (003 §4.1.1, §4.3.2) ---------------------------------------------
@dataclass(frozen=True)
class ConvergenceStudy:
    """Seeds of a synthetic scene updated ``n_obs`` times at several outlier rates (our experiment).

    ``sigma`` (R, n_obs + 1) median σ_ρ (1/m), ``inlier`` (R, n_obs + 1) median a/(a+b),
    ``error`` (R, n_obs + 1) median |ρ − ρ_true| (1/m), ``converged`` (R, n_obs + 1) share of seeds
    passing SVO's σ test, ``mu`` (R, n_seeds) final means, ``rho_true`` (n_seeds,).
    """

    outlier_rates: tuple
    sigma: np.ndarray = field(repr=False)
    inlier: np.ndarray = field(repr=False)
    error: np.ndarray = field(repr=False)
    converged: np.ndarray = field(repr=False)
    mu: np.ndarray = field(repr=False)
    rho_true: np.ndarray = field(repr=False)
    tau: float

    def __str__(self) -> str:
        return (f"depth filter, {self.mu.shape[1]} seeds, {self.sigma.shape[1] - 1} observations, "
                f"outlier rates {', '.join(f'{r:.0%}' for r in self.outlier_rates)}")

    def table(self, at=(0, 5, 10, 20, 40)) -> str:
        at = [k for k in at if k < self.sigma.shape[1]]
        rows = []
        for i, r in enumerate(self.outlier_rates):
            for k in at:
                rows.append([f"{100 * r:.0f}", f"{k}", f"{self.sigma[i, k]:.4f}", f"{self.error[i, k]:.4f}",
                             f"{self.inlier[i, k]:.2f}", f"{100 * self.converged[i, k]:.0f}"])
        return format_table(["outliers, %", "observations", "median sigma_rho, 1/m", "median |rho - rho_true|",
                             "median a/(a+b)", "converged (SVO), %"], rows,
                            title=f"Depth-filter convergence (tau = {self.tau} 1/m, SVO initialisation)")


def run_depth_filter_convergence(outlier_rates=(0.0, 0.2, 0.4, 0.6), *, n_obs: int = 40, n_seeds: int = 500,
                                 tau: float = 0.01, depth_min_m: float = 0.5, rng=0) -> ConvergenceStudy:
    """Gaussian × Beta seeds (SVO's start) fed inliers ``N(ρ_true, τ²)`` and outliers ``U(0, ρ_range)``."""
    from .depth_filter import converged_sigma, init_seeds, inlier_ratio, update_seeds

    rng = v.as_rng(rng)
    n_obs = v.check_int(n_obs, "n_obs", minimum=1)
    n_seeds = v.check_int(n_seeds, "n_seeds", minimum=1)
    rates = tuple(float(r) for r in outlier_rates)
    if not rates or any(not 0.0 <= r < 1.0 for r in rates):
        raise ValueError(f"`outlier_rates` must be rates in [0, 1); got {outlier_rates!r}")
    rho_true = rng.uniform(0.2, 1.0 / depth_min_m, n_seeds)
    R = len(rates)
    sig, inl, err, conv = (np.zeros((R, n_obs + 1)) for _ in range(4))
    mus = np.zeros((R, n_seeds))
    for i, r in enumerate(rates):
        s = init_seeds(np.zeros((n_seeds, 2)), np.tile([0.0, 0.0, 1.0], (n_seeds, 1)), 1.0 / np.mean(rho_true), depth_min_m)
        for k in range(n_obs + 1):
            sig[i, k] = np.median(np.sqrt(s.sigma2))
            inl[i, k] = np.median(inlier_ratio(s.a, s.b))
            err[i, k] = np.median(np.abs(s.mu - rho_true))
            conv[i, k] = np.mean(converged_sigma(s.sigma2, s.rho_range))
            if k == n_obs:
                break
            out = rng.random(n_seeds) < r
            x = np.where(out, rng.uniform(0.0, s.rho_range), rho_true + rng.normal(0.0, tau, n_seeds))
            s.mu, s.sigma2, s.a, s.b = update_seeds(s.mu, s.sigma2, s.a, s.b, x, tau**2, s.rho_range)
        mus[i] = s.mu
    return ConvergenceStudy(rates, sig, inl, err, conv, mus, rho_true, tau)


# -- homography vs essential matrix (003 §4.3.1) -------------------------------------------------
def compare_init_methods(*, n_points: int = 200, noise_px: float = 0.5, n_trials: int = 20, rng=0) -> str:
    """Median rotation error and translation-direction error of both two-view methods (003 §4.3.1).

    Synthetic views (K: f = 500 px, 640×480; a 0.4 m mostly sideways baseline with a small rotation) of a
    tilted plane 4 m ahead and of a deep scene (2.5-8 m); pixel noise ``noise_px``; ``n_trials`` draws.
    """
    from ..geometry.camera import rotation_xyz
    from .initialise import relative_pose_essential, relative_pose_homography

    rng = v.as_rng(rng)
    K = np.array([[500.0, 0, 320], [0, 500.0, 240], [0, 0, 1]])
    R = rotation_xyz(0.02, -0.05, 0.01)
    t = np.array([0.4, -0.05, 0.1])
    t_dir = t / np.linalg.norm(t)
    rows = []
    for scene in ("planar", "non-planar"):
        errs = {"homography": [], "essential": []}
        for _ in range(n_trials):
            if scene == "planar":
                xy = rng.uniform(-2, 2, (n_points, 2))
                X0 = np.column_stack([xy, 4.0 + 0.3 * xy[:, 0] - 0.2 * xy[:, 1]])
            else:
                X0 = np.column_stack([rng.uniform(-2, 2, (n_points, 2)), rng.uniform(2.5, 8.0, n_points)])
            X1 = X0 @ R.T + t
            uv0 = X0 @ K.T
            uv1 = X1 @ K.T
            uv0 = uv0[:, :2] / uv0[:, 2:] + rng.normal(0, noise_px, (n_points, 2))
            uv1 = uv1[:, :2] / uv1[:, 2:] + rng.normal(0, noise_px, (n_points, 2))
            for name, fn in (("homography", relative_pose_homography), ("essential", relative_pose_essential)):
                pose = fn(uv0, uv1, K, ransac_px=1.5)
                if not pose.ok:
                    errs[name].append((np.inf, np.inf))
                    continue
                dR = pose.R @ R.T
                e_r = np.degrees(np.arccos(np.clip((np.trace(dR) - 1) / 2, -1, 1)))
                e_t = np.degrees(np.arccos(np.clip(pose.t @ t_dir, -1, 1)))
                errs[name].append((e_r, e_t))
        for name, e in errs.items():
            e = np.array(e)
            rows.append([scene, name, f"{np.median(e[:, 0]):.2f}", f"{np.median(e[:, 1]):.1f}",
                         f"{100 * np.mean(e[:, 1] > 10):.0f}"])
    return format_table(["scene", "method", "median rotation error, deg", "median t direction error, deg",
                         "t off by > 10 deg, %"], rows,
                        title=f"Two-view initialisation, {n_trials} draws, {n_points} points, noise {noise_px} px")


# -- failure cases (003 §5.3) as rendered sequences ---------------------------------------------
def _case_frames(case: str, size: str, n_frames: int, rng):
    from ..sim.arena import StereoArena

    render = {}
    arena = None
    overrides = {}
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
        arena = StereoArena(60.0, 60.0, floor_contrast=1.0, floor_texel_m=0.05, seed=0)
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
        overrides = {"init_disparity_px": 2.0, "init_min_parallax_deg": 0.0}
    else:
        raise ValueError(f"`case` must be one of {('normal', *FAILURE_CASES)}; got {case!r}")
    sim = mono_sim(size, arena=arena, rng=rng)
    imgs, Ts = render_sequence(sim, poses, progress=False, **render)
    return imgs, Ts, sim.rig.left.K, overrides


def run_failure_cases(cases=("normal", *FAILURE_CASES), *, size: str = "tiny", n_frames: int = 30,
                      params: MonoParams | None = None, progress=None, rng=0, **overrides) -> dict:
    """003 §5.3's failure cases rendered in the arena (our constructions), each run with MonoSLAM.

    ``normal`` strafe; ``little_texture`` blurred, low-contrast images; ``fast_motion`` 15 cm per
    frame; ``pure_rotation`` 2° per frame in place; ``distant_points`` a 60×60 m arena seen from
    its middle; ``kidnap`` carried 2 m between two frames; ``bad_initial_map`` initialised after
    2 px of displacement. Returns ``{case: MonoRunResult}``.
    """
    out = {}
    seeds = np.random.SeedSequence(v.check_int(rng, "rng", minimum=0)).spawn(len(cases))
    for case, ss in zip(progress_bar(cases, desc="failure cases", progress=progress), seeds, strict=True):
        imgs, Ts, K, ov = _case_frames(case, size, n_frames, np.random.default_rng(ss))
        out[case] = run_mono(imgs, Ts, K, name=case, params=params, progress=False, **{**overrides, **ov})
    return out


def failure_table(results: dict) -> str:
    """003 §5.5.1's table layout: tracked share with its mark (X < 30 %, * 30-70 %) and ATE."""
    rows = []
    for name, r in results.items():
        ate_txt = f"{r.ate_m:.3f}" if np.isfinite(r.ate_m) else "-"
        rows.append([name, f"{100 * r.fraction_tracked:.0f}", r.verdict, ate_txt, f"{r.counts.get('lost', 0)}",
                     f"{sum(k.startswith('init_') and k not in ('init_done', 'init_tracking', 'init_first_frame') for k in r.counts)}"])
    return format_table(["case (003 §5.3)", "tracked, %", "mark", "ATE Sim(3), m", "lost frames",
                         "init failure kinds"], rows, title="Failure cases, rendered")


# -- KITTI left camera --------------------------------------------------------------------------
def run_kitti_mono(folder=None, *, n_frames: int | None = None, params: MonoParams | None = None,
                   **overrides) -> MonoRunResult:
    """MonoSLAM on the left camera of a KITTI odometry folder; ATE (Sim(3)) against ``poses.txt``."""
    from ..data import find_data
    from ..evaluation import read_kitti
    from ..io.kitti import read_kitti_calib, read_kitti_image

    d = find_data("kitti-odometry-06-stereo/calib.txt").parent if folder is None else v.as_path(folder, "folder", kind="dir")
    P0 = read_kitti_calib(d / "calib.txt")["P0"]
    K = P0[:, :3]
    gt = read_kitti(d / "poses.txt").poses
    n = len(gt) if n_frames is None else min(len(gt), v.check_int(n_frames, "n_frames", minimum=2))
    imgs = [read_kitti_image(d / "image_0" / f"{i:06d}.png") for i in range(n)]
    return run_mono(imgs, gt[:n], K, name=d.name, params=params, progress=False, **overrides)


# -- the parameters 003 tuned (003 §5.1.1) on slamlab.sweep ---------------------------------------
def _sweep_run(init_disparity_px, max_keyframes, kf_max_lost_ratio, max_matches, rng, size="tiny", n_frames=30):
    imgs, Ts, K, _ = _case_frames("normal", size, n_frames, rng)
    r = run_mono(imgs, Ts, K, name="sweep", progress=False, init_disparity_px=init_disparity_px,
                 max_keyframes=max_keyframes, kf_max_lost_ratio=kf_max_lost_ratio, max_matches=max_matches,
                 kf_min_frames=10)
    return {"tracked_pct": round(100 * r.fraction_tracked), "ate_mm": round(1000 * r.ate_m),
            "keyframes": r.n_keyframes, "tracking_ms": round(1000 * sum(r.stage_time_s[k] for k in ("align", "match", "refine")), 1)}


def run_parameter_sweep(grid=None, *, n_jobs: int = 1, size: str = "tiny", n_frames: int = 30, seed: int = 0,
                        progress=None):
    """003 §5.1.1's four tuning parameters on the rendered strafe, via :func:`slamlab.sweep.sweep`.

    Default grid: one parameter at a time around the defaults. Returns the sweep's DataFrame
    (``tracking_ms`` is a timing: print it only where timings are allowed).
    """
    from ..sweep import sweep

    base = {"init_disparity_px": 15.0, "max_keyframes": 10, "kf_max_lost_ratio": 0.3, "max_matches": 120}
    if grid is None:
        grid = [base, {**base, "init_disparity_px": 5.0}, {**base, "init_disparity_px": 30.0},
                {**base, "max_keyframes": 3}, {**base, "kf_max_lost_ratio": 0.1}, {**base, "max_matches": 30}]
    return sweep(_sweep_run, grid, seed=seed, n_jobs=n_jobs, progress=progress,
                 fixed={"size": size, "n_frames": n_frames})


# -- mono vs stereo on the same frames ----------------------------------------------------------
def run_mono_vs_stereo(sequence: str = "strafe", *, n_frames: int = 40, size: str = "small", rng=0,
                       snapshot_frames=()):
    """The monocular pipeline on the left images and Ch. 4's stereo pipeline on the pairs, same poses.

    Returns ``(mono MonoRunResult, stereo ATE SE(3) m, stereo ATE Sim(3) m, stereo RPE m)``.
    """
    from ..stereo.slam import StereoSLAM

    sim = mono_sim(size, rng=rng)
    poses = sequence_poses(sequence, n_frames)
    imgs, Ts = render_sequence(sim, poses, progress=False)
    mono = run_mono(imgs, Ts, sim.rig.left.K, name=f"{sequence} (mono)", progress=False,
                    snapshot_frames=snapshot_frames)
    c, s_ = np.cos(PITCH_DOWN_RAD), np.sin(PITCH_DOWN_RAD)
    tilt = np.eye(4)
    tilt[1:3, 1:3] = [[c, s_], [-s_, c]]
    T_bl = sim.T_body_left @ tilt
    T_right_left = np.eye(4)
    T_right_left[:3, :3], T_right_left[:3, 3] = sim.rig.R_rl, sim.rig.t_rl
    T_br = T_bl @ se3_inverse(T_right_left)
    st = StereoSLAM(sim.rig, T_bl)
    for pose, left in zip(poses, imgs, strict=True):
        T_wb = se3_from_planar(*pose)
        right = sim.arena.render(sim.rig.right, T_wb @ T_br) * 255.0
        right = np.clip(np.rint(right + sim.rng.normal(0.0, sim.noise_std, right.shape)), 0, 255).astype(np.uint8)
        st.process(left, right)
    est_body = st.trajectory  # (N, 4, 4) body poses in the map frame (the first body pose)
    est_cam = np.einsum("nij,jk->nik", est_body, T_bl)
    est_cam = np.einsum("ij,njk->nik", se3_inverse(est_cam[0]), est_cam)
    ok = np.ones(len(poses), bool)
    from ..evaluation import Trajectory, ate

    ts = np.arange(len(poses)) * 0.1
    ref = Trajectory(mono.truth[:, :3, 3], mono.truth[:, :3, :3], ts)
    est = Trajectory(est_cam[:, :3, 3], est_cam[:, :3, :3], ts)
    a_se3 = float(ate(ref, est, align="se3").rmse)
    a_sim3, r_st = trajectory_errors(mono.truth, est_cam, ok)
    return MonoVsStereo(mono, a_se3, a_sim3, r_st)


@dataclass(frozen=True)
class MonoVsStereo:
    """The monocular run and Ch. 4's stereo pipeline on the same rendered poses."""

    mono: MonoRunResult
    stereo_ate_se3_m: float
    stereo_ate_sim3_m: float
    stereo_rpe_m: float

    def table(self) -> str:
        m = self.mono
        rows = [["monocular (left camera)", f"{100 * m.fraction_tracked:.0f}", "-", f"{m.ate_m:.3f}", f"{m.rpe_m:.3f}"],
                # 2 decimals: the stereo pipeline's last digit changes with the number of BLAS threads
                ["stereo pipeline of Ch. 4", "100", f"{self.stereo_ate_se3_m:.2f}", f"{self.stereo_ate_sim3_m:.2f}",
                 f"{self.stereo_rpe_m:.2f}"]]
        return format_table(["pipeline", "tracked, %", "ATE SE(3), m", "ATE Sim(3), m", "RPE (Sim(3) scale), m"], rows,
                            title=f"{m.name.split(' ')[0]}, {len(m.tracked)} frames, same poses")


def epipolar_demo(folder=None, *, frames=(0, 1, 2), n_seeds: int = 60, depth_mean_m: float = 10.0,
                  depth_min_m: float = 2.0, fast_threshold: int = 30):
    """Seeds of KITTI frame ``frames[0]`` searched along their epipolar segments in the next frames (003 §4.2).

    The poses are KITTI's ground truth (the search itself is what is shown). Returns a list of
    dicts, one per searched frame: ``img_ref, img_cur, uv_ref, a, b, uv_match, found, n_candidates,
    sigma`` (σ_ρ before that search).
    """
    from ..data import find_data
    from ..evaluation import read_kitti
    from ..features.opencv import fast_cv
    from ..io.kitti import read_kitti_calib, read_kitti_image
    from .depth_filter import compute_tau, init_seeds, tau_inverse, update_seeds
    from .epipolar import extract_patches, search_epipolar

    d = find_data("kitti-odometry-06-stereo/calib.txt").parent if folder is None else v.as_path(folder, "folder", kind="dir")
    K = read_kitti_calib(d / "calib.txt")["P0"][:, :3]
    gt = read_kitti(d / "poses.txt").poses
    imgs = {i: read_kitti_image(d / "image_0" / f"{i:06d}.png") for i in frames}
    ref = imgs[frames[0]]
    F = fast_cv(ref, threshold=fast_threshold)
    h, w = ref.shape
    keep = (F.uv[:, 0] > 20) & (F.uv[:, 0] < w - 20) & (F.uv[:, 1] > 20) & (F.uv[:, 1] < h - 20)
    uv = F.uv[keep][np.argsort(-F.response[keep], kind="stable")[:n_seeds]]
    f = np.column_stack([(uv - K[:2, 2]) / [K[0, 0], K[1, 1]], np.ones(len(uv))])
    s = init_seeds(uv, f, depth_mean_m, depth_min_m)
    patches = extract_patches(ref, uv, 9)
    out = []
    px_angle = 2 * np.arctan(1.0 / (2 * K[0, 0]))
    for fr in frames[1:]:
        T_cur_ref = se3_inverse(gt[fr]) @ gt[frames[0]]
        sigma = np.sqrt(s.sigma2)
        cur = imgs[fr]
        C = fast_cv(cur, threshold=fast_threshold).uv
        m = search_epipolar(K, T_cur_ref, s.f, s.mu, sigma, patches, cur, C, patch_px=9, tol_px=2.0)
        out.append({"img_ref": ref, "img_cur": cur, "uv_ref": uv, "a": m.a, "b": m.b, "uv_match": m.uv,
                    "found": m.found, "n_candidates": m.n_candidates, "sigma": sigma, "frame": fr})
        fi = np.flatnonzero(m.found)
        if fi.size:
            z = m.depth_m[fi]
            tau = compute_tau(se3_inverse(T_cur_ref)[:3, 3], s.f[fi], z, px_angle)
            good = np.isfinite(tau)
            fi, z, tau = fi[good], z[good], tau[good]
            s.mu[fi], s.sigma2[fi], s.a[fi], s.b[fi] = update_seeds(s.mu[fi], s.sigma2[fi], s.a[fi], s.b[fi], 1 / z,
                                                                    tau_inverse(z, tau) ** 2, s.rho_range[fi])
        s.b[np.setdiff1d(np.arange(len(s)), fi)] += 1
    return out


def ours_vs_source(failures: dict, sequence: MonoRunResult, kitti: MonoRunResult | None = None,
                   convergence: ConvergenceStudy | None = None) -> str:
    """003's stated figures beside ours (003 §4.3, §4.4.1, §5.1.1, §5.4, §5.5.1), from the runs' results."""
    p = MonoParams()
    n_fail_ok = sum(r.verdict == "ok" for k, r in failures.items() if k != "normal")
    n_cases = sum(k != "normal" for k in failures)
    rows = [
        ["FAST points to start", ">= 50 (usually > 300)", f">= {p.min_corners}"],
        ["initial displacement", "10-20 px", f"{p.init_disparity_px:.0f} px"],
        ["initialisation", "homography + RANSAC (5-point named)", p.init_method + " (essential available)"],
        ["search band", "rho +- 2 sigma; 1e-10 if rho - 2 sigma <= 0", f"rho +- {p.n_sigma:.0f} sigma; 1e-10"],
        ["convergence", "L < 0.1", f"L < {p.L_max} (or SVO sigma < range/200)"],
        ["keyframe rule", ">= 30 frames and >= 10 % lost, or > 30 %",
         f">= {p.kf_min_frames} and >= {100 * p.kf_lost_ratio:.0f} %, or > {100 * p.kf_max_lost_ratio:.0f} %"],
        ["alignment patch", "4x4, pyramid, coarse to fine",
         f"{p.align_patch_px}x{p.align_patch_px}, levels {p.align_max_level}..{p.align_min_level}"],
        ["motion prior", "constant velocity", p.motion_model.replace("_", " ")],
        ["accuracy", "'not more than a couple of cm' (ICL-NUIM OR3)",
         f"ATE {100 * sequence.ate_m:.1f} cm ({sequence.name}, rendered)"],
        ["failure cases tracked > 70 %", "6 named, no numbers", f"{n_fail_ok} of {n_cases}"],
    ]
    if convergence is not None:
        def half(i):
            k = np.flatnonzero(convergence.converged[i] >= 0.5)
            return f"{k[0]}" if k.size else "> " + str(convergence.converged.shape[1] - 1)

        rows.append(["seeds converged (half, SVO test)", "'with enough parallax' (Fig. 4.5, no numbers)",
                     "; ".join(f"{100 * r:.0f} % outliers: {half(i)} obs."
                               for i, r in enumerate(convergence.outlier_rates))])
    if kitti is not None:
        rows.append(["real data", "ICL-NUIM OR3 (tables lost)",
                     f"KITTI 06, 20 frames: tracked {100 * kitti.fraction_tracked:.0f} %, ATE {kitti.ate_m:.2f} m"])
    return format_table(["item", "003", "ours"], rows, title="Ours vs the source (003)")
