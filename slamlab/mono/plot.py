"""Plots of Ch. 9 (003 §4, §5): depth-filter convergence, epipolar segments, seeds, map and path from above."""

from __future__ import annotations

import matplotlib.pyplot as plt
import numpy as np

from ..plotting import new_axes

__all__ = ["plot_convergence", "plot_epipolar_pair", "plot_map_top", "plot_seed_histograms"]


def plot_convergence(study, *, axes=None):
    """σ_ρ and the inlier ratio a/(a+b) against the number of observations, one line per outlier rate."""
    if axes is None:
        _, axes = plt.subplots(1, 2, figsize=(11, 3.6))
    k = np.arange(study.sigma.shape[1])
    for i, r in enumerate(study.outlier_rates):
        axes[0].semilogy(k, study.sigma[i], label=f"{100 * r:.0f} % outliers")
        axes[1].plot(k, study.inlier[i], label=f"{100 * r:.0f} % outliers")
        axes[1].axhline(1 - r, color=axes[1].lines[-1].get_color(), ls=":", lw=0.8)
    axes[0].set(xlabel="observations", ylabel="median σ_ρ [1/m]", title="inverse-depth std")
    axes[1].set(xlabel="observations", ylabel="median a/(a+b)", title="inlier ratio (dotted: true)")
    axes[0].legend(fontsize=8)
    return axes


def plot_epipolar_pair(img_ref, img_cur, uv_ref, a, b, uv_match=None, found=None, *, axes=None, max_lines: int = 40):
    """Seeds in the reference image and their searched epipolar segments ρ ± 2σ in the current one (003 Fig. 4.2-4.3)."""
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
    """Histograms of the seeds' σ_ρ/ρ_range at several frames: ``snapshots`` = {label: values}."""
    ax = new_axes(ax, figsize=(6.5, 3.4), title="seeds converging", xlabel="σ_ρ / ρ_range (log)", ylabel="seeds")
    allv = np.concatenate([np.asarray(v_) for v_ in snapshots.values() if len(v_)]) if snapshots else np.ones(1)
    edges = np.logspace(np.log10(max(allv.min(), 1e-5)), np.log10(max(allv.max(), 1e-4)), bins)
    for label, vals in snapshots.items():
        ax.hist(vals, bins=edges, histtype="step", lw=1.5, label=label)
    ax.set_xscale("log")
    ax.axvline(1 / 200, color="k", ls=":", lw=1)
    ax.legend(fontsize=8)
    return ax


def plot_map_top(result, *, ax=None, aligned=True):
    """Map points and the path from above (x right, z forward of the first camera), after Sim(3) alignment."""
    from ..geometry.registration import umeyama

    ax = new_axes(ax, figsize=(6.5, 5), title=f"{result.name}: map and path from above", xlabel="x [m]",
                  ylabel="z [m]", equal=True)
    tr = result.tracked
    est = result.estimate[:, :3, 3]
    pts = result.points if result.points is not None else np.zeros((0, 3))
    if aligned and tr.sum() >= 3:
        S = umeyama(est[tr], result.truth[tr, :3, 3], with_scale=True)
        est = S.c * est @ S.R.T + S.t
        pts = S.c * pts @ S.R.T + S.t if len(pts) else pts
    ax.plot(pts[:, 0], pts[:, 2], ".", ms=1, color="0.5", label="map points")
    ax.plot(result.truth[:, 0, 3], result.truth[:, 2, 3], "k-", lw=2, label="truth")
    ax.plot(est[tr, 0], est[tr, 2], "o-", ms=3, color="tab:red", label="monocular (Sim(3))")
    ax.legend(fontsize=8)
    return ax
