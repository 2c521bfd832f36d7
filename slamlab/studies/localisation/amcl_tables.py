"""ROS 1 AMCL, ROS 2 Nav2 AMCL and ours side by side (:data:`AMCL_DEFAULTS`, :func:`amcl_defaults_table`), and
003 beside what chapter 08 does (:func:`ours_vs_source`).

Moved unchanged from :mod:`slamlab.studies.localisation.experiments` (which re-exports every name).
"""

from __future__ import annotations

from ...localisation.mcl import MCLParams
from ._tables import table

__all__ = ["AMCL_DEFAULTS", "amcl_defaults_table", "ours_vs_source"]


# --- AMCL defaults and "Ours vs the source" ------------------------------------------------------------

#: AMCL's defaults as declared in the node sources (read 2026-11-26 from the snapshots): ROS 1
#: ``ros-planning/navigation`` ``amcl/src/amcl_node.cpp`` (``private_nh_.param(...)``), ``amcl/cfg/AMCL.cfg`` and
#: ``amcl/src/amcl/pf/pf.c``, ``amcl/src/amcl/sensors/amcl_laser.cpp``; ROS 2 ``ros-navigation/navigation2``
#: ``nav2_amcl/src/amcl_node.cpp`` (``declare_or_get_parameter``) and its ``pf/pf.c``. Lengths in metres.
AMCL_DEFAULTS = {
    "particles (min … max)": ("100 … 5000", "500 … 2000"),
    "KLD ε (kld_err / pf_err)": ("0.01", "0.05"),
    "KLD 1 − δ (kld_z / pf_z)": ("0.99", "0.99"),
    "sensor model": ("likelihood_field", "likelihood_field"),
    "observation weight": ("1 + Σ p³ [1]", "1 + Σ p³ [1]"),
    "z_hit": ("0.95", "0.5"),
    "z_rand": ("0.05", "0.5"),
    "σ_hit [m]": ("0.2", "0.2"),
    "likelihood max dist [m]": ("2.0", "2.0"),
    "beams used": ("30", "60"),
    "α1 … α4": ("0.2 each", "0.2 each"),
    "α_slow / α_fast": ("0.001 / 0.1 [2]", "0 / 0 (off)"),
    "w_slow, w_fast start": ("first w_avg [3]", "first w_avg [3]"),
    "resampling": ("every 2nd update [4]", "every update"),
    "beam skipping": ("off [5]", "off [5]"),
    "convergence test": ("within 0.5 m [6]", "within 0.5 m [6]"),
}
#: The notes under :func:`amcl_defaults_table` (the ``[n]`` marks of :data:`AMCL_DEFAULTS` and of ours).
AMCL_NOTES = (
    "[1] the likelihood_field model's weight; the product p(z | x) of PR Table 6.3 is their likelihood_field_prob",
    "[2] declared in the node's code; its dynamic-reconfigure file AMCL.cfg (and the ROS wiki) default to 0 / 0",
    "[3] and set back to 0 after every injection (pf.c)",
    "[4] resample_interval 2; selective_resampling off",
    "[5] do_beamskip, with the likelihood_field_prob model only",
    "[6] every particle within this distance of the particles' mean in x and in y",
    "[7] the weights are p(z | x)^gamma = (Π_k q_k)^gamma; ω is the score that eq 2.8 averages",
    ("[8] resampling only when N_eff < threshold·M; injected particles replace resampled ones, so injection happens "
    "only at a resampling"),
)


def amcl_defaults_table(params: MCLParams | None = None, cell_m: float = 0.1) -> str:
    """ROS 1 AMCL, ROS 2 Nav2 AMCL and ours side by side (ours in cells, and in metres at ``cell_m``).

    Parameters
    ----------
    params : MCLParams, optional
        Our settings (default: the defaults).
    cell_m : float
        Cell size [m] to express ours in metres.

    Returns
    -------
    str
    """
    p = MCLParams() if params is None else params
    score = {"likelihood": "p(z | x)", "geometric_mean": "geometric mean (ours)", "amcl_cubes": "1 + Σ p³"}[p.score]
    ours = {
        "particles (min … max)": f"{p.n_particles} fixed" + (f" (KLD: {p.n_min} … {p.n_particles})"
                                                             if p.use_kld else ""),
        "KLD ε (kld_err / pf_err)": f"{p.kld_epsilon:g} (when use_kld)",
        "KLD 1 − δ (kld_z / pf_z)": f"{p.kld_z:g} (when use_kld)",
        "sensor model": "likelihood_field",
        "observation weight": f"p(z | x)^{p.gamma:g}; ω: {score} [7]",
        "z_hit": f"{p.z_hit:g}",
        "z_rand": f"{p.z_rand:g}",
        "σ_hit [m]": f"{p.sigma_hit:g} cells = {p.sigma_hit * cell_m:g} m",
        "likelihood max dist [m]": f"{p.max_dist:g} cells = {p.max_dist * cell_m:g} m",
        "beams used": f"{p.max_beams}",
        "α1 … α4": ", ".join(f"{a:g}" for a in p.alpha),
        "α_slow / α_fast": f"{p.alpha_slow:g} / {p.alpha_fast:g} (on)" if p.injection else "0 / 0 (off)",
        "w_slow, w_fast start": {"003": "0 (003), never restarted", "amcl": "first w_avg [3]",
                                 "first": "first w_avg, never restarted",
                                 "debiased": "0 (003), ÷ 1 − (1 − α)^t"}[p.averages],
        "resampling": "every step" if p.resample_threshold >= 1 else
                      f"when N_eff < {p.resample_threshold:g}·M [8]",
        "beam skipping": "on, once converged" if p.beam_skip else "off",
        "convergence test": f"within {p.converged_dist:g} cells = {p.converged_dist * cell_m:g} m [6]",
    }
    rows = [[k, a, b, ours[k]] for k, (a, b) in AMCL_DEFAULTS.items()]
    return table(["setting", "ROS 1 amcl", "ROS 2 Nav2 amcl", "ours"], rows,
                 title=f"AMCL defaults (node sources) beside ours (ours in cells, and in metres at {cell_m:g} m cells)",
                 notes=AMCL_NOTES)


def ours_vs_source(global_result=None, kidnap=None, ablation=None) -> str:
    """003 §2.2 / §1.2.4 beside what this chapter does, with our figures where a run is given
    (a :class:`~slamlab.studies.localisation.studies.GlobalResult`, ``KidnapResult``, ``AblationResult``).

    Parameters
    ----------
    global_result : GlobalResult, optional
        A global-localisation study.
    kidnap : KidnapResult, optional
        A kidnap study.
    ablation : AblationResult, optional
        An ablation.

    Returns
    -------
    str
    """
    p = MCLParams()
    rows = [
        ["three cases", "tracking, global, SLAM (§1.2.4)", "tracking, global; SLAM: Ch. 05, 07, 09, 10"],
        ["Markov grid", "cells summing to 1, uniform if no prior", "(x, y, θ) grid, uniform on free cells"],
        ["Markov motion", "odometry (no formula)", "shift + Gaussian blur from α1…α4 (ours)"],
        ["Markov cost", "grows with the number of cells", "see the Markov tables"],
        ["MCL motion", "odometry (no formula)", f"PR Table 5.6 + jitter ({p.jitter[0]:g} cell, {p.jitter[1]:g} rad)"],
        ["MCL weight", "observation model in [0, 1]", f"p(z | x)^{p.gamma:g}; ω of eq 2.8: '{p.score}'"],
        ["eq 2.7", "Markov property (lost image)", "p(x_t+1 | x_0..t) = p(x_t+1 | x_t) (PR)"],
        ["eq 2.8", "mean weight (lost image)", "w_avg = Σ w_prev·ω, ω the score (PR Table 8.3)"],
        ["eqs 2.9-2.10", "w_slow, w_fast, 'initially 0' (lost)", f"PR Table 8.3; averages '{p.averages}'"],
        ["eq 2.11", "particles scattered at random (lost)", "M·max(0, 1 − w_fast/w_slow) expected"],
        ["resampling", "by probability", "low-variance (PR 4.4) when N_eff < M/2"],
        ["particle count", "not given", "fixed, or KLD sampling (our addition)"],
        ["results", "none survive (tables lost)", "tables of this notebook"],
    ]
    if global_result is not None:
        s = global_result.summary()
        best = s["success"].idxmax()
        rows.append(["global success", "—", (f"{s.loc[best, 'success']:.2f}, {int(best)} particles, step "
                                            f"{global_result.n_steps} ({global_result.n_runs} runs)")])
    if kidnap is not None:
        rows.append(["kidnap recovery", "—", (f"{kidnap.recovered():.2f} defaults, {kidnap.recovered(kidnap.labels[0]):.2f}"
                                             f" 003's start ({kidnap.n_runs} runs)")])
    if ablation is not None and "defaults" in ablation.labels:
        s = ablation.summary()
        k = f"success@{ablation.n_steps}"
        rows.append(["plain → defaults", "—", (f"{s[k].iloc[0]:.2f} → {s.loc['defaults', k]:.2f} "
                                                     f"({ablation.n_particles} particles, {ablation.n_runs} runs)")])
    return table(["item", "003", "ours"], rows, title="Ours vs the source (003 §1.2.4, §2.2)")
