"""Plots of Ch. 1's study results (000 §1.2): a constant-velocity run, the unicycle paths with covariance
ellipses, the Joseph form against the short form, and the figures that put them beside the NEES."""

from __future__ import annotations

import matplotlib.pyplot as plt
import numpy as np

from ...filters.plot import FILTER_COLORS, plot_nees
from ...geometry import covariance_ellipse
from ...plotting import STYLE, new_axes

__all__ = ["cv_figure", "plot_cv_example", "plot_joseph", "plot_unicycle_paths", "unicycle_figure"]


def plot_cv_example(result, *, ax=None, ellipse_every: int = 5):
    """One run of the constant-velocity target: truth, measurements, KF estimate.

    Parameters
    ----------
    result : CVTargetResult
        Its ``example_*`` fields are drawn.
    ax : matplotlib.axes.Axes, optional
        Axes to draw on; None makes a new figure.
    ellipse_every : int, default 5
        Accepted for symmetry with :func:`plot_unicycle_paths`; this plot draws no ellipses.

    Returns
    -------
    matplotlib.axes.Axes
    """
    ax = new_axes(ax, title="Constant-velocity target (one run)", xlabel="x [m]", ylabel="y [m]", equal=True)
    X, Z, E = result.example_truth, result.example_meas, result.example_est
    ax.plot(X[:, 0], X[:, 2], **STYLE["truth"], label="truth")
    ax.plot(Z[:, 0], Z[:, 1], **STYLE["measurement"], label="measurement")
    ax.plot(E[:, 0], E[:, 2], **STYLE["estimate"], label="KF estimate")
    ax.legend(loc="best")
    return ax


def plot_unicycle_paths(result, *, ax=None, ellipse_every: int = 10, n_std: float = 2.0):
    """First Monte Carlo run: true path, each filter's estimate, 2-sigma position ellipses, landmarks.

    Parameters
    ----------
    result : UnicycleResult
        Its first run, filters and landmarks are drawn.
    ax : matplotlib.axes.Axes, optional
        Axes to draw on; None makes a new figure.
    ellipse_every : int, default 10
        Draw an ellipse every this many steps.
    n_std : float, default 2.0
        Ellipse size in standard deviations.

    Returns
    -------
    matplotlib.axes.Axes
    """
    ax = new_axes(ax, title="Unicycle with range-bearing landmarks (run 1)", xlabel="x [m]", ylabel="y [m]",
                  equal=True)
    X = result.example_truth
    ax.plot(X[:, 0], X[:, 1], **STYLE["truth"], label="truth")
    lm = result.landmarks_m
    ax.plot(lm[:, 0], lm[:, 1], **STYLE["landmark"], label="landmarks")
    for i, name in enumerate(result.filters):
        E, P = result.example_est[i], result.example_P[i]
        if not np.all(np.isfinite(E)):
            continue
        color = FILTER_COLORS.get(name)
        ax.plot(E[:, 0], E[:, 1], color=color, linewidth=1.2, label=name)
        for k in range(0, len(E), ellipse_every):
            pts = covariance_ellipse(P[k, :2, :2], E[k, :2], n_std=n_std)
            ax.plot(*np.vstack([pts, pts[:1]]).T, color=color, linewidth=0.6, alpha=0.6)
    lim_lo = np.minimum(X[:, :2].min(axis=0), lm.min(axis=0)) - 2.0
    lim_hi = np.maximum(X[:, :2].max(axis=0), lm.max(axis=0)) + 2.0
    ax.set_xlim(lim_lo[0], lim_hi[0])
    ax.set_ylim(lim_lo[1], lim_hi[1])
    ax.set_aspect("equal", adjustable="box")
    ax.legend(loc="upper left", fontsize=8)
    return ax


def plot_joseph(result, *, ax=None):
    """Posterior variance vs gain scale: short form, Joseph form, sampled truth.

    Parameters
    ----------
    result : JosephResult
        From :func:`~slamlab.studies.filters.run_joseph_vs_short`.
    ax : matplotlib.axes.Axes, optional
        Axes to draw on; None makes a new figure.

    Returns
    -------
    matplotlib.axes.Axes
    """
    ax = new_axes(ax, title="Covariance update with a scaled gain", xlabel="K / K_opt",
                  ylabel="posterior position variance [m²]")
    g = result.gain_scales
    ax.plot(g, result.var_short, "o-", color="tab:red", label="short (I-KH)P")
    ax.plot(g, result.var_joseph, "s-", color="tab:blue", label="Joseph")
    ax.plot(g, result.var_sampled, "k+", markersize=10, label="sampled error variance")
    ax.axvline(1.0, color="0.5", linestyle=":")
    ax.legend(loc="best")
    return ax


def unicycle_figure(result):
    """Paths and NEES side by side (used by the widget).

    Parameters
    ----------
    result : UnicycleResult
        From :func:`~slamlab.studies.filters.run_unicycle_comparison`.

    Returns
    -------
    matplotlib.figure.Figure
    """
    fig, axes = plt.subplots(1, 2, figsize=(11, 4.2))
    plot_unicycle_paths(result, ax=axes[0])
    plot_nees(result.anees, result.nees_bounds, labels=list(result.filters), ax=axes[1], dim=3)
    fig.tight_layout()
    return fig


def cv_figure(result):
    """One constant-velocity run and the KF's NEES side by side.

    Parameters
    ----------
    result : CVTargetResult
        From :func:`~slamlab.studies.filters.run_cv_target`.

    Returns
    -------
    matplotlib.figure.Figure
    """
    fig, axes = plt.subplots(1, 2, figsize=(11, 4.2))
    plot_cv_example(result, ax=axes[0])
    plot_nees(result.anees, result.nees_bounds, labels=["KF"], ax=axes[1], dim=4, title="KF NEES (expect 4)")
    fig.tight_layout()
    return fig
