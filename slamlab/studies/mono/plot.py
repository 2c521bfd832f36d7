"""Plots of Ch. 9's studies (003 §2.1, §4, §5): depth-filter convergence, a run's map and path, Fig. 2.1."""

from __future__ import annotations

import matplotlib.pyplot as plt
import numpy as np

from ...plotting import new_axes

__all__ = ["plot_convergence", "plot_map_top", "plot_pinhole"]


def plot_convergence(study, *, axes=None):
    """σ_ρ and the inlier ratio a/(a+b) against the number of observations, one line per outlier rate.

    Parameters
    ----------
    study : ConvergenceStudy
        Result of :func:`~slamlab.studies.mono.convergence.run_depth_filter_convergence`.
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


def plot_map_top(result, *, ax=None, aligned=True):
    """Map points and the path from above (x right, z forward of the first camera), after the run's Sim(3).

    The Sim(3) is fitted on the frames the tracker claims; claimed frames outside the run's
    tolerance are drawn as crosses.

    Parameters
    ----------
    result : MonoRunResult
        A run (:func:`~slamlab.studies.mono.runs.run_mono`).
    ax : Axes, optional
        Where to draw; ``None`` = new axes.
    aligned : bool
        Apply the Sim(3) fitted on the claimed frames (default True); False draws map units.

    Returns
    -------
    ax : Axes
    """
    from ...mono.evaluate import sim3_fit

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
