"""One monocular run scored against ground truth (003 §5.2): :func:`run_mono` and its :class:`MonoRunResult`.

The runner takes frames and true poses from anywhere (rendered in :mod:`slamlab.studies.mono.experiments`, read
from KITTI in :mod:`slamlab.studies.mono.kitti`); :func:`trajectory_errors` gives ATE and RPE via
:mod:`slamlab.evaluation`.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np

from ..._progress import progress_bar
from ..._table import format_table
from ..._validate import as_finite_array, as_image
from ...geometry.se3 import se3_inverse
from ...mono.evaluate import TRACK_TOL_FRAC, RunScore, score_run
from ...mono.params import MonoParams
from ...mono.slam import MonoSLAM

__all__ = ["MonoRunResult", "run_mono", "trajectory_errors"]


def trajectory_errors(truth, estimate, tracked):
    """ATE (Sim(3), m) and RPE (1-frame translation, m) over the tracked frames, via :mod:`slamlab.evaluation`.

    ``truth``/``estimate`` (N, 4, 4). Returns ``(ate_m, rpe_m)``; NaN-free: ``inf`` when fewer
    than 3 frames were tracked.

    Parameters
    ----------
    truth, estimate : ndarray, shape (N, 4, 4)
        True and estimated camera poses.
    tracked : array_like of bool, shape (N,)
        Frames to evaluate.

    Returns
    -------
    ate_m : float
        ATE RMSE after Sim(3) alignment [m].
    rpe_m : float
        RPE RMSE of one-frame translations [m].
    """
    from ...evaluation import Trajectory, ate, rpe

    idx = np.flatnonzero(np.asarray(tracked, bool))
    if idx.size < 3:
        return float("inf"), float("inf")
    ts = idx * 0.1
    ref = Trajectory(truth[idx, :3, 3], truth[idx, :3, :3], ts)
    est = Trajectory(estimate[idx, :3, 3], estimate[idx, :3, :3], ts)
    a = float(ate(ref, est, align="sim3").rmse)
    # RPE after the Sim(3) scale: the monocular map has no metric scale
    from ...evaluation.metrics import align_trajectory

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

    Attributes
    ----------
    name : str
        Label of the run.
    truth : ndarray, shape (N, 4, 4)
        True camera poses in the first frame's camera frame.
    estimate : ndarray, shape (N, 4, 4)
        Estimated camera poses (map units).
    claimed : ndarray of bool, shape (N,)
        The tracker's own "tracked" flags.
    status : tuple of str
        Status of every frame.
    score : RunScore
        Per-frame errors after the run's Sim(3), ``correct`` frames, ATE and scale figures.
    rpe_m : float
        RPE of one-frame translations [m].
    n_keyframes, n_points : int
        Size of the final map.
    counts : dict
        Status → number of frames.
    stage_time_s : dict
        Seconds spent per stage.
    fps : float
        Frames per second of the run.
    points : ndarray, shape (M, 3), optional
        Final map points.
    seed_snapshots : dict, optional
        Frame → the seeds' ``σ_ρ / ρ_range`` after it.
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
    out = [as_image(img, f"images[{i}]") for i, img in enumerate(images)]
    shape0 = out[0].shape
    for i, img in enumerate(out):
        if img.shape != shape0:
            raise ValueError(f"`images` must all have one size; images[0] is {shape0} (H, W) but images[{i}] is "
                             f"{img.shape}")
    return out


def _check_truth(truth_T_wc, n: int) -> np.ndarray:
    """``truth_T_wc`` as an (n, 4, 4) array, or a ValueError naming ``truth_T_wc``."""
    T = as_finite_array(truth_T_wc, "truth_T_wc", ndim=3)
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

    Parameters
    ----------
    images : sequence of ndarray, shape (H, W)
        Grey frames of one size.
    truth_T_wc : array_like, shape (N, 4, 4)
        True camera poses, one per frame.
    K : array_like, shape (3, 3)
        Intrinsic matrix.
    name : str
        Label of the run (default ``"run"``).
    params : MonoParams, optional
        Settings (default values).
    progress : bool, callable or None
        Progress display.
    snapshot_frames : iterable of int
        Frames after which the seeds are kept.
    track_tol : float
        Tolerance of a correctly tracked frame as a fraction of the path length (default 0.05).
    **overrides
        Fields of :class:`MonoParams` to change.

    Returns
    -------
    MonoRunResult
        ``tracked``, ``ate_m``, ``rpe_m``, ``counts``, ``fps`` among others.
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
