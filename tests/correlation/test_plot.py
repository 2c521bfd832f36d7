"""Ch. 5 plots draw what they are given (smoke tests on tiny results)."""

import matplotlib.pyplot as plt
import numpy as np

from slamlab import correlation as C
from slamlab import sim as S


def test_plots_draw():
    M = S.test_room_200()
    scan = S.Rangefinder(n_beams=90, max_range_cells=60).scan(M, [70, 30, 0.3])
    loc = C.localise(M, scan, delta_alpha_rad=np.radians(5.0))
    fig = C.localisation_figure(M, scan, loc, np.array([70.0, 30.0, 0.3]))
    assert len(fig.axes) == 4  # three panels + the colour bar
    ax = C.plot_grid(M)
    assert ax.images[0].get_array().shape == (200, 200)
    T, o = C.rasterise_scan(scan.angles_rad, scan.ranges_cells, scan.hit, [0.0])
    ax = C.plot_stamp(T[0], o)
    assert ax.images[0].get_array().shape == T[0].shape
    t1 = C.run_table1(2, rng=1)
    ax = C.plot_table1(t1, M)
    assert len(ax.lines) >= 4
    mc = C.run_monte_carlo(2, rng=1)
    axes = C.plot_error_distribution(mc)
    assert len(axes) == 2
    plt.close("all")
