"""Widgets for Ch. 4: detector, RANSAC iterations, landmark policy, image noise and calibration drift."""

from __future__ import annotations

import ipywidgets as widgets
from IPython.display import display

from ...stereo.params import STEREO_DETECTORS, RenderParams
from ...widgets import STYLE as _STYLE
from ...widgets import interactive, show_run
from .experiments import experiment_poses, run_experiment
from .plot import run_figure

__all__ = ["explore_stereo_slam"]



def explore_stereo_slam(**defaults):
    """Run the turn in place or the closed loop (small size) with the chosen settings -> table and plots.

    Each change starts a run of 15-30 s; the run button (``manual``) avoids a run per slider step.
    ``n_frames`` (a default, not a slider) keeps the first frames only (quick checks).
    A bad combination prints its message instead of failing.

    Parameters
    ----------
    **defaults
        Initial values: ``experiment`` ("turn in place"), ``detector`` ("surf"), ``policy`` ("oldest"),
        ``ransac_iters`` (200), ``noise_std`` (0), ``drift_mrad`` (0) and the fixed ``rng`` (0), ``n_frames`` (None).

    Returns
    -------
    ipywidgets.interactive
    """
    d = {"experiment": "turn in place", "detector": "surf", "policy": "oldest", "ransac_iters": 200,
         "noise_std": 0.0, "drift_mrad": 0.0, "rng": 0, "n_frames": None}  # fmt: skip
    d.update(defaults)

    def show(experiment, detector, policy, ransac_iters, noise_std, drift_mrad):
        n = len(experiment_poses(experiment, "small")) if d["n_frames"] is None else d["n_frames"]
        bar = widgets.IntProgress(min=0, max=n, description="frames")
        display(bar)
        show_run(
            lambda: run_experiment(
                experiment, "small", n_frames=d["n_frames"], detector=detector, policy=policy,
                ransac_iters=int(ransac_iters),
                render=RenderParams(noise_std=float(noise_std), drift_std_rad=float(drift_mrad) * 1e-3),
                rng=d["rng"], progress=lambda i: setattr(bar, "value", i + 1),
            ),
            run_figure, table=lambda res: f"{res.table()}\n{res.timing_table()}",
        )  # fmt: skip

    return interactive(
        show,
        {"manual": True, "manual_name": "run"},
        experiment=widgets.Dropdown(options=["turn in place", "closed loop"], value=d["experiment"], description="experiment"),
        detector=widgets.Dropdown(options=list(STEREO_DETECTORS), value=d["detector"], description="detector"),
        policy=widgets.Dropdown(options=["oldest", "all"], value=d["policy"], description="landmarks"),
        ransac_iters=widgets.IntSlider(value=d["ransac_iters"], min=1, max=500, step=1, description="RANSAC iterations",
                                       continuous_update=False, style=_STYLE),
        noise_std=widgets.FloatSlider(value=d["noise_std"], min=0.0, max=20.0, step=0.5, description="image noise σ [grey]",
                                      continuous_update=False, style=_STYLE),
        drift_mrad=widgets.FloatSlider(value=d["drift_mrad"], min=0.0, max=5.0, step=0.1,
                                       description="calibration drift [mrad/frame]", continuous_update=False, style=_STYLE),
    )  # fmt: skip

