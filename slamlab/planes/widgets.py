"""Widgets for Ch. 10 (002): a short flight with the filter's knobs (ipywidgets)."""

from __future__ import annotations

import ipywidgets as widgets

from ..widgets import STYLE as _STYLE
from ..widgets import slider as _slider
from .experiments import run_flight
from .plot import plot_flight_errors

__all__ = ["explore_flight"]


def explore_flight(**defaults):
    """A short flight: particle count, V (translation and rotation stds), RANSAC tolerance, intensity weights
    on/off and frame length → :func:`~slamlab.planes.run_flight`'s table and the Fig. 8 errors."""
    d = {"duration_s": 5.0, "n_particles": 200, "sigma_xyz_m": 0.03, "sigma_rpy_deg": 0.5,
         "ransac_tolerance_m": 0.04, "intensity_weights": True, "frame_lines": 40, "rng": 0}
    d.update(defaults)

    def show(n_particles, sigma_xyz_m, sigma_rpy_deg, ransac_tolerance_m, intensity_weights, frame_lines):
        try:
            res = run_flight(d["duration_s"], frame_lines=int(frame_lines), n_particles=int(n_particles),
                             sigma_xyz_m=sigma_xyz_m, sigma_rpy_deg=sigma_rpy_deg,
                             ransac_tolerance_m=ransac_tolerance_m, intensity_weights=bool(intensity_weights),
                             rng=d["rng"])
        except (ValueError, TypeError) as exc:
            print(f"Cannot run with these settings: {exc}")
            return
        print(res)
        print(res.table())
        plot_flight_errors(res)

    return widgets.interactive(
        show,
        n_particles=_slider(widgets.IntSlider, d["n_particles"], 10, 400, 10, "particles"),
        sigma_xyz_m=_slider(widgets.FloatSlider, d["sigma_xyz_m"], 0.0, 0.3, 0.01, "V: σ xyz [m]"),
        sigma_rpy_deg=_slider(widgets.FloatSlider, d["sigma_rpy_deg"], 0.0, 3.0, 0.1, "V: σ rpy [deg]"),
        ransac_tolerance_m=_slider(widgets.FloatSlider, d["ransac_tolerance_m"], 0.01, 0.2, 0.01,
                                   "RANSAC tolerance [m]"),
        intensity_weights=widgets.Checkbox(value=d["intensity_weights"], description="intensity weights",
                                           style=_STYLE),
        frame_lines=_slider(widgets.IntSlider, d["frame_lines"], 10, 80, 5, "lines per frame (40 = 1 s)"),
    )
