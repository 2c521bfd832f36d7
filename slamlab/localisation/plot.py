"""Drawing the localisation filters' own objects: the map, particle clouds, weights, w_slow/w_fast, the Markov belief."""

from __future__ import annotations

import numpy as np
from matplotlib.colors import ListedColormap

from ..plotting import STYLE, new_axes

__all__ = [
    "plot_averages",
    "plot_belief",
    "plot_map",
    "plot_particles",
    "plot_weights",
]

_MAP_CMAP = ListedColormap(["#dddddd", "white", "black"])  # unexplored, free, obstacle


def plot_map(grid, *, ax=None, extent=None):
    """The grid map (free white, obstacle black, unexplored grey), ``origin="lower"``.

    Parameters
    ----------
    grid : array_like, shape (H, W)
        The map.
    ax : matplotlib Axes, optional
        Where to draw (a new figure when None).
    extent : sequence of 4 float, optional
        imshow's extent (default: cells).

    Returns
    -------
    matplotlib Axes
    """
    ax = new_axes(ax)
    ax.set_aspect("equal", adjustable="box")  # fixed limits are set after: keep them, shape the box
    ax.imshow(np.asarray(grid) + 1, cmap=_MAP_CMAP, vmin=0, vmax=2, origin="lower", interpolation="nearest",
              extent=extent)
    return ax


def plot_particles(grid, particles, weights=None, *, true_pose=None, estimate=None, ax=None, title=None,
                   max_points: int = 3000):
    """Particles (coloured by weight when given) over the map, with the true pose and the estimate.

    Parameters
    ----------
    grid : array_like, shape (H, W)
        The map.
    particles : array_like, shape (N, 3)
        The particles (cells, rad).
    weights : array_like, shape (N,), optional
        Their weights (colour).
    true_pose, estimate : array_like, shape (3,), optional
        Poses to mark.
    ax : matplotlib Axes, optional
        Where to draw.
    title : str, optional
        The axes' title.
    max_points : int
        At most this many particles are drawn.

    Returns
    -------
    matplotlib Axes
    """
    ax = plot_map(grid, ax=ax)
    P = np.asarray(particles)
    step = max(1, P.shape[0] // max_points)
    c = None if weights is None else np.asarray(weights)[::step]
    colour = {"color": "tab:red"} if c is None else {"c": c, "cmap": "viridis"}
    ax.scatter(P[::step, 0], P[::step, 1], s=2, alpha=0.6, linewidths=0, **colour)
    for pose, style, label in ((true_pose, STYLE["truth"], "truth"), (estimate, STYLE["estimate"], "estimate")):
        if pose is not None:
            ax.plot(pose[0], pose[1], marker="o", color=style["color"], markersize=5, linestyle="none", label=label)
            ax.arrow(pose[0], pose[1], 8 * np.cos(pose[2]), 8 * np.sin(pose[2]), color=style["color"], width=0.8)
    if title:
        ax.set_title(title)
    ax.set_xlim(0, grid.shape[1] - 1)
    ax.set_ylim(0, grid.shape[0] - 1)
    return ax


def plot_weights(weights, *, ax=None, bins: int = 50, title=None):
    """Histogram of the normalised weights (log-scaled counts).

    Parameters
    ----------
    weights : array_like, shape (N,)
        The weights.
    ax : matplotlib Axes, optional
        Where to draw.
    bins : int
        Histogram bins.
    title : str, optional
        The axes' title.

    Returns
    -------
    matplotlib Axes
    """
    ax = new_axes(ax, xlabel="weight × M", ylabel="particles", title=title)
    w = np.asarray(weights)
    ax.hist(w * w.size, bins=bins, color="tab:blue", log=True)
    return ax


def plot_averages(result, *, ax=None, kidnap_step=None):
    """log w_avg, log w_slow, log w_fast and the injected count against the step (003 eqs 2.8-2.11).

    Parameters
    ----------
    result : MCL or FilterRun
        An MCL filter, or anything with its ``records`` (a list of
        :class:`~slamlab.localisation.StepRecord`), e.g. a study's recorded run.
    ax : matplotlib Axes, optional
        Where to draw.
    kidnap_step : int, optional
        Marked with a vertical line.

    Returns
    -------
    matplotlib Axes
    """
    ax = new_axes(ax, xlabel="step", ylabel="log of the average score",
                  title="w_avg, w_slow, w_fast (log) and injected particles")
    r = result.records
    k = np.arange(len(r))
    ax.plot(k, [x.log_w_avg for x in r], color="0.6", label="log w_avg (2.8)")
    ax.plot(k, [x.log_w_slow for x in r], color="tab:blue", label="log w_slow (2.9)")
    ax.plot(k, [x.log_w_fast for x in r], color="tab:orange", label="log w_fast (2.10)")
    ax2 = ax.twinx()
    ax2.bar(k, [x.n_injected for x in r], color="tab:red", alpha=0.35, label="injected (2.11)")
    ax2.set_ylabel("injected particles")
    if kidnap_step is not None:
        ax.axvline(kidnap_step, color="k", linestyle=":", label="kidnap")
    h1, l1 = ax.get_legend_handles_labels()
    h2, l2 = ax2.get_legend_handles_labels()
    ax.legend(h1 + h2, l1 + l2, loc="lower left", fontsize=8)
    return ax


def plot_belief(markov, *, true_pose=None, ax=None):
    """The Markov belief summed over headings, over the map.

    Parameters
    ----------
    markov : MarkovGrid
        The grid filter.
    true_pose : array_like, shape (3,), optional
        Marked on the map.
    ax : matplotlib Axes, optional
        Where to draw.

    Returns
    -------
    matplotlib Axes
    """
    ax = new_axes(ax, equal=True, title="Markov belief (sum over θ)")
    b = markov.belief.sum(axis=0)
    s = markov.params.resolution
    h, w = b.shape
    ax.imshow(markov.model.grid == 1, cmap="Greys", origin="lower", interpolation="nearest")
    ax.imshow(np.ma.masked_less_equal(b, b.max() * 1e-4), origin="lower", cmap="magma", alpha=0.8,
              extent=(-s / 2, (w - 0.5) * s, -s / 2, (h - 0.5) * s))
    if true_pose is not None:
        ax.plot(true_pose[0], true_pose[1], "c+", markersize=12)
    return ax
