"""Widgets for Ch. 6: noise, clutter, Δθ, Δrho, H_min, scan choice and log choice (ipywidgets)."""

from __future__ import annotations

import math

import ipywidgets as widgets

from ...hough.lines import find_peaks
from ...hough.plot import accumulator_figure
from ...hough.slam import detect_lines
from ...hough.transform import hough_polar
from ...widgets import STYLE as _STYLE
from ...widgets import interactive, show_run
from ...widgets import slider as _slider
from .experiments import SHARED_LOGS, run_real_log, run_sim_slam
from .plot import real_log_figure, sim_figure

__all__ = ["explore_accumulator", "explore_hough_slam", "explore_real_log"]


def _theta_choice(value):
    return widgets.Dropdown(options=[0.25, 0.5, 1.0, 2.0, 3.0, 5.0], value=value, description="Δθ [°]",
                            style=_STYLE)


def explore_accumulator(**defaults):
    """One scan of 004's path: its polar accumulator, the peaks above H_min and the lines they give.

    Parameters
    ----------
    **defaults
        Initial values: ``pose_index`` (20), ``range_std_cells`` (0.1), ``clutter`` (False), ``delta_theta_deg`` (1),
        ``delta_rho`` (1), ``H_min`` (15) and the fixed ``rng`` (2010).

    Returns
    -------
    ipywidgets.interactive
    """
    from ... import sim

    d = {"pose_index": 20, "range_std_cells": 0.1, "clutter": False, "delta_theta_deg": 1.0, "delta_rho": 1.0,
         "H_min": 15, "rng": 2010}
    d.update(defaults)
    path = sim.path_004()

    def show(pose_index, range_std_cells, clutter, delta_theta_deg, delta_rho, H_min):
        def run():
            world = sim.measurement_room_200() if clutter else sim.test_room_200()
            rf = sim.Rangefinder(n_beams=360, max_range_cells=100.0, range_std_cells=range_std_cells)
            s = rf.scan(world, path[int(pose_index)], rng=d["rng"])
            phi, r = s.bearings_rad[s.valid], s.ranges[s.valid]
            acc = hough_polar(phi, r, delta_rho=delta_rho, delta_theta_rad=math.radians(delta_theta_deg))
            peaks = find_peaks(acc, int(H_min), max_lines=12)
            lines = detect_lines(s, delta_rho=delta_rho, delta_theta_rad=math.radians(delta_theta_deg),
                                 H_min=int(H_min))
            return acc, peaks, phi, r, lines  # accumulator_figure's arguments

        def table(out):
            acc, peaks, phi, _, lines = out
            return (f"pose {int(pose_index)}: {phi.size} returns, accumulator {acc.size_theta_rho[0]}×"
                    f"{acc.size_theta_rho[1]} (θ×ρ), {len(peaks)} peaks, {len(lines)} lines after the refit")

        show_run(run, lambda out: accumulator_figure(*out), table=table)

    return interactive(
        show,
        pose_index=_slider(widgets.IntSlider, d["pose_index"], 0, path.shape[0] - 1, 1, "scan (pose n)"),
        range_std_cells=_slider(widgets.FloatSlider, d["range_std_cells"], 0.0, 1.0, 0.05, "range σ [cells]"),
        clutter=widgets.Checkbox(value=d["clutter"], description="unmapped clutter", style=_STYLE),
        delta_theta_deg=_theta_choice(d["delta_theta_deg"]),
        delta_rho=_slider(widgets.FloatSlider, d["delta_rho"], 0.25, 3.0, 0.25, "Δρ [cells]"),
        H_min=_slider(widgets.IntSlider, d["H_min"], 3, 80, 1, "H_min"),
    )


def explore_hough_slam(**defaults):
    """004's experiment with the knobs: noise, clutter, Δθ, Δrho, H_min, method -> table and figures.

    Parameters
    ----------
    **defaults
        Initial values: ``n_poses`` (61), ``range_std_cells`` (0.1), ``clutter`` (False), ``delta_theta_deg`` (1),
        ``delta_rho`` (1), ``H_min`` (15), ``method`` ("least_squares"), ``refine`` (True) and the fixed ``rng`` (2010).

    Returns
    -------
    ipywidgets.interactive
    """
    d = {"n_poses": 61, "range_std_cells": 0.1, "clutter": False, "delta_theta_deg": 1.0, "delta_rho": 1.0,
         "H_min": 15, "method": "least_squares", "refine": True, "rng": 2010}
    d.update(defaults)

    def show(n_poses, range_std_cells, clutter, delta_theta_deg, delta_rho, H_min, method, refine):
        show_run(lambda: run_sim_slam(
            int(n_poses), range_std_cells=range_std_cells, clutter=clutter, with_icp=True, rng=d["rng"],
            delta_theta_rad=math.radians(delta_theta_deg), delta_rho=delta_rho, H_min=int(H_min), method=method,
            refine=refine), sim_figure)

    return interactive(
        show,
        n_poses=_slider(widgets.IntSlider, d["n_poses"], 21, 241, 10, "poses along the path"),
        range_std_cells=_slider(widgets.FloatSlider, d["range_std_cells"], 0.0, 1.0, 0.05, "range σ [cells]"),
        clutter=widgets.Checkbox(value=d["clutter"], description="unmapped clutter", style=_STYLE),
        delta_theta_deg=_theta_choice(d["delta_theta_deg"]),
        delta_rho=_slider(widgets.FloatSlider, d["delta_rho"], 0.25, 3.0, 0.25, "Δρ [cells]"),
        H_min=_slider(widgets.IntSlider, d["H_min"], 3, 80, 1, "H_min"),
        method=widgets.Dropdown(options=[("least squares (ours)", "least_squares"), ("two lines (004)", "two_lines")],
                                value=d["method"], description="pose from", style=_STYLE),
        refine=widgets.Checkbox(value=d["refine"], description="least-squares refit of lines (ours)", style=_STYLE),
    )


def explore_real_log(**defaults):
    """Hough SLAM on a real log: log choice, number of scans, H_min and Δrho -> table and maps.

    Parameters
    ----------
    **defaults
        Initial values: ``name`` ("mbicp", a key of ``SHARED_LOGS``), ``n_scans`` (160), ``step`` (1), ``H_min`` (15),
        ``delta_rho_cm`` (2).

    Returns
    -------
    ipywidgets.interactive
    """
    d = {"name": "mbicp", "n_scans": 160, "step": 1, "H_min": 15, "delta_rho_cm": 2.0}
    d.update(defaults)

    def show(name, n_scans, step, H_min, delta_rho_cm):
        def run():
            from ...data import find_data

            return run_real_log(find_data(SHARED_LOGS[name]), n_scans=int(n_scans), step=int(step), H_min=int(H_min),
                                delta_rho=delta_rho_cm / 100.0)

        show_run(run, real_log_figure, errors=(ValueError, TypeError, FileNotFoundError))  # the logs are files

    return interactive(
        show,
        name=widgets.Dropdown(options=[("MbICP SICK log", "mbicp"), ("Mines URG-04LX log exp2", "urg04lx"),
                                              ("Mines URG-04LX log exp1", "urg04lx_exp1")],
                              value=d["name"], description="log", style=_STYLE),
        n_scans=_slider(widgets.IntSlider, d["n_scans"], 20, 800, 20, "scans"),
        step=_slider(widgets.IntSlider, d["step"], 1, 5, 1, "use every k-th scan"),
        H_min=_slider(widgets.IntSlider, d["H_min"], 5, 60, 1, "H_min"),
        delta_rho_cm=_slider(widgets.FloatSlider, d["delta_rho_cm"], 0.5, 10.0, 0.5, "Δρ [cm]"),
    )
