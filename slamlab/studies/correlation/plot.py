"""Plots of Ch. 5's studies (004 §7): Table 1, the Monte Carlo errors, the constants a_c/a_p, a real CARMEN log."""

from __future__ import annotations

import matplotlib.pyplot as plt
import numpy as np

from ...correlation.plot import plot_grid, pose_arrow
from ...plotting import STYLE, new_axes

__all__ = ["constants_figure", "plot_error_distribution", "plot_log_localisation", "plot_table1"]


def plot_table1(result, grid, *, ax=None):
    """Table 1 poses on the map: truth (black circles) and estimates (blue crosses), with headings.

    Parameters
    ----------
    result : Table1Result
        From :func:`~slamlab.studies.correlation.run_table1`.
    grid : array_like of int, shape (H, W)
        The map.
    ax : matplotlib.axes.Axes, optional
        Axes to draw on; None makes a new figure.

    Returns
    -------
    matplotlib.axes.Axes
    """
    ax = plot_grid(grid, ax=ax, title="Table 1: true (o) and estimated (x) poses", figsize=(7, 7))
    for i, (t, e) in enumerate(zip(result.true_poses, result.est_poses, strict=True)):
        ax.plot(t[0], t[1], "o", color="black", mfc="none", ms=9)
        pose_arrow(ax, t, 10, color="black")
        ax.plot(e[0], e[1], "x", color=STYLE["estimate"]["color"], ms=8, mew=2)
        pose_arrow(ax, e, 10, color=STYLE["estimate"]["color"])
        ax.annotate(str(i + 1), (t[0] + 3, t[1] + 3), fontsize=9, color="tab:red")
    return ax


def plot_error_distribution(result, *, axes=None):
    """Monte Carlo: histogram of heading errors [deg] and of position errors [cells].

    Parameters
    ----------
    result : MonteCarloResult
        From :func:`~slamlab.studies.correlation.run_monte_carlo`.
    axes : sequence of two matplotlib.axes.Axes, optional
        None makes a new figure.

    Returns
    -------
    sequence of matplotlib.axes.Axes
    """
    if axes is None:
        _fig, axes = plt.subplots(1, 2, figsize=(11, 3.8))
    ea = np.degrees(result.err_heading_rad)
    bins = np.arange(0, max(2.0, min(ea.max(), 10.0)) + 0.125, 0.125)
    new_axes(axes[0], title="Heading error", xlabel="|error| [deg]", ylabel="poses")
    axes[0].hist(np.minimum(ea, bins[-1]), bins=bins, color=STYLE["estimate"]["color"], alpha=0.8)
    axes[0].axvline(0.5, color="0.3", ls=":", lw=1, label="half the 1° step")
    axes[0].axvline(np.degrees(0.0098), color="tab:red", ls="--", lw=1, label="004 max (0.56°)")
    axes[0].legend(fontsize=8)
    ep = result.err_pos_cells
    labels = ["0", "1", "√2", "(√2, 2]", "> 2 (failure)"]
    counts = [np.sum(ep == 0), np.sum(np.isclose(ep, 1.0)), np.sum(np.isclose(ep, np.sqrt(2))),
              np.sum((ep > np.sqrt(2) + 1e-9) & (ep <= 2.0)), np.sum(ep > 2.0)]
    new_axes(axes[1], title="Position error", xlabel="|error| [cells]", ylabel="poses")
    axes[1].bar(labels, counts, color=STYLE["estimate"]["color"], alpha=0.8)
    axes[0].figure.tight_layout()
    return axes


def constants_figure(result, grid):
    """Score maps of one scan at its true heading for each choice of constants.

    Parameters
    ----------
    result : ConstantsResult
        From :func:`~slamlab.studies.correlation.run_constants_study`.
    grid : array_like of int, shape (H, W)
        The map (not drawn; kept for a uniform call).

    Returns
    -------
    matplotlib.figure.Figure
    """
    k = len(result.labels)
    fig, axes = plt.subplots(1, k, figsize=(5.2 * k, 4.4))
    axes = np.atleast_1d(axes)
    p = result.example_pose
    for ax, lb, D in zip(axes, result.labels, result.example_maps, strict=True):
        new_axes(ax, title=lb, xlabel="x [cells]", ylabel="y [cells]")
        im = ax.imshow(D, origin="lower", cmap="viridis", interpolation="nearest")
        ax.plot(p[0], p[1], "o", color="red", mfc="none", ms=10, mew=1.5)
        fig.colorbar(im, ax=ax, shrink=0.8)
    fig.tight_layout()
    return fig


def plot_log_localisation(result, *, mode: int = 0, ax=None):
    """A log's grid (metres), the logged poses of the test scans, estimates of ``result.joined[mode]`` and the
    first scan at its single-mode estimate.

    Parameters
    ----------
    result : LogLocalisationResult
        From :func:`~slamlab.studies.correlation.run_log_localisation`.
    mode : int, default 0
        Index into ``result.joined``.
    ax : matplotlib.axes.Axes, optional
        Axes to draw on; None makes a new figure.

    Returns
    -------
    matplotlib.axes.Axes
    """
    f = result.frame
    extent = (f.x0_m - f.cell_m / 2, f.x0_m + (f.shape[1] - 0.5) * f.cell_m,
              f.y0_m - f.cell_m / 2, f.y0_m + (f.shape[0] - 0.5) * f.cell_m)
    k = result.joined[mode]
    what = "one scan" if k == 1 else f"{k} scans joined by odometry"
    ax = plot_grid(result.grid, ax=ax, extent=extent, title=f"{result.name}: grid from the logged poses, "
                   f"localised from {what}", figsize=(8, 8))
    if result.example_points_m is not None:
        pts = result.example_points_m
        ax.plot(pts[:, 0], pts[:, 1], **{**STYLE["measurement"], "markersize": 2.5},
                label=f"scan {result.scan_indices[0]} at its estimate")
    t, e = result.true_poses_m, result.est_poses_m[mode]
    ax.plot(t[:, 0], t[:, 1], "o", color="black", mfc="none", ms=9, label="logged pose")
    ok = result.success[mode]
    ax.plot(e[ok, 0], e[ok, 1], "x", color=STYLE["estimate"]["color"], ms=8, mew=2, label="estimate (ok)")
    if (~ok).any():
        ax.plot(e[~ok, 0], e[~ok, 1], "x", color="tab:red", ms=9, mew=2, label="estimate (failed)")
    for i, p in zip(result.scan_indices, t, strict=True):
        ax.annotate(str(i), (p[0] + 0.4, p[1] + 0.4), fontsize=8, color="tab:red")
    ax.legend(loc="upper left", fontsize=8, framealpha=0.9)
    return ax
