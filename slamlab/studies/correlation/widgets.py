"""Widgets for Ch. 5: turn the noise, clutter, Δα and a_c/a_p knobs; pick a real scan (ipywidgets)."""

from __future__ import annotations

import functools

import ipywidgets as widgets
import numpy as np

from ...correlation.algorithm import heading_error, localise, localise_joined
from ...correlation.plot import localisation_figure
from ...scans import log_grid
from ...sim.grid import add_clutter, measurement_room_200, test_room_200
from ...sim.rangefinder import Rangefinder
from ...widgets import STYLE as _STYLE
from ...widgets import interactive, show_run
from ...widgets import slider as _slider
from .carmen_logs import as_carmen_log as _carmen_log
from .experiments import random_clutter

__all__ = ["explore_localisation", "explore_log_scan"]




def explore_localisation(**defaults):
    """One scan in the test room: pose, noise, clutter, Δα and a_c/a_p → localisation, score map, heading profile.

    Calls :func:`~slamlab.correlation.localise` with the slider values. A bad
    combination (a_c = a_p, a pose inside an obstacle) prints its message.

    Parameters
    ----------
    **defaults
        Initial slider values: ``x`` (60), ``y`` (40) [cells], ``heading_deg`` (30), ``range_std_cells`` (0.3),
        ``clutter`` (True), ``extra_clutter`` (0), ``delta_alpha_deg`` (1), ``a_c`` (-1), ``a_p`` (1),
        ``n_beams`` (360) and the fixed ``rng`` (2010).

    Returns
    -------
    ipywidgets.interactive
    """
    d = {"x": 60, "y": 40, "heading_deg": 30.0, "range_std_cells": 0.3, "clutter": True, "extra_clutter": 0,
         "delta_alpha_deg": 1.0, "a_c": -1.0, "a_p": 1.0, "n_beams": 360, "rng": 2010}
    d.update(defaults)
    M = test_room_200()

    def show(x, y, heading_deg, range_std_cells, clutter, extra_clutter, delta_alpha_deg, a_c, a_p, n_beams):
        def run():
            W = measurement_room_200() if clutter else M.copy()
            if extra_clutter:
                W = add_clutter(W, random_clutter(W, int(extra_clutter), rng=d["rng"]))
            if W[int(y), int(x)] != 0:
                raise ValueError(f"the pose ({x}, {y}) is not in free space; move it")
            truth = np.array([float(x), float(y), np.radians(heading_deg)])
            rf = Rangefinder(n_beams=int(n_beams), max_range_cells=100.0, range_std_cells=range_std_cells)
            scan = rf.scan(W, truth, rng=d["rng"])
            loc = localise(M, scan, delta_alpha_rad=float(np.radians(delta_alpha_deg)), a_c=a_c, a_p=a_p)
            return W, scan, loc, truth  # localisation_figure's arguments

        def table(out):
            _, _, loc, truth = out
            err = np.hypot(*(loc.pose[:2] - truth[:2]))
            return f"{loc}; error {err:.2f} cells, {np.degrees(heading_error(loc.pose[2], truth[2])):.2f}°"

        show_run(run, lambda out: localisation_figure(*out), table=table)

    return interactive(
        show,
        x=_slider(widgets.IntSlider, d["x"], 3, 196, 1, "x [cells]"),
        y=_slider(widgets.IntSlider, d["y"], 3, 196, 1, "y [cells]"),
        heading_deg=_slider(widgets.FloatSlider, d["heading_deg"], 0.0, 359.0, 1.0, "heading [deg]"),
        range_std_cells=_slider(widgets.FloatSlider, d["range_std_cells"], 0.0, 3.0, 0.1, "range σ [cells]"),
        clutter=widgets.Checkbox(value=d["clutter"], description="clutter of Fig. 3b", style=_STYLE),
        extra_clutter=_slider(widgets.IntSlider, d["extra_clutter"], 0, 200, 10, "extra clutter discs"),
        delta_alpha_deg=_slider(widgets.FloatSlider, d["delta_alpha_deg"], 0.5, 10.0, 0.5, "Δα [deg]"),
        a_c=_slider(widgets.FloatSlider, d["a_c"], -2.0, 2.0, 0.25, "a_c (free)"),
        a_p=_slider(widgets.FloatSlider, d["a_p"], -2.0, 2.0, 0.25, "a_p (obstacle)"),
        n_beams=_slider(widgets.IntSlider, d["n_beams"], 30, 1080, 30, "beams"),
    )


@functools.lru_cache(maxsize=2)
def _log(path):
    return _carmen_log(path)


def explore_log_scan(path=None, **defaults):
    """Pick a scan of a CARMEN log (default: the corrected Intel log), a_c/a_p and how many consecutive scans to
    join by (logged) odometry; it is localised on a grid built from the log's poses without its neighbours
    (what :func:`run_log_localisation` does) and its ambiguity printed.

    Parameters
    ----------
    path : str or os.PathLike, optional
        CARMEN log; default the corrected Intel log.
    **defaults
        Initial values: ``scan`` (250), ``a_c`` (-1), ``a_p`` (1), ``exclude`` (10), ``joined`` (1) and the fixed
        ``cell_m`` (0.2), ``max_range_m`` (10).

    Returns
    -------
    ipywidgets.interactive
    """
    d = {"scan": 250, "a_c": -1.0, "a_p": 1.0, "exclude": 10, "joined": 1, "cell_m": 0.2, "max_range_m": 10.0}
    d.update(defaults)
    log = _log(path)

    def show(scan, a_c, a_p, exclude, joined):
        def run():
            js = [scan - j for j in range(joined) if scan - j >= 0]
            ex = max(exclude, len(js) - 1)  # the joined scans never draw the map they are matched against
            leave = range(max(0, scan - ex), min(log.n_scans, scan + ex + 1))
            G, frame, scans_c, Pc = log_grid(log, cell_m=d["cell_m"], max_range_m=d["max_range_m"], leave_out=leave)
            loc = localise_joined(G, [scans_c[j] for j in js], Pc[js], a_c=a_c, a_p=a_p)
            return len(js), frame, (G, scans_c[scan], loc, Pc[scan])  # the last: localisation_figure's arguments

        def table(out):
            n_joined, frame, (_, _, loc, _) = out
            est = frame.to_metres(loc.pose[None])[0]
            err = np.hypot(*(est[:2] - log.poses[scan, :2]))
            return (f"{log.name} scan {scan} ({n_joined} scan(s) joined by the logged odometry): error {err:.2f} m, "
                    f"{np.degrees(heading_error(est[2], log.poses[scan, 2])):.1f}°, ambiguity {loc.ambiguity:.3f}")

        show_run(run, lambda out: localisation_figure(*out[2]), table=table)

    return interactive(
        show,
        scan=_slider(widgets.IntSlider, min(d["scan"], log.n_scans - 1), 0, log.n_scans - 1, 1, "scan"),
        a_c=_slider(widgets.FloatSlider, d["a_c"], -2.0, 2.0, 0.25, "a_c (free)"),
        a_p=_slider(widgets.FloatSlider, d["a_p"], -2.0, 2.0, 0.25, "a_p (obstacle)"),
        exclude=_slider(widgets.IntSlider, d["exclude"], 0, 50, 1, "scans left out of the map (±)"),
        joined=_slider(widgets.IntSlider, d["joined"], 1, 3, 1, "scans joined by odometry"),
    )
