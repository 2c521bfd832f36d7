"""Shared plot styles and figure helpers (000 §1.1).

Every plot in slamlab draws ground truth, estimates, measurements, landmarks and
covariance ellipses with the same look, taken from :data:`STYLE`::

    ax.plot(x, y, **STYLE["truth"], label="truth")

Plot functions follow one pattern: ``plot_<thing>(..., *, ax=None, **style) ->
Axes``; they make their own figure when ``ax`` is None (via :func:`new_axes`)
and never call ``plt.show()`` or ``plt.gca()``.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import matplotlib.pyplot as plt
from matplotlib.patches import FancyArrowPatch, FancyBboxPatch

if TYPE_CHECKING:
    from matplotlib.axes import Axes

__all__ = ["STYLE", "new_axes", "plot_slam_scheme"]

#: Keyword arguments for ``Axes.plot`` per kind of quantity.
STYLE: dict[str, dict] = {
    "truth": {"color": "black", "linestyle": "-", "linewidth": 1.5},
    "estimate": {"color": "tab:blue", "linestyle": "-", "linewidth": 1.5},
    "measurement": {"color": "tab:orange", "linestyle": "none", "marker": ".", "markersize": 5},
    "landmark": {"color": "tab:green", "linestyle": "none", "marker": "*", "markersize": 10},
    "covariance": {"color": "tab:blue", "linestyle": "-", "linewidth": 0.8, "alpha": 0.5},
}


def new_axes(
    ax: Axes | None = None,
    *,
    figsize: tuple[float, float] | None = None,
    title: str | None = None,
    xlabel: str | None = None,
    ylabel: str | None = None,
    equal: bool = False,
) -> Axes:
    """Return ``ax``, or the axes of a new figure when ``ax`` is None, with labels set.

    Parameters
    ----------
    ax : matplotlib.axes.Axes, optional
        Axes to draw on; a new figure (``figsize``, default from rcParams) when None.
    figsize : (float, float), optional
        Size in inches of the new figure; ignored when ``ax`` is given.
    title, xlabel, ylabel : str, optional
        Set when given.
    equal : bool
        Equal scale on both axes (maps, trajectories).

    Examples
    --------
    >>> ax = new_axes(title="path", xlabel="x [m]", ylabel="y [m]", equal=True)
    >>> ax.get_title(), ax.get_xlabel(), ax.get_aspect()
    ('path', 'x [m]', 1.0)
    >>> plt.close(ax.figure)
    """
    if ax is None:
        _fig, ax = plt.subplots(figsize=figsize)
    if title is not None:
        ax.set_title(title)
    if xlabel is not None:
        ax.set_xlabel(xlabel)
    if ylabel is not None:
        ax.set_ylabel(ylabel)
    if equal:
        ax.set_aspect("equal", adjustable="datalim")
    return ax


# --- the classic SLAM scheme (000 §1.1, Fig. 2) -------------------------------------------------

# (key, centre x, centre y, text, subtask number in 000 §1's list or None, face colour)
_SCHEME_BOXES = (
    ("sensors", 1.75, 5.25, "Sensor data", None, "#eeeeee"),
    ("detect", 1.75, 3.95, "Landmark detection\nand description", 2, "#dbe9f6"),
    ("assoc", 1.75, 2.55, "Data association:\nsearch the store for\ncorrespondences", 3, "#dbe9f6"),
    ("add", 5.2, 3.95, "Add the landmark\nto the store", None, "#f3f3f3"),
    ("store", 8.55, 2.55, "Landmark store\n(landmarks and\ntheir descriptions)", None, "#fdf1d6"),
    ("pose", 1.75, 0.85, "Pose computation\nfrom matched landmarks", 4, "#dbe9f6"),
    ("filter", 5.2, 0.85, "Recursive filter:\npose refinement", 1, "#e2f0d9"),
    ("refine", 8.55, 0.85, "Landmark refinement\nby the recursive filter", 5, "#e2f0d9"),
)
_BOX_W, _BOX_H = 2.75, 0.95


def _arrow(ax, start, end, *, text=None, text_xy=None, dashed=False, both=False, rad=0.0):
    ax.add_patch(
        FancyArrowPatch(
            start,
            end,
            arrowstyle="<|-|>" if both else "-|>",
            mutation_scale=12,
            linewidth=1.2,
            linestyle="--" if dashed else "-",
            color="0.25",
            connectionstyle=f"arc3,rad={rad}",
            shrinkA=0,
            shrinkB=0,
        )
    )
    if text:
        ax.text(*text_xy, text, ha="center", va="center", fontsize=8.5, style="italic", color="0.2",
                bbox={"boxstyle": "round,pad=0.15", "facecolor": "white", "edgecolor": "none"})


def plot_slam_scheme(*, ax: Axes | None = None) -> Axes:
    """Draw the classic SLAM scheme as a block diagram (000 §1.1, Fig. 2).

    Per step: sensor data come in; landmarks are detected and described; each
    is searched for in the landmark store; an unmatched landmark is added to
    the store, matched ones give the pose; a recursive filter refines the
    pose, then the matched landmarks' positions, which go back to the store.
    Small circled numbers give the subtask's place in 000 §1's list of five
    (1 recursive filter, 2 finding landmarks, 3 correspondences, 4 pose,
    5 landmark refinement).

    Parameters
    ----------
    ax : matplotlib.axes.Axes, optional
        Axes to draw on; a new 9 x 5 inch figure when None.

    Returns
    -------
    matplotlib.axes.Axes

    Examples
    --------
    >>> ax = plot_slam_scheme()
    >>> len(ax.patches) > 8
    True
    >>> plt.close(ax.figure)
    """
    own_figure = ax is None
    ax = new_axes(ax, figsize=(9.0, 5.0))
    if own_figure:
        ax.figure.subplots_adjust(left=0.01, right=0.99, bottom=0.01, top=0.93)
    ax.set_xlim(0.25, 10.05)
    ax.set_ylim(-0.6, 5.85)
    ax.set_axis_off()
    centre = {}
    for key, x, y, text, subtask, face in _SCHEME_BOXES:
        centre[key] = (x, y)
        ax.add_patch(
            FancyBboxPatch(
                (x - _BOX_W / 2, y - _BOX_H / 2),
                _BOX_W,
                _BOX_H,
                boxstyle="round,pad=0.02,rounding_size=0.12",
                facecolor=face,
                edgecolor="0.3",
                linewidth=1.4 if key == "store" else 1.0,
            )
        )
        ax.text(x, y, text, ha="center", va="center", fontsize=9.5, linespacing=1.25)
        if subtask is not None:
            ax.text(x - _BOX_W / 2 + 0.16, y + _BOX_H / 2 - 0.17, str(subtask), ha="center", va="center",
                    fontsize=7.5, fontweight="bold", color="white",
                    bbox={"boxstyle": "circle,pad=0.18", "facecolor": "0.35", "edgecolor": "none"})
    h, w = _BOX_H / 2, _BOX_W / 2

    def at(key, dx=0.0, dy=0.0):
        x, y = centre[key]
        return (x + dx, y + dy)

    # main chain down the left column
    _arrow(ax, at("sensors", dy=-h), at("detect", dy=h))
    _arrow(ax, at("detect", dy=-h), at("assoc", dy=h))
    # association <-> store: the search for correspondences
    _arrow(ax, at("assoc", dx=w, dy=-0.15), at("store", dx=-w, dy=-0.15), dashed=True, both=True,
           text="search", text_xy=(5.2, 2.4))
    # no match: add to the store
    _arrow(ax, at("assoc", dx=w, dy=0.3), at("add", dx=-w, dy=-0.2), text="no match", text_xy=(3.65, 3.35))
    _arrow(ax, at("add", dx=w, dy=-0.2), at("store", dx=-w, dy=0.3))
    # match: pose, filter, landmark refinement, back to the store
    _arrow(ax, at("assoc", dy=-h), at("pose", dy=h), text="match", text_xy=(1.75, 1.7))
    _arrow(ax, at("pose", dx=w), at("filter", dx=-w))
    _arrow(ax, at("filter", dx=w), at("refine", dx=-w))
    _arrow(ax, at("refine", dy=h), at("store", dy=-h), text="update", text_xy=(8.55, 1.7))
    ax.text(5.15, -0.55, "numbered: the subtask's place in 000 §1's list (1 recursive filter, 2 landmark detection, "
            "3 correspondences,\n4 pose recomputation, 5 landmark refinement)", ha="center", va="bottom",
            fontsize=8, color="0.35")
    ax.set_title("Classic SLAM scheme (after 000 §1.1, Fig. 2)", fontsize=11)
    return ax
