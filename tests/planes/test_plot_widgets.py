"""Ch. 10 plots draw what they are given; the widget gives a table or a readable message."""

import matplotlib.pyplot as plt
import numpy as np
import pytest

from slamlab import planes as PL
from slamlab import sim as S
from slamlab.studies import planes as SP


@pytest.fixture(scope="module")
def results():
    fl = SP.run_flight(3.0, rng=1, n_particles=30)
    return fl, SP.run_pairs_figure(20, rng=1), SP.run_intensity_figure(n_particles=30, rounds=1, rng=1)


def test_plots_draw(results):
    fl, pairs, fig4 = results
    fig = SP.scanner_geometry_figure()
    assert len(fig.axes) == 2
    flight = S.simulate_flight(1.0, rng=2)
    _, frame, _, _ = next(SP.flight_frames(flight))
    ax = PL.plot_frame_points(frame, max_points=500)
    assert len(ax.collections) == 1
    found, _ = PL.extract_planes(frame.points, rng=0)
    ax = PL.plot_frame_planes(frame, found, max_points=500)
    assert len(ax.collections) == 1 + len(found)
    assert len(SP.plot_pairs_figure(pairs).axes) == 3
    ax = SP.plot_intensity_figure(fig4)
    assert len(ax.collections) == 1
    assert len(SP.plot_flight_errors(fl).axes) == 6
    ax = SP.plot_plane_map(fl, max_cells=300)
    assert len(ax.lines) == 2
    n, p, idx = found[0]
    pl = PL.describe_plane(frame.points[idx], frame.intensities[idx], n, p, rays=frame.rays[idx])
    a1, a2 = PL.plot_plane_description(pl, frame.points[idx], max_points=300)
    assert len(a1.collections) == 1
    assert len(a2.images) == 1
    room = S.build_plane_room(rng=0)
    ax = SP.plot_room(room, path=fl.poses_true[:, :3, 3])          # Fig. 7: the panels, the ceiling hidden
    assert len(ax.collections) == 1
    assert len(ax.lines) == 1
    shown = sum(int(np.ceil(2 * room.half_u[i] - 1e-9)) * int(np.ceil(2 * room.half_v[i] - 1e-9))
                for i in range(len(room)) if room.names[i] != "room z+")
    assert len(ax.collections[0].get_facecolors()) == shown
    plt.close("all")


def test_explore_flight(capsys):
    w = SP.explore_flight(duration_s=2.0, n_particles=20)
    out = capsys.readouterr().out
    assert "Flight: 2 frames" in out
    w.f(**{**w.kwargs, "frame_lines": 60})                # 80 lines: one frame of 60 only
    out = capsys.readouterr().out
    assert "Cannot run with these settings" in out
    assert "Traceback" not in out
    plt.close("all")


def test_explore_intensity_figure(capsys):
    w = SP.explore_intensity_figure(n_particles=40)
    out = capsys.readouterr().out
    assert "one cycle" in out
    assert "V of the prediction" in out
    w.f(**{**w.kwargs, "V_xyz_m2": 0.0})                 # no spread: a readable result, not a traceback
    out = capsys.readouterr().out
    assert "Traceback" not in out
    plt.close("all")
