"""Plots for Ch. 5 (004 §7): maps, the scan's stamps T_n, a localised scan, its score map and heading profile."""

from __future__ import annotations

import matplotlib.pyplot as plt
import numpy as np
from matplotlib.colors import ListedColormap

from ..plotting import STYLE, new_axes

__all__ = [
    "localisation_figure",
    "plot_grid",
    "plot_grids",
    "plot_heading_profile",
    "plot_localisation",
    "plot_score_map",
    "plot_stamp",
    "plot_stamps",
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
        One image of :func:`~slamlab.correlation.scan_stamps`.
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


def pose_arrow(ax, pose, length, **kw):
    """Draw a pose ``(x, y, θ)`` as an arrow of ``length`` along its heading (004 §7's figures).

    Parameters
    ----------
    ax : matplotlib Axes
        Where to draw.
    pose : array_like, shape (3,)
        ``(x, y, θ)`` in the axes' units and radians.
    length : float
        The arrow's length, in the axes' units.
    **kw
        Arrow properties (``color``, ...).
    """
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
        pose_arrow(ax, truth, 12, color="black")
    ax.plot(loc.pose[0], loc.pose[1], "x", color=STYLE["estimate"]["color"], ms=9, mew=2, label="estimate")
    pose_arrow(ax, loc.pose, 12, color=STYLE["estimate"]["color"])
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
