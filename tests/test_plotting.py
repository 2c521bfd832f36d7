"""Shared plot styles and helpers."""

from __future__ import annotations

import matplotlib.pyplot as plt
import pytest

from slamlab import plotting


@pytest.fixture(autouse=True)
def _close_figures():
    yield
    plt.close("all")


def test_style_keys_and_looks():
    assert set(plotting.STYLE) == {"truth", "estimate", "measurement", "landmark", "covariance"}
    assert plotting.STYLE["truth"]["color"] == "black"
    assert plotting.STYLE["truth"]["linestyle"] == "-"
    assert plotting.STYLE["estimate"]["color"] == "tab:blue"
    assert plotting.STYLE["measurement"]["color"] == "tab:orange"
    assert plotting.STYLE["measurement"]["linestyle"] == "none"
    assert plotting.STYLE["measurement"]["marker"]
    assert (plotting.STYLE["landmark"]["color"], plotting.STYLE["landmark"]["marker"]) == ("tab:green", "*")
    assert plotting.STYLE["covariance"]["color"] == "tab:blue"
    assert plotting.STYLE["covariance"]["alpha"] < 1


@pytest.mark.parametrize("kind", sorted(plotting.STYLE))
def test_styles_are_valid_plot_kwargs(kind):
    ax = plotting.new_axes()
    (line,) = ax.plot([0, 1], [0, 1], **plotting.STYLE[kind])
    assert line.get_color() == plotting.STYLE[kind]["color"]


def test_new_axes_makes_figure_and_sets_labels():
    ax = plotting.new_axes(figsize=(3, 2), title="t", xlabel="x [m]", ylabel="y [m]", equal=True)
    assert tuple(ax.figure.get_size_inches()) == (3, 2)
    assert (ax.get_title(), ax.get_xlabel(), ax.get_ylabel()) == ("t", "x [m]", "y [m]")
    assert ax.get_aspect() == 1.0


def test_new_axes_reuses_given_axes():
    _fig, ax = plt.subplots()
    assert plotting.new_axes(ax, title="again") is ax
    assert ax.get_aspect() == "auto"


def test_slam_scheme_draws_on_given_axes():
    _fig, ax = plt.subplots()
    assert plotting.plot_slam_scheme(ax=ax) is ax


def test_slam_scheme_text_does_not_overlap():
    ax = plotting.plot_slam_scheme()
    fig = ax.figure
    assert tuple(fig.get_size_inches()) == (9.0, 5.0)
    renderer = fig.canvas.get_renderer()
    labels = [t for t in ax.texts if len(t.get_text()) > 1]  # box labels, arrow labels, note
    boxes = [t.get_window_extent(renderer) for t in labels]
    for i in range(len(boxes)):
        for j in range(i + 1, len(boxes)):
            assert not boxes[i].overlaps(boxes[j]), (labels[i].get_text(), labels[j].get_text())
    # everything inside the figure
    fig_box = fig.bbox
    for t, box in zip(labels, boxes, strict=True):
        assert fig_box.x0 <= box.x0, t.get_text()
        assert box.x1 <= fig_box.x1, t.get_text()
        assert fig_box.y0 <= box.y0, t.get_text()
        assert box.y1 <= fig_box.y1, t.get_text()


def test_slam_scheme_names_every_step():
    ax = plotting.plot_slam_scheme()
    text = " ".join(t.get_text().replace("\n", " ") for t in ax.texts).lower()
    for phrase in (
        "sensor data",
        "landmark detection and description",
        "search the store for correspondences",
        "add the landmark to the store",
        "pose computation",
        "recursive filter: pose refinement",
        "landmark refinement by the recursive filter",
        "landmark store",
        "no match",
        "match",
    ):
        assert phrase in text, phrase
