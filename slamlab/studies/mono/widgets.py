"""Widgets of Ch. 9: a short rendered run, the failure cases, the motion prior, the depth filter.

Each widget only calls the ``run_*`` / ``plot_*`` functions the tests call; a combination that
cannot run prints its message instead of a traceback.
"""

from __future__ import annotations

import ipywidgets as widgets

from ...widgets import interactive, show_run
from ...widgets import slider as _slider
from .experiments import (
    FAILURE_CASES,
    mono_sim,
    render_sequence,
    run_depth_filter_convergence,
    run_failure_cases,
    run_mono,
    sequence_poses,
)
from .plot import plot_convergence, plot_map_top

__all__ = ["explore_depth_filter", "explore_failure_cases", "explore_mono", "explore_motion_prior"]


def _draw_run(r):
    if r.claimed.sum() >= 3:
        plot_map_top(r)
    else:
        print("too few tracked frames to draw the path")


def explore_mono(**defaults):
    """A rendered strafe run with the slider values; prints the run and draws the map from above.

    Calls :func:`~slamlab.studies.mono.run_mono`; a combination that cannot run prints its message.

    Parameters
    ----------
    **defaults
        Start values: ``init_disparity_px``, ``kf_min_frames``, ``kf_max_lost_ratio``, ``patch_px``,
        ``noise_std`` (sliders), ``n_frames``, ``size``, ``rng``.

    Returns
    -------
    ipywidgets.interactive
    """
    d = {"init_disparity_px": 15.0, "kf_min_frames": 10, "kf_max_lost_ratio": 0.3, "patch_px": 9,
         "noise_std": 1.0, "n_frames": 24, "size": "tiny", "rng": 0}
    d.update(defaults)

    def show(init_disparity_px, kf_min_frames, kf_max_lost_ratio, patch_px, noise_std):
        def run():
            sim = mono_sim(d["size"], noise_std=noise_std, rng=d["rng"])
            imgs, Ts = render_sequence(sim, sequence_poses("strafe", d["n_frames"]), progress=False)
            return run_mono(imgs, Ts, sim.rig.left.K, name="strafe", progress=False,
                            init_disparity_px=init_disparity_px, kf_min_frames=int(kf_min_frames),
                            kf_max_lost_ratio=kf_max_lost_ratio, patch_px=int(patch_px) | 1)

        show_run(run, _draw_run, table=str)

    return interactive(
        show,
        init_disparity_px=_slider(widgets.FloatSlider, d["init_disparity_px"], 2.0, 40.0, 1.0, "init disp. [px]"),
        kf_min_frames=_slider(widgets.IntSlider, d["kf_min_frames"], 1, 40, 1, "KF min frames"),
        kf_max_lost_ratio=_slider(widgets.FloatSlider, d["kf_max_lost_ratio"], 0.05, 0.9, 0.05, "KF lost ratio"),
        patch_px=_slider(widgets.IntSlider, d["patch_px"], 5, 15, 2, "patch [px]"),
        noise_std=_slider(widgets.FloatSlider, d["noise_std"], 0.0, 10.0, 0.5, "noise [grey]"),
    )


def explore_failure_cases(**defaults):
    """One of 003 §5.3's failure cases (rendered) with the chosen motion prior: its table row and map.

    Parameters
    ----------
    **defaults
        Start values: ``case``, ``motion_model`` (menus), ``size``, ``n_frames``, ``rng``.

    Returns
    -------
    ipywidgets.interactive
    """
    d = {"case": "normal", "motion_model": "constant_velocity", "size": "tiny", "n_frames": 24, "rng": 0}
    d.update(defaults)

    def show(case, motion_model):
        show_run(lambda: run_failure_cases((case,), size=d["size"], n_frames=d["n_frames"], rng=d["rng"],
                                               progress=False, motion_model=motion_model)[case],
                     _draw_run, table=str)

    return interactive(
        show,
        case=widgets.Dropdown(options=("normal", *FAILURE_CASES), value=d["case"], description="case"),
        motion_model=widgets.ToggleButtons(options=("constant_velocity", "constant_position"), value=d["motion_model"],
                                           description="motion prior"),
    )


def explore_motion_prior(**defaults):
    """003's constant velocity or SVO's constant position on a rendered sequence: the run and its map.

    Parameters
    ----------
    **defaults
        Start values: ``sequence``, ``motion_model``, ``n_frames`` (controls), ``size``, ``rng``.

    Returns
    -------
    ipywidgets.interactive
    """
    d = {"sequence": "strafe", "motion_model": "constant_velocity", "size": "tiny", "n_frames": 30, "rng": 0}
    d.update(defaults)

    def show(sequence, motion_model, n_frames):
        def run():
            sim = mono_sim(d["size"], rng=d["rng"])
            imgs, Ts = render_sequence(sim, sequence_poses(sequence, int(n_frames)), progress=False)
            return run_mono(imgs, Ts, sim.rig.left.K, name=f"{sequence}, {motion_model}", progress=False,
                            motion_model=motion_model)

        show_run(run, _draw_run, table=str)

    return interactive(
        show,
        sequence=widgets.Dropdown(options=("strafe", "arc"), value=d["sequence"], description="sequence"),
        motion_model=widgets.ToggleButtons(options=("constant_velocity", "constant_position"), value=d["motion_model"],
                                           description="motion prior"),
        n_frames=_slider(widgets.IntSlider, d["n_frames"], 10, 60, 5, "frames"),
    )


def explore_depth_filter(**defaults):
    """The depth filter of 003 §4.1.1 fed ``n_obs`` measurements at an outlier rate and noise τ_ρ (1/m).

    Parameters
    ----------
    **defaults
        Start values: ``outlier_rate``, ``tau``, ``n_obs`` (sliders), ``rng``.

    Returns
    -------
    ipywidgets.interactive
    """
    d = {"outlier_rate": 0.4, "tau": 0.01, "n_obs": 40, "rng": 0}
    d.update(defaults)

    def show(outlier_rate, tau, n_obs):
        show_run(lambda: run_depth_filter_convergence((outlier_rate,), n_obs=int(n_obs), tau=tau, rng=d["rng"]),
                     plot_convergence, table=lambda c: c.table(at=tuple(sorted({0, 5, 10, 20, int(n_obs)}))))

    return interactive(
        show,
        outlier_rate=_slider(widgets.FloatSlider, d["outlier_rate"], 0.0, 0.9, 0.05, "outliers"),
        tau=widgets.FloatLogSlider(value=d["tau"], base=10, min=-3, max=-1, step=0.25, description="τ_ρ [1/m]",
                                   continuous_update=False),
        n_obs=_slider(widgets.IntSlider, d["n_obs"], 5, 100, 5, "observations"),
    )
