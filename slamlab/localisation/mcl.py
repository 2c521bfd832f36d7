"""Monte Carlo localisation: MCL, augmented MCL (random injection) and KLD sampling (003 §2.2, eqs 2.8-2.11).

003's Monte Carlo method: particles scored by an observation model with values in
[0, 1] and resampled; the mean score (2.8), two running averages initialised at 0
and updated each iteration (2.9, 2.10), and a number of particles scattered at
random each iteration (2.11). The equations are lost images; we read them as PR's
augmented MCL (Table 8.3; our identification). What the code does::

    w[m]   ∝ w_prev[m]·p(z | x[m])^gamma            (PR Table 8.2 line 5; gamma = 1)
    w_avg  = Σ_m w_prev[m]·ω[m]                     (2.8)  ω the score (``score``)
    w_slow = w_slow + α_slow·(w_avg − w_slow)       (2.9)
    w_fast = w_fast + α_fast·(w_avg − w_fast)       (2.10)
    P_A    = M·max(0, 1 − w_fast / w_slow)          (2.11) expected number injected

``score`` (what 2.8 averages): ``"likelihood"`` ω = p(z | x) (PR Table 8.3), ``"geometric_mean"``
(ours, default) the per-beam geometric mean of q_k/q_max in [0, 1], ``"amcl_cubes"`` ROS 1 amcl's
1 + Σ p³. ``averages`` (how 2.9-2.10 start): ``"003"`` at 0; ``"debiased"`` (default) at 0 and divided
by 1 − (1 − α)^t; ``"amcl"`` at the first w_avg and again after every injection (ROS 1 amcl, Beluga);
``"first"`` at the first w_avg. Averages are kept in log space.

Each particle of the resampled set is replaced by a uniform pose on the free cells
with probability ``max(0, 1 − w_fast/w_slow)`` (so ``P_A`` in expectation).
Resampling (low-variance) runs only when ``N_eff < resample_threshold·M`` (ROS 1 amcl's selective
resampling; ``resample_threshold = 1``: every step, as 003 and PR Table 8.2); otherwise weights carry
over, and nothing is injected (as in ROS 1 amcl, injection happens in the resampling). Beam skipping (Nav2's
``likelihood_field_prob``) and KLD sampling (Fox 2003, PR Table 8.4) are our additions, off by default.
After resampling the set is tested for convergence as ROS 1 amcl does (every particle within
``converged_dist`` of the mean in x and y).

API summary
-----------
- :class:`MCLParams`: every setting with its source.
- :func:`mcl_step` ``(state, odom_prev, odom_now, scan, model, params, rng) -> (state, StepRecord)``.
- :class:`MCL`: the filter as an object (``step``, ``records``, particle snapshots).
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace

import numpy as np

from .._validate import as_rng
from ..geometry import wrap_angle
from .mcl_params import AVERAGES, MCLParams
from .models import (
    Beams,
    LikelihoodFieldModel,
    check_particles,
    sample_motion_odometry,
    scan_beams,
)
from .particles import (
    amcl_converged,
    best_cluster_estimate,
    free_cell_centres,
    is_localised,
    kld_sample_count,
    low_variance_resample,
    n_eff,
    normalise_log_weights,
    pose_estimate,
    uniform_free_particles,
)

__all__ = ["AVERAGES", "MCL", "MCLParams", "MCLState", "StepRecord", "mcl_step"]


@dataclass(frozen=True)
class MCLState:
    """The filter's state: particles, their normalised weights, the logs of the two running averages
    (``-inf`` = 0, 003's start) and whether the last resampled set passed amcl's convergence test.

    Parameters
    ----------
    particles : ndarray, shape (M, 3)
        The particle set.
    weights : ndarray, shape (M,)
        Normalised weights.
    log_w_slow, log_w_fast : float
        Logs of the running averages (eqs 2.9, 2.10); ``-inf`` = 0.
    converged : bool
        Whether the last resampled set passed amcl's convergence test.
    n_updates : int
        Updates of the averages since they last started at 0.
    """

    particles: np.ndarray = field(repr=False)  # (M, 3)
    weights: np.ndarray = field(repr=False)  # (M,) summing to 1
    log_w_slow: float = -np.inf
    log_w_fast: float = -np.inf
    converged: bool = False
    n_updates: int = 0  # updates of the averages since they last started at 0

    @property
    def w_slow(self) -> float:
        """w_slow (eq 2.9) on the score's scale."""
        return float(np.exp(self.log_w_slow))

    @property
    def w_fast(self) -> float:
        """w_fast (eq 2.10) on the score's scale."""
        return float(np.exp(self.log_w_fast))


@dataclass(frozen=True)
class StepRecord:
    """What one MCL iteration did (for the tables and the time plots).

    Parameters
    ----------
    mean : ndarray, shape (3,)
        Weighted mean pose of the set before resampling.
    cov : ndarray, shape (3, 3)
        Its covariance.
    n_particles : int
        Particles after the step.
    n_eff : float
        Effective sample size before resampling.
    w_avg, w_slow, w_fast : float
        Eq 2.8's average score and the two running averages (debiased when ``averages = "debiased"``).
    p_inject : float
        The injection probability ``max(0, 1 − w_fast/w_slow)``.
    n_injected : int
        Particles replaced at random.
    resampled : bool
        Whether the set was resampled.
    localised : bool
        The "localised" test on ``cov``.
    weights_vanished : bool
        Whether every weight was 0.
    note : str
        What happened when something unusual did.
    converged : bool
        amcl's convergence test on the set after the step.
    n_beams : int
        Beams that weighed the particles.
    log_w_avg, log_w_slow, log_w_fast : float
        Logs of ``w_avg``, ``w_slow``, ``w_fast``.
    """

    mean: np.ndarray
    cov: np.ndarray
    n_particles: int
    n_eff: float
    w_avg: float
    w_slow: float
    w_fast: float
    p_inject: float
    n_injected: int
    resampled: bool
    localised: bool
    weights_vanished: bool = False
    note: str = ""
    converged: bool = False  # amcl's test on the set after this step
    n_beams: int = 0  # beams that weighed the particles (after beam skipping)
    log_w_avg: float = -np.inf
    log_w_slow: float = -np.inf  # the averages that set p_inject (debiased when averages = "debiased")
    log_w_fast: float = -np.inf


def _log_average(log_w: float, log_x: float, alpha: float) -> float:
    """``log(w + α·(x − w))`` from ``log w`` and ``log x`` (eqs 2.9, 2.10 in log space)."""
    if alpha <= 0:
        return log_w
    if alpha >= 1:
        return log_x
    return float(np.logaddexp(np.log1p(-alpha) + log_w, np.log(alpha) + log_x))


def _log_bias(alpha: float, t: int) -> float:
    """``log(1 − (1 − α)^t)``: the weight an average started at 0 has put on the data after ``t`` updates."""
    if alpha <= 0:
        return 0.0
    return float(np.log(-np.expm1(t * np.log1p(-alpha)))) if alpha < 1 else 0.0


#: ``|log w_fast − log w_slow|`` below this is a tie (no injection): the two averages are sums of the same terms
#: in another order, and their last bits depend on the CPU's vector units (numpy's exp/log kernels), while 1e-12 is
#: far below any difference that eq 2.11 acts on (p_inj < 1e-12: less than one particle in 10^9 steps of 1000)
LOG_AVERAGE_TIE = 1e-12


def _injection_probability(log_slow: float, log_fast: float) -> float:
    """003 eq 2.11's ``max(0, 1 − w_fast / w_slow)`` from the log averages; a tie within :data:`LOG_AVERAGE_TIE` is 0.

    At the first updates both averages hold the same single term (debiased, they agree to the last bits or not,
    by CPU), so without the tie rule the injection step ran or not by rounding alone.
    """
    if log_slow == -np.inf:
        return 0.0
    d = log_fast - log_slow
    if d >= -LOG_AVERAGE_TIE:
        return 0.0
    return float(-np.expm1(d))


def _beam_mask(model, X, beams, params) -> np.ndarray:
    """Nav2 / ROS 1 ``likelihood_field_prob`` beam skipping: keep a beam when more than
    ``beam_skip_threshold`` of the particles put its end point within ``beam_skip_distance`` of an
    obstacle; all beams when ``beam_skip_error_threshold`` of them would be skipped."""
    d, keep = model.beam_distances(X, beams)
    agree = (d < params.beam_skip_distance).mean(axis=0) > params.beam_skip_threshold
    mask = np.zeros(beams.n, bool)
    mask[keep] = agree
    if np.count_nonzero(~agree) >= params.beam_skip_error_threshold * agree.size:
        mask[keep] = True
    return mask


def mcl_step(state: MCLState, odom_prev, odom_now, scan, model: LikelihoodFieldModel, params: MCLParams,
             rng=None, *, free_xy=None) -> tuple[MCLState, StepRecord]:
    """One iteration of (augmented) MCL (003 §2.2; PR Tables 8.2, 8.3, optionally 8.4).

    Parameters
    ----------
    state : MCLState
    odom_prev, odom_now : array_like, shape (3,), or None
        The odometry reading since the last step (None: no motion).
    scan : Scan or Beams
        The scan in cell units (or its :func:`scan_beams`).
    model : LikelihoodFieldModel
    params : MCLParams
    rng : Generator, int or None
    free_xy : (K, 2) array, optional
        Free cell centres for injection (computed from the model's grid when None).

    Returns
    -------
    (MCLState, StepRecord)
    """
    state, rec, _ = _mcl_step(state, odom_prev, odom_now, scan, model, params, rng, free_xy=free_xy)
    return state, rec


def _update_averages(state, log_w_avg, params):
    """Eqs 2.9, 2.10 in log space: the new ``(log w_slow, log w_fast)`` and the pair that sets the injection
    probability (bias-corrected when ``params.averages == "debiased"``)."""
    ls, lf = state.log_w_slow, state.log_w_fast
    if params.averages in ("amcl", "first") and ls == -np.inf:  # amcl / Beluga: an average at 0 starts at w_avg
        ls = lf = log_w_avg
    else:
        ls = _log_average(ls, log_w_avg, params.alpha_slow)  # 2.9
        lf = _log_average(lf, log_w_avg, params.alpha_fast)  # 2.10
    n_up = state.n_updates + 1
    ls_used, lf_used = ls, lf
    if params.averages == "debiased":  # an average started at 0, divided by 1 − (1 − α)^t (Adam's bias correction)
        ls_used = ls - _log_bias(params.alpha_slow, n_up)
        lf_used = lf - _log_bias(params.alpha_fast, n_up)
    return ls, lf, ls_used, lf_used


def _resample(X, w, params, rng):
    """Low-variance resampling to ``params.n_particles`` (PR Table 4.4), or KLD sampling (PR Table 8.4)."""
    if params.use_kld:
        n_max = params.n_particles
        idx = rng.choice(X.shape[0], size=n_max, p=w)  # PR Table 8.4 draws i.i.d.
        m_keep = kld_sample_count(X[idx], bin_size=params.kld_bin, epsilon=params.kld_epsilon,
                                  z_quantile=params.kld_z, n_min=min(params.n_min, n_max))
        return X[idx[:m_keep]]
    return X[low_variance_resample(w, params.n_particles, rng)]


def _mcl_step(state, odom_prev, odom_now, scan, model, params, rng=None, *, free_xy=None):
    """The body of :func:`mcl_step`; also returns the weighted set before resampling ``(X, w)``."""
    if not isinstance(state, MCLState):
        raise TypeError(f"`state` must be an MCLState; got {type(state).__name__}")
    if not isinstance(params, MCLParams):
        raise TypeError(f"`params` must be MCLParams; got {type(params).__name__}")
    rng = as_rng(rng)
    X = check_particles(state.particles, "state.particles")
    beams = scan if isinstance(scan, Beams) else scan_beams(scan, params.max_beams)
    # PR Table 8.2 line 4: x[m] ~ p(x | u, x[m])
    if odom_prev is not None and odom_now is not None:
        X = sample_motion_odometry(X, odom_prev, odom_now, params.alpha, rng)
    if params.jitter[0] > 0 or params.jitter[1] > 0:
        X = X + rng.standard_normal(X.shape) * np.array([params.jitter[0], params.jitter[0], params.jitter[1]])
        X[:, 2] = wrap_angle(X[:, 2])
    # line 5: the likelihood of every particle and the score ω of eq 2.8, in log space (30-60 beams underflow)
    mask = _beam_mask(model, X, beams, params) if params.beam_skip and state.converged else None
    n_beams = model.n_used(beams) if mask is None else int(np.count_nonzero(mask))
    L = model.log_score(X, beams, "likelihood", mask)  # log p(z | x), PR Table 6.3
    if params.score == "likelihood":
        log_s = L
    elif params.score == "geometric_mean":
        log_s = L / max(1, n_beams) - model.log_q_max
    else:
        log_s = model.log_score(X, beams, params.score, mask)
    w_prev = state.weights
    log_wp = np.log(np.maximum(w_prev, 1e-300))
    # 2.8: w_avg = Σ_m w_prev[m]·ω[m], the weighted mean of the score (PR Table 8.3 with ω = p(z | x))
    fin = np.isfinite(log_s)
    log_w_avg = float(np.logaddexp.reduce(log_wp[fin] + log_s[fin])) if fin.any() else -np.inf
    ls, lf, ls_used, lf_used = _update_averages(state, log_w_avg, params)
    n_up = state.n_updates + 1
    log_w = log_wp + params.gamma * L  # PR Table 8.2 line 5: w = p(z | x) (tempered by gamma)
    w, ok = normalise_log_weights(log_w)
    p_inj = _injection_probability(ls_used, lf_used) if params.injection else 0.0
    note = ""
    if not ok:
        if params.injection:
            p_inj, note = 1.0, "all weights vanished: every particle re-drawn at random"
        else:
            note = "all weights vanished: no injection (α_slow = 0), particles kept with uniform weights"
    weighted = (X, w)
    mean, cov = pose_estimate(X, w) if params.estimate == "mean" else best_cluster_estimate(X, w, params.kld_bin)
    neff = n_eff(w)
    M = X.shape[0]  # the set's size, 003 eq 2.11's M (params.n_particles, or fewer after KLD sampling)
    resample = params.resample_threshold >= 1 or neff < params.resample_threshold * M or not ok
    n_inj = 0
    if resample:
        X = _resample(X, w, params, rng)
        M = X.shape[0]
        if params.injection:
            # drawn whatever p_inj is, so that the stream's use never depends on how p_inj rounds
            inj = rng.random(M) < p_inj  # 2.11: P_A = M·p_inj in expectation
            n_inj = int(inj.sum())
            if n_inj:
                xy = free_cell_centres(model.grid) if free_xy is None else free_xy
                X = X.copy()
                X[inj] = uniform_free_particles(model.grid, n_inj, rng, centres=xy)
            if params.averages == "amcl" and p_inj > 0:  # pf.c: "reset averages, to avoid spiraling off into ..."
                ls = lf = -np.inf
                n_up = 0
        w = np.full(M, 1.0 / M)
    conv = amcl_converged(X, params.converged_dist)
    new = MCLState(X, w, float(ls), float(lf), conv, n_up)
    rec = StepRecord(mean, cov, M, neff, float(np.exp(log_w_avg)), float(np.exp(ls_used)), float(np.exp(lf_used)),
                     p_inj, n_inj,
                     bool(resample), is_localised(cov, pos_std=params.localised_pos_std,
                                                  heading_std_rad=params.localised_heading_std_rad),
                     weights_vanished=not ok, note=note, converged=conv, n_beams=n_beams, log_w_avg=log_w_avg,
                     log_w_slow=float(ls_used), log_w_fast=float(lf_used))
    return new, rec, weighted


class MCL:
    """Monte Carlo localisation on a grid map (003 §2.2): holds the state and the record of every step.

    Parameters
    ----------
    grid : array_like of int, shape (H, W)
        The map in cells.
    z_max : float
        The rangefinder's maximum range in cells.
    params : MCLParams, optional
    rng : Generator, int or None
    init_pose, init_std : optional
        Tracking: particles ~ N(init_pose, diag(init_std²)); global (default): uniform on free cells.
    keep_particles : bool
        Keep the weighted particles of every step, before resampling (plots, histogram, time slider).
    **overrides
        Fields of :class:`MCLParams`.

    Examples
    --------
    >>> g = np.zeros((20, 20), np.int8); g[0] = g[-1] = g[:, 0] = g[:, -1] = 1
    >>> f = MCL(g, 30.0, n_particles=50, rng=0)
    >>> f.state.particles.shape
    (50, 3)
    """

    def __init__(self, grid, z_max: float, *, params: MCLParams | None = None, rng=None, init_pose=None,
                 init_std=(1.0, 1.0, 0.05), keep_particles: bool = False, **overrides):
        self.params = MCLParams.resolve(params, **overrides)
        self.model = self.params.model(grid, z_max)
        self.rng = as_rng(rng)
        self.free_xy = free_cell_centres(self.model.grid)
        n_particles = self.params.n_particles
        if init_pose is None:
            X = uniform_free_particles(self.model.grid, n_particles, self.rng, centres=self.free_xy)
        else:
            p = check_particles(init_pose, "init_pose")[0]
            sd = np.asarray(init_std, dtype=float)
            if sd.shape != (3,) or np.any(sd < 0) or not np.all(np.isfinite(sd)):
                raise ValueError(f"`init_std` must be three finite numbers >= 0; got {init_std!r}")
            X = p + self.rng.standard_normal((n_particles, 3)) * sd
        self.state = MCLState(X, np.full(n_particles, 1.0 / n_particles))
        self.records: list[StepRecord] = []
        self._odom_ref = None  # odometry at the last update (update_min_d / update_min_a)
        self.keep_particles = bool(keep_particles)
        self.snapshots: list[tuple[np.ndarray, np.ndarray]] = []

    def step(self, odom_prev, odom_now, scan) -> StepRecord:
        """One iteration; returns (and keeps) its :class:`StepRecord`.

        With ``update_min_d`` / ``update_min_a`` (ROS amcl's thresholds) the filter is updated only once the
        odometry has moved that far since the last update (the motion of all the skipped steps is applied
        then); a skipped step repeats the last record (``note = "no update: moved too little"``).

        Parameters
        ----------
        odom_prev, odom_now : array_like, shape (3,), or None
            The odometry reading since the last step (None: no motion).
        scan : Scan or Beams
            The scan in cell units (or its beams).

        Returns
        -------
        StepRecord
        """
        p = self.params
        if odom_prev is not None and odom_now is not None and (p.update_min_d > 0 or p.update_min_a > 0):
            ref = odom_prev if self._odom_ref is None else self._odom_ref
            a = np.asarray(ref, dtype=float)
            b = np.asarray(odom_now, dtype=float)
            moved_d = float(np.hypot(b[0] - a[0], b[1] - a[1]))
            moved_a = abs(float(wrap_angle(b[2] - a[2])))
            if self.records and moved_d < p.update_min_d and moved_a < p.update_min_a:
                self._odom_ref = a
                rec = replace(self.records[-1], note="no update: moved too little", n_injected=0, resampled=False)
                self.records.append(rec)
                if self.keep_particles:
                    self.snapshots.append(self.snapshots[-1])
                return rec
            odom_prev, self._odom_ref = a, b
        self.state, rec, weighted = _mcl_step(self.state, odom_prev, odom_now, scan, self.model, self.params,
                                              self.rng, free_xy=self.free_xy)
        self.records.append(rec)
        if self.keep_particles:
            self.snapshots.append((weighted[0].copy(), weighted[1].copy()))
        return rec

    def estimate(self) -> tuple[np.ndarray, np.ndarray]:
        """Mean pose and covariance of the current particles."""
        return pose_estimate(self.state.particles, self.state.weights)
