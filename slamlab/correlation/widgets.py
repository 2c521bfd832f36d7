"""Widgets for Ch. 5: turn the noise, clutter, Δα and a_c/a_p knobs; pick a real scan (ipywidgets)."""

from __future__ import annotations

import functools

import ipywidgets as widgets
import numpy as np

from ..sim.grid import add_clutter, measurement_room_200, test_room_200
from ..sim.rangefinder import Rangefinder
from ..widgets import STYLE as _STYLE
from ..widgets import slider as _slider
from .algorithm import heading_error, localise
from .experiments import random_clutter
from .plot import localisation_figure

__all__ = ["explore_intel_scan", "explore_localisation"]




def explore_localisation(**defaults):
    """One scan in the test room: pose, noise, clutter, Δα and a_c/a_p → localisation, score map, heading profile.

    Calls :func:`~slamlab.correlation.localise` with the slider values. A bad
    combination (a_c = a_p, a pose inside an obstacle) prints its message.
    """
    d = {"x": 60, "y": 40, "heading_deg": 30.0, "range_std_cells": 0.3, "clutter": True, "extra_clutter": 0,
         "delta_alpha_deg": 1.0, "a_c": -1.0, "a_p": 1.0, "n_beams": 360, "rng": 2010}
    d.update(defaults)
    M = test_room_200()

    def show(x, y, heading_deg, range_std_cells, clutter, extra_clutter, delta_alpha_deg, a_c, a_p, n_beams):
        try:
            W = measurement_room_200() if clutter else M.copy()
            if extra_clutter:
                W = add_clutter(W, random_clutter(W, int(extra_clutter), rng=d["rng"]))
            if W[int(y), int(x)] != 0:
                raise ValueError(f"the pose ({x}, {y}) is not in free space; move it")
            truth = np.array([float(x), float(y), np.radians(heading_deg)])
            rf = Rangefinder(n_beams=int(n_beams), max_range_cells=100.0, range_std_cells=range_std_cells)
            scan = rf.scan(W, truth, rng=d["rng"])
            loc = localise(M, scan, delta_alpha_rad=np.radians(delta_alpha_deg), a_c=a_c, a_p=a_p,
                           dtype=np.float32)
        except (ValueError, TypeError) as exc:
            print(f"Cannot run with these settings: {exc}")
            return
        err = np.hypot(*(loc.pose[:2] - truth[:2]))
        print(f"{loc}; error {err:.2f} cells, {np.degrees(heading_error(loc.pose[2], truth[2])):.2f}°")
        localisation_figure(W, scan, loc, truth)

    return widgets.interactive(
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


@functools.lru_cache(maxsize=1)
def _intel_map(cell_m: float, max_range_m: float):
    from ..data import find_data
    from ..io import read_carmen
    from .mapping import GridFrame

    log = read_carmen(find_data("carmen-radish-corrected/intel-corrected.log.gz"))
    valid = log.valid & (np.nan_to_num(log.ranges_m) < max_range_m)
    R = np.where(valid, np.nan_to_num(log.ranges_m), max_range_m) / cell_m
    pts = np.vstack([log.points(i) for i in range(0, log.n_scans, 10)])
    pts = pts[np.hypot(*(pts - log.poses[:, :2].mean(axis=0)).T) < max_range_m + 40]
    frame = GridFrame.around(np.vstack([log.poses[:, :2], pts]), cell_m, 1.0)
    return log, frame, R, valid, frame.to_cells(log.poses)


def explore_intel_scan(**defaults):
    """Pick a scan of the corrected Intel log and a_c/a_p; it is localised on a grid built without its neighbours."""
    from .mapping import occupancy_grid_from_scans

    d = {"scan": 250, "a_c": -1.0, "a_p": 1.0, "exclude": 10, "cell_m": 0.2, "max_range_m": 10.0}
    d.update(defaults)

    def show(scan, a_c, a_p, exclude):
        try:
            log, frame, R, valid, Pc = _intel_map(d["cell_m"], d["max_range_m"])
            keep = np.ones(log.n_scans, bool)
            keep[max(0, scan - exclude):scan + exclude + 1] = False
            G = occupancy_grid_from_scans(log.angles_rad, R[keep], valid[keep], Pc[keep], frame.shape)
            loc = localise(G, (log.angles_rad, R[scan], valid[scan]), a_c=a_c, a_p=a_p, dtype=np.float32)
        except (ValueError, TypeError, FileNotFoundError) as exc:
            print(f"Cannot run with these settings: {exc}")
            return
        est = frame.to_metres(loc.pose[None])[0]
        err = np.hypot(*(est[:2] - log.poses[scan, :2]))
        print(f"scan {scan}: error {err:.2f} m, {np.degrees(heading_error(est[2], log.poses[scan, 2])):.1f}°")
        localisation_figure(G, (log.angles_rad, R[scan], valid[scan]), loc, Pc[scan])

    return widgets.interactive(
        show,
        scan=_slider(widgets.IntSlider, d["scan"], 0, 909, 1, "scan"),
        a_c=_slider(widgets.FloatSlider, d["a_c"], -2.0, 2.0, 0.25, "a_c (free)"),
        a_p=_slider(widgets.FloatSlider, d["a_p"], -2.0, 2.0, 0.25, "a_p (obstacle)"),
        exclude=_slider(widgets.IntSlider, d["exclude"], 0, 50, 1, "scans left out of the map (±)"),
    )
