"""Drawing the localisation chapter: particle clouds over the map, weights, w_slow/w_fast, beliefs, tables' plots."""

from __future__ import annotations

import matplotlib.pyplot as plt
import numpy as np
from matplotlib.colors import ListedColormap

from ..plotting import STYLE, new_axes

__all__ = [
    "mcl_figure",
    "plot_averages",
    "plot_belief",
    "plot_clouds",
    "plot_errors",
    "plot_global",
    "plot_log_run",
    "plot_map",
    "plot_particles",
    "plot_weights",
    "recorded_step_figure",
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


def plot_clouds(run, result, steps=(0, 3, 10, -1), *, axes=None):
    """The weighted particle cloud at chosen steps of a recorded run (``result.snapshots``).

    Parameters
    ----------
    run : SimRun
        The run.
    result : FilterRun
        Its recorded filter run (with snapshots).
    steps : sequence of int
        Steps to show (negative: from the end).
    axes : sequence of matplotlib Axes, optional
        One per step.

    Returns
    -------
    sequence of matplotlib Axes
    """
    steps = [s if s >= 0 else run.n_steps + s for s in steps]
    if axes is None:
        _fig, axes = plt.subplots(1, len(steps), figsize=(3.2 * len(steps), 3.4))
    for ax, k in zip(np.atleast_1d(axes), steps, strict=True):
        X, w = result.snapshots[k]
        plot_particles(run.grid, X, w, true_pose=run.true_poses[k], estimate=result.est[k], ax=ax,
                       title=f"step {k}: err {result.err_pos[k]:.1f} cells")
        ax.set_xticks([])
        ax.set_yticks([])
    return axes


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
    result : FilterRun
        An MCL run.
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


def plot_errors(result, *, ax=None, kidnap_step=None, label="MCL"):
    """Position error [cells] against the step.

    Parameters
    ----------
    result : FilterRun
        A filter run.
    ax : matplotlib Axes, optional
        Where to draw.
    kidnap_step : int, optional
        Marked with a vertical line.
    label : str
        The line's label.

    Returns
    -------
    matplotlib Axes
    """
    ax = new_axes(ax, xlabel="step", ylabel="position error [cells]", title="Error against the truth")
    ax.semilogy(np.maximum(result.err_pos, 1e-2), label=label)
    if kidnap_step is not None:
        ax.axvline(kidnap_step, color="k", linestyle=":")
    ax.legend()
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


def plot_global(result, *, ax=None):
    """Success (solid) and amcl's convergence test (dotted) against the step, one line per particle count.

    Parameters
    ----------
    result : GlobalResult
        A global-localisation study.
    ax : matplotlib Axes, optional
        Where to draw.

    Returns
    -------
    matplotlib Axes
    """
    from .studies import _per_step

    ax = new_axes(ax, xlabel="step", ylabel="share of runs", title="Global localisation")
    df = result.table_df
    for i, n in enumerate(sorted(df["n_particles"].unique())):
        g = df[df["n_particles"] == n]
        k = np.arange(1, result.n_steps + 1)
        c = f"C{i}"
        ax.plot(k, _per_step(g, "ok").mean(axis=0), "-", color=c, label=f"{n} particles: within 3 cells, 5°")
        ax.plot(k, _per_step(g, "conv").mean(axis=0), ":", color=c, label=f"{n}: amcl converged")
    ax.set_ylim(-0.05, 1.05)
    ax.legend(fontsize=7, loc="lower right")
    return ax


def plot_log_run(result, *, ax=None):
    """A CARMEN run: the map, the corrected path, odometry, tracking and global estimates (metres).

    Parameters
    ----------
    result : LogMCLResult
        A run on a CARMEN log.
    ax : matplotlib Axes, optional
        Where to draw.

    Returns
    -------
    matplotlib Axes
    """
    f = result.frame
    H, W = result.grid_shape
    ext = (f.x0_m - f.cell_m / 2, f.x0_m + (W - 0.5) * f.cell_m, f.y0_m - f.cell_m / 2, f.y0_m + (H - 0.5) * f.cell_m)
    ax = plot_map(result.grid, ax=ax, extent=ext)
    ax.plot(*result.true_m[:, :2].T, **STYLE["truth"], label="corrected")
    ax.plot(*result.odo_m[:, :2].T, color="tab:gray", linestyle="--", label="noisy odometry")
    ax.plot(*result.track_m[:, :2].T, color="tab:blue", label="MCL tracking")
    ax.plot(*result.global_m[:, :2].T, color="tab:orange", marker=".", linestyle="none", markersize=3,
            label="MCL global")
    lo = np.minimum(result.true_m[:, :2].min(axis=0), result.track_m[:, :2].min(axis=0)) - 3
    hi = np.maximum(result.true_m[:, :2].max(axis=0), result.track_m[:, :2].max(axis=0)) + 3
    ax.set_xlim(lo[0], hi[0])
    ax.set_ylim(lo[1], hi[1])
    ax.set_title(result.name.split("-")[0])
    ax.legend(fontsize=7)
    return ax


def mcl_figure(run, result):
    """Last step's cloud, the error and w_slow/w_fast/injected against the step, side by side.

    Parameters
    ----------
    run : SimRun
        The run.
    result : FilterRun
        Its recorded MCL run.

    Returns
    -------
    matplotlib Figure
    """
    fig, ax = plt.subplots(1, 3, figsize=(13, 3.8))
    X, w = result.snapshots[-1]
    plot_particles(run.grid, X, w, true_pose=run.true_poses[-1], estimate=result.est[-1], ax=ax[0],
                   title="last step")
    plot_errors(result, ax=ax[1], kidnap_step=run.kidnap_step)
    plot_averages(result, ax=ax[2], kidnap_step=run.kidnap_step)
    fig.tight_layout()
    return fig


def recorded_step_figure(run, result, step: int):
    """One step of a recorded run: the weighted cloud and the histogram of its weights.

    Parameters
    ----------
    run : SimRun
        The run.
    result : FilterRun
        Its recorded MCL run (with snapshots).
    step : int
        The step to show.

    Returns
    -------
    matplotlib Figure
    """
    fig, ax = plt.subplots(1, 2, figsize=(10, 4))
    X, w = result.snapshots[step]
    plot_particles(run.grid, X, w, true_pose=run.true_poses[step], estimate=result.est[step], ax=ax[0],
                   title=f"step {step}")
    plot_weights(w, ax=ax[1], title="weights before resampling")
    fig.tight_layout()
    return fig
