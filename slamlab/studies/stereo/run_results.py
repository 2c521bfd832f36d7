"""Ch. 4 run results (000 §3.7): the frame steps per size, :class:`StereoRunResult` with its tables, the default
comparison and its table, and the calibration-drift study (no simulator here: the runs live in :mod:`~slamlab.studies.stereo.experiments`)."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..._table import format_table
from ...geometry import wrap_angle
from ...stereo.params import StereoParams
from ...stereo.slam import STAGES

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
            f"{len(self.degenerate)} degenerate"
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
            ["max heading error, deg", f"{deg(np.abs(self.yaw_err_rad).max()):.1f}", ""],
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


#: the default comparison of :func:`run_comparison`: 000's pipeline, and ORB with and without §3.5's policy
COMPARISON = {
    "SURF, oldest": {},
    "ORB, oldest": {"detector": "orb"},
    "ORB, all": {"detector": "orb", "policy": "all"},
}


def comparison_table(results: dict) -> str:
    """000's figures for the turn or the loop, one column per run of :func:`run_comparison`.

    Parameters
    ----------
    results : dict
        Label -> :class:`StereoRunResult` from :func:`run_comparison`, all of one experiment.

    Returns
    -------
    str
    """
    runs = list(results.values())
    if not runs:
        raise ValueError("`results` is empty")
    deg = np.rad2deg
    rows = [["max position error, m", *(f"{r.pos_err_m.max():.2f}" for r in runs)],
            ["max heading error, deg", *(f"{deg(np.abs(r.yaw_err_rad).max()):.1f}" for r in runs)]]
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
    """Runs of one experiment at several calibration-drift levels (000 §3.2; our experiment).

    Attributes
    ----------
    experiment : str
        "turn in place" or "closed loop".
    drift_std_rad : tuple of float
        Random-walk step of the right camera per axis and frame [rad], one per level.
    runs : tuple of StereoRunResult
        One run per level.
    """

    experiment: str
    drift_std_rad: tuple
    runs: tuple = field(repr=False)  # StereoRunResult per level

    def table(self) -> str:
        """Errors, stereo matches and inliers per drift level (fixed precision).

        Returns
        -------
        str
        """
        rows = []
        for d, r in zip(self.drift_std_rad, self.runs, strict=True):
            c = r.counts
            # the random walk's typical accumulated angle at the last frame: sqrt(N) sigma per axis
            rows.append([f"{1e3 * d:.1f}", f"{1e3 * d * np.sqrt(r.n_frames):.1f}", f"{r.pos_err_m.max():.2f}",
                         f"{np.rad2deg(np.abs(r.yaw_err_rad).max()):.1f}", f"{np.median(c['n_stereo']):.0f}",
                         f"{np.min(c['n_stereo']):.0f}", f"{np.median(c['n_inliers'][1:]):.0f}", f"{len(r.degenerate)}"])  # fmt: skip
        head = ["σ, mrad/frame", "~at end, mrad", "max pos., m", "max yaw, deg", "stereo median", "min",
                "inliers median", "degenerate"]  # fmt: skip
        return (format_table(head, rows, title=f"calibration drift of the right camera: {self.experiment} "
                                               f"({self.runs[0].detector})")
                + "\nσ: random-walk step per axis and frame; at end: σ √frames; max: over the frames"
                  "\nstereo matches and RANSAC inliers: per frame")
