"""The settings of Monte Carlo localisation (:class:`MCLParams`, :data:`AVERAGES`), every one with its source.

Moved unchanged from :mod:`slamlab.localisation.mcl` (which re-exports both names).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .._params import param
from .._validate import check_choice, check_int, check_positive, check_probability
from .models import SCORES, LikelihoodFieldModel, ModelParams

__all__ = ["AVERAGES", "ESTIMATES", "MCLParams"]


#: How w_slow and w_fast start (and restart): see :class:`MCLParams`.
AVERAGES = ("003", "amcl", "first", "debiased")
#: The pose a step reports: see :class:`MCLParams`.
ESTIMATES = ("mean", "best_cluster")


@dataclass(frozen=True)
class MCLParams(ModelParams):
    """Settings of Monte Carlo localisation; lengths in cells (the map's unit). The motion and sensor
    model's fields come first (:class:`~slamlab.localisation.models.ModelParams`).

    Parameters
    ----------
    alpha, z_hit, z_rand, sigma_hit, max_dist, max_beams, gamma : see ModelParams
        The motion and sensor model (:class:`~slamlab.localisation.models.ModelParams`; MCL's own defaults).
    n_particles : int
        Particles (the most, with KLD sampling).
    score : str
        The score ω that eq 2.8 averages (:data:`~slamlab.localisation.models.SCORES`).
    alpha_slow, alpha_fast : float
        Rates of the slow and fast averages (eqs 2.9, 2.10); ``alpha_slow = 0``: no injection.
    averages : str
        How the averages start and restart (:data:`AVERAGES`).
    resample_threshold : float
        Resample when ``N_eff < resample_threshold·M`` (1: every step).
    beam_skip : bool
        Nav2's beam skipping, once converged.
    beam_skip_distance, beam_skip_threshold, beam_skip_error_threshold : float
        Its distance (cells), agreeing share of particles and share of skipped beams that turns it off.
    jitter : tuple of 2 float
        σ of the jitter added at every step (cells, rad).
    update_min_d, update_min_a : float
        Update only after moving this far (cells) or turning this far (rad).
    converged_dist : float
        amcl's convergence test distance (cells).
    use_kld : bool
        KLD sampling.
    kld_epsilon, kld_z : float
        KLD's ε and 1 − δ.
    kld_bin : tuple of 3 float
        KLD bin size (x, y cells, θ rad).
    n_min : int
        KLD's lower bound on the count.
    localised_pos_std, localised_heading_std_rad : float
        The "localised" test's bounds (cells, rad).
    estimate : str
        The pose a step reports (:data:`ESTIMATES`).
    """

    alpha: tuple = param((0.2, 0.008, 0.2, 0.02), "ours: 4 × the Markov grid's α, in cells, chosen with sigma_hit, "
                                                  "jitter and gamma as one change (Ch. 08 §4); PR Tables 5.5-5.6 "
                                                  "α1…α4 (ROS: 0.2 each, in metres)")
    sigma_hit: float = param(4.0, "ours, cells, chosen with alpha, jitter and gamma as one change (Ch. 08 §4: taken "
                                  "back alone to 2 cells, it does worse on 50 runs); PR Table 6.3 (ROS: 0.2 m)")
    max_dist: float = param(12.0, "ours, cells: 3 σ_hit, cap of the distance table (ROS: 2 m)")
    gamma: float = param(0.5, "ours: weights p(z | x)^gamma, a tempered likelihood (1 = PR's product of the beams "
                              "as if independent)")
    n_particles: int = param(2000, "ours (003: not given; ROS AMCL 100…5000, Nav2 500…2000)")
    score: str = param("geometric_mean", "ours: the score ω that eq 2.8 averages (SCORES; 003: 'a probability "
                                         "between 0 and 1'); 'likelihood' = PR Table 8.3. The weights are "
                                         "p(z | x)^gamma whatever the score")
    alpha_slow: float = param(0.001, "003 eq 2.9 (value not given); ROS AMCL docs suggest 0.001")
    alpha_fast: float = param(0.1, "003 eq 2.10 (value not given); ROS AMCL docs suggest 0.1")
    averages: str = param("debiased", "ours: 'debiased', from 0 as 003 says, divided by 1 − (1 − α)^t; '003': "
                                      "w_slow, w_fast start at 0 ('initially 0'); 'amcl': at the first w_avg, and "
                                      "again after every injection (ROS 1 amcl pf.c, Beluga); 'first' (ours): at "
                                      "the first w_avg, never restarted")
    resample_threshold: float = param(0.5, "ours: resample when N_eff < threshold·M (ROS 1 amcl's selective "
                                           "resampling: 0.5); 1 = every step (003, PR Table 8.2)")
    beam_skip: bool = param(False, "ours: Nav2/ROS 1 likelihood_field_prob's beam skipping, once converged")
    beam_skip_distance: float = param(5.0, "cells; ROS/Nav2 beam_skip_distance 0.5 m (= 5 cells of 0.1 m)")
    beam_skip_threshold: float = param(0.3, "ROS/Nav2 beam_skip_threshold: keep a beam when > this share of "
                                            "the particles put its end point near an obstacle")
    beam_skip_error_threshold: float = param(0.9, "ROS/Nav2: if this share of the beams is skipped, use all")
    jitter: tuple = param((0.6, 0.04), "ours: σ of a Gaussian jitter (cells, rad) added to every particle at "
                                       "every step, moving or not (cf. the roughening of Gordon et al. "
                                       "1993, after resampling); (0, 0) = none")
    update_min_d: float = param(0.0, "cells; ROS amcl update_min_d (0.2 m; Nav2 0.25 m): update only after "
                                     "moving this far (0 = every step, 003)")
    update_min_a: float = param(0.0, "rad; ROS amcl update_min_a (π/6; Nav2 0.2): … or turning this far")
    converged_dist: float = param(5.0, "cells; ROS 1 amcl's convergence test: every particle within 0.5 m "
                                       "(= 5 cells of 0.1 m) of the mean in x and y")
    use_kld: bool = param(False, "ours: KLD sampling, Fox 2003 / PR Table 8.4 (ROS AMCL does it)")
    kld_epsilon: float = param(0.05, "Fox 2003 / PR Table 8.4 ε (ROS 1: 0.01, Nav2: 0.05)")
    kld_z: float = param(0.99, "Fox 2003 / PR Table 8.4: 1 − δ (ROS: 0.99)")
    kld_bin: tuple = param((2.0, 2.0, float(np.radians(10))), "ours: KLD bin (x, y cells, θ rad)")
    n_min: int = param(100, "ours: KLD lower bound (ROS 1: 100, Nav2: 500)")
    localised_pos_std: float = param(2.0, "ours: 'localised' when the position σ < this (cells)")
    localised_heading_std_rad: float = param(float(np.radians(5)), "ours: … and the heading σ < this")
    estimate: str = param("mean", "ours: 'mean', the weighted mean of the whole set (003: the set is the estimate); "
                                  "'best_cluster': the mean of the heaviest cluster of kld_bin bins, the pose "
                                  "ROS 1 amcl publishes")

    def check(self) -> None:
        super().check()
        check_int(self.n_particles, "n_particles", minimum=1)
        check_choice(self.score, "score", SCORES)
        check_choice(self.averages, "averages", AVERAGES)
        check_choice(self.estimate, "estimate", ESTIMATES)
        s = check_positive(self.alpha_slow, "alpha_slow", allow_zero=True)
        f = check_positive(self.alpha_fast, "alpha_fast", allow_zero=True)
        if s > 1 or f > 1:
            raise ValueError(f"`alpha_slow` and `alpha_fast` must be in [0, 1]; got {s}, {f}")
        if s > 0 and not f > s:
            raise ValueError(f"`alpha_fast` must be > `alpha_slow` (PR: 0 ≤ α_slow ≪ α_fast); got {f} <= {s}")
        t = check_positive(self.resample_threshold, "resample_threshold", allow_zero=True)
        if t > 1:
            raise ValueError(f"`resample_threshold` must be in [0, 1]; got {t}")
        for name in ("use_kld", "beam_skip"):
            if not isinstance(getattr(self, name), (bool, np.bool_)):
                raise TypeError(f"`{name}` must be a bool; got {type(getattr(self, name)).__name__}")
        check_positive(self.beam_skip_distance, "beam_skip_distance")
        check_probability(self.beam_skip_threshold, "beam_skip_threshold")
        check_probability(self.beam_skip_error_threshold, "beam_skip_error_threshold")
        check_positive(self.converged_dist, "converged_dist")
        j = np.asarray(self.jitter, dtype=float) if isinstance(self.jitter, tuple) else np.full(1, np.nan)
        if j.shape != (2,) or not np.all(np.isfinite(j)) or np.any(j < 0):
            raise ValueError(f"`jitter` must be a tuple of two numbers >= 0 (cells, rad); got {self.jitter!r}")
        check_positive(self.update_min_d, "update_min_d", allow_zero=True)
        check_positive(self.update_min_a, "update_min_a", allow_zero=True)
        check_positive(self.kld_epsilon, "kld_epsilon")
        check_probability(self.kld_z, "kld_z")
        b = np.asarray(self.kld_bin, dtype=float)
        if b.shape != (3,) or np.any(b <= 0):
            raise ValueError(f"`kld_bin` must be three sizes > 0 (x, y, θ); got {self.kld_bin!r}")
        check_int(self.n_min, "n_min", minimum=1)
        check_positive(self.localised_pos_std, "localised_pos_std")
        check_positive(self.localised_heading_std_rad, "localised_heading_std_rad")

    @property
    def injection(self) -> bool:
        """Whether random particles are injected (α_slow > 0)."""
        return self.alpha_slow > 0

    def model(self, grid, z_max: float) -> LikelihoodFieldModel:
        """The likelihood-field model of these settings on ``grid``.

        Parameters
        ----------
        grid : array_like of int, shape (H, W)
            The map.
        z_max : float
            The rangefinder's maximum range (cells).

        Returns
        -------
        LikelihoodFieldModel
        """
        return LikelihoodFieldModel(grid, z_hit=self.z_hit, z_rand=self.z_rand, sigma_hit=self.sigma_hit,
                                    z_max=z_max, max_dist=self.max_dist)
