"""The turn or the loop once per pipeline setting on the same frames (000 §3.5, §3.7), side by side."""

from __future__ import annotations

import numpy as np

from ... import _validate as v
from ..._table import format_table
from ..params import RenderParams, StereoParams
from .runs import SIZES, _first, experiment_poses, run_stereo_slam_variants

#: the default comparison of :func:`run_comparison`: 000's pipeline, and ORB with and without §3.5's policy
COMPARISON = {
    "SURF, oldest": {},
    "ORB, oldest": {"detector": "orb"},
    "ORB, all": {"detector": "orb", "policy": "all"},
}


def run_comparison(
    experiment: str = "closed loop", size: str = "small", variants: dict | None = None, *, n_frames: int | None = None,
    params: StereoParams | None = None, render: RenderParams | None = None, progress=None, rng=0,
) -> dict:
    """The turn or the loop once per pipeline setting, on the same rendered frames (000 §3.5, §3.7).

    ``variants`` maps a label to a :class:`StereoParams` or to overrides of ``params`` (default
    :data:`COMPARISON`); ``render``: :class:`RenderParams` (``noise_std``, ``drift_std_rad``, ...).
    Returns label -> :class:`StereoRunResult`; :func:`comparison_table` prints them side by side.

    Parameters
    ----------
    experiment : {"closed loop", "turn in place"}
        The trajectory.
    size : {"small", "full"}
        Frame step.
    variants : dict, optional
        Label -> :class:`StereoParams` or overrides of ``params`` (default ``COMPARISON``).
    n_frames : int, optional
        Keep only the first frames.
    params : StereoParams, optional
        Pipeline settings (default :class:`StereoParams`).
    render : RenderParams, optional
        Renderer settings (``arena_seed``, ``camera_height_m``, ``noise_std``, ``drift_std_rad``).
    progress : bool, None or callable
        A bar over the frames (None: on unless ``$SLAMLAB_PROGRESS=0``), or ``progress(i)`` after frame ``i``.
    rng : int or numpy.random.Generator, default 0
        Seed of the RANSAC stream (and the image noise).

    Returns
    -------
    dict
        Label -> :class:`StereoRunResult`.
    """
    v.check_choice(size, "size", SIZES)
    v.check_choice(experiment, "experiment", ("turn in place", "closed loop"))
    poses = _first(experiment_poses(experiment, size), n_frames)
    return run_stereo_slam_variants(poses, COMPARISON if variants is None else variants, name=experiment,
                                    params=params, render=render, progress=progress, rng=rng)


def comparison_table(results: dict) -> str:
    """000's figures for the turn or the loop, one column per run of :func:`run_comparison`.

    Parameters
    ----------
    results : dict
        Label -> :class:`StereoRunResult` from :func:`run_comparison`, all of one experiment.

    Returns
    -------
    str
    """
    runs = list(results.values())
    if not runs:
        raise ValueError("`results` is empty")
    deg = np.rad2deg
    rows = [["max position error, m", *(f"{r.pos_err_m.max():.2f}" for r in runs)]]
    if runs[0].name == "turn in place":
        rows.append(["spread of positions, m", *(f"{r.position_spread_m:.2f}" for r in runs)])
        rows.append(["heading error at 180 deg, deg", *(f"{deg(abs(r.yaw_err_rad[r.frame_at_turn(np.pi)])):.1f}" for r in runs)])
        rows.append(["heading error back at 0 deg, deg", *(f"{deg(abs(r.yaw_err_rad[-1])):.1f}" for r in runs)])
    else:
        rows.append(["max heading error / turned angle, %", *(f"{100 * r.heading_error_ratio:.1f}" for r in runs)])
        rows.append(["revisit: pose change, m", *(f"{r.revisit_difference[0]:.2f}" for r in runs)])
        rows.append(["revisit: heading change, deg", *(f"{deg(abs(r.revisit_difference[1])):.1f}" for r in runs)])
    rows.append(["degenerate frames", *(f"{len(r.degenerate)}" for r in runs)])
    rows.append(["RANSAC inliers per frame (median)", *(f"{np.median(r.counts['n_inliers'][1:]):.0f}" for r in runs)])
    return format_table(["quantity", *results], rows, title=f"{runs[0].name}, {runs[0].n_frames} frames")
