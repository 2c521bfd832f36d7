"""Plots for Ch. 6 (Hough SLAM): accumulators, 004's example, error curves (Fig. 10), built maps (Fig. 11)."""

from __future__ import annotations

import math

import matplotlib.pyplot as plt
import numpy as np

from ..plotting import STYLE, new_axes
from .transform import HoughAccumulator

__all__ = [
    "accumulator_figure",
    "example_figure",
    "plot_accumulator",
    "plot_built_map",
    "plot_pose_errors",
    "plot_scan_lines",
    "real_log_figure",
    "sim_figure",
]

#: 004 Fig. 10's colours: Ea green, Ex blue, Ey red.
_ERR_COLORS = {"Ex": "tab:blue", "Ey": "tab:red", "Ea": "tab:green"}


def plot_accumulator(acc: HoughAccumulator, lines=None, *, ax=None, title: str = "Hough accumulator"):
    """The votes H(rho, θ) as an image, θ in degrees across, rho up; peaks circled when ``lines`` is given.

    Parameters
    ----------
    acc : HoughAccumulator
        The votes.
    lines : Lines, optional
        Peaks to circle.
    ax : matplotlib.axes.Axes, optional
        Axes to draw on; None makes a new figure.
    title : str
        Axes title.

    Returns
    -------
    matplotlib.axes.Axes
    """
    if not isinstance(acc, HoughAccumulator):
        raise TypeError(f"`acc` must be a HoughAccumulator; got {type(acc).__name__}")
    ax = new_axes(ax, title=title, xlabel="θ [°]", ylabel="ρ")
    t = np.degrees(acc.theta_rad)
    dt, dr = math.degrees(acc.delta_theta_rad), acc.delta_rho
    extent = (t[0] - dt / 2, t[-1] + dt / 2, acc.rho[0] - dr / 2, acc.rho[-1] + dr / 2)
    im = ax.imshow(acc.H, origin="lower", aspect="auto", extent=extent, cmap="magma", interpolation="nearest")
    ax.figure.colorbar(im, ax=ax, label="votes")
    if lines is not None and len(lines):
        ax.plot(np.degrees(lines.theta_rad), lines.rho, "o", mfc="none", mec="cyan", ms=10, mew=1.5,
                label=f"{len(lines)} peaks")
        ax.legend(loc="upper right")
    return ax


def plot_scan_lines(bearings_rad, ranges, lines=None, *, ax=None, title: str = "Scan and its lines",
                    extent: float | None = None):
    """Scan points in the sensor frame with the detected lines drawn across them.

    Parameters
    ----------
    bearings_rad, ranges : array_like, shape (N,)
        The scan; ranges ≤ 0 are skipped.
    lines : Lines, optional
        Lines to draw across the points.
    ax : matplotlib.axes.Axes, optional
        Axes to draw on; None makes a new figure.
    title : str
        Axes title.
    extent : float, optional
        Half-width of the drawn lines; default the farthest point coordinate.

    Returns
    -------
    matplotlib.axes.Axes
    """
    ax = new_axes(ax, title=title, xlabel="x", ylabel="y")
    ax.set_aspect("equal", adjustable="box")
    phi, r = np.asarray(bearings_rad, float), np.asarray(ranges, float)
    ok = r > 0
    x, y = r[ok] * np.cos(phi[ok]), r[ok] * np.sin(phi[ok])
    ax.plot(x, y, **{**STYLE["measurement"], "markersize": 3}, label="returns")
    ax.plot([0], [0], "k^", ms=8, label="sensor")
    span = extent if extent is not None else (float(np.abs(np.concatenate([x, y])).max()) if x.size else 1.0)
    if lines is not None:
        s = np.linspace(-1.5 * span, 1.5 * span, 2)
        for k, (rho, th) in enumerate(zip(lines.rho, lines.theta_rad, strict=True)):
            ax.plot(rho * math.cos(th) - s * math.sin(th), rho * math.sin(th) + s * math.cos(th), "-",
                    lw=1.0, alpha=0.8, label="lines" if k == 0 else None)
    ax.set_xlim(-1.1 * span, 1.1 * span)
    ax.set_ylim(-1.1 * span, 1.1 * span)
    ax.legend(loc="upper right", fontsize=8)
    return ax


def accumulator_figure(acc: HoughAccumulator, peaks, bearings_rad, ranges, lines):
    """A scan's accumulator with its peaks beside the scan and the refitted lines; returns the figure.

    Parameters
    ----------
    acc : HoughAccumulator
        The scan's accumulator.
    peaks : Lines
        Its peaks, circled.
    bearings_rad, ranges : array_like, shape (N,)
        The scan.
    lines : Lines
        The refitted lines, drawn over the scan.

    Returns
    -------
    matplotlib.figure.Figure
    """
    fig, axs = plt.subplots(1, 2, figsize=(14, 5))
    plot_accumulator(acc, peaks, ax=axs[0])
    plot_scan_lines(bearings_rad, ranges, lines, ax=axs[1])
    fig.tight_layout()
    return fig


def example_figure(result):
    """004 Fig. 5-8: the scan of the line θ = 45°, p = 10, its 33×33 image, both accumulators.

    Parameters
    ----------
    result : ExampleLineResult
        From :func:`~slamlab.hough.run_example_line`.

    Returns
    -------
    matplotlib.figure.Figure
    """
    fig, axs = plt.subplots(1, 4, figsize=(17, 4.2))
    phi, r = result.scan
    plot_scan_lines(phi, r, ax=axs[0], title="Fig. 5: scan D_i of the line", extent=16.0)
    axs[1].imshow(result.image, origin="lower", cmap="gray_r", interpolation="nearest")
    axs[1].set_title(f"Fig. 6: image A, {result.image.shape[0]}×{result.image.shape[1]}")
    axs[1].set_xlabel("column")
    axs[1].set_ylabel("row")
    plot_accumulator(result.classic, ax=axs[2],
                     title=f"Fig. 7: classic, {result.classic_size[0]}×{result.classic_size[1]}")
    plot_accumulator(result.polar, ax=axs[3], title=f"Fig. 8: polar, {result.polar_size[0]}×{result.polar_size[1]}")
    fig.tight_layout()
    return fig


def plot_pose_errors(errors, *, ax=None, title: str = "Hough SLAM errors (cf. 004 Fig. 10)", deg: bool = True):
    """Ex(n), Ey(n) [cells] and Ea(n) (004 Fig. 10: Ex blue, Ey red, Ea green).

    Parameters
    ----------
    errors : array_like, shape (n, 3)
        ``(Ex, Ey, Ea)`` per pose (:func:`~slamlab.hough.pose_errors`).
    ax : matplotlib.axes.Axes, optional
        Axes to draw on; None makes a new figure.
    title : str
        Axes title.
    deg : bool, default True
        Draw Ea in degrees (else radians).

    Returns
    -------
    matplotlib.axes.Axes
    """
    e = np.asarray(errors, dtype=float)
    ax = new_axes(ax, title=title, xlabel="pose n", ylabel="Ex, Ey [cells]")
    n = np.arange(e.shape[0])
    ax.plot(n, e[:, 0], color=_ERR_COLORS["Ex"], label="Ex(n)")
    ax.plot(n, e[:, 1], color=_ERR_COLORS["Ey"], label="Ey(n)")
    ax.axhline(0.0, color="0.6", lw=0.8)
    ax2 = ax.twinx()
    ax2.plot(n, np.degrees(e[:, 2]) if deg else e[:, 2], color=_ERR_COLORS["Ea"], label="Ea(n)")
    ax2.set_ylabel("Ea [°]" if deg else "Ea [rad]", color=_ERR_COLORS["Ea"])
    lo = min(-1.0, float(e[:, :2].min()) * 1.2)
    hi = max(1.0, float(e[:, :2].max()) * 1.2)
    ax.set_ylim(lo, hi)
    a = max(1.0, float(np.degrees(np.abs(e[:, 2])).max()) * 1.2)
    ax2.set_ylim(-a, a)
    lines = ax.get_lines()[:2] + ax2.get_lines()
    ax.legend(lines, [ln.get_label() for ln in lines], loc="upper left")
    return ax


def plot_built_map(built, *, frame=None, truth=None, estimate=None, ax=None,
                   title: str = "Built map (cf. 004 Fig. 11)"):
    """The three-valued built map (obstacle black, free white, unexplored grey) with the paths.

    ``frame``: the map's :class:`~slamlab.scans.GridFrame` (default: cell units, cell (0, 0) at the origin).

    Parameters
    ----------
    built : OccupancyGrid
        The built map.
    frame : GridFrame, optional
        The map's frame.
    truth, estimate : array_like, shape (n, 3), optional
        Paths to draw (in the frame's unit).
    ax : matplotlib.axes.Axes, optional
        Axes to draw on; None makes a new figure.
    title : str
        Axes title.

    Returns
    -------
    matplotlib.axes.Axes
    """
    ax = new_axes(ax, title=title, xlabel="x", ylabel="y", equal=True)
    g = built.grid
    shown = np.where(g == 1, 0.0, np.where(g == 0, 1.0, 0.75))
    h_, w_ = g.shape
    ox, oy, c = (0.0, 0.0, 1.0) if frame is None else (frame.x0_m, frame.y0_m, frame.cell_m)
    ax.imshow(shown, origin="lower", cmap="gray", vmin=0, vmax=1, interpolation="nearest",
              extent=(ox - c / 2, ox + (w_ - 0.5) * c, oy - c / 2, oy + (h_ - 0.5) * c))
    if truth is not None:
        ax.plot(truth[:, 0], truth[:, 1], **STYLE["truth"], label="true path")
    if estimate is not None:
        ax.plot(estimate[:, 0], estimate[:, 1], **{**STYLE["estimate"], "linestyle": "--"}, label="Hough SLAM")
    if truth is not None or estimate is not None:
        ax.legend(loc="upper right", fontsize=8)
    return ax


def sim_figure(result):
    """004's experiment: error curves (Fig. 10), the comparison with odometry and ICP, the built map (Fig. 11).

    Parameters
    ----------
    result : SimSlamResult
        From :func:`~slamlab.hough.run_sim_slam`.

    Returns
    -------
    matplotlib.figure.Figure
    """
    fig, axs = plt.subplots(1, 3, figsize=(17, 5))
    plot_pose_errors(result.errors["Hough SLAM"], ax=axs[0])
    ax = new_axes(axs[1], title="Position error: Hough SLAM vs odometry and ICP (our addition)", xlabel="pose n",
                  ylabel="position error [cells]")
    colors = {"Hough SLAM": "tab:blue", "odometry": "tab:orange", "ICP": "tab:purple"}
    for name, e in result.errors.items():
        ax.plot(np.hypot(e[:, 0], e[:, 1]), color=colors.get(name), label=name)
    ax.set_yscale("symlog", linthresh=0.1)
    ax.legend(loc="upper left")
    plot_built_map(result.built_map, truth=result.truth, estimate=result.slam.poses, ax=axs[2])
    fig.tight_layout()
    return fig


def real_log_figure(result, *, every: int = 2):
    """A real log: the map and path from Hough SLAM beside those from integrated odometry.

    Parameters
    ----------
    result : RealLogResult
        From :func:`~slamlab.hough.run_real_log`.
    every : int, default 2
        Draw the points of every ``every``-th scan.

    Returns
    -------
    matplotlib.figure.Figure
    """
    fig, axs = plt.subplots(1, 2, figsize=(14, 6.5))
    for ax, poses, name, color in ((axs[0], result.slam.poses, "Hough SLAM", STYLE["estimate"]["color"]),
                                   (axs[1], result.odometry, "integrated odometry", "tab:orange")):
        pts = [s.points(poses[k]) for k, s in enumerate(result.scans) if k % every == 0]
        pts = np.concatenate(pts) if pts else np.empty((0, 2))
        ax = new_axes(ax, title=f"{name}", xlabel="x [m]", ylabel="y [m]", equal=True)
        ax.plot(pts[:, 0], pts[:, 1], ",", color="0.15", alpha=0.5)
        ax.plot(poses[:, 0], poses[:, 1], "-", color=color, lw=1.5, label=f"{name} path")
        ax.plot(poses[0, 0], poses[0, 1], "go", label="start")
        ax.legend(loc="upper right", fontsize=8)
    fig.suptitle(result.name)
    fig.tight_layout()
    return fig
