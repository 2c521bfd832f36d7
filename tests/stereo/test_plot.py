"""Smoke tests of the Ch. 4 plots: they draw what they are given."""

import matplotlib.pyplot as plt
import numpy as np

from slamlab.geometry import StereoRig
from slamlab.sim.arena import StereoArena, StereoSim
from slamlab.sim.stereo_paths import turn_in_place
from slamlab.stereo import detect_features, stereo_match, triangulate_local
from slamlab.stereo.plot import plot_frame_stages, plot_triangulation
from slamlab.studies.stereo.experiments import run_stereo_slam
from slamlab.studies.stereo.plot import plot_kitti, plot_run_errors, plot_run_map


def test_plots():
    ax = plot_triangulation()
    assert len(ax.lines) == 3
    plt.close(ax.figure)
    rig = StereoRig.parallel(0.2, 384, 288)
    arena = StereoArena(texture_seed=0)
    sim = StereoSim(arena, rig, rng=0)
    left, right = sim.render_pair([3.0, 4.0, 1.0])
    fl, fr = detect_features(left, n_features=500), detect_features(right, n_features=500)
    sm = stereo_match(fl, fr, rig)
    cloud = triangulate_local(rig, fl, fr, sm)
    axes = plot_frame_stages(left, right, fl, fr, sm, cloud, np.arange(len(cloud.points)) % 2 == 0)
    assert "inliers" in axes[3].get_title()
    plt.close(axes[0].figure)
    res = run_stereo_slam(turn_in_place(np.deg2rad(5.0))[:3], name="turn in place", arena=arena, rig=rig, rng=0)
    ax = plot_run_map(res)
    np.testing.assert_allclose(ax.lines[2].get_xydata(), res.estimate[:, :2])
    plt.close(ax.figure)
    axes = plot_run_errors(res)
    np.testing.assert_allclose(axes[0].lines[0].get_ydata(), res.pos_err_m)
    assert axes[0].get_legend().get_texts()[0].get_text() == "surf, oldest"  # detector and policy
    plt.close(axes[0].figure)


def test_widget_runs_the_same_run_as_the_tests(capsys):
    from slamlab.stereo import RenderParams
    from slamlab.stereo.params import STEREO_DETECTORS
    from slamlab.studies.stereo import run_experiment
    from slamlab.studies.stereo.widgets import explore_stereo_slam

    w = explore_stereo_slam(policy="oldest", n_frames=3)
    names = [getattr(c, "description", "") for c in w.children]
    assert "landmarks" in names
    assert "run" in names  # manual: nothing runs until the button is pressed
    detector = next(c for c in w.children if getattr(c, "description", "") == "detector")
    assert tuple(detector.options) == STEREO_DETECTORS  # the one detector table, not a list of the widget's own
    capsys.readouterr()
    sliders = {"experiment": "turn in place", "policy": "oldest", "ransac_iters": 200}
    w.f(**sliders, detector="orb", noise_std=1.0, drift_mrad=0.5)  # what the button calls
    out = capsys.readouterr().out
    ref = run_experiment("turn in place", n_frames=3, detector="orb", render=RenderParams(noise_std=1.0, drift_std_rad=0.5e-3))
    assert ref.table() in out
    plt.close("all")
    w.f(**{**sliders, "ransac_iters": 0}, detector="orb", noise_std=0.0, drift_mrad=0.0)  # a message, not a traceback
    assert "Cannot run with these settings: `ransac_iters` must be >= 1" in capsys.readouterr().out


def test_plot_kitti_draws_the_paths_from_above():
    from types import SimpleNamespace

    T = np.tile(np.eye(4), (3, 1, 1))
    T[:, 2, 3] = [0.0, 1.0, 2.0]  # forward along z
    E = T.copy()
    E[:, 0, 3] = 0.1
    ax = plot_kitti(SimpleNamespace(truth=T, estimate=E))
    np.testing.assert_allclose(ax.lines[0].get_xydata(), [[0, 0], [0, 1], [0, 2]])
    np.testing.assert_allclose(ax.lines[1].get_xydata(), [[0.1, 0], [0.1, 1], [0.1, 2]])
    plt.close(ax.figure)
