"""Widgets for the landmark-store chapter: the cost surface and a small store run (ipywidgets)."""

from __future__ import annotations

import ipywidgets as widgets

from ...kdtree.cost_model import iter_time, run_cost_model
from ...widgets import interactive, show_run
from ...widgets import slider as _slider
from .experiments import run_store_comparison
from .store_plot import plot_cost_contour, plot_iteration_times

__all__ = ["explore_cost_model", "explore_stores"]




def explore_cost_model(**defaults):
    """n1, q, s, m, n, C -> the cost at (n1, q), the optimum and the contour (000 §4.1.2, Appendix).

    Calls :func:`~slamlab.kdtree.cost_model.run_cost_model`; a bad combination
    prints its message instead of failing.

    Parameters
    ----------
    **defaults
        Initial slider values: ``n1``, ``q``, ``s``, ``m``, ``n``, ``C``.

    Returns
    -------
    ipywidgets.interactive
    """
    d = {"n1": 3500, "q": 5.5, "s": 500, "m": 500, "n": 50000, "C": 9.0}
    d.update(defaults)

    def show(n1, q, s, m, n, C):
        def run():
            return run_cost_model(n=n, s=s, m=m, C=C), float(iter_time(n1, q, n=n, s=s, m=m, C=C))

        def table(out):
            res, here = out
            _, bn1, bq, best, _ = res.optimum
            return (f"iterTime at n1 = {n1:.0f}, q = {q:.2f}: {here:.3g} steps, {here / best:.3f} x the optimum "
                    f"(n1 = {bn1:.0f}, q = {bq:.2f})")

        def draw(out):
            ax = plot_cost_contour(out[0])
            ax.plot(n1, q, "s", color="orange", markersize=8, label="sliders")
            ax.legend(loc="upper right", facecolor="0.85")

        show_run(run, draw, table=table)

    return interactive(
        show,
        n1=_slider(widgets.IntSlider, d["n1"], 500, 20000, 100, "n1"),
        q=_slider(widgets.FloatSlider, d["q"], 1.5, 10.0, 0.1, "q"),
        s=_slider(widgets.IntSlider, d["s"], 10, 5000, 10, "s (searches per iteration)"),
        m=_slider(widgets.IntSlider, d["m"], 10, 5000, 10, "m (adds per iteration)"),
        n=_slider(widgets.IntSlider, d["n"], 5000, 500000, 5000, "n (stored points)"),
        C=_slider(widgets.FloatSlider, d["C"], 0.5, 50.0, 0.5, "C = C1/C2"),
    )


def explore_stores(**defaults):
    """n1, q, s, m -> a small Table 2 style run of the rebuilt kd-tree vs the multi kd-tree (000 §4.2).

    ``s`` queries per iteration (90 % re-observations of stored points, 10 %
    clutter), ``m`` new points per iteration, ``n_iterations`` iterations.

    Parameters
    ----------
    **defaults
        Initial values: ``n1``, ``q``, ``s``, ``m``, ``n_iterations``, ``checks`` and ``rng`` (seed of
        the workload).

    Returns
    -------
    ipywidgets.interactive
    """
    d = {"n1": 1000, "q": 4.0, "s": 400, "m": 500, "n_iterations": 8, "checks": 200, "rng": 2010}
    d.update(defaults)

    def show(n1, q, s, m, n_iterations, checks):
        n_old = int(0.9 * s)
        show_run(lambda: run_store_comparison(
            "table2", stores=("rebuild", "multi"), n1=int(n1), q=q, checks=int(checks), n_iterations=int(n_iterations),
            n_new=int(m), p_track=0.0, n_old=n_old, n_clutter=int(s) - n_old, rng=d["rng"]),
            plot_iteration_times, table=lambda res: f"{res.table()}\n{res.timed_table()}")

    return interactive(
        show,
        n1=_slider(widgets.IntSlider, d["n1"], 100, 20000, 100, "n1"),
        q=_slider(widgets.FloatSlider, d["q"], 1.5, 10.0, 0.1, "q"),
        s=_slider(widgets.IntSlider, d["s"], 10, 2000, 10, "s (queries per iteration)"),
        m=_slider(widgets.IntSlider, d["m"], 10, 3000, 10, "m (new points per iteration)"),
        n_iterations=_slider(widgets.IntSlider, d["n_iterations"], 2, 60, 1, "iterations"),
        checks=_slider(widgets.IntSlider, d["checks"], 8, 2000, 8, "BBF checks"),
    )
