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
from ..geometry.se3 import se3_from_planar, se3_inverse
from ..sim.arena import StereoArena, StereoSim
from .params import MonoParams
from .slam import STAGES, MonoSLAM

__all__ = [
    "FAILURE_CASES",
    "SEQUENCES",
    "MonoRunResult",
    "mono_sim",
    "render_sequence",
    "run_mono",
    "run_mono_sequence",
    "sequence_poses",
    "trajectory_errors",
]

#: image sizes per run size (width, height) - the benchmark uses 003's 768×576 rig
SIZES = {"small": (320, 240), "full": (768, 576)}

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
        T = se3_from_planar(*pose) @ sim.T_body_left @ tilt
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


def run_mono(images, truth_T_wc, K, *, name: str = "run", params: MonoParams | None = None, progress=None,
             **overrides) -> MonoRunResult:
    """Run :class:`MonoSLAM` on images with ground truth ``(N, 4, 4)`` and score it (003 §5.2)."""
    p = MonoParams.resolve(params, **overrides)
    slam = MonoSLAM(K, params=p)
    t = time.perf_counter()
    for img in progress_bar(images, desc=name, progress=progress):
        slam.process(img)
    dt = time.perf_counter() - t
    T0 = se3_inverse(truth_T_wc[0])
    truth = np.einsum("ij,njk->nik", T0, truth_T_wc)
    est = slam.trajectory
    tr = slam.tracked
    ate_m, rpe_m = trajectory_errors(truth, est, tr)
    return MonoRunResult(name, truth, est, tr, tuple(r["status"] for r in slam.records), ate_m, rpe_m,
                         len(slam.keyframes), len(slam.points), dict(slam.counts), slam.stage_times(),
                         len(images) / dt if dt > 0 else float("inf"), slam.points.copy())


def run_mono_sequence(sequence: str = "strafe", *, n_frames: int = 60, size: str = "small", step_m: float = 0.02,
                      noise_std: float = 1.0, params: MonoParams | None = None, progress=None, rng=0,
                      **overrides) -> MonoRunResult:
    """Render a sequence of the arena with the left camera and run the monocular pipeline on it."""
    sim = mono_sim(size, noise_std=noise_std, rng=rng)
    poses = sequence_poses(sequence, n_frames, step_m=step_m)
    imgs, Ts = render_sequence(sim, poses, progress=progress)
    return run_mono(imgs, Ts, sim.rig.left.K, name=sequence, params=params, progress=progress, **overrides)


STAGE_NAMES = STAGES
