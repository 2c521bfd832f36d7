"""Widgets for Ch. 1: turn the noise, nonlinearity and sigma-point knobs (ipywidgets)."""

from __future__ import annotations

import ipywidgets as widgets

from ...widgets import interactive, show_run
from ...widgets import slider as _slider
from .experiments import run_cv_target, run_unicycle_comparison
from .plot import cv_figure, unicycle_figure

__all__ = ["explore_cv_target", "explore_unicycle"]




def explore_unicycle(**defaults):
    """Noise levels, initial heading uncertainty, alpha/beta/kappa and stabilising noise -> table and plots.

    Calls :func:`run_unicycle_comparison` with the slider values; ``alpha`` is
    set on a log scale. A bad combination prints its message instead of failing.

    Parameters
    ----------
    **defaults
        Initial slider values and fixed settings: ``n_runs`` (10), ``n_steps`` (60), ``range_std_m``,
        ``bearing_std_deg``, ``omega_std_degps``, ``init_heading_std_deg``, ``alpha``, ``beta``, ``kappa``,
        ``stabilising_noise``, ``rng`` (2010).

    Returns
    -------
    ipywidgets.interactive
    """
    d = {"n_runs": 10, "n_steps": 60, "range_std_m": 0.5, "bearing_std_deg": 10.0, "omega_std_degps": 10.0,
             "init_heading_std_deg": 90.0, "alpha": 1e-3, "beta": 2.0, "kappa": 0.0, "stabilising_noise": 1.0, "rng": 2010}
    d.update(defaults)

    def show(n_runs, range_std_m, bearing_std_deg, omega_std_degps, init_heading_std_deg, alpha, beta, kappa,
             stabilising_noise):
        show_run(lambda: run_unicycle_comparison(
            int(n_runs), d["n_steps"], range_std_m=range_std_m, bearing_std_deg=bearing_std_deg,
            omega_std_degps=omega_std_degps, init_heading_std_deg=init_heading_std_deg, alpha=alpha, beta=beta,
            kappa=kappa, stabilising_noise=stabilising_noise, rng=d["rng"]), unicycle_figure)

    return interactive(
        show,
        n_runs=_slider(widgets.IntSlider, d["n_runs"], 1, 50, 1, "Monte Carlo runs"),
        range_std_m=_slider(widgets.FloatSlider, d["range_std_m"], 0.01, 2.0, 0.01, "range σ [m]"),
        bearing_std_deg=_slider(widgets.FloatSlider, d["bearing_std_deg"], 0.5, 30.0, 0.5, "bearing σ [deg]"),
        omega_std_degps=_slider(widgets.FloatSlider, d["omega_std_degps"], 0.0, 40.0, 0.5, "turn-rate σ [deg/s]"),
        init_heading_std_deg=_slider(widgets.FloatSlider, d["init_heading_std_deg"], 1.0, 120.0, 1.0,
                                     "initial heading σ [deg]"),
        alpha=widgets.FloatLogSlider(value=d["alpha"], base=10, min=-4, max=0, step=0.25, description="α",
                                     continuous_update=False, readout_format=".0e"),
        beta=_slider(widgets.FloatSlider, d["beta"], 0.0, 4.0, 0.5, "β"),
        kappa=_slider(widgets.FloatSlider, d["kappa"], -2.0, 5.0, 0.5, "κ"),
        stabilising_noise=_slider(widgets.FloatSlider, d["stabilising_noise"], 0.25, 16.0, 0.25,
                                  "stabilising noise (Q ×)"),
    )


def explore_cv_target(**defaults):
    """Constant-velocity target: acceleration noise and measurement noise -> KF table, NEES plot.

    Parameters
    ----------
    **defaults
        Initial values: ``n_runs`` (30), ``n_steps`` (50), ``accel_std`` (0.2), ``pos_std_m`` (1.0), ``rng`` (2010).

    Returns
    -------
    ipywidgets.interactive
    """
    d = {"n_runs": 30, "n_steps": 50, "accel_std": 0.2, "pos_std_m": 1.0, "rng": 2010}
    d.update(defaults)

    def show(accel_std, pos_std_m):
        show_run(lambda: run_cv_target(d["n_runs"], d["n_steps"], accel_std=accel_std, pos_std_m=pos_std_m,
                                           rng=d["rng"]), cv_figure)

    return interactive(
        show,
        accel_std=_slider(widgets.FloatSlider, d["accel_std"], 0.0, 2.0, 0.05, "acceleration σ [m/s²]"),
        pos_std_m=_slider(widgets.FloatSlider, d["pos_std_m"], 0.05, 5.0, 0.05, "position σ [m]"),
    )


