"""Ch. 5 experiment results (004 §7): the printable result dataclasses of Table 1, the Monte Carlo study, the constants
a_c/a_p and the corridor tie, with their tables (no simulator here: the runs live in :mod:`~slamlab.studies.correlation.experiments`)."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..._table import format_table
from ...correlation.algorithm import (
    Localisation,
    LocaliseParams,
    heading_error,
)
from .studies import SOURCE_TABLE1, source_table1_errors


@dataclass(frozen=True)
class Table1Result:
    """004 Table 1 reproduced: 10 random free poses, Δα = 1°, range noise, unmapped clutter.

    Attributes
    ----------
    true_poses, est_poses : numpy.ndarray, shape (n, 3)
        True and estimated poses ``(x, y)`` [cells], heading [rad].
    err_heading_rad : numpy.ndarray, shape (n,)
        Wrapped heading errors [rad].
    err_x_cells, err_y_cells : numpy.ndarray, shape (n,)
        Absolute position errors [cells].
    range_std_cells : float
        Range noise std of the scans [cells].
    n_beams : int
        Beams per scan.
    params : LocaliseParams
        Settings of the localisations.
    time_s : float
        Wall time of the localisations [s] (not compared).
    """

    true_poses: np.ndarray  # (n, 3)
    est_poses: np.ndarray  # (n, 3)
    err_heading_rad: np.ndarray
    err_x_cells: np.ndarray
    err_y_cells: np.ndarray
    range_std_cells: float
    n_beams: int
    params: LocaliseParams = field(default_factory=LocaliseParams, repr=False)
    time_s: float = field(default=0.0, compare=False)

    def __str__(self) -> str:
        s_ea, s_ex, s_ey = source_table1_errors()
        return (f"Table 1, {self.true_poses.shape[0]} poses: max errors {self.err_heading_rad.max():.4f} rad "
                f"({np.degrees(self.err_heading_rad.max()):.2f}°), |dX| {self.err_x_cells.max():.0f}, |dY| "
                f"{self.err_y_cells.max():.0f} cells; 004: {s_ea.max():.4f} rad ({np.degrees(s_ea.max()):.2f}°), "
                f"{s_ex.max():.0f}, {s_ey.max():.0f}")

    def table(self) -> str:
        """Our Table 1 (rows per pose, then our and 004's maximum errors).

        Returns
        -------
        str
        """
        rows = []
        for i, (t, e) in enumerate(zip(self.true_poses, self.est_poses, strict=True)):
            rows.append([i + 1, f"{t[2]:.4f}", f"{e[2]:.4f}", f"{t[0]:.0f}", f"{e[0]:.0f}", f"{t[1]:.0f}",
                         f"{e[1]:.0f}", f"{self.err_heading_rad[i]:.4f}", f"{self.err_x_cells[i]:.0f}",
                         f"{self.err_y_cells[i]:.0f}"])
        rows.append(["max (ours)", "", "", "", "", "", "", f"{self.err_heading_rad.max():.4f}",
                     f"{self.err_x_cells.max():.0f}", f"{self.err_y_cells.max():.0f}"])
        s_ea, s_ex, s_ey = source_table1_errors()
        rows.append(["max (004)", "", "", "", "", "", "", f"{s_ea.max():.4f}", f"{s_ex.max():.0f}",
                     f"{s_ey.max():.0f}"])
        head = ["#", "α0", "α0 est", "X", "X est", "Y", "Y est", "err α0", "err X", "err Y"]
        title = (f"Ours: {self.n_beams} beams over 360°, range σ = {self.range_std_cells:g} cell, 0.1-cell "
                 f"quantisation, Δα = {np.degrees(self.params.delta_alpha_rad):g}°, clutter (rad, cells)")
        return format_table(head, rows, title=title)

    def source_table(self) -> str:
        """004's Table 1 as printed (radians, cells).

        Returns
        -------
        str
        """
        src = SOURCE_TABLE1
        ea, ex, ey = source_table1_errors()
        rows = [[i + 1, f"{r[0]:.4f}", f"{r[1]:.4f}", f"{r[2]:.0f}", f"{r[3]:.0f}", f"{r[4]:.0f}", f"{r[5]:.0f}",
                 f"{ea[i]:.4f}", f"{ex[i]:.0f}", f"{ey[i]:.0f}"] for i, r in enumerate(src)]
        head = ["#", "α0", "α0 est", "X", "X est", "Y", "Y est", "err α0", "err X", "err Y"]
        return format_table(head, rows, title="004 Table 1 (its own map and poses)")


@dataclass(frozen=True)
class MonteCarloResult:
    """Error distribution and failure rate of the full 360° search over many random poses (our addition).

    Attributes
    ----------
    n_poses : int
        Localised poses.
    err_heading_rad : numpy.ndarray, shape (n_poses,)
        Wrapped heading errors [rad].
    err_pos_cells : numpy.ndarray, shape (n_poses,)
        Euclidean position errors [cells].
    failed : numpy.ndarray of bool, shape (n_poses,)
        Position error > 2 cells or heading error > 5°.
    range_std_cells : float
        Range noise std [cells].
    extra_clutter : int
        Random discs added to 004's clutter.
    time_s : float
        Wall time of the localisations [s] (not compared).
    params : LocaliseParams
        Settings of the localisations.
    """

    n_poses: int
    err_heading_rad: np.ndarray
    err_pos_cells: np.ndarray  # Euclidean position error
    failed: np.ndarray  # bool
    range_std_cells: float
    extra_clutter: int
    time_s: float = field(default=0.0, compare=False)
    params: LocaliseParams = field(default_factory=LocaliseParams, repr=False)

    @property
    def failure_rate(self) -> float:
        """Fraction of poses with position error > 2 cells or heading error > 5°."""
        return float(self.failed.mean())

    def __str__(self) -> str:
        return (f"Monte Carlo, {self.n_poses} poses: failure rate {self.failure_rate:.1%}, "
                f"exact position {np.mean(self.err_pos_cells == 0):.0%}")

    def table(self) -> str:
        """Error distribution table (exact, ≤ 1 cell, heading percentiles, failures).

        Returns
        -------
        str
        """
        ok = ~self.failed
        ea = np.degrees(self.err_heading_rad[ok]) if ok.any() else np.array([np.nan])
        ep = self.err_pos_cells
        rows = [
            ["poses", f"{self.n_poses}"],
            ["position exact (0 cells)", f"{np.mean(ep == 0):.1%}"],
            ["position error <= 1 cell", f"{np.mean(ep <= 1.0):.1%}"],
            ["position error <= 1.5 cells (incl. diagonal)", f"{np.mean(ep <= 1.5):.1%}"],
            ["heading error <= 0.5° (half the step)", f"{np.mean(np.degrees(self.err_heading_rad) <= 0.5):.1%}"],
            ["heading error <= 1°", f"{np.mean(np.degrees(self.err_heading_rad) <= 1.0):.1%}"],
            ["heading error median / 95 % / max, successes [deg]",
             f"{np.median(ea):.2f} / {np.percentile(ea, 95):.2f} / {ea.max():.2f}"],
            ["failures (> 2 cells or > 5°)", f"{self.failed.sum()} ({self.failure_rate:.1%})"],
        ]
        title = (f"Range σ = {self.range_std_cells:g} cell, clutter of 004 Fig. 3b"
                 + (f" + {self.extra_clutter} extra discs" if self.extra_clutter else ""))
        return format_table(["quantity", "value"], rows, title=title)


@dataclass(frozen=True)
class ConstantsResult:
    """Peak sharpness and robustness to unmapped clutter of two choices of 004's constants.

    Attributes
    ----------
    labels : tuple of str
        One label per choice of constants.
    constants : tuple of tuple of float
        ``(a_c, a_p, a_n)`` per choice.
    half_max_area : numpy.ndarray, shape (k, n)
        Cells scoring at least halfway from the median to the peak at the best heading.
    heading_margin : numpy.ndarray, shape (k, n)
        (Peak minus the best score ≥ 3° away) over (peak minus the median over headings).
    failure_rate : numpy.ndarray, shape (k,)
        Share of failed poses per choice.
    err_pos_cells : numpy.ndarray, shape (k, n)
        Position errors [cells].
    extra_clutter : int
        Random discs added to 004's clutter.
    example_maps : tuple of numpy.ndarray
        Score maps of the first scan at its true heading, one per choice.
    example_pose : numpy.ndarray, shape (3,)
        The first scan's true pose.
    time_s : float
        Wall time [s] (not compared).
    params : LocaliseParams
        Settings of the localisations but ``a_c, a_p, a_n`` (each choice sets them).
    """

    labels: tuple[str, ...]
    constants: tuple[tuple[float, float, float], ...]
    half_max_area: np.ndarray  # (k, n) cells with score >= median + (peak - median)/2 at the best heading
    heading_margin: np.ndarray  # (k, n) (peak - best >= 3° away) / (peak - median over headings)
    failure_rate: np.ndarray  # (k,)
    err_pos_cells: np.ndarray  # (k, n)
    extra_clutter: int
    example_maps: tuple = field(default=(), repr=False)  # score maps at the truth's heading, one per choice
    example_pose: np.ndarray = field(default=None, repr=False)
    time_s: float = field(default=0.0, compare=False)
    params: LocaliseParams = field(default_factory=LocaliseParams, repr=False)

    def __str__(self) -> str:
        return "; ".join(f"{lb}: failures {fr:.0%}" for lb, fr in zip(self.labels, self.failure_rate, strict=True))

    def table(self) -> str:
        """Median sharpness measures and failure rate per choice.

        Returns
        -------
        str
        """
        rows = []
        for k, lb in enumerate(self.labels):
            rows.append([lb, f"{np.median(self.half_max_area[k]):.0f}", f"{np.median(self.heading_margin[k]):.3f}",
                         f"{np.mean(self.err_pos_cells[k] <= 1.5):.0%}", _rate_of(self.failure_rate[k], self.err_pos_cells.shape[1])])
        title = (f"{self.err_pos_cells.shape[1]} poses, clutter of 004 Fig. 3b + {self.extra_clutter} extra discs; "
                 "medians;\na sharper peak has a smaller half-max area and a larger heading margin")
        return format_table(["constants", "half-max area", "heading margin", "pos. err <= 1.5", "failures"],
                            rows, title=title)


@dataclass(frozen=True)
class CorridorResult:
    """One scan vs two scans joined by odometry in :func:`corridor_grid` (ours).

    Attributes
    ----------
    true_pose : numpy.ndarray, shape (3,)
        Pose of the last scan [cells, rad].
    odom_poses : numpy.ndarray, shape (k, 3)
        The scans' poses, last scan first.
    single : Localisation
        The last scan alone.
    joined : Localisation
        The scans joined by odometry.
    params : LocaliseParams
        Settings of both localisations.
    """

    true_pose: np.ndarray  # (3,) cells, rad: the pose of the last scan
    odom_poses: np.ndarray  # (k, 3) the scans' poses, last scan first
    single: Localisation
    joined: Localisation
    params: LocaliseParams = field(default_factory=LocaliseParams, repr=False)

    def __str__(self) -> str:
        e1 = np.degrees(heading_error(self.single.pose[2], self.true_pose[2]))
        e2 = np.degrees(heading_error(self.joined.pose[2], self.true_pose[2]))
        return f"corridor: one scan {e1:.0f}° off (ambiguity {self.single.ambiguity:.3f}), " \
               f"{self.joined.n_scans} joined {e2:.0f}° off (ambiguity {self.joined.ambiguity:.3f})"

    def table(self) -> str:
        """One row per mode: estimate, errors, score, rival and ambiguity.

        Returns
        -------
        str
        """
        t = self.true_pose
        rows = []
        for label, loc in (("1 scan", self.single), (f"{self.joined.n_scans} scans + odometry", self.joined)):
            rows.append([label, f"{loc.pose[0]:.0f}", f"{loc.pose[1]:.0f}", f"{np.degrees(loc.pose[2]):.0f}",
                         f"{np.hypot(loc.pose[0] - t[0], loc.pose[1] - t[1]):.0f}",
                         f"{np.degrees(heading_error(loc.pose[2], t[2])):.0f}", f"{loc.score:.0f}",
                         f"{loc.rival_score:.0f}", f"{loc.ambiguity:.3f}"])
        title = (f"Corridor with a dead end, truth x = {t[0]:.0f}, y = {t[1]:.0f}, θ = {np.degrees(t[2]):.0f}° "
                 f"(cells, deg); noise-free scans, Δα = {np.degrees(self.single.headings_rad[1] - self.single.headings_rad[0]):g}°")
        return format_table(["mode", "x est", "y est", "θ est", "pos. err", "θ err", "score", "rival", "ambiguity"],
                            rows, title=title)


def _rate_of(rate: float, n: int) -> str:
    """A rate over ``n`` cases with its count: ``"33% (2/6)"``."""
    return f"{rate:.0%} ({round(rate * n)}/{n})"
