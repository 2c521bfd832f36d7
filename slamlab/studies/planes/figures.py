"""Ch. 10 figure experiments (002): Fig. 2 (one, two, three plane pairs) and Fig. 4 (three planes, two of them
parallel; the intensity weights pick the point on the line), with Fig. 4 over seeds and over V.

Each ``run_*`` returns a frozen dataclass: ``str()`` a one-line summary, ``.table()`` a fixed-precision text
table (printed in the notebook, compared by nbval).
"""

from __future__ import annotations

import itertools
from dataclasses import dataclass, field

import numpy as np

from ..._table import format_table
from ..._validate import as_rng, check_int, check_positive
from ...geometry.so3 import so3_exp
from ...planes.extraction import Frame
from ...planes.filter import PlaneSLAM, PlaneSLAMParams
from ...planes.mapping import PlaneMap
from ...planes.transform import lm_pose, planes_to_body
from .experiments import offset_frames

__all__ = ["FIG4_PARAMS", "IntensityResult", "IntensitySpread", "IntensityStudy", "PairsResult",
           "run_intensity_figure", "run_intensity_spread", "run_intensity_study", "run_pairs_figure"]


# --- 002 Fig. 2: the locus of the solved particles for one, two, three pairs --------------------------------
@dataclass(frozen=True)
class PairsResult:
    """Per number of pairs (1, 2, 3): particle positions before ``(P, 3)`` and after the LM, and the singular
    values of the solved positions (the locus: plane, line, point).

    Attributes
    ----------
    before, after : tuple of 3 (P, 3) float
        Particle positions in metres before and after the LM, for 1, 2, 3 pairs.
    spread_before, spread_after : (3, 3) float
        Singular values (RMS spread in metres) of those positions, one row per number of pairs.
    true_t : (3,) float
        The true position.
    """

    before: tuple
    after: tuple
    spread_before: np.ndarray
    spread_after: np.ndarray
    true_t: np.ndarray

    def __str__(self) -> str:
        dims = [int(np.sum(s > 1e-6)) for s in self.spread_after]
        return f"Fig. 2: solved positions span {dims[0]}-D, {dims[1]}-D, {dims[2]}-D sets for 1, 2, 3 pairs"

    def table(self) -> str:
        """Spread of the particles before and after the LM and the locus dimension per number of pairs (002 Fig. 2).

        Returns
        -------
        str
            Fixed-precision text table.
        """
        rows = []
        for k in range(3):
            sb, sa = self.spread_before[k], self.spread_after[k]
            dim = int(np.sum(sa > 1e-6))
            rows.append([str(k + 1), ("plane", "line", "point")[k], " ".join(f"{x:.3f}" for x in sb),
                         " ".join(f"{x:.3f}" for x in np.where(sa > 1e-6, sa, 0.0)), str(dim)])
        return format_table(["pairs", "002 says", "spread before [m] (3 axes)", "spread after [m]", "locus dim"],
                            rows, title="002 Fig. 2: where the particles go (LM, no prior)")


def run_pairs_figure(n_particles: int = 300, sigma_m: float = 0.3, *, rng=0) -> PairsResult:
    """002 Fig. 2: three perpendicular map planes; particles predicted around the truth, solved by LM on 1, 2, 3
    pairs (our exact synthetic case: noise-free planes, 002's bare system, no prior).

    Parameters
    ----------
    n_particles : int
        Particles (>= 2).
    sigma_m : float
        Standard deviation of the predicted positions around the truth, metres.
    rng : numpy.random.Generator, int or None
        Randomness of the prediction.

    Returns
    -------
    PairsResult
        Positions and their spread per number of pairs.
    """
    n_particles = check_int(n_particles, "n_particles", minimum=2)
    sigma_m = check_positive(sigma_m, "sigma_m")
    g = as_rng(rng)
    n_m = np.array([[1.0, 0, 0], [0, 1.0, 0], [0, 0, 1.0]])
    p_m = np.array([4.0, 3.0, 2.5])
    R_true, t_true = np.eye(3), np.array([1.0, 1.0, 1.0])
    n_b, p_b = planes_to_body(n_m, p_m, R_true, t_true)
    t0 = t_true + g.normal(0, sigma_m, (n_particles, 3))
    R0 = so3_exp(g.normal(0, np.deg2rad(1.0), (n_particles, 3)))
    before, after, sb, sa = [], [], [], []
    for k in (1, 2, 3):
        res = lm_pose(R0, t0, np.broadcast_to(n_m[:k], (n_particles, k, 3)),
                      np.broadcast_to(p_m[:k], (n_particles, k)), n_b[:k], p_b[:k], max_iters=40)
        before.append(t0)
        after.append(res.t)
        sb.append(np.linalg.svd(t0 - t0.mean(0), compute_uv=False) / np.sqrt(n_particles))
        sa.append(np.linalg.svd(res.t - res.t.mean(0), compute_uv=False) / np.sqrt(n_particles))
    return PairsResult(tuple(before), tuple(after), np.array(sb), np.array(sa), t_true)


# --- 002 Fig. 4: three planes, two parallel; the intensities pick the point -----------------------------------
#: the bins of |x - x_true| [m] of the weight profile (Fig. 4)
PROFILE_BINS_M = (0.0, 0.1, 0.2, 0.4, 0.7, np.inf)

#: Fig. 4's filter settings when no ``params`` is given (ours, 002 gives none but the 400 particles): the prediction's
#: variances V = 0.09 m² and 0.25 deg² (the particles spread along the walls), frames of two normal directions,
#: planes paired within 1.5 m (the spread particles still pair the walls).
FIG4_PARAMS = PlaneSLAMParams(n_particles=400, V_xyz_m2=0.09, V_rpy_deg2=0.25, min_normal_rank=2, pair_dist_m=1.5)


def _fig4_settings(params, overrides: dict) -> PlaneSLAMParams:
    """Fig. 4's settings: ``params`` (default :data:`FIG4_PARAMS`) with ``overrides``; the figure runs with the
    intensity weights and without them, so the caller's settings must leave ``intensity_weights`` alone."""
    from ..._params import refuse_set_fields

    refuse_set_fields(PlaneSLAMParams.resolve(params, **overrides), ["intensity_weights"],
                      "the figure runs with the intensity weights and, as its ablation, without them")
    return PlaneSLAMParams.resolve(FIG4_PARAMS if params is None else params, **overrides)


@dataclass(frozen=True)
class IntensityResult:
    """002 Fig. 4: particles ``predicted``, ``solved`` (after the LM: spread along the corridor), their ``sad`` and
    ``weights`` and the ``resampled`` ones of the first cycle; the along-corridor error of the pose after
    ``rounds`` cycles with and without the intensity weights; the frame's planes and normal directions.

    Attributes
    ----------
    predicted, solved, resampled : (P, 3) float
        Particle positions in metres of the first cycle: predicted, after the LM, after resampling.
    sad : (P,) float
        Intensity SAD per particle.
    weights : (P,) float
        Normalised intensity weights.
    true_t : (3,) float
        True position of the second frame.
    error_with_m, error_without_m : float
        Along-corridor error in metres after ``rounds`` cycles, with and without intensity weights.
    spread_solved_m : (3,) float
        Standard deviation of the solved positions per axis, metres.
    n_planes : int
        Planes in the frame.
    normal_rank : int
        Distinct normal directions among them.
    V_xyz_m2 : float
        Prediction variance of the position, m².
    rounds : int
        Cycles run on the frame.
    frame : Frame
        The second frame.
    map : PlaneMap
        The map built from the first frame.
    """

    predicted: np.ndarray
    solved: np.ndarray
    sad: np.ndarray
    weights: np.ndarray
    resampled: np.ndarray
    true_t: np.ndarray
    error_with_m: float
    error_without_m: float
    spread_solved_m: np.ndarray
    n_planes: int
    normal_rank: int
    V_xyz_m2: float
    rounds: int
    frame: Frame = field(repr=False)
    map: PlaneMap = field(repr=False)

    @property
    def peak(self) -> float:
        """Largest weight over the uniform weight ``1/P``."""
        return float(self.weights.max() * len(self.weights))

    def sad_bound(self) -> float:
        """``(max SAD − min SAD) / (max SAD − mean SAD)``: what ``peak`` must equal under 002's ``SAD* = max SAD −
        SAD`` (the identity behind the flat weights; NaN SADs count as the max).

        Returns
        -------
        float
        """
        s = self._sad_filled()
        return 1.0 if s.max() - s.mean() <= 0 else float((s.max() - s.min()) / (s.max() - s.mean()))

    def _sad_filled(self) -> np.ndarray:
        ok = np.isfinite(self.sad)
        return np.where(ok, self.sad, self.sad[ok].max()) if ok.any() else np.zeros_like(self.sad)

    def __str__(self) -> str:
        return (f"Fig. 4: along-corridor error {self.error_with_m:.3f} m with intensity weights, "
                f"{self.error_without_m:.3f} m without, after {self.rounds} cycle(s); peak weight {self.peak:.2f}x "
                f"uniform")

    def table(self) -> str:
        """Fig. 4's first cycle: planes, spread, weights' peak and the errors with and without the weights.

        Returns
        -------
        str
            Fixed-precision text table.
        """
        s = self._sad_filled()
        cyc = "one cycle" if self.rounds == 1 else f"{self.rounds} cycles"
        rows = [["planes in the frame / normal directions", f"{self.n_planes} / {self.normal_rank}"],
                ["V of the prediction [m^2] (sqrt V [m])", f"{self.V_xyz_m2:.3f} ({np.sqrt(self.V_xyz_m2):.2f})"],
                ["spread of solved particles x / y / z [m]", " / ".join(f"{x:.3f}" for x in self.spread_solved_m)],
                [f"along-corridor error after {cyc}, intensity weights on [m]", f"{self.error_with_m:.3f}"],
                [f"along-corridor error after {cyc}, weights off (ablation) [m]", f"{self.error_without_m:.3f}"],
                ["SAD min / mean / max", f"{s.min():.1f} / {s.mean():.1f} / {s.max():.1f}"],
                ["largest weight / uniform weight", f"{self.peak:.2f}"],
                ["(max SAD - min SAD) / (max SAD - mean SAD)", f"{self.sad_bound():.2f}"]]
        return format_table(["quantity", "value"], rows,
                            title=f"002 Fig. 4: three planes (two parallel walls + floor), {cyc}")

    def profile_table(self) -> str:
        """The first cycle's SAD and weight against the distance from the truth along the line (ours).

        Returns
        -------
        str
            Fixed-precision text table, one row per distance bin (:data:`PROFILE_BINS_M`).
        """
        d = np.abs(self.solved[:, 0] - self.true_t[0])
        P = len(self.weights)
        rows = []
        for lo, hi in itertools.pairwise(PROFILE_BINS_M):
            k = (d >= lo) & (d < hi)
            lab = f"{lo:.1f} - {hi:.1f}" if np.isfinite(hi) else f">= {lo:.1f}"
            if not k.any():
                rows.append([lab, "0", "-", "-"])
                continue
            sad = self.sad[k][np.isfinite(self.sad[k])]
            rows.append([lab, str(int(k.sum())), f"{sad.mean():.1f}" if len(sad) else "-",
                         f"{self.weights[k].mean() * P:.2f}"])
        return format_table(["|x - x_true| [m]", "particles", "mean SAD", "mean weight / uniform"], rows,
                            title="Fig. 4, first cycle: SAD and weight along the line of uncertainty (ours)")


def run_intensity_figure(offset_m: float = 0.4, *, rounds: int = 1, V_later_xyz_m2: float = 4e-4,
                         V_later_rpy_deg2: float = 0.04, params: PlaneSLAMParams | None = None, rng=0,
                         **overrides) -> IntensityResult:
    """002 Fig. 4: three planes, two of them parallel; one cycle of the filter (002 "Intensity weights").

    The map comes from a first frame at a known pose in :func:`three_plane_room` (two parallel walls and the
    floor); the vehicle then moves ``offset_m`` along the walls while the odometry says it did not. The particles
    are predicted with ``ε ~ N(0, V)`` (``V_xyz_m2`` [m²], ``V_rpy_deg2`` [deg²]: variances, as in 002), the LM
    puts them on the line the planes leave free (``x``), the intensity weights and one importance resampling
    pick a point on it. The ablation runs the same particles with ``intensity_weights=False``: the figure sets
    that field itself, and ``params`` and the overrides must leave it at its default (a ``ValueError`` names it).

    ``rounds`` > 1 (ours, not 002's figure) repeats the cycle on the same frame; those later cycles use
    ``V_later_xyz_m2``, ``V_later_rpy_deg2`` (default (2 cm)² and (0.2°)²: a re-run should not undo the first).

    Parameters
    ----------
    offset_m : float
        True motion along the walls between the two frames, metres (the odometry says 0).
    rounds : int
        Cycles on the second frame.
    V_later_xyz_m2, V_later_rpy_deg2 : float
        Prediction variances of the cycles after the first.
    params : PlaneSLAMParams, optional
        Filter settings (default :data:`FIG4_PARAMS`: 400 particles, ``V_xyz_m2`` 0.09 m², ``V_rpy_deg2``
        0.25 deg², ``min_normal_rank`` 2, ``pair_dist_m`` 1.5 m).
    rng : numpy.random.Generator, int or None
        Randomness of the room, flights and particles.
    **overrides
        :class:`PlaneSLAMParams` fields that replace those of ``params`` (e.g. ``n_particles``, ``V_xyz_m2``).

    Returns
    -------
    IntensityResult
        The first cycle's particles and weights and the errors with and without the weights.
    """
    p = _fig4_settings(params, overrides)
    g = as_rng(rng)
    offset_m = float(offset_m)
    rounds = check_int(rounds, "rounds", minimum=1)
    for name, val in (("V_later_xyz_m2", V_later_xyz_m2), ("V_later_rpy_deg2", V_later_rpy_deg2)):
        check_positive(val, name, allow_zero=True)
    flights, frames = offset_frames(offset_m, g)
    slam_seed = int(g.integers(2**31))           # the same particles for the run and its ablation
    out = {}
    for use in (True, False):
        slam = PlaneSLAM(flights[0].poses[-1], params=p.replace(intensity_weights=use), rng=slam_seed)
        slam.step(frames[0], np.eye(4))
        slam.update_map = False
        first = None
        for r in range(rounds):
            rep = slam.step(frames[1], np.eye(4))          # the odometry: no motion
            if r == 0:
                first = (slam.X_predicted[:, :3, 3].copy(), slam.X_solved[:, :3, 3].copy(), slam.last_sad.copy(),
                         slam.weights.copy(), slam.X[:, :3, 3].copy(), rep)
                slam.reconfigure(V_xyz_m2=V_later_xyz_m2, V_rpy_deg2=V_later_rpy_deg2)
        out[use] = (first, abs(slam.pose[0, 3] - flights[1].poses[-1][0, 3]), slam)
    (pred, solved, sad, w, res, rep), err_on, slam_on = out[True]
    return IntensityResult(pred, solved, sad, w, res, flights[1].poses[-1][:3, 3], float(err_on),
                           float(out[False][1]), solved.std(axis=0), rep.n_planes, rep.normal_rank,
                           float(p.V_xyz_m2), rounds, frames[1], slam_on.map)


@dataclass(frozen=True)
class IntensitySpread:
    """Fig. 4's first cycle for several V (ours): how the weights' peak follows the particles' spread.

    Attributes
    ----------
    results : tuple of IntensityResult
        One run per V.
    """

    results: tuple = field(repr=False)

    def __str__(self) -> str:
        return "Fig. 4 over V: peak weight " + ", ".join(f"{r.peak:.2f}x at V = {r.V_xyz_m2:g} m^2"
                                                         for r in self.results)

    def table(self) -> str:
        """Spread, SAD range, peak weight and the errors with and without the weights, per V (ours).

        Returns
        -------
        str
            Fixed-precision text table.
        """
        rows = []
        for r in self.results:
            s = r._sad_filled()
            rows.append([f"{r.V_xyz_m2:.3f}", f"{np.sqrt(r.V_xyz_m2):.2f}", f"{r.spread_solved_m[0]:.3f}",
                         f"{s.min():.1f} / {s.mean():.1f} / {s.max():.1f}", f"{r.peak:.2f}",
                         f"{r.error_with_m:.3f}", f"{r.error_without_m:.3f}"])
        return format_table(["V [m^2]", "sqrt V [m]", "x spread [m]", "SAD min / mean / max", "peak / uniform",
                             "error, weights [m]", "error, none [m]"], rows,
                            title="Fig. 4, one cycle, over the prediction's V (ours)")


def run_intensity_spread(V_values_m2=(0.01, 0.09, 0.36), offset_m: float = 0.4, *,
                         params: PlaneSLAMParams | None = None, rng=0, **overrides) -> IntensitySpread:
    """:func:`run_intensity_figure` (one cycle) for each V in ``V_values_m2`` with the same seed (ours).

    The study varies ``V_xyz_m2`` itself: ``params`` and the overrides must leave it (and ``intensity_weights``)
    at the default (a ``ValueError`` names the field otherwise).

    Parameters
    ----------
    V_values_m2 : sequence of float
        The prediction's position variances [m²], one run each (the study's own axis: not ``params.V_xyz_m2``).
    offset_m : float
        How far the vehicle moves along the walls while the odometry says it did not.
    params : PlaneSLAMParams, optional
        Filter settings (default :data:`FIG4_PARAMS`, see :func:`run_intensity_figure`), but for ``V_xyz_m2``.
    rng : int, SeedSequence or Generator
        The seed every run starts from (the same for every V).
    **overrides
        :class:`PlaneSLAMParams` fields (e.g. ``n_particles``).

    Returns
    -------
    IntensitySpread
    """
    from ..._params import refuse_set_fields
    from ...sweep import fresh_seed_sequence

    refuse_set_fields(PlaneSLAMParams.resolve(params, **overrides), ["V_xyz_m2"], "one run per value of `V_values_m2`")
    p = _fig4_settings(params, overrides)
    vals = [check_positive(x, "V_values_m2") for x in np.atleast_1d(np.asarray(V_values_m2, dtype=float))]
    if not vals:
        raise ValueError("`V_values_m2` must hold at least one variance")
    # a fresh copy of the same SeedSequence per V (an int seed: the stream of default_rng(seed) each time)
    return IntensitySpread(tuple(run_intensity_figure(offset_m, params=p.replace(V_xyz_m2=x),
                                                      rng=fresh_seed_sequence(rng)) for x in vals))


def _fig4_trial(offset_m: float, rng, params: PlaneSLAMParams, rounds: int = 1) -> dict:
    """One Fig. 4 run with a seed drawn from ``rng``: the along-corridor errors with and without the weights."""
    r = run_intensity_figure(offset_m, rounds=rounds, params=params, rng=int(rng.integers(2**31)))
    return {"error_with_m": r.error_with_m, "error_without_m": r.error_without_m, "peak": r.peak}


@dataclass(frozen=True)
class IntensityStudy:
    """Fig. 4 over seeds and offsets (ours: 002 shows one cycle): one row per run in ``runs`` (a DataFrame).

    Attributes
    ----------
    runs : pandas.DataFrame
        One row per (seed, offset) run.
    rounds : int
        Cycles per run.
    """

    runs: object = field(repr=False)
    rounds: int = 1

    def __str__(self) -> str:
        r = self.runs
        return (f"Fig. 4 study: {len(r)} runs, median error {r.error_with_m.median():.3f} m with the intensity "
                f"weights, {r.error_without_m.median():.3f} m without")

    def table(self) -> str:
        """Median and 90 % errors with and without the weights per offset, over the seeds (ours).

        Returns
        -------
        str
            Fixed-precision text table.
        """
        rows = []
        for off, g in self.runs.groupby("offset_m"):
            rows.append([f"{off:.2f}", str(len(g)), f"{g.error_with_m.median():.3f}",
                         f"{g.error_with_m.quantile(0.9):.3f}", f"{g.error_without_m.median():.3f}",
                         f"{100 * (g.error_with_m < 0.5 * g.error_without_m).mean():.0f}", f"{g.peak.median():.2f}"])
        cyc = "one cycle" if self.rounds == 1 else f"{self.rounds} cycles"
        return format_table(["offset [m]", "runs", "with: median [m]", "with: 90 % [m]", "without: median [m]",
                             "halved, %", "peak / uniform"],
                            rows, title=(f"002 Fig. 4 over seeds, {cyc} (ours): the error with and without the "
                                         "intensity weights;\nhalved: runs whose error with the weights is under "
                                         "half of it without; peak: the median largest weight"))


def run_intensity_study(n_seeds: int = 10, offsets_m=(0.2, 0.4, 0.8), *, rounds: int = 1,
                        params: PlaneSLAMParams | None = None, rng=0, n_jobs: int = 1, progress=None,
                        **overrides) -> IntensityStudy:
    """Fig. 4 (:func:`run_intensity_figure`) repeated over ``n_seeds`` seeds for each offset, by
    :func:`slamlab.sweep.sweep` (ours: how reliably the intensities resolve the line).

    Parameters
    ----------
    n_seeds : int
        Runs per offset, each from its own stream.
    offsets_m : sequence of float
        How far the vehicle moves along the walls while the odometry says it did not.
    rounds : int
        Cycles on the second frame.
    params : PlaneSLAMParams, optional
        Filter settings (default :data:`FIG4_PARAMS`, see :func:`run_intensity_figure`).
    rng : int, SeedSequence or Generator
        Where every run's stream is spawned from.
    n_jobs : int
        Parallel workers of :func:`slamlab.sweep.sweep`.
    progress : bool, callable or None
        See :mod:`slamlab._progress`.
    **overrides
        :class:`PlaneSLAMParams` fields (e.g. ``n_particles``).

    Returns
    -------
    IntensityStudy
    """
    from ...sweep import root_seed_sequence, sweep

    p = _fig4_settings(params, overrides)
    n_seeds = check_int(n_seeds, "n_seeds", minimum=1)
    rounds = check_int(rounds, "rounds", minimum=1)
    table = sweep(_fig4_trial, {"offset_m": [float(o) for o in offsets_m]}, seeds=n_seeds,
                  rng=root_seed_sequence(rng, "rng"), n_jobs=n_jobs, on_error="raise", desc="Fig. 4 study",
                  fixed={"rounds": rounds, "params": p}, progress=progress)
    return IntensityStudy(table, rounds)
