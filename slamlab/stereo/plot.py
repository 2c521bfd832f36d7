"""Plots for Ch. 4 (stereo SLAM): the triangulation geometry and one frame's stages (the runs' paths, maps and
error curves: :mod:`slamlab.studies.stereo.plot`)."""

from __future__ import annotations

import matplotlib.pyplot as plt
import numpy as np

from ..geometry.triangulation import triangulate_midpoint

__all__ = ["plot_frame_stages", "plot_triangulation"]


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
