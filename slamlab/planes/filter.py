"""The plane-based particle filter: motion, pairing + LM, intensity weights, resampling, pose, map (002 "MCL").

One cycle (002; the stage names are those of 002's timing table):

1. *extraction* — RANSAC planes in the frame (:func:`~slamlab.planes.extract_planes`);
2. *description* — each plane's frame and cell grid (:func:`~slamlab.planes.describe_plane`);
3. *motion* — every particle moved by the odometry increment ``(ΔR, Δt)`` between the
   frames plus ``ε ~ N(0, V)``, "ε a normally distributed random variable with zero mean and
   variance V" (002: V is a *variance*): ``R ← R ΔR Exp(ε_r)``, ``t ← t + R Δt + ε_t`` (002's
   formula is garbled; ours: body-frame composition; ours: one V per translation axis
   ``V_xyz_m2`` [m²] and one per rotation axis ``V_rpy_deg2`` [deg²]);
4. *equations* — per particle, frame planes paired with map planes (normals within
   ``pair_angle_deg``, offsets within ``pair_dist_m`` once moved by the particle; the
   closest pair wins, ours) and the pose solved by :func:`~slamlab.planes.lm_pose`;
5. *weights* — ``SAD_i = (1/N_i) Σ_planes Σ_cells |ᵇI − ᵐI|`` over a thinned set of the
   frame planes' cells (every ``thin``-th), the map cell being the one under the frame
   cell's centre moved by the particle; ``SAD*_i = max SAD − SAD_i``, ``w_i = SAD*_i / Σ SAD*``
   (002); importance resampling (ours: systematic);
6. *pose* — the mean of the particles (rotation: the chordal mean, projected on SO(3));
   then the frame's planes enter the map (ours: timed apart as *map*, 002's table has
   no such row).

A frame whose planes' normals span fewer than ``min_normal_rank`` directions (no plane,
one plane, parallel planes only) or that is not finite keeps the prediction and is
counted (ours: 002 says one pair still works, :func:`lm_pose` accepts it; the filter is
stricter by default, ``min_normal_rank=1`` follows 002).
"""

from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np

from .._params import Params, param
from .._validate import as_matrix, as_rng, check_int, check_positive
from ..filters.particles import systematic_resample  # the shared particle toolbox (re-exported here)
from ..geometry import se3_inverse
from .description import Plane, describe_plane, lookup_local
from .extraction import Frame, extract_planes
from .mapping import PlaneMap
from .stages import intensity_weights, mean_pose, pair_planes, predict_particles
from .transform import lm_pose

__all__ = ["STAGES", "CycleReport", "PlaneSLAM", "PlaneSLAMParams", "intensity_weights", "mean_pose",
           "pair_planes", "predict_particles", "systematic_resample"]

#: the stages of 002's timing table, in order (plus our "map")
STAGES = ("extraction", "description", "motion", "equations", "weights", "pose", "map")


@dataclass(frozen=True)
class PlaneSLAMParams(Params):
    """Settings of the plane particle filter (002; "ours" where 002 gives no value).

    Attributes
    ----------
    n_particles : int
        Particles (002: 400).
    V_xyz_m2, V_rpy_deg2 : float
        Prediction noise variances per axis per frame: position in m², roll/pitch/yaw in deg².
    ransac_tolerance_m : float
        Inlier distance of the plane RANSAC, metres.
    ransac_iterations, ransac_min_support, ransac_sample_points : int
        RANSAC minimal samples per plane, smallest inlier count of a plane, random points the hypotheses are
        drawn and scored on.
    max_planes : int
        Most planes extracted per frame.
    min_width_m : float
        Planes narrower than this (10-90 % spread) are dropped, metres.
    cell_m : float
        Cell side of the plane description, metres.
    thin : int
        Every ``thin``-th cell enters the SAD (and every ``thin``-th leftover point the voxel map).
    pair_angle_deg, pair_dist_m : float
        Pairing tolerances of frame and map planes: normal angle in degrees, offset in metres.
    lm_iters : int
        Levenberg-Marquardt iterations per cycle.
    sigma_normal : float
        Scale of the normal residuals (unitless).
    sigma_offset_m : float
        Scale of the offset residuals, metres.
    lm_prior : bool
        A weak prior at the prediction in the LM (False: 002's bare system).
    lm_prior_scale : float
        The prior's standard deviations are this times √V.
    lm_lambda : float
        Initial LM damping.
    min_normal_rank : int
        Distinct normal directions (1-3) a frame needs to be used.
    intensity_weights : bool
        Weight and resample the particles by the intensity SAD (002).
    incidence_correction : bool
        Divide intensities by the incidence cosine (002 after [17]).
    merge_angle_deg, merge_dist_m : float
        Tolerances for merging a new plane into a map plane: degrees, metres.
    voxel_m : float
        Voxel side of the map's leftover points, metres.
    """

    n_particles: int = param(400, "002: 400 particles")
    V_xyz_m2: float = param(9e-4, "002: ε ~ N(0, V), V a variance; value ours: (3 cm)² per axis per frame")
    V_rpy_deg2: float = param(0.25, "002: ε ~ N(0, V), V a variance; value ours: (0.5°)² per axis per frame")
    ransac_tolerance_m: float = param(0.04, "ours (002: PCL RANSAC, tolerance not given)")
    ransac_iterations: int = param(100, "ours")
    ransac_min_support: int = param(400, "ours")
    ransac_sample_points: int = param(1000, "ours")
    max_planes: int = param(10, "ours")
    min_width_m: float = param(0.6, "ours: planes narrower than this (10-90 % spread) are dropped")
    cell_m: float = param(0.25, "ours (002: 'cells of a given size')")
    thin: int = param(3, "ours (002: 'a thinned set of parts')")
    pair_angle_deg: float = param(10.0, "ours")
    pair_dist_m: float = param(0.4, "ours")
    lm_iters: int = param(6, "ours")
    sigma_normal: float = param(0.02, "ours: scale of the normal residuals")
    sigma_offset_m: float = param(0.03, "ours: scale of the offset residuals")
    lm_prior: bool = param(True, "ours: a weak prior at the prediction in the LM (False: 002's bare system)")
    lm_prior_scale: float = param(10.0, "ours: the prior's stds are this times √V")
    lm_lambda: float = param(1e-3, "ours")
    min_normal_rank: int = param(2, "ours (002: 1 pair is enough)")
    intensity_weights: bool = param(True, "002")
    incidence_correction: bool = param(True, "002 after [17]")
    merge_angle_deg: float = param(8.0, "ours (002: 'some tolerance')")
    merge_dist_m: float = param(0.15, "ours")
    voxel_m: float = param(0.1, "ours")

    def check(self) -> None:
        check_int(self.n_particles, "n_particles", minimum=1)
        for name in ("V_xyz_m2", "V_rpy_deg2"):
            check_positive(getattr(self, name), name, allow_zero=True)
        for name in ("ransac_tolerance_m", "cell_m", "pair_angle_deg", "pair_dist_m", "lm_lambda",
                     "merge_angle_deg", "merge_dist_m", "voxel_m"):
            check_positive(getattr(self, name), name)
        for name, lo in (("ransac_iterations", 1), ("ransac_min_support", 3), ("ransac_sample_points", 3),
                         ("max_planes", 1), ("thin", 1), ("lm_iters", 1), ("min_normal_rank", 1)):
            check_int(getattr(self, name), name, minimum=lo)
        if self.min_normal_rank > 3:
            raise ValueError(f"`min_normal_rank` must be 1, 2 or 3; got {self.min_normal_rank}")
        for name in ("intensity_weights", "incidence_correction", "lm_prior"):
            if not isinstance(getattr(self, name), bool):
                raise TypeError(f"`{name}` must be a bool; got {type(getattr(self, name)).__name__}")


@dataclass(frozen=True)
class CycleReport:
    """What one cycle did: planes found, pairs, whether the frame was used, ``times_s`` per stage.

    Attributes
    ----------
    n_points : int
        Points in the frame.
    n_planes : int
        Planes extracted.
    normal_rank : int
        Distinct normal directions among them.
    corrected : bool
        The frame corrected the particles (False: the prediction was kept).
    mean_pairs : float
        Mean paired planes per particle.
    times_s : dict
        Wall seconds per stage (:data:`STAGES`).
    """

    n_points: int
    n_planes: int
    normal_rank: int
    corrected: bool
    mean_pairs: float
    times_s: dict


def _normal_rank(normals, tol_deg: float = 10.0) -> int:
    if len(normals) == 0:
        return 0
    s = np.linalg.svd(np.asarray(normals), compute_uv=False)
    return int(np.sum(s > np.sin(np.deg2rad(tol_deg)) * s[0]))


class PlaneSLAM:
    """The plane-based particle-filter SLAM of 002: particles ``X (P, 4, 4)`` (``ᵐT_b``), ``map``, counters.

    ``step(frame, odometry_increment)`` runs one cycle; ``history`` keeps the pose estimates.

    Parameters
    ----------
    initial_pose : (4, 4) float, optional
        Pose of every particle at the start (identity when None).
    params : PlaneSLAMParams, optional
        Settings (defaults when None).
    rng : numpy.random.Generator, int or None
        Randomness of RANSAC, prediction and resampling.
    **overrides
        :class:`PlaneSLAMParams` fields that replace those of ``params``.
    """

    def __init__(self, initial_pose=None, *, params: PlaneSLAMParams | None = None, rng=None, **overrides):
        self.params = p = PlaneSLAMParams.resolve(params, **overrides)
        self.rng = as_rng(rng)
        T0 = np.eye(4) if initial_pose is None else as_matrix(initial_pose, "initial_pose", (4, 4))
        self.X = np.repeat(T0[None], p.n_particles, axis=0)
        self.map = PlaneMap(angle_deg=p.merge_angle_deg, dist_m=p.merge_dist_m, voxel_m=p.voxel_m)
        self.pose = T0.copy()
        self.n_frames = 0
        self.n_kept_prediction = 0
        self.last_planes: list[Plane] = []
        self.X_predicted = self.X.copy()
        self.X_solved = self.X.copy()
        self.weights = np.full(p.n_particles, 1.0 / p.n_particles)
        #: the last cycle's ``SAD_i`` (NaN where not computed: weights off, frame not used)
        self.last_sad = np.full(p.n_particles, np.nan)
        #: False freezes the map (ours: for one-cycle studies such as 002 Fig. 4)
        self.update_map = True

    #: fields read once, when the filter is built (the particle array, the map's merge and voxel settings)
    FIXED_AT_START = ("n_particles", "merge_angle_deg", "merge_dist_m", "voxel_m")

    def reconfigure(self, **overrides) -> PlaneSLAMParams:
        """Change settings between cycles (ours): the next :meth:`step` uses them, as a re-tuned filter would.

        Parameters
        ----------
        **overrides
            :class:`PlaneSLAMParams` fields read at every cycle (e.g. the prediction variances ``V_xyz_m2``,
            ``V_rpy_deg2``); checked as at construction.

        Returns
        -------
        PlaneSLAMParams
            The settings now in force (also ``self.params``).

        Raises
        ------
        ValueError
            For a field in :attr:`FIXED_AT_START`, which only a new filter can change.
        """
        fixed = sorted(set(overrides) & set(self.FIXED_AT_START))
        if fixed:
            raise ValueError(f"{', '.join(map(repr, fixed))} cannot change after the filter is built "
                             "(build a new PlaneSLAM)")
        self.params = self.params.replace(**overrides)
        return self.params

    # --- the stages -------------------------------------------------------------------------------------------
    def detect(self, frame: Frame):
        """Stages 1-2: planes of ``frame`` and their descriptions (body frame), the leftover mask.

        Parameters
        ----------
        frame : Frame
            The range frame.

        Returns
        -------
        found : list of (n, p, idx)
            Per plane: normal ``(3,)``, offset in metres, indices of its points.
        leftover : (K,) bool
            Points in no plane.
        """
        p = self.params
        found, leftover = extract_planes(frame.points, tolerance_m=p.ransac_tolerance_m,
                                         iterations=p.ransac_iterations, min_support=p.ransac_min_support,
                                         max_planes=p.max_planes, sample_points=p.ransac_sample_points,
                                         min_width_m=p.min_width_m,
                                         rng=self.rng)
        return found, leftover

    def describe(self, frame: Frame, found) -> list[Plane]:
        """Stage 2: the cell description of each found plane (:func:`~slamlab.planes.describe_plane`).

        Parameters
        ----------
        frame : Frame
            The range frame.
        found : list of (n, p, idx)
            Planes from :meth:`detect`.

        Returns
        -------
        list of Plane
            In the body frame.
        """
        p = self.params
        return [describe_plane(frame.points[idx], frame.intensities[idx], n, off, cell_m=p.cell_m,
                               rays=frame.rays[idx], incidence_correction=p.incidence_correction)
                for n, off, idx in found]

    def solve(self, planes: list[Plane]):
        """Stage 4: pair and solve per particle; returns the pairs ``(P, F)``.

        Parameters
        ----------
        planes : list of Plane
            The frame's planes (body frame).

        Returns
        -------
        pairs : (P, F) int
            Map plane per particle and frame plane, -1 for none (:func:`pair_planes`).
        """
        p = self.params
        n_b = np.array([pl.n for pl in planes])
        p_b = np.array([pl.p for pl in planes])
        N, Pm = self.map.arrays()
        pairs = pair_planes(self.X, n_b, p_b, N, Pm, angle_deg=p.pair_angle_deg, dist_m=p.pair_dist_m)
        mask = pairs >= 0
        prior = None
        if p.lm_prior:
            prior = p.lm_prior_scale * np.r_[[max(np.deg2rad(np.sqrt(p.V_rpy_deg2)), 1e-6)] * 3,
                                             [max(np.sqrt(p.V_xyz_m2), 1e-6)] * 3]
        if mask.any():
            k = np.where(mask, pairs, 0)
            res = lm_pose(self.X[:, :3, :3], self.X[:, :3, 3], N[k], Pm[k], n_b, p_b, mask,
                          sigma_n=p.sigma_normal, sigma_p_m=p.sigma_offset_m, prior_sigma=prior,
                          lambda0=p.lm_lambda, max_iters=p.lm_iters)
            self.X[:, :3, :3], self.X[:, :3, 3] = res.R, res.t
        return pairs

    def sad(self, planes: list[Plane], pairs) -> np.ndarray:
        """Stage 5a: ``SAD_i`` per particle (NaN where no cell overlaps) (002).

        Parameters
        ----------
        planes : list of Plane
            The frame's planes (body frame).
        pairs : (P, F) int
            From :meth:`solve`.

        Returns
        -------
        (P,) float
            Mean absolute intensity difference over the overlapping cells.
        """
        P = self.X.shape[0]
        tot, cnt = np.zeros(P), np.zeros(P)
        for f, pl in enumerate(planes):
            sel = slice(None, None, self.params.thin)
            uv = ((pl.ij[sel] + 0.5) * pl.cell_m).T                           # (2, C) frame-plane coordinates
            I_b = pl.mean_intensity[sel]
            for m in np.unique(pairs[:, f]):
                if m < 0:
                    continue
                who = np.flatnonzero(pairs[:, f] == m)
                mp = self.map.planes[m]
                # frame plane -> body -> map (particle) -> map plane: one affine map of the cell centres
                A = se3_inverse(mp.T) @ self.X[who] @ pl.T                    # (p, 4, 4)
                local = np.swapaxes(A[:, :2, :2] @ uv + A[:, :2, 3:], 1, 2)   # (p, C, 2)
                I_m = lookup_local(mp, local)                                  # (p, C)
                d = np.abs(I_b[None] - I_m)
                ok = np.isfinite(d)
                tot[who] += np.where(ok, d, 0.0).sum(axis=1)
                cnt[who] += ok.sum(axis=1)
        with np.errstate(invalid="ignore", divide="ignore"):
            return np.where(cnt > 0, tot / cnt, np.nan)

    # --- one cycle --------------------------------------------------------------------------------------------
    def step(self, frame: Frame, odometry_increment) -> CycleReport:
        """One cycle on ``frame`` (body frame of its last line) after the odometry increment ``(4, 4)``.

        Parameters
        ----------
        frame : Frame
            The range frame.
        odometry_increment : (4, 4) float
            Odometry pose increment since the previous frame.

        Returns
        -------
        CycleReport
        """
        if not isinstance(frame, Frame):
            raise TypeError(f"`frame` must be a Frame (see build_frame); got {type(frame).__name__}")
        U = as_matrix(odometry_increment, "odometry_increment", (4, 4))
        p = self.params
        times = dict.fromkeys(STAGES, 0.0)
        clock = time.perf_counter
        t0 = clock()
        finite = bool(np.isfinite(frame.points).all() and np.isfinite(frame.intensities).all())
        found, leftover = (self.detect(frame) if finite and len(frame) >= p.ransac_min_support
                           else ([], np.ones(len(frame), bool)))
        t1 = clock()
        planes = self.describe(frame, found)
        t2 = clock()
        first = len(self.map) == 0 and bool(planes)      # the first frame with planes founds the map
        if not first:
            self.X = predict_particles(self.X, U, p.V_xyz_m2, p.V_rpy_deg2, self.rng)
        self.X_predicted = self.X.copy()
        t3 = clock()
        rank = _normal_rank([pl.n for pl in planes])
        use = (not first) and rank >= p.min_normal_rank
        pairs = self.solve(planes) if use else np.full((len(self.X), len(planes)), -1)
        use = use and bool((pairs >= 0).any())
        self.X_solved = self.X.copy()
        t4 = clock()
        w = np.full(len(self.X), 1.0 / len(self.X))
        self.last_sad = np.full(len(self.X), np.nan)
        if use and p.intensity_weights:
            self.last_sad = self.sad(planes, pairs)
            w = intensity_weights(self.last_sad)
            self.X = self.X[systematic_resample(w, rng=self.rng)]
        self.weights = w
        t5 = clock()
        self.pose = mean_pose(self.X)
        t6 = clock()
        if first or (use and self.update_map):
            for pl in planes:
                self.map.add(pl.moved(self.pose))
        if finite and leftover.any() and self.update_map:
            pts = frame.points[leftover][:: max(1, p.thin)]
            self.map.voxels.add(pts @ self.pose[:3, :3].T + self.pose[:3, 3])
        t7 = clock()
        for name, a, b in zip(STAGES, (t0, t1, t2, t3, t4, t5, t6), (t1, t2, t3, t4, t5, t6, t7), strict=True):
            times[name] = b - a
        self.n_frames += 1
        if not (use or first):
            self.n_kept_prediction += 1
        self.last_planes = planes
        return CycleReport(len(frame), len(planes), rank, use, float((pairs >= 0).sum(axis=1).mean())
                           if pairs.size else 0.0, times)
