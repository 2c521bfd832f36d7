"""Plots of Ch. 4's runs (000 §3.7): a run's path and landmark map, its error curves, and the KITTI path from above."""

from __future__ import annotations

import matplotlib.pyplot as plt
import numpy as np

from ...plotting import STYLE, new_axes

__all__ = ["plot_kitti", "plot_run_errors", "plot_run_map", "run_figure"]


def plot_run_map(result, *, ax=None, every: int = 1):
    """Estimated path, true path and the base landmarks in the map frame (000 §3.7.2, Fig. 11).

    Parameters
    ----------
    result : StereoRunResult
        The run.
    ax : matplotlib.axes.Axes, optional
        Axes to draw on; None makes a new figure.
    every : int, default 1
        Draw every ``every``-th landmark.

    Returns
    -------
    matplotlib.axes.Axes
    """
    ax = new_axes(ax, title=f"{result.name}: path and landmark map", xlabel="x [m]", ylabel="y [m]", equal=True)
    L = result.landmarks_xy
    ax.plot(L[::every, 0], L[::every, 1], ".", color="tab:gray", markersize=1, label=f"landmarks ({len(L)})")
    ax.plot(*result.truth[:, :2].T, **STYLE["truth"], label="truth")
    ax.plot(*result.estimate[:, :2].T, **{**STYLE["estimate"], "marker": "."}, label=f"estimate ({result.policy})")
    e = result.estimate
    ax.quiver(e[::4, 0], e[::4, 1], np.cos(e[::4, 2]), np.sin(e[::4, 2]), color="tab:blue", scale=25, width=0.004)
    ax.legend(loc="best", fontsize=8)
    return ax


def plot_run_errors(result, *, axes=None, label: str | None = None):
    """Position and heading error per frame against the ground truth.

    Parameters
    ----------
    result : StereoRunResult
        The run.
    axes : sequence of two matplotlib.axes.Axes, optional
        None makes a new figure.
    label : str, optional
        Legend label (default detector and policy).

    Returns
    -------
    sequence of matplotlib.axes.Axes
    """
    if axes is None:
        _fig, axes = plt.subplots(1, 2, figsize=(11, 3.5))
    label = label or f"{result.detector}, {result.policy}"
    axes[0].plot(result.pos_err_m, label=label)
    axes[0].set_xlabel("frame")
    axes[0].set_ylabel("position error [m]")
    axes[1].plot(np.rad2deg(result.yaw_err_rad), label=label)
    axes[1].set_xlabel("frame")
    axes[1].set_ylabel("heading error [deg]")
    for a in axes:
        a.grid(True, alpha=0.3)
        a.legend(loc="best", fontsize=8)
    return axes


def run_figure(result, *, others=()):
    """Map of the run on top, error curves below (``others``: more results drawn on the error axes).

    Parameters
    ----------
    result : StereoRunResult
        The run drawn on the map.
    others : sequence of StereoRunResult
        More runs drawn on the error axes.

    Returns
    -------
    matplotlib.figure.Figure
    """
    fig = plt.figure(figsize=(11, 7.5))
    gs = fig.add_gridspec(2, 2, height_ratios=(2, 1))
    plot_run_map(result, ax=fig.add_subplot(gs[0, :]))
    axes = [fig.add_subplot(gs[1, 0]), fig.add_subplot(gs[1, 1])]
    for r in (result, *others):
        plot_run_errors(r, axes=axes)
    fig.tight_layout()
    return fig


def plot_kitti(result, *, ax=None):
    """KITTI run seen from above: the left camera's path (x right, z forward) against the ground truth.

    Parameters
    ----------
    result : KittiRunResult
        From :func:`~slamlab.studies.stereo.run_kitti`.
    ax : matplotlib.axes.Axes, optional
        Axes to draw on; None makes a new figure.

    Returns
    -------
    matplotlib.axes.Axes
    """
    ax = new_axes(ax, title="KITTI 06, frames 0-19: path from above", xlabel="x [m]", ylabel="z (forward) [m]",
                  equal=True)  # fmt: skip
    gt, est = result.truth[:, :3, 3], result.estimate[:, :3, 3]
    ax.plot(gt[:, 0], gt[:, 2], **{**STYLE["truth"], "marker": "."}, label="ground truth")
    ax.plot(est[:, 0], est[:, 2], **{**STYLE["estimate"], "marker": "."}, label="estimate")
    ax.plot(gt[0, 0], gt[0, 2], "o", color="black", label="start")
    ax.legend(loc="best", fontsize=8)
    return ax
