"""Plots for Ch. 5 (004 §7): maps, localised scans, score maps, Table 1, error distributions, a real CARMEN log."""

from __future__ import annotations

import matplotlib.pyplot as plt
import numpy as np
from matplotlib.colors import ListedColormap

from ..plotting import STYLE, new_axes

__all__ = [
    "constants_figure",
    "localisation_figure",
    "plot_error_distribution",
    "plot_grid",
    "plot_grids",
    "plot_heading_profile",
    "plot_localisation",
    "plot_log_localisation",
    "plot_score_map",
    "plot_stamp",
    "plot_stamps",
    "plot_table1",
]

# unexplored (-1) light grey, free (0) white, obstacle (1) black
_GRID_CMAP = ListedColormap(["0.82", "white", "black"])


def plot_grid(grid, *, ax=None, extent=None, title: str | None = None, figsize=None, **kw):
    """Occupancy grid with 004's colours: free white, obstacle black, unexplored grey; ``origin="lower"``.

    Parameters
    ----------
    grid : array_like of int, shape (H, W)
        Cell codes.
    ax : matplotlib.axes.Axes, optional
        Axes to draw on; None makes a new figure.
    extent : tuple of float, optional
        ``(left, right, bottom, top)`` in metres; None labels the axes in cells.
    title : str, optional
        Axes title.
    figsize : tuple of float, optional
        Size of a new figure [in].
    **kw
        Passed to ``imshow``.

    Returns
    -------
    matplotlib.axes.Axes
    """
    ax = new_axes(ax, title=title, figsize=figsize, xlabel="x [cells]" if extent is None else "x [m]",
                  ylabel="y [cells]" if extent is None else "y [m]")
    ax.imshow(np.asarray(grid), origin="lower", cmap=_GRID_CMAP, vmin=-1.5, vmax=1.5, interpolation="nearest",
              extent=extent, **kw)
    return ax


def plot_stamp(T_n, origin: int, *, a_c: float = -1.0, a_p: float = 1.0, ax=None, title=None):
    """One image T_n of 004 §7 with the map's colours: a_c white, a_p black, a_n grey; robot cell marked.

    Parameters
    ----------
    T_n : array_like, shape (S, S)
        One image of :func:`~slamlab.correlation.rasterise_scan`.
    origin : int
        The robot's cell ``T_n[origin, origin]``.
    a_c, a_p : float
        The values drawn white and black.
    ax : matplotlib.axes.Axes, optional
        Axes to draw on; None makes a new figure.
    title : str, optional
        Axes title.

    Returns
    -------
    matplotlib.axes.Axes
    """
    T_n = np.asarray(T_n)
    codes = np.select([T_n == a_c, T_n == a_p], [0, 1], -1)
    ax = plot_grid(codes, ax=ax, title=title)
    ax.set_xlabel("column of T_n")
    ax.set_ylabel("row of T_n")
    ax.plot(origin, origin, "+", color="tab:red", ms=12, mew=2)
    return ax


def plot_stamps(T, origin: int, headings_deg=(0, 30, 135), *, a_c: float = -1.0, a_p: float = 1.0):
    """Several images T_n side by side (004 §7), one per heading index in ``headings_deg``; returns the figure.

    Parameters
    ----------
    T : array_like, shape (n, S, S)
        Images at 1° headings (index = heading in degrees).
    origin : int
        The robot's cell.
    headings_deg : sequence of int
        Heading indices to draw.
    a_c, a_p : float
        The values drawn white and black.

    Returns
    -------
    matplotlib.figure.Figure
    """
    headings = tuple(int(n) for n in headings_deg)
    fig, axes = plt.subplots(1, len(headings), figsize=(4.7 * len(headings), 4.6), squeeze=False)
    for ax, n in zip(axes[0], headings, strict=True):
        plot_stamp(T[n], origin, a_c=a_c, a_p=a_p, ax=ax, title=f"T_n at α0n = {n}° (a_c white, a_p black, a_n grey)")
    fig.tight_layout()
    return fig


def plot_grids(grids, titles):
    """Grids side by side with 004's colours (:func:`plot_grid`); returns the figure.

    Parameters
    ----------
    grids : sequence of array_like
        Cell-code grids.
    titles : sequence of str
        One title per grid.

    Returns
    -------
    matplotlib.figure.Figure
    """
    grids, titles = list(grids), list(titles)
    if len(grids) != len(titles):
        raise ValueError(f"`titles` must have one entry per grid ({len(grids)}); got {len(titles)}")
    fig, axes = plt.subplots(1, len(grids), figsize=(5.5 * len(grids), 5.2), squeeze=False)
    for ax, g, t in zip(axes[0], grids, titles, strict=True):
        plot_grid(g, ax=ax, title=t)
    fig.tight_layout()
    return fig


def _pose_arrow(ax, pose, length, **kw):
    ax.annotate("", xy=(pose[0] + length * np.cos(pose[2]), pose[1] + length * np.sin(pose[2])),
                xytext=(pose[0], pose[1]), arrowprops=dict(arrowstyle="->", lw=1.8, **kw))


def plot_localisation(grid, scan, loc, truth=None, *, ax=None, title="Scan drawn at the estimated pose"):
    """The map, the scan's returns drawn from the estimated pose, the true and estimated poses.

    Parameters
    ----------
    grid : array_like of int, shape (H, W)
        The map.
    scan : Scan
        The localised scan in cell units.
    loc : Localisation
        Result of :func:`~slamlab.correlation.localise`.
    truth : array_like, shape (3,), optional
        True pose ``(x, y)`` [cells], heading [rad].
    ax : matplotlib.axes.Axes, optional
        Axes to draw on; None makes a new figure.
    title : str
        Axes title.

    Returns
    -------
    matplotlib.axes.Axes
    """
    ax = plot_grid(grid, ax=ax, title=title)
    pts = scan.points(loc.pose)
    ax.plot(pts[:, 0], pts[:, 1], **{**STYLE["measurement"], "markersize": 2.5}, label="scan at estimate")
    if truth is not None:
        ax.plot(truth[0], truth[1], "o", color="black", mfc="none", ms=9, label="true pose")
        _pose_arrow(ax, truth, 12, color="black")
    ax.plot(loc.pose[0], loc.pose[1], "x", color=STYLE["estimate"]["color"], ms=9, mew=2, label="estimate")
    _pose_arrow(ax, loc.pose, 12, color=STYLE["estimate"]["color"])
    ax.legend(loc="upper left", fontsize=8, framealpha=0.9)
    return ax


def plot_score_map(loc, *, ax=None, title=None):
    """The correlation scores D_n(row, col) at the best heading, with the peak marked.

    Parameters
    ----------
    loc : Localisation
        Result of :func:`~slamlab.correlation.localise`.
    ax : matplotlib.axes.Axes, optional
        Axes to draw on; None makes a new figure.
    title : str, optional
        Axes title (default names the best heading).

    Returns
    -------
    matplotlib.axes.Axes
    """
    ax = new_axes(ax, title=title or f"Scores at heading {np.degrees(loc.pose[2]):.0f}°", xlabel="x [cells]",
                  ylabel="y [cells]")
    im = ax.imshow(loc.score_map, origin="lower", cmap="viridis", interpolation="nearest")
    ax.plot(loc.col, loc.row, "+", color="red", ms=12, mew=2)
    ax.figure.colorbar(im, ax=ax, shrink=0.8, label="C_n")
    return ax


def plot_heading_profile(loc, truth_heading_rad=None, *, ax=None):
    """The best score of every candidate heading (the maximum over each D_n).

    Parameters
    ----------
    loc : Localisation
        Result of :func:`~slamlab.correlation.localise`.
    truth_heading_rad : float, optional
        True heading [rad], drawn dotted.
    ax : matplotlib.axes.Axes, optional
        Axes to draw on; None makes a new figure.

    Returns
    -------
    matplotlib.axes.Axes
    """
    ax = new_axes(ax, title="Best score per heading", xlabel="heading [deg]", ylabel="max C_n")
    ax.plot(np.degrees(loc.headings_rad), loc.best_per_heading, color=STYLE["estimate"]["color"], lw=1.2)
    ax.axvline(np.degrees(loc.headings_rad[loc.heading_index]), color="red", lw=1, ls="--", label="estimate")
    if truth_heading_rad is not None:
        th = np.degrees(np.mod(truth_heading_rad, 2 * np.pi)) if loc.headings_rad.min() >= 0 \
            else np.degrees(truth_heading_rad)
        ax.axvline(th, color="black", lw=1, ls=":", label="truth")
    ax.legend(loc="best", fontsize=8)
    return ax


def localisation_figure(grid, scan, loc, truth=None):
    """Map with the localised scan, the score map at the best heading and the heading profile.

    Parameters
    ----------
    grid : array_like of int, shape (H, W)
        The map.
    scan : Scan
        The localised scan in cell units.
    loc : Localisation
        Result of :func:`~slamlab.correlation.localise`.
    truth : array_like, shape (3,), optional
        True pose.

    Returns
    -------
    matplotlib.figure.Figure
    """
    fig, axes = plt.subplots(1, 3, figsize=(15, 4.6), gridspec_kw={"width_ratios": [1, 1.15, 1.1]})
    plot_localisation(grid, scan, loc, truth, ax=axes[0])
    plot_score_map(loc, ax=axes[1])
    plot_heading_profile(loc, None if truth is None else truth[2], ax=axes[2])
    fig.tight_layout()
    return fig


def plot_table1(result, grid, *, ax=None):
    """Table 1 poses on the map: truth (black circles) and estimates (blue crosses), with headings.

    Parameters
    ----------
    result : Table1Result
        From :func:`~slamlab.correlation.run_table1`.
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
        _pose_arrow(ax, t, 10, color="black")
        ax.plot(e[0], e[1], "x", color=STYLE["estimate"]["color"], ms=8, mew=2)
        _pose_arrow(ax, e, 10, color=STYLE["estimate"]["color"])
        ax.annotate(str(i + 1), (t[0] + 3, t[1] + 3), fontsize=9, color="tab:red")
    return ax


def plot_error_distribution(result, *, axes=None):
    """Monte Carlo: histogram of heading errors [deg] and of position errors [cells].

    Parameters
    ----------
    result : MonteCarloResult
        From :func:`~slamlab.correlation.run_monte_carlo`.
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
        From :func:`~slamlab.correlation.run_constants_study`.
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
        From :func:`~slamlab.correlation.run_log_localisation`.
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
