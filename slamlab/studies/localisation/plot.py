"""Plots of Ch. 8's studies (003 §2.2): recorded runs (clouds, errors), global localisation, the CARMEN logs."""

from __future__ import annotations

import matplotlib.pyplot as plt
import numpy as np

from ...localisation.plot import plot_averages, plot_map, plot_particles, plot_weights
from ...plotting import STYLE, new_axes

__all__ = [
    "mcl_figure",
    "plot_clouds",
    "plot_errors",
    "plot_global",
    "plot_log_run",
    "recorded_step_figure",
]


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
    ax = new_axes(ax, xlabel="step", ylabel="share of runs", title="Global localisation")
    k = np.arange(1, result.n_steps + 1)
    for i, n in enumerate(sorted(result.table_df["n_particles"].unique())):
        ok, converged = result.step_shares(n)
        c = f"C{i}"
        ax.plot(k, ok, "-", color=c, label=f"{n} particles: within 3 cells, 5°")
        ax.plot(k, converged, ":", color=c, label=f"{n}: amcl converged")
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
