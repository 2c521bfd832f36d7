"""Ch. 5 plots draw what they are given (smoke tests on tiny results)."""

import matplotlib.pyplot as plt
import numpy as np
import pytest

from slamlab import correlation as C
from slamlab import sim as S
from slamlab.studies import correlation as CS


def test_plots_draw():
    M = S.test_room_200()
    scan = S.Rangefinder(n_beams=90, max_range_cells=60).scan(M, [70, 30, 0.3])
    loc = C.localise(M, scan, delta_alpha_rad=np.radians(5.0))
    fig = C.localisation_figure(M, scan, loc, np.array([70.0, 30.0, 0.3]))
    assert len(fig.axes) == 4  # three panels + the colour bar
    ax = C.plot_grid(M)
    assert ax.images[0].get_array().shape == (200, 200)
    T, o = C.scan_stamps(scan, [0.0])
    ax = C.plot_stamp(T[0], o)
    assert ax.images[0].get_array().shape == T[0].shape
    T3, _ = C.scan_stamps(scan, np.radians([0.0, 30.0, 60.0]))
    fig = C.plot_stamps(T3, o, (0, 2))
    assert [ax.get_title()[:14] for ax in fig.axes] == ["T_n at α0n = 0", "T_n at α0n = 2"]
    fig = C.plot_grids([M, M[:100]], ["a", "b"])
    assert [ax.images[0].get_array().shape for ax in fig.axes] == [(200, 200), (100, 200)]
    with pytest.raises(ValueError, match="titles"):
        C.plot_grids([M], ["a", "b"])
    t1 = CS.run_table1(2, rng=1)
    ax = CS.plot_table1(t1, M)
    assert len(ax.lines) >= 4
    mc = CS.run_monte_carlo(2, rng=1)
    axes = CS.plot_error_distribution(mc)
    assert len(axes) == 2
    plt.close("all")


def test_time_localise_reports_each_dtype():
    M = S.test_room_200()
    scan = S.Rangefinder(n_beams=90, max_range_cells=60).scan(M, [70, 30, 0.3])
    t = CS.time_localise(M, scan)
    assert set(t) == {"float64", "float32"}
    assert all(v > 0 for v in t.values())
