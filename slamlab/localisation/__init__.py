"""Probabilistic localisation: Markov grid localisation and Monte Carlo localisation (003 §1.2.4, §2.2; Ch. 8).

The chapter's studies (simulated runs, the global, kidnapped and Markov studies, the CARMEN logs, their
tables, plots and widgets) are in :mod:`slamlab.studies.localisation`.
"""

from .._lazy import lazy_exports
from .markov import MarkovGrid, MarkovParams, markov_correct, markov_log_likelihood, markov_predict
from .mcl import AVERAGES, MCL, MCLParams, MCLState, StepRecord, mcl_step
from .models import (
    SCORES,
    Beams,
    LikelihoodFieldModel,
    ModelParams,
    beam_model_prob,
    check_alpha,
    check_particles,
    motion_density_odometry,
    odometry_deltas,
    sample_motion_odometry,
    scan_beams,
)
from .particles import (
    amcl_converged,
    free_cell_centres,
    is_localised,
    kld_bound,
    kld_sample_count,
    low_variance_resample,
    n_eff,
    normalise_log_weights,
    pose_estimate,
    uniform_free_particles,
)

_PLOT = ("plot_averages", "plot_belief", "plot_map", "plot_particles", "plot_weights")
__getattr__, __dir__ = lazy_exports(__name__, dict.fromkeys(_PLOT, ".plot"))

__all__ = [
    "AVERAGES",
    "MCL",
    "SCORES",
    "Beams",
    "LikelihoodFieldModel",
    "MCLParams",
    "MCLState",
    "MarkovGrid",
    "MarkovParams",
    "ModelParams",
    "StepRecord",
    "amcl_converged",
    "beam_model_prob",
    "check_alpha",
    "check_particles",
    "free_cell_centres",
    "is_localised",
    "kld_bound",
    "kld_sample_count",
    "low_variance_resample",
    "markov_correct",
    "markov_log_likelihood",
    "markov_predict",
    "mcl_step",
    "motion_density_odometry",
    "n_eff",
    "normalise_log_weights",
    "odometry_deltas",
    "pose_estimate",
    "sample_motion_odometry",
    "scan_beams",
    "uniform_free_particles",
]
__all__ += list(_PLOT)  # loaded on first use
