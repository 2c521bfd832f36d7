"""Plots for Ch. 10 (002): scanner geometry (Fig. 5), a frame by intensity, its planes, a plane's description
(Fig. 6), the room (Fig. 7).

The plots of the chapter's study results (Fig. 2, Fig. 4, Fig. 8, Fig. 9) and of the simulated scanner and room are in
:mod:`slamlab.studies.planes.plot`.
"""

from __future__ import annotations

import matplotlib.pyplot as plt
import numpy as np

__all__ = [
    "plot_frame_planes",
    "plot_frame_points",
    "plot_plane_description",
]


def axes_3d(ax=None, figsize=(6, 5), title=None):
    """A 3-D axes with metre labels: ``ax`` itself, or a new figure's (002's figures).

    Parameters
    ----------
    ax : matplotlib 3-D Axes or None
        Axes to use; None makes a figure of ``figsize``.
    figsize : (float, float)
        Size of a new figure, in inches.
    title : str or None
        The axes' title.

    Returns
    -------
    matplotlib 3-D Axes
    """
    if ax is None:
        fig = plt.figure(figsize=figsize)
        ax = fig.add_subplot(projection="3d")
    if title:
        ax.set_title(title)
    ax.set_xlabel("x [m]")
    ax.set_ylabel("y [m]")
    ax.set_zlabel("z [m]")
    return ax


def thin_points(n, max_points, rng=0):
    """Sorted indices of at most ``max_points`` of ``n`` points, drawn without replacement (for drawing only).

    Parameters
    ----------
    n : int
        How many points there are.
    max_points : int
        How many to keep at most.
    rng : Generator, int or None
        The draw's stream.

    Returns
    -------
    ndarray of int
    """
    if n <= max_points:
        return np.arange(n)
    return np.sort(np.random.default_rng(rng).choice(n, max_points, replace=False))


def plot_frame_points(frame, *, ax=None, max_points: int = 6000, title: str | None = None):
    """A frame's points (body frame of its last line) coloured by intensity (002 Fig. 3).

    Parameters
    ----------
    frame : Frame
        The range frame.
    ax : mpl_toolkits.mplot3d.Axes3D, optional
        3-D axes to draw into.
    max_points : int
        At most this many points, a fixed random subset.
    title : str, optional
        Axes title.

    Returns
    -------
    mpl_toolkits.mplot3d.Axes3D
    """
    ax = axes_3d(ax, title=title or f"one frame: {len(frame)} points, coloured by intensity")
    k = thin_points(len(frame), max_points)
    sc = ax.scatter(*frame.points[k].T, c=frame.intensities[k], s=1, cmap="gray")
    ax.figure.colorbar(sc, ax=ax, shrink=0.6, label="intensity")
    return ax


def plot_frame_planes(frame, found, *, ax=None, max_points: int = 6000, title: str | None = None):
    """The frame's points coloured by the RANSAC plane they belong to (grey: on no plane).

    Parameters
    ----------
    frame : Frame
        The range frame.
    found : list of (n, p, idx)
        Planes from :func:`~slamlab.planes.extract_planes`.
    ax : mpl_toolkits.mplot3d.Axes3D, optional
        3-D axes to draw into.
    max_points : int
        At most this many points, a fixed random subset.
    title : str, optional
        Axes title.

    Returns
    -------
    mpl_toolkits.mplot3d.Axes3D
    """
    ax = axes_3d(ax, title=title or f"{len(found)} planes found by RANSAC")
    lab = np.full(len(frame), -1)
    for i, (_, _, idx) in enumerate(found):
        lab[idx] = i
    k = thin_points(len(frame), max_points)
    off = k[lab[k] < 0]
    ax.scatter(*frame.points[off].T, s=1, c="0.7")
    for i in range(len(found)):
        on = k[lab[k] == i]
        ax.scatter(*frame.points[on].T, s=1, label=f"plane {i}")
    ax.legend(markerscale=8, fontsize=8, loc="upper left")
    return ax


def plot_plane_description(plane, points=None, *, axs=None, max_points: int = 4000):
    """002 Fig. 6: a plane's points in its own frame ``Π`` (left: projected on its ``OXY`` plane) and its cells
    (right: the parts ``A``, coloured by the mean intensity ``I_k = Σ I / N_k``, a cell outlined per part).

    Parameters
    ----------
    plane : Plane
        The described plane.
    points : (K, 3) float, optional
        Its points in the plane's parent frame (without them only the cells are drawn).
    axs : (2,) matplotlib.axes.Axes, optional
        Axes to draw into.
    max_points : int
        At most this many points, a fixed random subset.

    Returns
    -------
    (2,) matplotlib.axes.Axes
    """
    if axs is None:
        _fig, axs = plt.subplots(1, 2, figsize=(11, 4.2))
    a1, a2 = axs
    T = plane.T
    if points is not None:
        X = np.asarray(points, dtype=float)
        local = (X - T[:3, 3]) @ T[:3, :3]                   # ᴾp = (ᵇ_ΠT)⁻¹ ᵇp
        k = thin_points(len(local), max_points)
        a1.scatter(local[k, 0], local[k, 1], s=1, c="tab:blue")
        a1.set_title(f"{len(X)} points in the plane's frame, on OXY\n(dropped z: |z| <= "
                     f"{np.abs(local[:, 2]).max():.3f} m)", fontsize=9)
    c = plane.cell_m
    lo, hi = plane.ij.min(axis=0), plane.ij.max(axis=0)
    grid = np.full((hi[1] - lo[1] + 1, hi[0] - lo[0] + 1), np.nan)
    grid[plane.ij[:, 1] - lo[1], plane.ij[:, 0] - lo[0]] = plane.mean_intensity
    im = a2.imshow(grid, origin="lower", cmap="gray", interpolation="nearest",
                   extent=(lo[0] * c, (hi[0] + 1) * c, lo[1] * c, (hi[1] + 1) * c))
    a2.figure.colorbar(im, ax=a2, shrink=0.8, label="mean intensity of the part")
    a2.set_title(f"{len(plane.ij)} parts of {c} m\n(cells with at least one point)", fontsize=9)
    for ax in (a1, a2):
        ax.set_xlabel("plane x [m]")
        ax.set_ylabel("plane y [m]")
        ax.set_aspect("equal")
    if points is not None:
        a1.set_xlim(a2.get_xlim())
        a1.set_ylim(a2.get_ylim())
    return axs
