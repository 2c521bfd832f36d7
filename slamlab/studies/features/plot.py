"""Plots of the feature chapters' studies (Ch. 2, 3; 000 §1.4, §3.3): detector evaluation, recall, ratio test."""

from __future__ import annotations

import matplotlib.pyplot as plt
import numpy as np

from ...features.plot import DETECTOR_COLORS
from ...plotting import new_axes

__all__ = [
    "plot_pair_evaluation",
    "plot_ratio_tradeoff",
    "plot_recall_vs_leaves",
    "plot_surf_threshold",
]


def plot_pair_evaluation(result, *, axes=None):
    """Repeatability and matching precision per viewpoint step, one panel per sequence.

    Parameters
    ----------
    result : PairEvaluationResult
        From :func:`slamlab.studies.features.experiments.run_pair_evaluation`.
    axes : (2, n_sequences) array of matplotlib.axes.Axes, optional
        Axes to draw into.

    Returns
    -------
    (2, n_sequences) array of matplotlib.axes.Axes
    """
    n = len(result.sequences)
    if axes is None:
        _, axes = plt.subplots(2, n, figsize=(4.5 * n, 6), squeeze=False)
    axes = np.asarray(axes).reshape(2, n)
    for i, seq in enumerate(result.sequences):
        for row, (arr, name) in enumerate(((result.rep, "repeatability"), (result.precision, "precision"))):
            ax = axes[row, i]
            for k, det in enumerate(result.detectors):
                ax.plot(result.steps, arr[i, :, k], "o-", color=DETECTOR_COLORS.get(det), label=det)
            ax.set_title(f"{seq}: {name}")
            ax.set_xlabel("img1 → img j")
            ax.set_ylim(0, 1)
            ax.set_xticks(result.steps)
    axes[0, 0].legend(loc="best")
    plt.tight_layout()
    return axes


def plot_recall_vs_leaves(result, *, ax=None):
    """Recall of the true nearest neighbour against max_leaves (BBF) and checks (FLANN).

    Parameters
    ----------
    result : LeavesCurveResult
        From :func:`slamlab.studies.features.matching_experiments.run_recall_vs_leaves`.
    ax : matplotlib.axes.Axes, optional
        Axes to draw into.

    Returns
    -------
    matplotlib.axes.Axes
    """
    ax = new_axes(ax, title=f"Nearest-neighbour recall, {result.n_stored} stored descriptors",
                  xlabel="max_leaves (BBF) / checks (FLANN)", ylabel="recall")
    ax.semilogx(result.budgets, result.recall_bbf, "o-", label="BBF (ours)")
    ax.semilogx(result.budgets, result.recall_flann, "s--", label="FLANN kd-tree")
    ax.axvline(200, color="0.5", linestyle=":", label="000: ~200 leaves")
    ax.set_ylim(0, 1.02)
    ax.legend(loc="lower right")
    return ax


def plot_ratio_tradeoff(result, *, ax=None):
    """Precision against recall as the ratio threshold varies; 000's rule marked.

    Parameters
    ----------
    result : RatioTradeoffResult
        From :func:`slamlab.studies.features.matching_experiments.run_ratio_tradeoff`.
    ax : matplotlib.axes.Axes, optional
        Axes to draw into.

    Returns
    -------
    matplotlib.axes.Axes
    """
    ax = new_axes(ax, title=f"Ratio rule, {result.detector} on {result.pair}", xlabel="recall",
                  ylabel="precision")
    ax.plot(result.recall, result.precision, "o-")
    for r, x, y in zip(result.ratios, result.recall, result.precision, strict=True):
        ax.annotate(f"{r:.1f}", (x, y), textcoords="offset points", xytext=(4, 4), fontsize=8)
    _, p, rc, _ = result.source_row
    ax.plot([rc], [p], "r*", markersize=12, label="000: d2 ≥ 2·d1 with limit")
    ax.set_xlim(0, 1)
    ax.set_ylim(0, 1.05)
    ax.legend(loc="lower left")
    return ax


def plot_surf_threshold(result, *, ax=None):
    """SURF point count against the threshold on our scale; 000's '~2000 points' marked.

    Parameters
    ----------
    result : SurfThresholdResult
        From :func:`slamlab.studies.features.detector_experiments.run_surf_threshold`.
    ax : matplotlib.axes.Axes, optional
        Axes to draw into.

    Returns
    -------
    matplotlib.axes.Axes
    """
    ax = new_axes(ax, title=f"SURF points vs threshold, {result.image_name}", xlabel="threshold (ours)",
                  ylabel="points")
    ax.semilogx(result.thresholds, result.counts, "o-")
    ax.axhline(2000, color="0.5", linestyle=":", label="000: ~2000 points")
    ax.axvline(0.05, color="tab:red", linestyle="--", label="000: threshold 0.05")
    ax.legend(loc="best")
    return ax
