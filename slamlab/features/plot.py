"""Plots for Ch. 2 and 3: keypoints, matches, box filters, the FAST circle, the detector gallery."""

from __future__ import annotations

import matplotlib.pyplot as plt
import numpy as np

from ..plotting import new_axes
from .fast import CIRCLE_OFFSETS

__all__ = [
    "DETECTOR_GALLERY",
    "plot_box_filters",
    "plot_detector_gallery",
    "plot_fast_circle",
    "plot_keypoint_pair",
    "plot_keypoints",
    "plot_matches",
]

#: the detectors of notebook 02's gallery: (title, method, parameters of ``slamlab.features.detect``)
DETECTOR_GALLERY = (
    ("SURF (ours)", "surf", {"threshold": 4e-4}),
    ("SIFT (OpenCV)", "sift", {}),
    ("ORB (OpenCV)", "orb", {}),
    ("FAST-9 (ours)", "fast", {"threshold": 20}),
    ("Moravec (ours)", "moravec", {"threshold": 0.1}),
    ("MSER (OpenCV)", "mser", {}),
)


def plot_detector_gallery(image, detectors=DETECTOR_GALLERY, *, max_points: int = 300, ncols: int = 3):
    """Keypoints of several detectors on one image, one panel each (000 §1.4); returns the figure.

    Parameters
    ----------
    image : (H, W) array
        Grey image.
    detectors : sequence of (str, str, dict)
        (panel title, method of :func:`slamlab.features.detect`, its parameters) per panel.
    max_points : int
        Strongest keypoints drawn per panel.
    ncols : int
        Panels per row.

    Returns
    -------
    matplotlib.figure.Figure
    """
    from .detect import detect

    detectors = tuple(detectors)
    nrows = -(-len(detectors) // ncols)
    fig, axes = plt.subplots(nrows, ncols, figsize=(4 * ncols, 3.25 * nrows), squeeze=False)
    for ax in axes.ravel()[len(detectors):]:
        ax.set_visible(False)
    for ax, (name, method, params) in zip(axes.ravel(), detectors, strict=False):
        f = detect(image, method, descriptors=False, **params)
        plot_keypoints(image, f, ax=ax, max_points=max_points, title=f"{name}: {len(f)} points",
                       circles=method in ("surf", "sift", "orb", "mser"))
    fig.tight_layout()
    return fig


def plot_keypoint_pair(img1, f1, img2, f2, titles=("image 1", "image 2")):
    """Keypoints of two images side by side (:func:`plot_keypoints`); returns the figure.

    Parameters
    ----------
    img1, img2 : (H, W) array
        The two grey images.
    f1, f2 : Features
        Their keypoints.
    titles : (str, str)
        Panel titles.

    Returns
    -------
    matplotlib.figure.Figure
    """
    fig, axes = plt.subplots(1, 2, figsize=(10, 4))
    plot_keypoints(img1, f1, ax=axes[0], title=titles[0])
    plot_keypoints(img2, f2, ax=axes[1], title=titles[1])
    fig.tight_layout()
    return fig


DETECTOR_COLORS = {"SIFT": "tab:blue", "SURF": "tab:red", "ORB": "tab:green", "FAST": "tab:purple"}


def plot_keypoints(image, features, *, ax=None, max_points: int = 400, color="tab:red", title=None,
                   circles: bool = True):
    """Keypoints on the image: circles of radius σ with an orientation tick (strongest ``max_points``).

    Parameters
    ----------
    image : (H, W) array
        Grey image.
    features : Features
        Keypoints to draw.
    ax : matplotlib.axes.Axes, optional
        Axes to draw into (a new figure when None).
    max_points : int
        Strongest keypoints drawn.
    color : str
        Matplotlib colour of the marks.
    title : str, optional
        Axes title (default ``str(features)``).
    circles : bool
        Circles of radius σ with orientation ticks; False draws ``+`` marks.

    Returns
    -------
    matplotlib.axes.Axes
    """
    ax = new_axes(ax, title=title or str(features))
    ax.imshow(image, cmap="gray", interpolation="nearest")
    f = features.strongest(max_points) if len(features) > max_points else features
    if circles and len(f):
        from matplotlib.collections import EllipseCollection, LineCollection

        r = np.maximum(f.scale_px, 1.5)
        ax.add_collection(EllipseCollection(2 * r, 2 * r, np.zeros(len(f)), units="xy", offsets=f.uv,
                                            offset_transform=ax.transData, facecolors="none", edgecolors=color,
                                            linewidths=0.7))
        tip = f.uv + r[:, None] * np.column_stack([np.cos(f.orientation_rad), np.sin(f.orientation_rad)])
        ax.add_collection(LineCollection(np.stack([f.uv, tip], axis=1), colors=color, linewidths=0.7))
    else:
        ax.plot(f.uv[:, 0], f.uv[:, 1], "+", color=color, markersize=4)
    ax.set_xlim(-0.5, image.shape[1] - 0.5)
    ax.set_ylim(image.shape[0] - 0.5, -0.5)
    ax.set_axis_off()
    return ax


def plot_matches(img1, img2, f1, f2, matches, correct=None, *, ax=None, max_lines: int = 150, title=None):
    """Two images side by side with match lines (green correct, red wrong when ``correct`` is given).

    Parameters
    ----------
    img1, img2 : (H, W) array
        The grey images (query and train side).
    f1, f2 : Features
        Their keypoints.
    matches : Matches
        Matches, f1 as query and f2 as train.
    correct : (len(matches),) bool, optional
        Which matches are correct (lines yellow when None).
    ax : matplotlib.axes.Axes, optional
        Axes to draw into.
    max_lines : int
        At most this many lines, evenly spaced over the matches.
    title : str, optional
        Axes title (default: the number of matches).

    Returns
    -------
    matplotlib.axes.Axes
    """
    h = max(img1.shape[0], img2.shape[0])
    canvas = np.zeros((h, img1.shape[1] + img2.shape[1]), dtype=float)
    canvas[:img1.shape[0], :img1.shape[1]] = img1
    canvas[:img2.shape[0], img1.shape[1]:] = img2
    ax = new_axes(ax, title=title or f"{len(matches)} matches", figsize=(10, 4))
    ax.imshow(canvas, cmap="gray", interpolation="nearest")
    n = len(matches)
    sel = np.linspace(0, n - 1, min(n, max_lines)).astype(int) if n else np.zeros(0, int)
    from matplotlib.collections import LineCollection

    p1 = f1.uv[matches.query_idx[sel]]
    p2 = f2.uv[matches.train_idx[sel]] + np.array([img1.shape[1], 0])
    colors = "yellow" if correct is None else np.where(np.asarray(correct)[sel], "lime", "red")
    ax.add_collection(LineCollection(np.stack([p1, p2], axis=1), colors=colors, linewidths=0.6))
    ax.set_xlim(-0.5, canvas.shape[1] - 0.5)
    ax.set_ylim(h - 0.5, -0.5)
    ax.set_axis_off()
    return ax


def plot_box_filters(L: int = 9, *, axes=None):
    """The three SURF box filters Dxx, Dyy, Dxy of side L (weights +1 white, -1/-2 dark).

    Parameters
    ----------
    L : int
        Filter side in pixels (9, 15, 21, ...).
    axes : sequence of 3 matplotlib.axes.Axes, optional
        Axes to draw into.

    Returns
    -------
    sequence of matplotlib.axes.Axes
    """
    if axes is None:
        _, axes = plt.subplots(1, 3, figsize=(8, 2.8))
    l = L // 3
    b = (L - 1) // 2
    kxx = np.zeros((L, L))
    kxx[b - l + 1:b + l, :] = 1.0
    kxx[b - l + 1:b + l, b - l // 2:b - l // 2 + l] = -2.0
    kyy = kxx.T
    kxy = np.zeros((L, L))
    kxy[b - l:b, b + 1:b + l + 1] = 1.0
    kxy[b + 1:b + l + 1, b - l:b] = 1.0
    kxy[b - l:b, b - l:b] = -1.0
    kxy[b + 1:b + l + 1, b + 1:b + l + 1] = -1.0
    for ax, k, name in zip(axes, (kxx, kyy, kxy), ("$D_{xx}$", "$D_{yy}$", "$D_{xy}$"), strict=True):
        ax.imshow(k, cmap="gray", vmin=-2, vmax=1, interpolation="nearest")
        ax.set_title(f"{name}, L = {L}")
        ax.set_xticks([])
        ax.set_yticks([])
        ax.grid(False)
    return axes


def plot_fast_circle(image, row: int, col: int, threshold: int = 20, *, ax=None, half: int = 6):
    """A patch around (row, col) with the 16 circle pixels marked brighter (+), darker (-) or similar.

    Pixels are numbered as in 003's figure: 1 at the top, clockwise (v down).

    Parameters
    ----------
    image : (H, W) uint8
        Grey image.
    row, col : int
        The centre pixel (at least ``half`` pixels inside the image).
    threshold : int
        FAST threshold t in grey levels.
    ax : matplotlib.axes.Axes, optional
        Axes to draw into.
    half : int
        Half-width of the patch shown, in pixels.

    Returns
    -------
    matplotlib.axes.Axes
    """
    ax = new_axes(ax, title=f"FAST circle at (u={col}, v={row}), t = {threshold}")
    img = np.asarray(image)
    patch = img[row - half:row + half + 1, col - half:col + half + 1].astype(int)
    ax.imshow(patch, cmap="gray", vmin=0, vmax=255, interpolation="nearest",
              extent=(col - half - 0.5, col + half + 0.5, row + half + 0.5, row - half - 0.5))
    centre = int(img[row, col])
    for n, (du, dv) in enumerate(CIRCLE_OFFSETS):
        val = int(img[row + dv, col + du])
        mark, color = ("+", "tab:red") if val > centre + threshold else ("-", "tab:blue") if (
            val < centre - threshold) else ("·", "tab:gray")
        label = (8 - n) % 16 + 1  # OpenCV's order starts below and turns the other way
        ax.add_patch(plt.Circle((col + du, row + dv), 0.45, color=color, fill=False, linewidth=1.5))
        ax.text(col + du, row + dv, f"{label}{mark}", color=color, ha="center", va="center", fontsize=8,
                fontweight="bold")
    ax.plot(col, row, "s", color="yellow", markersize=6, markerfacecolor="none")
    ax.grid(False)
    return ax
