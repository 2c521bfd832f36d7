"""Plots of Ch. 9 (003 §4, §5): depth-filter convergence, epipolar segments, seeds, map and path from above."""

from __future__ import annotations

import matplotlib.pyplot as plt
import numpy as np

from ..plotting import new_axes

__all__ = ["plot_convergence", "plot_epipolar_pair", "plot_map_top", "plot_pinhole", "plot_seed_histograms"]


def plot_convergence(study, *, axes=None):
    """σ_ρ and the inlier ratio a/(a+b) against the number of observations, one line per outlier rate.

    Parameters
    ----------
    study : ConvergenceStudy
        Result of :func:`~slamlab.mono.convergence.run_depth_filter_convergence`.
    axes : sequence of two Axes, optional
        Where to draw; ``None`` = a new figure.

    Returns
    -------
    axes : sequence of Axes
        The two panels.
    """
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


def plot_map_top(result, *, ax=None, aligned=True):
    """Map points and the path from above (x right, z forward of the first camera), after the run's Sim(3).

    The Sim(3) is fitted on the frames the tracker claims; claimed frames outside the run's
    tolerance are drawn as crosses.

    Parameters
    ----------
    result : MonoRunResult
        A run (:func:`~slamlab.mono.runs.run_mono`).
    ax : Axes, optional
        Where to draw; ``None`` = new axes.
    aligned : bool
        Apply the Sim(3) fitted on the claimed frames (default True); False draws map units.

    Returns
    -------
    ax : Axes
    """
    from .evaluate import sim3_fit

    ax = new_axes(ax, figsize=(6.5, 5), title=f"{result.name}: map and path from above", xlabel="x [m]",
                  ylabel="z [m]", equal=True)
    cl = result.claimed
    ok = result.tracked
    est = result.estimate[:, :3, 3]
    pts = result.points if result.points is not None else np.zeros((0, 3))
    S = sim3_fit(est[cl], result.truth[cl, :3, 3]) if aligned else None
    if S is not None:
        c, R, t = S
        est = c * est @ R.T + t
        pts = c * pts @ R.T + t if len(pts) else pts
    ax.plot(pts[:, 0], pts[:, 2], ".", ms=1, color="0.5", label="map points")
    ax.plot(result.truth[:, 0, 3], result.truth[:, 2, 3], "k-", lw=2, label="truth")
    ax.plot(est[cl, 0], est[cl, 2], "-", lw=1, color="tab:red")
    ax.plot(est[ok, 0], est[ok, 2], "o", ms=3, color="tab:red", label="monocular, correct (Sim(3))")
    bad = cl & ~ok
    if bad.any():
        ax.plot(est[bad, 0], est[bad, 2], "x", ms=5, color="tab:purple", label="claimed, off by > tolerance")
    ax.legend(fontsize=8)
    return ax


def plot_pinhole(K, width_px: int, X_cam=(0.5, -0.2, 4.0), *, ax=None):
    """003 Fig. 2.1 redrawn from above (x right, Z forward): the centre, the image plane one focal length
    ahead (drawn at Z = 1 in units of f), the field of view and the ray of ``X_cam`` with its pixel column
    ``u = fx X/Z + u0``.

    Parameters
    ----------
    K : array_like, shape (3, 3)
        Intrinsic matrix.
    width_px : int
        Image width [px].
    X_cam : array_like, shape (3,)
        Point in the camera frame [m] whose ray is drawn.
    ax : Axes, optional
        Where to draw; ``None`` = new axes.

    Returns
    -------
    ax : Axes
    """
    K = np.asarray(K, dtype=np.float64)
    X = np.asarray(X_cam, dtype=np.float64)
    ax = new_axes(ax, figsize=(6.5, 3.6), title="pinhole camera from above (003 §2.1)", xlabel="x [m]",
                  ylabel="Z [m]", equal=True)
    half = (width_px / 2.0) / K[0, 0]  # tan of the half field of view
    zf = X[2] * 1.1
    ax.plot([0, -half * zf], [0, zf], color="0.6", lw=1)
    ax.plot([0, half * zf], [0, zf], color="0.6", lw=1, label="field of view")
    ax.plot([-half, half], [1.0, 1.0], color="tab:blue", lw=2, label="image plane (Z = f)")
    ax.plot([0, X[0]], [0, X[2]], "k--", lw=1)
    ax.plot(X[0], X[2], "o", color="tab:red", label=f"X = ({X[0]:g}, {X[1]:g}, {X[2]:g}) m")
    xn = X[0] / X[2]
    u = K[0, 0] * xn + K[0, 2]
    ax.plot(xn, 1.0, "s", color="tab:red", ms=5, label=f"u = fx X/Z + u0 = {u:.1f} px")
    ax.plot(0, 0, "k^", ms=8, label="optical centre")
    ax.legend(fontsize=8, loc="upper left")
    return ax
