"""Figures of Ch. 6's studies (004 §Hough SLAM): 004's example (Fig. 5-8), error curves (Fig. 10), the simulated
run (Fig. 10-11) and the real logs."""

from __future__ import annotations

import matplotlib.pyplot as plt
import numpy as np

from ...hough.plot import plot_accumulator, plot_built_map, plot_scan_lines
from ...plotting import STYLE, new_axes

__all__ = [
    "example_figure",
    "plot_pose_errors",
    "real_log_figure",
    "sim_figure",
]

#: 004 Fig. 10's colours: Ea green, Ex blue, Ey red.
_ERR_COLORS = {"Ex": "tab:blue", "Ey": "tab:red", "Ea": "tab:green"}


def example_figure(result):
    """004 Fig. 5-8: the scan of the line θ = 45°, p = 10, its 33×33 image, both accumulators.

    Parameters
    ----------
    result : ExampleLineResult
        From :func:`~slamlab.studies.hough.run_example_line`.

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
        ``(Ex, Ey, Ea)`` per pose (:func:`~slamlab.studies.hough.pose_errors`).
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


def sim_figure(result):
    """004's experiment: error curves (Fig. 10), the comparison with odometry and ICP, the built map (Fig. 11).

    Parameters
    ----------
    result : SimSlamResult
        From :func:`~slamlab.studies.hough.run_sim_slam`.

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
        From :func:`~slamlab.studies.hough.run_real_log`.
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
