"""Where the stereo scale bias comes from: an ablation on a simulated scene (issue 25; ours).

:func:`run_scale_ablation` runs :class:`~slamlab.stereo.StereoSLAM` on keypoints observed in a
simulated scene (such as :class:`slamlab.sim.highway.HighwayScene`, passed in: this module does not
import the simulator) once per setting and seed, and tabulates the path-length ratio, the per-frame
step ratios (mean ± standard error) and the ATE. Each setting changes one thing against
:data:`ABLATION_BASE` (:data:`~slamlab.studies.stereo.KITTI_PARAMS` without the stop-37 fix): the pixel noise of the keypoints, which depth sets a match's
weight in the pose and an observation's covariance in the landmark filter, the depth cut, the RANSAC
threshold's growth with depth, the oldest-landmark policy.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..._params import refuse_set_fields
from ..._table import format_table
from ..._validate import as_finite_array, as_rng, check_int, check_positive
from ...stereo.params import StereoParams
from ...stereo.slam import StereoSLAM
from ._text import fit_table
from .kitti_experiments import KITTI_PARAMS

__all__ = ["ABLATION_BASE", "CONDITION_SETTINGS", "PROPOSED_FIX", "PROPOSED_FIX_OFF", "SCALE_ABLATION", "ConditionAblation", "ScaleAblation", "run_condition_ablation",
           "run_scale_ablation"]

_FIX = {"pose_refine": "reprojection", "reobserve_depth_factor": 1.5, "drop_first_sighting": True, "refine_min_seen": 2}

#: the settings of the ablation: label -> overrides of ABLATION_BASE (``pixel_std_obs``: the scene's keypoint noise);
#: 'measured' / 'map': the depth behind a match's weight in the pose (``weight_depth``) and an observation's
#: covariance in the landmark filter (``update_cov_depth``); 'true' and ``_oracle``: the simulator's truth
#: (see :func:`run_scale_ablation`)
SCALE_ABLATION = {
    "both at the landmark's depth (KITTI_PARAMS without PROPOSED_FIX)": {},
    "no keypoint noise": {"pixel_std_obs": 0.0},
    "both at the measured depth": {"weight_depth": "measured", "update_cov_depth": "measured"},
    "pose weight at the measured depth only": {"weight_depth": "measured"},
    "filter covariance at the measured depth only": {"update_cov_depth": "measured"},
    "depth cut 80 m": {"max_depth_m": 80.0},
    "depth cut 80 m, both at the measured depth": {"max_depth_m": 80.0, "weight_depth": "measured",
                                                   "update_cov_depth": "measured"},
    "RANSAC threshold 0.5 m at every depth, equal weights": {"depth_ref_m": 1000.0, "threshold_m": 0.5},
    "pose from all inliers": {"policy": "all"},
    # oracles (stop 37): the simulator's truth where a noisy estimate was used; which one removes the bias?
    "pose weight at the true depth (oracle)": {"weight_depth": "true"},
    "pose weight, filter and first covariances at the true depth (oracle)": {
        "weight_depth": "true", "update_cov_depth": "true", "init_cov_depth": "true"},
    "depth cut on the true depth (oracle)": {"_oracle": ("cut",)},
    "new landmarks at their true position (oracle)": {"_oracle": ("init_position",)},
    "pose from the exact local points (oracle)": {"_oracle": ("pose_points",)},
    # the options that do not know the scene (stop 37; all off in ABLATION_BASE)
    "points up to 1.5 x the cut match landmarks": {"reobserve_depth_factor": 1.5},
    "landmark filter in pixels": {"filter_space": "pixels"},
    "pose refined on the reprojection error": {"pose_refine": "reprojection"},
    "refined pose + 1.5 x the cut": {"pose_refine": "reprojection", "reobserve_depth_factor": 1.5},
    "refined pose + 1.5 x the cut + landmark filter in pixels": {
        "pose_refine": "reprojection", "reobserve_depth_factor": 1.5, "filter_space": "pixels"},
    "refined pose, depth cut on the true depth (oracle)": {"pose_refine": "reprojection", "_oracle": ("cut",)},
    "refined pose + 1.5 x the cut, new landmarks at their true position (oracle)": {
        "pose_refine": "reprojection", "reobserve_depth_factor": 1.5, "_oracle": ("init_position",)},
    "refined pose + 1.5 x the cut + second sighting replaces the first": {
        "pose_refine": "reprojection", "reobserve_depth_factor": 1.5, "drop_first_sighting": True},
    "... + refinement on landmarks seen twice (PROPOSED_FIX)": {
        "pose_refine": "reprojection", "reobserve_depth_factor": 1.5, "drop_first_sighting": True,
        "refine_min_seen": 2},
    # the noise model (stop 38): the filter's pixel_std (0.5 px) against the scene's keypoint noise
    "PROPOSED_FIX + pixel_std 1 px (the 1 px scene's noise: an oracle there)": {**_FIX, "pixel_std": 1.0},
    "PROPOSED_FIX + no innovation gate in the landmark filter": {**_FIX, "update_gate": None},
    "PROPOSED_FIX + Huber threshold 4 px": {**_FIX, "refine_huber_px": 4.0},
    "PROPOSED_FIX + pixel_std estimated online (KITTI_PARAMS)": {**_FIX, "pixel_std_estimate": True},
}

#: the options stop 37 proposes against the displacement underestimate (issue 25): the pose refined on the
#: stereo reprojection error of the landmarks seen at least twice; points up to 1.5 x ``max_depth_m`` matched to
#: landmarks (not made new ones); a landmark's second sighting replaces its first triangulation, which the depth
#: cut selected on its own noisy depth
PROPOSED_FIX = dict(_FIX)

#: the base of the ablations: :data:`~slamlab.studies.stereo.KITTI_PARAMS` without ``PROPOSED_FIX`` (its options at
#: :class:`StereoParams`' defaults), i.e. KITTI_PARAMS as it was until stop 37 made the fix part of it; every row
#: of :data:`SCALE_ABLATION` and :data:`CONDITION_SETTINGS` overrides this
#: ``PROPOSED_FIX``'s options at :class:`StereoParams`' defaults: overrides that turn the fix off
#: (stop 38: and the online noise estimate, which needs the refinement; and the disparity-offset estimate, which came
#: after them, for KITTI 01: the simulated rigs are exact, so these studies leave it off, and "KITTI_PARAMS" in their
#: labels means KITTI_PARAMS without it)
PROPOSED_FIX_OFF = {k: getattr(StereoParams(), k) for k in (*PROPOSED_FIX, "pixel_std_estimate",
                                                              "disparity_offset_estimate")}
ABLATION_BASE = KITTI_PARAMS.replace(**PROPOSED_FIX_OFF)

#: the settings of :func:`run_condition_ablation`: the defaults before issue 25, KITTI_PARAMS of stop 36, of
#: stop 37 (with PROPOSED_FIX) and today's (with the noise estimated online, stop 38)
CONDITION_SETTINGS = {
    "old defaults (measured depth)": {"weight_depth": "measured", "update_cov_depth": "measured"},
    "KITTI_PARAMS without PROPOSED_FIX": {},
    "KITTI_PARAMS without the noise estimate": PROPOSED_FIX,
    "KITTI_PARAMS (+ pixel_std estimated online)": {**PROPOSED_FIX, "pixel_std_estimate": True},
}


@dataclass(frozen=True)
class ScaleAblation:
    """Scale figures of each setting of :func:`run_scale_ablation` (issue 25).

    Attributes
    ----------
    labels : tuple of str
        The settings.
    path_ratio : numpy.ndarray, shape (S, n_seeds)
        Estimated over true path length, per setting and seed.
    step_ratios : numpy.ndarray, shape (S, n_seeds, n_frames - 1)
        Estimated over true length of every frame-to-frame step.
    ate_m : numpy.ndarray, shape (S, n_seeds)
        ATE RMSE (no alignment: both start at frame 0) [m].
    path_length_m : float
        True path length [m].
    pixel_std_obs : float
        Keypoint noise of the scene [px] (settings may override it).
    n_degenerate : numpy.ndarray, shape (S, n_seeds)
        Frames that kept the last pose.
    end_ratio : numpy.ndarray or None, shape (S, n_seeds)
        The estimated end position projected on the true one, over the true one's length: the scale
        of the displacement, which pose jitter does not lengthen (the path length grows with it).
    """

    labels: tuple
    path_ratio: np.ndarray = field(repr=False)
    step_ratios: np.ndarray = field(repr=False)
    ate_m: np.ndarray = field(repr=False)
    path_length_m: float
    pixel_std_obs: float
    n_degenerate: np.ndarray = field(repr=False)
    end_ratio: np.ndarray | None = field(default=None, repr=False)

    def __str__(self) -> str:
        i = int(np.argmax(np.abs(self.path_ratio.mean(axis=1) - 1)))
        return (f"scale ablation, {len(self.labels)} settings x {self.path_ratio.shape[1]} seeds over "
                f"{self.path_length_m:.1f} m: largest bias {self.path_ratio[i].mean():.3f} ({self.labels[i]})")

    def step_mean_se(self) -> np.ndarray:
        """Mean of the step ratios over every seed and step, and its standard error, per setting: ``(S, 2)``.

        Returns
        -------
        numpy.ndarray, shape (S, 2)
        """
        s = self.step_ratios.reshape(len(self.labels), -1)
        return np.column_stack([s.mean(axis=1), s.std(axis=1, ddof=1) / np.sqrt(s.shape[1])])

    def table(self, end: bool = False) -> str:
        """Per setting: path ratio (mean over seeds), step ratio mean ± s.e., ATE in % of the path (fixed precision).

        Parameters
        ----------
        end : bool, default False
            Add the end ratio (mean over seeds) after the path ratio.

        Returns
        -------
        str
        """
        ms = self.step_mean_se()
        rows = [[lab, f"{self.path_ratio[i].mean():.3f}", f"{ms[i, 0]:.3f} ± {ms[i, 1]:.3f}",
                 f"{100 * self.ate_m[i].mean() / self.path_length_m:.2f}", f"{int(self.n_degenerate[i].sum())}"]
                for i, lab in enumerate(self.labels)]
        head = ["setting", "path est./true", "step est./true: mean ± s.e.", "ATE, % of path", "degenerate"]
        if end and self.end_ratio is not None:
            head.insert(2, "end est./true")
            for i, row in enumerate(rows):
                row.insert(2, f"{self.end_ratio[i].mean():.3f}")
        n_seeds, n_steps = self.step_ratios.shape[1:]
        return fit_table(head,
                         rows, title=(f"scale ablation: {n_seeds} seeds x {n_steps + 1} frames, {self.path_length_m:.1f} m, "
                                         f"keypoint noise {self.pixel_std_obs:g} px (simulated)"))


def run_scale_ablation(scene_factory, poses, variants: dict | None = None, *, params: StereoParams | None = None,
                       n_seeds: int = 3, pixel_std_obs: float = 0.5, rng=0) -> ScaleAblation:
    """StereoSLAM on a simulated scene's keypoints once per setting and seed: the scale bias and its causes (issue 25).

    Every setting sees the same scenes and the same keypoints for a given seed (the noise streams are
    spawned per seed, not per setting), so differences between rows come from the setting alone.

    Parameters
    ----------
    scene_factory : callable
        ``scene_factory(rng)`` returns a scene with ``rig``, ``T_body_left``,
        ``ground_truth_se3(pose)`` and ``observe(pose, pixel_std=, rng=) -> (left, right)`` features
        (:class:`slamlab.sim.highway.HighwayScene`).
    poses : array_like, shape (N, 3)
        Body poses ``(x_m, y_m, yaw_rad)``, N ≥ 3 (:func:`slamlab.sim.highway.highway_path`).
    variants : dict, optional
        Label -> overrides of ``params`` (default :data:`SCALE_ABLATION`); the key ``pixel_std_obs``
        sets the scene's keypoint noise instead (of the argument ``pixel_std_obs``). Oracles (ablation only): a depth source ``'true'``
        (``weight_depth``, ``update_cov_depth``, ``init_cov_depth``) takes the true depth of each point
        from the scene (``last_observed``); the key ``_oracle``, a tuple of ``'cut'`` (the depth cut on
        the true depth), ``'init_position'`` (new landmarks at their true position seen from the
        estimated pose) and ``'pose_points'`` (the pose fit from the exact local points), replaces
        one noisy quantity by the truth.
    params : StereoParams, optional
        Base settings (default :data:`ABLATION_BASE`). A field that a setting of ``variants`` sets must keep
        ``ABLATION_BASE``'s value here (``ValueError`` naming it otherwise): the setting would replace it.
    n_seeds : int, default 3
        Scenes (layouts and noise) per setting.
    pixel_std_obs : float, default 0.5
        Keypoint noise [px] of the scene's observations (not the pipeline's ``pixel_std``, its noise model).
    rng : int or numpy.random.Generator, default 0
        Root of the seeds.

    Returns
    -------
    ScaleAblation
    """
    if not callable(scene_factory):
        raise TypeError(f"`scene_factory` must be callable (rng -> scene); got {type(scene_factory).__name__}")
    P = as_finite_array(poses, "poses", ndim=2)
    if P.shape[1] != 3 or P.shape[0] < 3:
        raise ValueError(f"`poses` must have shape (N, 3) with N >= 3; got {P.shape}")
    variants = SCALE_ABLATION if variants is None else variants
    if not isinstance(variants, dict) or not variants:
        raise TypeError("`variants` must be a non-empty dict of label -> dict of overrides")
    n_seeds = check_int(n_seeds, "n_seeds", minimum=1)
    sigma = check_positive(pixel_std_obs, "pixel_std_obs", allow_zero=True)
    base = ABLATION_BASE if params is None else StereoParams.resolve(params)
    resolved = {}
    for label, over in variants.items():
        over = dict(over)
        oracle_items = frozenset(over.pop("_oracle", ()))
        noise = check_positive(over.pop("pixel_std_obs", sigma), "pixel_std_obs", allow_zero=True)
        refuse_set_fields(base, sorted(k for k in over if k in StereoParams.field_names()),
                          f"the setting {label!r} of `variants` sets it", default=ABLATION_BASE)
        resolved[label] = (StereoParams.resolve(base, **over), noise, oracle_items)
    seeds = np.random.SeedSequence(int(as_rng(rng).integers(2**32))).spawn(n_seeds)
    S, n = len(variants), len(P)
    path_ratio, ate_m, n_deg = np.empty((S, n_seeds)), np.empty((S, n_seeds)), np.zeros((S, n_seeds), int)
    end_ratio = np.empty((S, n_seeds))
    steps = np.empty((S, n_seeds, n - 1))
    path_len = 0.0
    for j, ss in enumerate(seeds):
        s_scene, s_noise, s_slam = ss.spawn(3)
        scene = scene_factory(np.random.default_rng(s_scene))
        T0inv = np.linalg.inv(scene.ground_truth_se3(P[0]))
        truth = np.array([(T0inv @ scene.ground_truth_se3(p))[:3, 3] for p in P])
        true_steps = np.linalg.norm(np.diff(truth, axis=0), axis=1)
        path_len = float(true_steps.sum())
        for i, (p, noise, oracle_items) in enumerate(resolved.values()):
            g = np.random.default_rng(s_noise)  # the same keypoints for every setting
            slam = StereoSLAM(scene.rig, scene.T_body_left, params=p, rng=np.random.default_rng(s_slam))
            slam.oracles = oracle_items
            oracle = "true" in (p.weight_depth, p.update_cov_depth, p.init_cov_depth) or bool(oracle_items)
            for pose in P:
                fl, fr = scene.observe(pose, pixel_std=noise, rng=g)
                if oracle:  # the true left-camera position of every left keypoint (the ablation's oracle)
                    T_wl = scene.ground_truth_se3(pose) @ scene.T_body_left
                    X = scene.points_at(pose)[scene.last_observed[0]]
                    slam.truth_left_cam_m = (X - T_wl[:3, 3]) @ T_wl[:3, :3]
                slam.process_features(fl, fr)
            est = slam.trajectory[:, :3, 3]
            est_steps = np.linalg.norm(np.diff(est, axis=0), axis=1)
            steps[i, j] = est_steps / true_steps
            path_ratio[i, j] = est_steps.sum() / path_len
            end_ratio[i, j] = est[-1] @ truth[-1] / (truth[-1] @ truth[-1])
            ate_m[i, j] = np.sqrt(np.mean(np.sum((est - truth) ** 2, axis=1)))
            n_deg[i, j] = len(slam.degenerate_frames)
    return ScaleAblation(tuple(variants), path_ratio, steps, ate_m, path_len, sigma, n_deg, end_ratio)


@dataclass(frozen=True)
class ConditionAblation:
    """Scale figures per scene condition and setting of :func:`run_condition_ablation` (issue 25).

    Attributes
    ----------
    conditions : tuple of str
        The scene conditions.
    results : tuple of ScaleAblation
        One per condition (its rows: the settings).
    """

    conditions: tuple
    results: tuple = field(repr=False)

    def __str__(self) -> str:
        return f"condition ablation, {len(self.conditions)} conditions x {len(self.results[0].labels)} settings"

    def table(self) -> str:
        """Rows condition x setting: path ratio (mean over seeds), step ratio mean ± s.e., ATE % of path, degenerate.

        Returns
        -------
        str
        """
        rows = []
        for cond, a in zip(self.conditions, self.results, strict=True):
            ms = a.step_mean_se()
            rows += [[cond, lab, f"{a.pixel_std_obs:g}", f"{a.path_ratio[i].mean():.3f}", f"{a.end_ratio[i].mean():.3f}",
                      f"{ms[i, 0]:.3f} ± {ms[i, 1]:.3f}",
                      f"{100 * a.ate_m[i].mean() / a.path_length_m:.2f}", f"{int(a.n_degenerate[i].sum())}"]
                     for i, lab in enumerate(a.labels)]
        a = self.results[0]
        n_seeds, n_steps = a.step_ratios.shape[1:]
        return format_table(["scene condition", "setting", "noise px", "path est./true", "end est./true",
                             "step est./true: mean ± s.e.",
                             "ATE, % of path", "degenerate"], rows,
                            title=f"scene conditions: {n_seeds} seeds x {n_steps + 1} frames, {a.path_length_m:.1f} m (simulated)")


def run_condition_ablation(conditions: dict, poses, variants: dict | None = None, *, params: StereoParams | None = None,
                           n_seeds: int = 3, rng=0) -> ConditionAblation:
    """:func:`run_scale_ablation` once per scene condition: which realistic condition biases the scale (issue 25).

    Every condition sees the same seeds, so a row differs from the plain scene's by its condition
    (and by the layout draws a condition adds, such as vehicles).

    Parameters
    ----------
    conditions : dict
        Label -> ``(scene_factory, pixel_std)``: a factory as in :func:`run_scale_ablation` and the
        keypoint noise [px] (:data:`slamlab.sim.highway.HIGHWAY_CONDITIONS` gives the scene options).
    poses : array_like, shape (N, 3)
        Body poses, N ≥ 3.
    variants : dict, optional
        Settings (default :data:`CONDITION_SETTINGS`).
    params : StereoParams, optional
        Base settings (default :data:`ABLATION_BASE`).
    n_seeds : int, default 3
        Scenes per condition and setting.
    rng : int or numpy.random.Generator, default 0
        Root of the seeds, the same for every condition.

    Returns
    -------
    ConditionAblation
    """
    if not isinstance(conditions, dict) or not conditions:
        raise TypeError("`conditions` must be a non-empty dict of label -> (scene_factory, pixel_std)")
    for label, c in conditions.items():
        if not isinstance(c, tuple) or len(c) != 2:
            raise TypeError(f"`conditions`[{label!r}] must be a pair (scene_factory, pixel_std); got {c!r}")
    variants = CONDITION_SETTINGS if variants is None else variants
    # an int seed goes to every condition as it is (the plain scene's rows then equal run_scale_ablation's)
    root = int(rng) if isinstance(rng, (int, np.integer)) else int(as_rng(rng).integers(2**32))
    results = tuple(run_scale_ablation(f, poses, variants, params=params, n_seeds=n_seeds, pixel_std_obs=sigma, rng=root)
                    for f, sigma in conditions.values())
    return ConditionAblation(tuple(conditions), results)
