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
from .evaluate import TRACK_TOL_FRAC, RunScore, score_run
from .params import MonoParams
from .slam import STAGES, MonoSLAM

__all__ = [
    "FAILURE_CASES",
    "FAILURE_CONSTRUCTIONS",
    "SEQUENCES",
    "ConvergenceStudy",
    "MonoRunResult",
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
#: which Ch. 4 renders (003 used a Kinect camera and the ICL-NUIM scenes; it states no image size)
SIZES = {"tiny": (192, 144), "small": (320, 240), "full": (768, 576)}

SEQUENCES = ("strafe", "arc")
#: 003 §5.3's failure cases, rendered (our constructions)
FAILURE_CASES = ("little_texture", "fast_motion", "pure_rotation", "distant_points", "kidnap", "bad_initial_map")
#: how each case is made (ours), printed with the table
FAILURE_CONSTRUCTIONS = {
    "normal": "strafe, 2 cm per frame",
    "little_texture": "strafe, blur 2.5 px, contrast 12 %",
    "fast_motion": "strafe, 15 cm per frame",
    "pure_rotation": "2 deg per frame in place",
    "distant_points": "strafe in a 60 x 60 m arena",
    "kidnap": "carried 2 m and 0.6 rad at mid-run",
    "bad_initial_map": "initialised after 2 px",
}


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
    """The stereo chapter's arena simulator (000's robot's 40° stereo rig, left camera used) at the size of ``size``.

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
    """A monocular run against ground truth (003 §5.2: ATE after alignment; ours: Sim(3), RPE, correct frames).

    ``claimed`` are the tracker's own flags; ``tracked`` the **correctly tracked** frames (claimed and
    within ``score.tol_m`` after the run's Sim(3), :func:`~slamlab.mono.evaluate.score_run`); ``ate_m``
    is over all frames (a frame not tracked counts with the pose the tracker reports for it),
    ``ate_claimed_m`` over the claimed ones.
    """

    name: str
    truth: np.ndarray = field(repr=False)  # (N, 4, 4) camera poses in the first frame's camera frame
    estimate: np.ndarray = field(repr=False)  # (N, 4, 4)
    claimed: np.ndarray = field(repr=False)  # (N,) the tracker's own "tracked"
    status: tuple = field(repr=False)
    score: RunScore = field(repr=False)
    rpe_m: float
    n_keyframes: int
    n_points: int
    counts: dict = field(repr=False, compare=False)
    stage_time_s: dict = field(repr=False, compare=False)
    fps: float = field(compare=False)
    points: np.ndarray = field(repr=False, compare=False, default=None)
    seed_snapshots: dict = field(repr=False, compare=False, default=None)  # frame -> σ_ρ/ρ_range of the seeds

    @property
    def tracked(self) -> np.ndarray:
        """(N,) correctly tracked frames (claimed and within the tolerance after Sim(3))."""
        return self.score.correct

    @property
    def ate_m(self) -> float:
        """ATE RMSE (m) after the run's Sim(3), over all frames."""
        return self.score.ate_all_m

    @property
    def ate_claimed_m(self) -> float:
        """ATE RMSE (m) after the run's Sim(3), over the frames the tracker claims."""
        return self.score.ate_claimed_m

    @property
    def fraction_tracked(self) -> float:
        """Share of the frames correctly tracked."""
        return float(np.mean(self.tracked)) if len(self.tracked) else 0.0

    @property
    def fraction_claimed(self) -> float:
        """Share of the frames the tracker claims as tracked."""
        return float(np.mean(self.claimed)) if len(self.claimed) else 0.0

    @property
    def verdict(self) -> str:
        """003 §5.5.1's marks on the correctly tracked share: 'X' < 30 %, '*' 30-70 %, 'ok' > 70 %."""
        f = self.fraction_tracked
        return "X" if f < 0.3 else ("*" if f <= 0.7 else "ok")

    def __str__(self) -> str:
        return (f"{self.name}: {len(self.tracked)} frames, correctly tracked {100 * self.fraction_tracked:.0f} % "
                f"(claimed {100 * self.fraction_claimed:.0f} %), ATE (Sim(3), all frames) {self.ate_m:.3f} m, "
                f"{self.n_keyframes} keyframes, {self.n_points} points")

    def table(self) -> str:
        sc = self.score
        f3 = lambda x: f"{x:.3f}" if np.isfinite(x) else "-"
        rows = [["frames", f"{len(self.tracked)}"],
                ["path of the truth, m", f"{sc.path_m:.2f}"],
                ["claimed by the tracker, %", f"{100 * self.fraction_claimed:.0f}"],
                [f"correctly tracked (error <= {100 * sc.tol_frac:.0f} % of path = {sc.tol_m:.3f} m), %",
                 f"{100 * self.fraction_tracked:.0f}"],
                ["ATE RMSE after Sim(3), all frames, m", f3(self.ate_m)],
                ["ATE RMSE after Sim(3), claimed frames, m", f3(self.ate_claimed_m)],
                ["ATE, all frames, % of path", f"{100 * self.ate_m / sc.path_m:.1f}" if sc.path_m > 0
                 and np.isfinite(self.ate_m) else "-"],
                ["RPE RMSE (1 frame, Sim(3) scale), m", f3(self.rpe_m)],
                ["scale, first / last third (m per map unit, from the truth)", f"{f3(sc.scale_first)} / {f3(sc.scale_last)}"],
                ["scale drift (last / first)", f"{sc.scale_drift:.2f}" if np.isfinite(sc.scale_drift) else "-"],
                ["keyframes / map points", f"{self.n_keyframes} / {self.n_points}"]]
        return format_table(["quantity", "value"], rows,
                            title=f"{self.name} (a frame not tracked counts at the pose the tracker reports for it)")


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
             snapshot_frames=(), track_tol: float = TRACK_TOL_FRAC, **overrides) -> MonoRunResult:
    """Run :class:`MonoSLAM` on images with ground truth ``(N, 4, 4)`` and score it (003 §5.2).

    ``snapshot_frames``: frames after which the seeds' ``σ_ρ / ρ_range`` are kept (for histograms).
    ``track_tol``: a claimed frame is correctly tracked when its position error after the run's Sim(3)
    is at most this share of the path length (ours, default 5 %). Raises ``ValueError`` naming the argument when the frames differ in size or ``truth_T_wc``
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
    _, rpe_m = trajectory_errors(truth, est, tr)
    score = score_run(truth, est, tr, tol_frac=track_tol)
    return MonoRunResult(name, truth, est, tr, tuple(r["status"] for r in slam.records), score, rpe_m,
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
    ``error`` (R, n_obs + 1) median ``|ρ − ρ_true|`` (1/m), ``converged`` (R, n_obs + 1) share of seeds
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

    def first_half(self) -> list:
        """Observations until half of the seeds pass SVO's test, per outlier rate (None: never)."""
        out = []
        for row in self.converged:
            k = np.flatnonzero(row >= 0.5)
            out.append(int(k[0]) if k.size else None)
        return out

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
    tau = v.check_positive(tau, "tau")
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
    from ..sweep import fresh_seed_sequence

    seeds = fresh_seed_sequence(rng).spawn(len(cases))  # an int seed: SeedSequence(seed)'s children as before
    for case, ss in zip(progress_bar(cases, desc="failure cases", progress=progress), seeds, strict=True):
        imgs, Ts, K, ov = _case_frames(case, size, n_frames, np.random.default_rng(ss))
        out[case] = run_mono(imgs, Ts, K, name=case, params=params, progress=False, **{**overrides, **ov})
    return out


def failure_table(results: dict) -> str:
    """003 §5.5.1's table layout: the correctly tracked share with its mark (X < 30 %, * 30-70 %) and the ATE."""
    rows = []
    for name, r in results.items():
        ate_txt = f"{r.ate_m:.3f}" if np.isfinite(r.ate_m) else "-"
        rows.append([name, FAILURE_CONSTRUCTIONS.get(name, "-"), f"{100 * r.fraction_claimed:.0f}", f"{100 * r.fraction_tracked:.0f}", r.verdict, ate_txt,
                     f"{r.counts.get('lost', 0)}",
                     f"{sum(k.startswith('init_') and k not in ('init_done', 'init_tracking', 'init_first_frame') for k in r.counts)}"])
    tol = next(iter(results.values())).score.tol_frac if results else 0.05
    return format_table(["case (003 §5.3)", "construction (ours)", "claimed, %", "correct, %", "mark", "ATE Sim(3) all frames, m",
                         "lost frames", "init failure kinds"], rows,
                        title=f"Failure cases, rendered (correct: error <= {100 * tol:.0f} % of the path after Sim(3))")


# -- the parameters 003 tuned (003 §5.1.1) on slamlab.sweep ---------------------------------------
def _sweep_run(init_disparity_px, max_keyframes, kf_max_lost_ratio, max_matches, rng, size="tiny", n_frames=30,
               params=None):
    imgs, Ts, K, _ = _case_frames("normal", size, n_frames, rng)
    r = run_mono(imgs, Ts, K, name="sweep", params=params, progress=False, init_disparity_px=init_disparity_px,
                 max_keyframes=max_keyframes, kf_max_lost_ratio=kf_max_lost_ratio, max_matches=max_matches,
                 kf_min_frames=10)
    return {"tracked_pct": round(100 * r.fraction_tracked), "ate_mm": round(1000 * r.ate_m),
            "keyframes": r.n_keyframes, "tracking_ms": round(1000 * sum(r.stage_time_s[k] for k in ("align", "match", "refine")), 1)}


def run_parameter_sweep(grid=None, *, n_jobs: int = 1, size: str = "tiny", n_frames: int = 30,
                        params: MonoParams | None = None, rng=0, progress=None, seed=None, **overrides):
    """003 §5.1.1's four tuning parameters on the rendered strafe, via :func:`slamlab.sweep.sweep`.

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
        The settings the grid changes (default: the defaults; ``kf_min_frames`` is 10 in these runs).
    rng : int, SeedSequence or Generator
        Where every run's stream is spawned from.
    progress : bool, callable or None
        See :mod:`slamlab._progress`.
    seed : int, optional
        Deprecated name of ``rng``.
    **overrides
        :class:`MonoParams` fields under the grid's.

    Returns
    -------
    pandas.DataFrame
        The sweep's table (``tracking_ms`` is a timing: print it only where timings are allowed).
    """
    from ..sweep import renamed_seed, root_seed_sequence, sweep

    rng = renamed_seed(rng, seed, "run_parameter_sweep")
    p = MonoParams.resolve(params, **overrides) if (params is not None or overrides) else None
    base = {"init_disparity_px": 15.0, "max_keyframes": 10, "kf_max_lost_ratio": 0.3, "max_matches": 120}
    if grid is None:
        grid = [base, {**base, "init_disparity_px": 5.0}, {**base, "init_disparity_px": 30.0},
                {**base, "max_keyframes": 3}, {**base, "kf_max_lost_ratio": 0.1}, {**base, "max_matches": 30}]
    return sweep(_sweep_run, grid, seed=root_seed_sequence(rng, "rng"), n_jobs=n_jobs, progress=progress,
                 fixed={"size": size, "n_frames": n_frames, "params": p})
