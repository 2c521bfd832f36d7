"""Plots for Ch. 1 (filters): a filter's NEES (or NIS) against its chi-square bounds.

The plots of the chapter's study results (paths with covariance ellipses, the Joseph form) are in
:mod:`slamlab.studies.filters.plot`.
"""

from __future__ import annotations

import numpy as np

from ..plotting import new_axes

__all__ = ["plot_nees"]

FILTER_COLORS = {"LKF": "tab:red", "EKF": "tab:orange", "UKF-aug": "tab:blue", "UKF-add": "tab:purple",
                  "KF": "tab:blue"}


def plot_nees(anees, bounds, *, labels=None, ax=None, dim: int | None = None, title: str = "NEES"):
    """Run-averaged NEES (or NIS) per step with its chi-square interval; log scale when it explodes.

    Parameters
    ----------
    anees : array_like, shape (n_steps,) or (n_filters, n_steps)
        Run-averaged NEES, one row per filter.
    bounds : tuple of float
        Chi-square interval ``(lo, hi)``, shaded.
    labels : list of str, optional
        Filter name per row (also picks its colour).
    ax : matplotlib.axes.Axes, optional
        Axes to draw on; None makes a new figure.
    dim : int, optional
        Expected value, drawn as a dotted line.
    title : str, default "NEES"
        Axes title.

    Returns
    -------
    matplotlib.axes.Axes
    """
    anees = np.atleast_2d(np.asarray(anees, dtype=float))
    ax = new_axes(ax, title=title, xlabel="step", ylabel="run-averaged NEES")
    labels = labels or [None] * len(anees)
    steps = np.arange(1, anees.shape[1] + 1)
    for a, lab in zip(anees, labels, strict=True):
        ax.plot(steps, a, color=FILTER_COLORS.get(lab), label=lab, linewidth=1.2)
    lo, hi = bounds
    ax.axhspan(lo, hi, color="0.85", alpha=0.6, label="95% interval", zorder=0)
    if dim is not None:
        ax.axhline(dim, color="0.4", linestyle=":", linewidth=1.0)
    if np.nanmax(anees) > 20 * hi:
        ax.set_yscale("log")
    ax.legend(loc="best")
    return ax
