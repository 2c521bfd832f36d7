"""Probabilistic localisation: Markov grid localisation and Monte Carlo localisation (003 §1.2.4, §2.2; Ch. 8)."""

from .markov import MarkovGrid, MarkovParams, markov_correct, markov_log_likelihood, markov_predict
from .mcl import MCL, MCLParams, MCLState, StepRecord, mcl_step
from .models import (
    Beams,
    LikelihoodFieldModel,
    beam_model_prob,
    check_particles,
    motion_density_odometry,
    odometry_deltas,
    ray_cast,
    sample_motion_odometry,
    scan_beams,
)
from .particles import (
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

__all__ = [
    "MCL",
    "Beams",
    "LikelihoodFieldModel",
    "MCLParams",
    "MCLState",
    "MarkovGrid",
    "MarkovParams",
    "StepRecord",
    "beam_model_prob",
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
    "ray_cast",
    "sample_motion_odometry",
    "scan_beams",
    "uniform_free_particles",
]
