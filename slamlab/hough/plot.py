"""Plots for Ch. 6 (Hough SLAM) of the algorithm's own objects: accumulators, scans with their lines, built maps
(cf. 004 Fig. 11). The figures of notebook 07's experiments live one layer up, in the chapter's study package."""

from __future__ import annotations

import math

import matplotlib.pyplot as plt
import numpy as np

from ..plotting import STYLE, new_axes
from .transform import HoughAccumulator

__all__ = [
    "accumulator_figure",
    "plot_accumulator",
    "plot_built_map",
    "plot_scan_lines",
]


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
