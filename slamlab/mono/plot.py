"""Plots of Ch. 9's own objects (003 §4): the epipolar segments searched for seeds, the seeds' σ_ρ."""

from __future__ import annotations

import matplotlib.pyplot as plt
import numpy as np

from ..plotting import new_axes

__all__ = ["plot_epipolar_pair", "plot_seed_histograms"]


def plot_epipolar_pair(img_ref, img_cur, uv_ref, a, b, uv_match=None, found=None, *, axes=None, max_lines: int = 40):
    """Seeds in the reference image and their searched epipolar segments ρ ± 2σ in the current one (003 Fig. 4.2-4.3).

    Parameters
    ----------
    img_ref, img_cur : ndarray, shape (H, W)
        Reference and current grey images.
    uv_ref : ndarray, shape (N, 2)
        Seeds' pixels in the reference image.
    a, b : ndarray, shape (N, 2)
        End points of their searched segments in the current image [px].
    uv_match : ndarray, shape (N, 2), optional
        Matched pixels, drawn where ``found``.
    found : ndarray of bool, shape (N,), optional
        Which seeds were found.
    axes : sequence of two Axes, optional
        Where to draw; ``None`` = a new figure.
    max_lines : int
        Most segments drawn (default 40).

    Returns
    -------
    axes : sequence of Axes
        The two panels.
    """
    if axes is None:
        _, axes = plt.subplots(1, 2, figsize=(12, 3.4))
    n = min(len(uv_ref), max_lines)
    idx = np.linspace(0, len(uv_ref) - 1, n).astype(int) if len(uv_ref) else np.zeros(0, int)
    axes[0].imshow(img_ref, cmap="gray")
    axes[0].plot(uv_ref[idx, 0], uv_ref[idx, 1], "y+", ms=6)
    axes[0].set_title("reference keyframe: seeds")
    axes[1].imshow(img_cur, cmap="gray")
    h, w = img_cur.shape[:2]
    for i in idx:
        axes[1].plot([a[i, 0], b[i, 0]], [a[i, 1], b[i, 1]], "-", color="tab:orange", lw=1)
        if uv_match is not None and found is not None and found[i]:
            axes[1].plot(*uv_match[i], "r.", ms=5)
    axes[1].set(xlim=(0, w - 1), ylim=(h - 1, 0), title="current frame: segments [1/(ρ+2σ), 1/(ρ−2σ)], matches (red)")
    for ax in axes:
        ax.set_axis_off()
    return axes


def plot_seed_histograms(snapshots, *, ax=None, bins=40):
    """Histograms of the seeds' σ_ρ/ρ_range at several frames: ``snapshots`` = {label: values}.

    Parameters
    ----------
    snapshots : dict
        Label → array of the seeds' ``σ_ρ / ρ_range`` at that moment.
    ax : Axes, optional
        Where to draw; ``None`` = new axes.
    bins : int
        Number of histogram bins (default 40).

    Returns
    -------
    ax : Axes
    """
    ax = new_axes(ax, figsize=(6.5, 3.4), title="seeds converging", xlabel="σ_ρ / ρ_range (log)", ylabel="seeds")
    allv = np.concatenate([np.asarray(v_) for v_ in snapshots.values() if len(v_)]) if snapshots else np.ones(1)
    edges = np.logspace(np.log10(max(allv.min(), 1e-5)), np.log10(max(allv.max(), 1e-4)), bins)
    for label, vals in snapshots.items():
        ax.hist(vals, bins=edges, histtype="step", lw=1.5, label=label)
    ax.set_xscale("log")
    ax.axvline(1 / 200, color="k", ls=":", lw=1)
    ax.legend(fontsize=8)
    return ax
