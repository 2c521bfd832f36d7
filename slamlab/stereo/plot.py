"""Plots for Ch. 4 (stereo SLAM): triangulation geometry, one frame's stages, paths and landmark maps."""

from __future__ import annotations

import matplotlib.pyplot as plt
import numpy as np

from ..geometry.triangulation import triangulate_midpoint
from ..plotting import STYLE, new_axes

__all__ = ["plot_frame_stages", "plot_kitti", "plot_run_errors", "plot_run_map", "plot_triangulation", "run_figure"]


def plot_triangulation(*, ax=None, baseline_m: float = 0.4, skew_m: float = 0.15):
    """The midpoint of the common perpendicular of two skew viewing rays (000 §3.3), drawn in 3-D.

    Parameters
    ----------
    ax : matplotlib.axes.Axes (3-D), optional
        Axes to draw on; None makes a new figure.
    baseline_m : float, default 0.4
        Distance between the camera centres [m].
    skew_m : float, default 0.15
        Vertical offset that makes the rays skew [m].

    Returns
    -------
    matplotlib.axes.Axes
    """
    if ax is None:
        ax = plt.figure(figsize=(6, 4.5)).add_subplot(projection="3d")
    c1, c2 = np.zeros(3), np.array([baseline_m, 0.0, 0.0])
    X = np.array([0.25, 0.0, 1.6])
    d1 = X - c1
    d2 = X + np.array([0.0, skew_m, 0.0]) - c2  # a pixel error makes the rays miss each other
    tri = triangulate_midpoint(c1, d1[None], c2, d2[None])
    p1, p2 = c1 + tri.s[0] * d1, c2 + tri.t[0] * d2
    for c, p, name in ((c1, p1, "left ray"), (c2, p2, "right ray")):
        q = c + 1.15 * (p - c)
        ax.plot(*np.c_[c, q], label=name)
        ax.scatter(*c, color="black", s=20)
    ax.plot(*np.c_[p1, p2], color="tab:red", linewidth=2, label="common perpendicular")
    ax.scatter(*tri.points[0], color="tab:red", marker="*", s=120, label="landmark (midpoint)")
    ax.set_xlabel("x [m]")
    ax.set_ylabel("y [m]")
    ax.set_zlabel("z (forward) [m]")
    ax.set_ylim(-0.5, 0.5)  # equal-ish scale: the gap is not exaggerated
    ax.text(*(0.5 * (p1 + p2) + [0.05, 0.0, 0.0]), f"gap {tri.gap_m[0] * 100:.0f} cm", color="tab:red")
    ax.set_title("Midpoint triangulation (000 §3.3)")
    ax.legend(loc="upper left", fontsize=8)
    return ax


def plot_frame_stages(left, right, left_features, right_features, matches, cloud, inliers=None, *, axes=None):
    """One frame's stages: keypoints, stereo matches, local cloud (top view) and RANSAC inliers.

    Parameters
    ----------
    left, right : array_like
        The stereo pair.
    left_features, right_features : Features
        Their keypoints.
    matches : StereoMatches
        Stereo matches (every 10th drawn).
    cloud : LocalCloud
        The triangulated points.
    inliers : array_like of bool, shape (K,), optional
        RANSAC inliers over the cloud's points.
    axes : array_like of four matplotlib.axes.Axes, optional
        None makes a new figure.

    Returns
    -------
    numpy.ndarray of matplotlib.axes.Axes
    """
    if axes is None:
        _fig, axes = plt.subplots(2, 2, figsize=(11, 8))
    axes = np.asarray(axes).ravel()
    ax = axes[0]
    ax.imshow(left, cmap="gray")
    ax.plot(*left_features.uv.T, ".", color="tab:orange", markersize=2)
    ax.set_title(f"left image: {len(left_features.uv)} keypoints")
    ax = axes[1]
    ax.imshow(np.vstack([left, right]), cmap="gray")
    ul, ur = left_features.uv[matches.left], right_features.uv[matches.right]
    h = left.shape[0]
    for a, b in zip(ul[::10], ur[::10], strict=True):  # every 10th match, a few hundred lines at most
        ax.plot([a[0], b[0]], [a[1], b[1] + h], color="tab:green", linewidth=0.5)
    ax.set_title(f"stereo matches: {len(matches.left)} (every 10th drawn)")
    ax = axes[2]
    P = cloud.points
    ax.scatter(P[:, 0], P[:, 2], s=2, color="tab:blue")
    ax.set_xlabel("x (right) [m]")
    ax.set_ylabel("z (forward) [m]")
    ax.set_aspect("equal", adjustable="datalim")
    ax.set_title(f"local cloud (top view): {len(P)} points")
    ax = axes[3]
    ax.imshow(left, cmap="gray")
    uv = left_features.uv[cloud.left]
    if inliers is not None:
        ax.plot(*uv[~inliers].T, ".", color="black", markersize=2, label="not used")
        ax.plot(*uv[inliers].T, ".", color="white", markersize=3, label="RANSAC inliers")
        ax.set_title(f"pose from {int(inliers.sum())} inliers (white, as 000 Fig. 12)")
        ax.legend(loc="lower right", fontsize=8)
    else:
        ax.plot(*uv.T, ".", color="white", markersize=3)
        ax.set_title("triangulated keypoints")
    for a in axes[[0, 1, 3]]:
        a.set_axis_off()
    return axes


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
        From :func:`~slamlab.stereo.run_kitti`.
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
