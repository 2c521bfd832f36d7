"""Widgets for Ch. 10 (002): a short flight with the filter's knobs, and Fig. 4's one cycle (ipywidgets)."""

from __future__ import annotations

import ipywidgets as widgets

from ...widgets import STYLE as _STYLE
from ...widgets import interactive, show_run
from ...widgets import slider as _slider
from .experiments import run_flight
from .figures import run_intensity_figure
from .plot import plot_flight_errors, plot_intensity_figure

__all__ = ["explore_flight", "explore_intensity_figure"]


def explore_flight(**defaults):
    """A short flight: particle count, V (the variances of ε, 002), RANSAC tolerance, intensity weights on/off and
    frame length → :func:`~slamlab.studies.planes.run_flight`'s table and the Fig. 8 errors.

    Parameters
    ----------
    **defaults
        Initial values: ``duration_s``, ``n_particles``, ``V_xyz_m2``, ``V_rpy_deg2``,
        ``ransac_tolerance_m``, ``intensity_weights``, ``frame_lines``, ``rng`` (seed).

    Returns
    -------
    ipywidgets.interactive
    """
    d = {"duration_s": 5.0, "n_particles": 200, "V_xyz_m2": 9e-4, "V_rpy_deg2": 0.25,
         "ransac_tolerance_m": 0.04, "intensity_weights": True, "frame_lines": 40, "rng": 0}
    d.update(defaults)

    def show(n_particles, V_xyz_m2, V_rpy_deg2, ransac_tolerance_m, intensity_weights, frame_lines):
        show_run(lambda: run_flight(d["duration_s"], frame_lines=int(frame_lines), n_particles=int(n_particles),
                                        V_xyz_m2=V_xyz_m2, V_rpy_deg2=V_rpy_deg2,
                                        ransac_tolerance_m=ransac_tolerance_m,
                                        intensity_weights=bool(intensity_weights), rng=d["rng"]),
                     plot_flight_errors, table=lambda res: f"{res}\n{res.table()}")

    return interactive(
        show,
        n_particles=_slider(widgets.IntSlider, d["n_particles"], 10, 400, 10, "particles"),
        V_xyz_m2=_slider(widgets.FloatSlider, d["V_xyz_m2"], 0.0, 0.01, 1e-4, "V xyz [m²] (variance)",
                         readout_format=".4f"),
        V_rpy_deg2=_slider(widgets.FloatSlider, d["V_rpy_deg2"], 0.0, 4.0, 0.05, "V rpy [deg²] (variance)"),
        ransac_tolerance_m=_slider(widgets.FloatSlider, d["ransac_tolerance_m"], 0.01, 0.2, 0.01,
                                   "RANSAC tolerance [m]"),
        intensity_weights=widgets.Checkbox(value=d["intensity_weights"], description="intensity weights",
                                           style=_STYLE),
        frame_lines=_slider(widgets.IntSlider, d["frame_lines"], 10, 80, 5, "lines per frame (40 = 1 s)"),
    )


def explore_intensity_figure(**defaults):
    """002 Fig. 4, one cycle: the offset along the walls, V of the prediction (a variance, m²), particle count and
    the incidence correction → :func:`~slamlab.studies.planes.run_intensity_figure`'s tables and the weights plot.

    Parameters
    ----------
    **defaults
        Initial values: ``offset_m``, ``V_xyz_m2``, ``n_particles``, ``incidence_correction``, ``rng`` (seed).

    Returns
    -------
    ipywidgets.interactive
    """
    d = {"offset_m": 0.4, "V_xyz_m2": 0.09, "n_particles": 400, "incidence_correction": True, "rng": 0}
    d.update(defaults)

    def show(offset_m, V_xyz_m2, n_particles, incidence_correction):
        show_run(lambda: run_intensity_figure(offset_m, n_particles=int(n_particles), V_xyz_m2=V_xyz_m2,
                                                  incidence_correction=bool(incidence_correction), rng=d["rng"]),
                     plot_intensity_figure, table=lambda r: f"{r.table()}\n{r.profile_table()}")

    return interactive(
        show,
        offset_m=_slider(widgets.FloatSlider, d["offset_m"], 0.0, 1.5, 0.1, "offset along the walls [m]"),
        V_xyz_m2=_slider(widgets.FloatSlider, d["V_xyz_m2"], 0.0, 1.0, 0.01, "V xyz [m²] (variance)"),
        n_particles=_slider(widgets.IntSlider, d["n_particles"], 20, 800, 20, "particles"),
        incidence_correction=widgets.Checkbox(value=d["incidence_correction"], description="incidence correction",
                                              style=_STYLE),
    )
