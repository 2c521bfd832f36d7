"""Widgets of Ch. 9: the initial displacement, keyframe rules, patch size and noise on a short rendered run."""

from __future__ import annotations

import ipywidgets as widgets

from ..widgets import slider as _slider
from .experiments import mono_sim, render_sequence, run_mono, sequence_poses
from .plot import plot_map_top

__all__ = ["explore_mono"]


def explore_mono(**defaults):
    """A rendered strafe run with the slider values; prints the run and draws the map from above.

    Calls :func:`~slamlab.mono.run_mono`; a combination that cannot run prints its message.
    """
    d = {"init_disparity_px": 15.0, "kf_min_frames": 10, "kf_max_lost_ratio": 0.3, "patch_px": 9,
         "noise_std": 1.0, "n_frames": 24, "size": "tiny", "rng": 0}
    d.update(defaults)

    def show(init_disparity_px, kf_min_frames, kf_max_lost_ratio, patch_px, noise_std):
        try:
            sim = mono_sim(d["size"], noise_std=noise_std, rng=d["rng"])
            imgs, Ts = render_sequence(sim, sequence_poses("strafe", d["n_frames"]), progress=False)
            r = run_mono(imgs, Ts, sim.rig.left.K, name="strafe", progress=False,
                         init_disparity_px=init_disparity_px, kf_min_frames=int(kf_min_frames),
                         kf_max_lost_ratio=kf_max_lost_ratio, patch_px=int(patch_px) | 1)
        except (ValueError, TypeError) as exc:
            print(f"Cannot run with these settings: {exc}")
            return
        print(r)
        if r.tracked.sum() >= 3:
            plot_map_top(r)
        else:
            print("too few tracked frames to draw the path")

    return widgets.interactive(
        show,
        init_disparity_px=_slider(widgets.FloatSlider, d["init_disparity_px"], 2.0, 40.0, 1.0, "init disp. [px]"),
        kf_min_frames=_slider(widgets.IntSlider, d["kf_min_frames"], 1, 40, 1, "KF min frames"),
        kf_max_lost_ratio=_slider(widgets.FloatSlider, d["kf_max_lost_ratio"], 0.05, 0.9, 0.05, "KF lost ratio"),
        patch_px=_slider(widgets.IntSlider, d["patch_px"], 5, 15, 2, "patch [px]"),
        noise_std=_slider(widgets.FloatSlider, d["noise_std"], 0.0, 10.0, 0.5, "noise [grey]"),
    )
