"""Widgets of the localisation chapter: MCL settings, a time slider over a recorded run, the CARMEN logs."""

from __future__ import annotations

import functools

import ipywidgets as widgets
import numpy as np

from ...localisation.plot import plot_belief
from ...widgets import interactive, show_run
from ...widgets import slider as _slider
from .experiments import demo_run
from .log_maps import CARMEN_LOGS
from .logs import run_log_mcl
from .plot import mcl_figure, plot_log_run, recorded_step_figure

__all__ = ["explore_log", "explore_markov", "explore_mcl", "explore_recorded_run"]


def explore_mcl(**defaults):
    """Particle count, α_slow/α_fast, z_hit/σ_hit, odometry noise, kidnap step → a recorded global run
    (cloud at the end, error and w_slow/w_fast against the step). Any setting gives a result or a message.

    Parameters
    ----------
    **defaults
        Start values of the controls: ``n_particles``, ``alpha_slow``, ``alpha_fast``, ``z_hit``, ``sigma_hit``,
        ``odo_noise``, ``kidnap_step``, ``seed``.

    Returns
    -------
    ipywidgets.interactive
    """
    from ...localisation.mcl import MCLParams

    p0 = MCLParams()
    d = {"n_particles": 2000, "alpha_slow": p0.alpha_slow, "alpha_fast": p0.alpha_fast, "z_hit": p0.z_hit,
         "sigma_hit": p0.sigma_hit, "odo_noise": 1.0, "kidnap_step": 25, "seed": 7}
    d.update(defaults)

    def show(n_particles, alpha_slow, alpha_fast, z_hit, sigma_hit, odo_noise, kidnap_step):
        def run():
            alpha = tuple(float(a * odo_noise) for a in p0.alpha)
            return demo_run(n_particles=int(n_particles), kidnap_step=int(kidnap_step) or None, alpha_slow=alpha_slow,
                            alpha_fast=alpha_fast, rng=d["seed"], z_hit=z_hit, z_rand=1.0 - z_hit,
                            sigma_hit=sigma_hit, max_dist=3 * sigma_hit, alpha=alpha)

        def table(out):
            sim_run, res = out
            return (f"final error {res.err_pos[-1]:.2f} cells, {np.degrees(res.err_heading_rad[-1]):.1f}°; "
                    f"injected {sum(r.n_injected for r in res.records)} particles in {sim_run.n_steps} steps")

        show_run(run, lambda out: mcl_figure(*out), table=table)

    return interactive(
        show,
        n_particles=_slider(widgets.IntSlider, d["n_particles"], 100, 10000, 100, "particles"),
        alpha_slow=_slider(widgets.FloatSlider, d["alpha_slow"], 0.0, 0.2, 0.001, "α_slow", readout_format=".3f"),
        alpha_fast=_slider(widgets.FloatSlider, d["alpha_fast"], 0.0, 1.0, 0.01, "α_fast"),
        z_hit=_slider(widgets.FloatSlider, d["z_hit"], 0.05, 1.0, 0.05, "z_hit (z_rand = 1 − z_hit)"),
        sigma_hit=_slider(widgets.FloatSlider, d["sigma_hit"], 0.5, 6.0, 0.25, "σ_hit [cells]"),
        odo_noise=_slider(widgets.FloatSlider, d["odo_noise"], 0.1, 10.0, 0.1, "odometry noise (× α)"),
        kidnap_step=_slider(widgets.IntSlider, d["kidnap_step"], 0, 59, 1, "kidnap step (0 = none)"),
    )


def explore_recorded_run(run, result):
    """A time slider over a recorded run: the weighted cloud and the weights' histogram at each step.

    Parameters
    ----------
    run : SimRun
        The run.
    result : FilterRun
        Its recorded MCL run (``keep_particles=True``).

    Returns
    -------
    ipywidgets.interactive
    """

    def show(step):
        w = result.snapshots[step][1]
        rec = result.records[step]
        print(f"step {step}: error {result.err_pos[step]:.2f} cells; N_eff {rec.n_eff:.0f} of {len(w)}; "
              f"w_slow {rec.w_slow:.3f}, w_fast {rec.w_fast:.3f}; injected {rec.n_injected}")
        recorded_step_figure(run, result, step)

    return interactive(show, step=widgets.IntSlider(value=0, min=0, max=run.n_steps - 1, step=1,
                                                            description="step", continuous_update=False))


@functools.lru_cache(maxsize=8)
def _log_run(name, n_scans, start, n_global):
    return run_log_mcl(name, n_scans=n_scans, start=start, n_particles_global=n_global)


def explore_log(**defaults):
    """Pick a corrected CARMEN log, the stretch of scans and the global particle count → tracking and global.

    Parameters
    ----------
    **defaults
        Start values of the controls: ``log``, ``start``, ``n_scans``, ``n_global``.

    Returns
    -------
    ipywidgets.interactive
    """
    d = {"log": "intel", "start": 0, "n_scans": 30, "n_global": 10000}
    d.update(defaults)

    def show(log, start, n_scans, n_global):
        show_run(lambda: _log_run(log, int(n_scans), int(start), int(n_global)), plot_log_run, table=str,
                     errors=(ValueError, TypeError, FileNotFoundError))  # the logs are data files

    return interactive(
        show,
        log=widgets.Dropdown(options=list(CARMEN_LOGS), value=d["log"], description="log"),
        start=_slider(widgets.IntSlider, d["start"], 0, 150, 10, "first scan"),
        n_scans=_slider(widgets.IntSlider, d["n_scans"], 10, 80, 5, "scans"),
        n_global=_slider(widgets.IntSlider, d["n_global"], 1000, 40000, 1000, "global particles"),
    )


def explore_markov(**defaults):
    """The Markov grid (003 §2.2.1): belief-cell size, headings, steps, the prior and an optional kidnap → the
    belief over the map after the last step, and the error at each step.

    Parameters
    ----------
    **defaults
        Start values of the controls: ``resolution``, ``n_headings``, ``n_steps``, ``prior``, ``kidnap_step``,
        ``uniform_floor``, ``seed``.

    Returns
    -------
    ipywidgets.interactive
    """
    from ...localisation.markov import MarkovGrid
    from .experiments import simulate_run

    d = {"resolution": 4, "n_headings": 36, "n_steps": 8, "prior": "uniform", "kidnap_step": 0,
         "uniform_floor": 0.0, "seed": 7}
    d.update(defaults)

    def show(resolution, n_headings, n_steps, prior, kidnap_step, uniform_floor):
        def run():
            k = int(kidnap_step) or None
            if k is not None and k >= n_steps:
                raise ValueError(f"the kidnap step ({k}) must come before the last step ({n_steps - 1})")
            rng = np.random.default_rng(d["seed"])
            sim_run = simulate_run(int(n_steps), start=0, kidnap_step=k, rng=rng)
            g = MarkovGrid(sim_run.grid, sim_run.max_range, resolution=int(resolution), n_headings=int(n_headings),
                           uniform_floor=float(uniform_floor))
            if prior != "uniform":
                off = 0.0 if prior == "Gaussian at the start" else 30.0
                g.belief = g.gaussian_prior(sim_run.true_poses[0] + [off, 0.0, 0.0], 10.0, np.radians(20))
            errs = []
            for i in range(sim_run.n_steps):
                prev, now = (sim_run.odom_poses[i - 1], sim_run.odom_poses[i]) if i else (None, None)
                m = g.step(prev, now, sim_run.scans[i])
                errs.append(float(np.hypot(*(m[:2] - sim_run.true_poses[i, :2]))))
            return g, errs, sim_run.true_poses[-1]

        def table(out):
            g, errs, _ = out
            return (f"belief {g.belief.shape} ({g.nbytes / 2**20:.2f} MiB); position error per step [cells]: "
                    + ", ".join(f"{e:.1f}" for e in errs))

        show_run(run, lambda out: plot_belief(out[0], true_pose=out[2]), table=table)

    return interactive(
        show,
        resolution=_slider(widgets.IntSlider, d["resolution"], 2, 10, 1, "cell size [map cells]"),
        n_headings=_slider(widgets.IntSlider, d["n_headings"], 8, 72, 4, "headings"),
        n_steps=_slider(widgets.IntSlider, d["n_steps"], 2, 30, 1, "steps"),
        prior=widgets.Dropdown(options=["uniform", "Gaussian at the start", "Gaussian 30 cells off"],
                               value=d["prior"], description="prior"),
        kidnap_step=_slider(widgets.IntSlider, d["kidnap_step"], 0, 29, 1, "kidnap step (0 = none)"),
        uniform_floor=widgets.Dropdown(options=[0.0, 1e-6, 1e-3], value=d["uniform_floor"], description="floor ε"),
    )
