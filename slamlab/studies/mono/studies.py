"""Ch. 9 studies beside 003's text (003 §2.1, §4.1.2, §4.3.2, §5.4-5.5): tables the notebook prints.

* :func:`pinhole_table` - 003 §2.1's pinhole model and K on the two cameras of the chapter;
* :func:`inverse_depth_point_table` - 003 §4.1.2's eq. 6.4 (lost; reconstruction) ``X = T_F + R_F v / ρ``;
* :func:`tau_table` - how one pixel becomes ``τ`` (metres) and then an inverse-depth std (SVO);
* :func:`run_convergence_tests` - 003's ``L < 0.1`` beside SVO's σ test on one synthetic sideways motion;
* :func:`run_ablation` / :func:`source_findings_table` - 003 §5.4-5.5's questions (and the motion prior)
  on our pipeline;
* :func:`compare_init_methods`, :func:`run_mono_vs_stereo`, :func:`ours_vs_source`.

Every experiment here is ours; 003's statements are quoted beside, never its (lost) tables.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..._params import refuse_set_fields
from ..._table import format_table
from ..._validate import as_rng
from ...geometry.se3 import se3_from_planar, se3_inverse
from ...mono.params import MonoParams
from .convergence import ConvergenceTests, run_convergence_tests
from .experiments import (
    FAILURE_SETTINGS,
    PITCH_DOWN_RAD,
    ConvergenceStudy,
    MonoRunResult,
    case_seed,
    failure_case_frames,
    mono_sim,
    render_sequence,
    run_mono,
    sequence_poses,
    trajectory_errors,
)
from .formulas import chapter_cameras, inverse_depth_point_table, pinhole_table, tau_table

__all__ = [
    "ConvergenceTests",
    "MonoVsStereo",
    "chapter_cameras",
    "compare_init_methods",
    "inverse_depth_point_table",
    "ours_vs_source",
    "pinhole_table",
    "run_ablation",
    "run_convergence_tests",
    "run_mono_vs_stereo",
    "source_findings_table",
    "table_notes",
    "tau_table",
]


# -- 003 §5.4-5.5: its questions asked of our pipeline --------------------------------------------------
ABLATIONS = {
    "defaults": {},
    "no outlier rejection (RdE off)": {"outlier_rejection": False},
    "no refinement (alignment only)": {"refine": False},
    "SVO's constant-position prior": {"motion_model": "constant_position"},
    "homography initialisation always": {"init_method": "homography"},
    "5-point initialisation always": {"init_method": "essential"},
}


def run_ablation(configs=None, *, cases=("fast_motion",), size: str = "tiny", n_frames: int = 24,
                 params: MonoParams | None = None, rng=0, progress=None, **overrides) -> dict:
    """Our pipeline with 003 §5.4's switches (ours: outlier rejection, motion-only refinement) on rendered cases.

    Every configuration sees the same frames.

    Parameters
    ----------
    configs : mapping, optional
        Label → :class:`MonoParams` overrides (default :data:`ABLATIONS`).
    cases : sequence of str
        Rendered cases (see :func:`~slamlab.studies.mono.experiments.run_failure_cases`).
    size : str
        Render size.
    n_frames : int
        Frames per case.
    params : MonoParams, optional
        The settings every configuration changes (default: the defaults); not the fields a configuration
        or a case sets itself (``ValueError`` naming them).
    rng : int, SeedSequence or Generator
        The renders' seed: a case renders from :func:`~slamlab.studies.mono.experiments.case_seed`, the same
        frames as in :func:`~slamlab.studies.mono.experiments.run_failure_cases` with the same ``rng``.
    progress : bool, callable or None
        See :mod:`slamlab._progress`.
    **overrides
        :class:`MonoParams` fields under every configuration's.

    Returns
    -------
    dict
        ``{(config, case): MonoRunResult}``.
    """
    from ..._progress import progress_bar

    configs = ABLATIONS if configs is None else dict(configs)
    p = MonoParams.resolve(params, **overrides)  # a bad `params` or override fails here, naming the fields
    for o in configs.values():
        p.replace(**o)  # and a bad configuration
    varied = {k for o in (*configs.values(), *(FAILURE_SETTINGS.get(c, {}) for c in cases)) for k in o}
    refuse_set_fields(p, sorted(varied), "the configurations or cases of run_ablation set it")
    out = {}
    for case in cases:
        imgs, Ts, K, ov = failure_case_frames(case, size, n_frames, rng=np.random.default_rng(case_seed(rng, case)))
        for label, o in progress_bar(list(configs.items()), desc=case, progress=progress):
            out[(label, case)] = run_mono(imgs, Ts, K, name=f"{case}, {label}", params=p, progress=False, **{**ov, **o})
    return out


def ablation_table(results: dict, *, title: str = "003 §5.4's switches and the motion prior on our pipeline (rendered)") -> str:
    """One row per (configuration, case): claimed and correct shares, ATE over all and claimed frames, losses.

    When every row has one case, the case is named in the title instead of a column.

    Parameters
    ----------
    results : dict
        ``(configuration, case)`` → :class:`MonoRunResult` (:func:`run_ablation`).
    title : str
        Table title.

    Returns
    -------
    str
    """
    rows = []
    cases = list(dict.fromkeys(case for _, case in results))
    one = len(cases) == 1
    for (label, case), r in results.items():
        f3 = lambda x: f"{x:.3f}" if np.isfinite(x) else "-"
        rows.append([label, *(() if one else (case,)), f"{100 * r.fraction_claimed:.0f}",
                     f"{100 * r.fraction_tracked:.0f}", f3(r.ate_m), f3(r.ate_claimed_m), f"{r.counts.get('lost', 0)}"])
    return format_table(["configuration", *(() if one else ("case",)), "claimed, %", "correct, %", "ATE all, m",
                         "ATE claimed, m", "lost frames"], rows,
                        title=f"{title}: {cases[0]}" if one else title)


def source_findings_table(ablation: dict, failures: dict) -> str:
    """003 §5.4-5.5's findings (quoted, no numbers survive) beside what our runs print on the same questions.

    ``ablation``: ``{(configuration, case): MonoRunResult}`` with at least the labels ``"defaults"``,
    ``"no outlier rejection (RdE off)"`` and ``"no refinement (alignment only)"`` for each case (the
    rendered :func:`run_ablation` and the KITTI ablation may be merged into one dict).

    Parameters
    ----------
    ablation : dict
        ``(configuration, case)`` → :class:`MonoRunResult`.
    failures : dict
        Case → :class:`MonoRunResult` (:func:`run_failure_cases`).

    Returns
    -------
    str
        One row per finding: 003's words beside our figures.
    """
    cases = list(dict.fromkeys(case for _, case in ablation))
    fails = {k: r for k, r in failures.items() if k != "normal"}
    n_x = sum(r.verdict == "X" for r in fails.values())
    n_star = sum(r.verdict == "*" for r in fails.values())

    def cm(r):
        return f"{100 * r.ate_m:.1f} cm" if np.isfinite(r.ate_m) else "-"

    def compare(label):
        parts = []
        for case in cases:
            d, o = ablation.get(("defaults", case)), ablation.get((label, case))
            if d is not None and o is not None:
                parts.append(f"{case}: on {cm(d)}, {100 * d.fraction_tracked:.0f} %; off {cm(o)}, "
                             f"{100 * o.fraction_tracked:.0f} %")
        return " | ".join(parts) or "-"

    d0 = ablation.get(("defaults", cases[0])) if cases else None
    rows = [
        ["outlier rejection (RdE)", "§5.4: slightly more accurate in static scenes; key in dynamic ones",
         compare("no outlier rejection (RdE off)")],
        ["refinement after alignment", "§4.4 step 4 (003 reports no ablation)", compare("no refinement (alignment only)")],
        ["bundle adjustment", "§5.4: needed for high accuracy in large scenes; tracking time unaffected",
         "not implemented (no BA)"],
        ["ORB descriptors", "§5.4: slightly more accurate, slower tracking; §5.5.2: ~40 % lower tracking time without",
         "not implemented (patches only)"],
        ["accuracy", "§5.4: 'not more than a couple of cm' with some configurations",
         f"ATE {cm(d0)} ({cases[0]}, rendered)" if d0 is not None else "-"],
        ["robustness", ("§5.5.1: six experiments, the compared systems tuned per case and shown at their most "
                        "accurate of 3 runs (§5.5); SVO lost in 3 of 6, PTAM finished 1, ORB-SLAM most accurate, "
                        "SDVL in between (its sequences, not our constructed cases: the counts do not compare)"),
         f"our failure cases: X in {n_x} of {len(fails)}, * in {n_star}"],
        ["tracking time", ("§5.5.2: SVO fastest (a few ms), ORB-SLAM slowest, LSD-SLAM between them; SDVL between "
                           "SVO and LSD-SLAM"), "ours only, no ranking: the timing table of this section"],
    ]
    table = format_table(["question", "our pipeline (ATE all frames, correct share)"], [[q, o] for q, _, o in rows],
                         title="003 §5.4-5.5 beside our runs (003's words below the table)")
    return table + "\n" + table_notes("003 found:", [f"{q}: {w}" for q, w, _ in rows])


def table_notes(head: str, items, width: int = 110) -> str:
    """``head`` then each item as a wrapped line under a table, no line wider than ``width``.

    Parameters
    ----------
    head : str
        The first line (e.g. ``"Notes:"``).
    items : iterable of str
        One note each, indented by two spaces, continued by four.
    width : int
        Widest line (default 110, the notebook's output area).

    Returns
    -------
    str

    Examples
    --------
    >>> print(table_notes("Notes:", ["a b c"], width=5))
    Notes:
      a b
        c
    """
    import textwrap

    return "\n".join([head, *(textwrap.fill(t, width, initial_indent="  ", subsequent_indent="    ") for t in items)])


# -- homography vs essential matrix (003 §4.3.1) -------------------------------------------------
def compare_init_methods(*, n_points: int = 200, noise_px: float = 0.5, n_trials: int = 20, rng=0) -> str:
    """Median rotation error and translation-direction error of both two-view methods (003 §4.3.1).

    Synthetic views (K: f = 500 px, 640×480; a 0.4 m mostly sideways baseline with a small rotation) of a
    tilted plane 4 m ahead and of a deep scene (2.5-8 m); pixel noise ``noise_px``; ``n_trials`` draws.

    Parameters
    ----------
    n_points : int
        Points per scene (default 200).
    noise_px : float
        Pixel noise σ [px] (default 0.5).
    n_trials : int
        Random draws per scene (default 20).
    rng : Generator, int or None
        Randomness of the scenes and the noise (default 0).

    Returns
    -------
    str
        One row per (scene, method): median rotation and translation-direction errors [deg].
    """
    from ...geometry.camera import project_points, rotation_xyz
    from ...geometry.so3 import rotation_angle
    from ...mono.initialise import relative_pose_essential, relative_pose_homography

    rng = as_rng(rng)
    K = np.array([[500.0, 0, 320], [0, 500.0, 240], [0, 0, 1]])
    R = rotation_xyz(0.02, -0.05, 0.01)
    t = np.array([0.4, -0.05, 0.1])
    t_dir = t / np.linalg.norm(t)
    rows = []
    for scene in ("planar", "non-planar"):
        errs = {"homography": [], "essential": []}
        for _ in range(n_trials):
            if scene == "planar":
                xy = rng.uniform(-2, 2, (n_points, 2))
                X0 = np.column_stack([xy, 4.0 + 0.3 * xy[:, 0] - 0.2 * xy[:, 1]])
            else:
                X0 = np.column_stack([rng.uniform(-2, 2, (n_points, 2)), rng.uniform(2.5, 8.0, n_points)])
            X1 = X0 @ R.T + t
            uv0 = project_points(K, X0) + rng.normal(0, noise_px, (n_points, 2))
            uv1 = project_points(K, X1) + rng.normal(0, noise_px, (n_points, 2))
            for name, fn in (("homography", relative_pose_homography), ("essential", relative_pose_essential)):
                pose = fn(uv0, uv1, K, ransac_px=1.5)
                if not pose.ok:
                    errs[name].append((np.inf, np.inf))
                    continue
                e_r = np.degrees(rotation_angle(pose.R @ R.T))
                e_t = np.degrees(np.arccos(np.clip(pose.t @ t_dir, -1, 1)))
                errs[name].append((e_r, e_t))
        for name, e in errs.items():
            e = np.array(e)
            rows.append([scene, name, f"{np.median(e[:, 0]):.2f}", f"{np.median(e[:, 1]):.1f}",
                         f"{100 * np.mean(e[:, 1] > 10):.0f}"])
    return format_table(["scene", "method", "median rotation error, deg", "median t direction error, deg",
                         "t off by > 10 deg, %"], rows,
                        title=f"Two-view initialisation, {n_trials} draws, {n_points} points, noise {noise_px} px")


def ours_vs_source(failures: dict, sequence: MonoRunResult, kitti: MonoRunResult | None = None,
                   convergence: ConvergenceStudy | None = None) -> str:
    """003's stated figures beside ours (003 §4.3, §4.4.1, §5.1.1, §5.2, §5.4, §5.5.1), from the runs' results.

    Parameters
    ----------
    failures : dict
        Case → :class:`MonoRunResult` (:func:`run_failure_cases`).
    sequence : MonoRunResult
        A rendered sequence run.
    kitti : MonoRunResult, optional
        The KITTI run, when there is one.
    convergence : ConvergenceStudy, optional
        The depth-filter study, when there is one.

    Returns
    -------
    str
        One row per figure: 003's value beside ours.
    """
    p = MonoParams()
    n_fail_ok = sum(r.verdict == "ok" for k, r in failures.items() if k != "normal")
    n_cases = sum(k != "normal" for k in failures)
    rows = [
        ["camera", "'Kinetic' [a]; ICL-NUIM OR3 (§5.2)", "rendered 40° (000's rig); KITTI 06 left"],
        ["FAST points to start", ">= 50 (usually > 300)", f">= {p.min_corners}"],
        ["initial displacement", "10-20 px (§5.1.1)", f"{p.init_disparity_px:.0f} px"],
        ["initialisation", "5-point named, homography shown [b]", f"{p.init_method}: homography or 5-point"],
        ["search band", "rho +- 2 sigma; 1e-10 if <= 0", f"rho +- {p.n_sigma:.0f} sigma; 1e-10"],
        ["convergence", "L < 0.1", f"L < {p.L_max} (or SVO sigma < range/200)"],
        ["keyframe rule", ">= 30 frames, >= 10 % lost, or > 30 %",
         f">= {p.kf_min_frames}, >= {100 * p.kf_lost_ratio:.0f} %, or > {100 * p.kf_max_lost_ratio:.0f} %"],
        ["alignment patch", "4x4, pyramid, coarse to fine",
         f"{p.align_patch_px}x{p.align_patch_px}, levels {p.align_max_level}..{p.align_min_level}"],
        ["motion prior", "constant velocity", p.motion_model.replace("_", " ")],
        ["accuracy", "'a couple of cm' [c]", f"ATE {100 * sequence.ate_m:.1f} cm, all frames, {sequence.name.split(' (')[0]}"],
        ["failure cases ok (> 70 %)", "6 named (§5.3), no numbers", f"{n_fail_ok} of {n_cases} (our constructions)"],
    ]
    if convergence is not None:
        def half(i):
            k = np.flatnonzero(convergence.converged[i] >= 0.5)
            return f"{k[0]}" if k.size else "> " + str(convergence.converged.shape[1] - 1)

        rows.append(["seeds converged (half)", "'enough parallax' (Fig. 4.5)",
                     " / ".join(half(i) for i in range(len(convergence.outlier_rates))) + " obs. (SVO test) [d]"])
    if kitti is not None:
        rows.append(["real data", "ICL-NUIM OR3 (§5.2) [e]",
                     (f"KITTI 06, {len(kitti.tracked)} fr.: {100 * kitti.fraction_tracked:.0f} % correct, "
                      f"ATE {kitti.ate_m:.2f} m")])
    notes = [("[a] 003 §5.1.2: the images came from a monocular camera it calls 'Kinetic', run under ROS; we "
              "read it as a Kinect (our reading: it may name ROS Kinetic, the ROS release)."),
             ("[b] 003 §4.3.1: 'the initial map is computed with the 5-point algorithm', then a RANSAC homography "
              "'assuming a dominant plane'; our 'auto' picks one of the two (ours)."),
             "[c] 003 §5.4: 'not more than a couple of centimetres', with some configurations.",
             ("[e] 003 §5.5.1: six experiments against PTAM, SVO, LSD-SLAM and ORB-SLAM, each of them tuned per "
              "case and shown at its most accurate of 3 runs (§5.5); its tables are lost. Our figures are one "
              "run each (section 8 prints the median and the best of 3).")]
    if convergence is not None:
        notes.insert(3, "[d] observations until half of the seeds pass SVO's test at "
                     + " / ".join(f"{100 * r:.0f}" for r in convergence.outlier_rates) + " % outliers.")
    return format_table(["item", "003", "ours"], rows, title="Ours vs the source (003)") + "\n" + table_notes("Notes:", notes)


# -- mono vs stereo on the same frames ----------------------------------------------------------
def run_mono_vs_stereo(sequence: str = "strafe", *, n_frames: int = 40, size: str = "small",
                       params: MonoParams | None = None, rng=0, snapshot_frames=(), **overrides):
    """The monocular pipeline on the left images and Ch. 5's stereo pipeline on the pairs, same poses.

    Parameters
    ----------
    sequence : str
        The rendered sequence (see :func:`~slamlab.studies.mono.experiments.sequence_poses`).
    n_frames : int
        Frames.
    size : str
        Render size.
    params : MonoParams, optional
        Settings of the monocular pipeline (the stereo pipeline keeps its defaults).
    rng : int, SeedSequence or Generator
        The renderer's seed.
    snapshot_frames : sequence of int
        Frames after which the mono seeds' spreads are kept.
    **overrides
        :class:`MonoParams` fields.

    Returns
    -------
    tuple
        ``(mono MonoRunResult, stereo ATE SE(3) m, stereo ATE Sim(3) m, stereo RPE m)``.
    """
    from ...stereo.slam import StereoSLAM

    sim = mono_sim(size, rng=rng)
    poses = sequence_poses(sequence, n_frames)
    imgs, Ts = render_sequence(sim, poses, progress=False)
    mono = run_mono(imgs, Ts, sim.rig.left.K, name=f"{sequence} (mono)", params=params, progress=False,
                    snapshot_frames=snapshot_frames, **overrides)
    c, s_ = np.cos(PITCH_DOWN_RAD), np.sin(PITCH_DOWN_RAD)
    tilt = np.eye(4)
    tilt[1:3, 1:3] = [[c, s_], [-s_, c]]
    T_bl = sim.T_body_left @ tilt
    T_right_left = np.eye(4)
    T_right_left[:3, :3], T_right_left[:3, 3] = sim.rig.R_rl, sim.rig.t_rl
    T_br = T_bl @ se3_inverse(T_right_left)
    # RANSAC's own stream, a child of the simulator's: spawning draws nothing, so the right images' noise is unchanged
    st = StereoSLAM(sim.rig, T_bl, rng=sim.rng.spawn(1)[0])
    for pose, left in zip(poses, imgs, strict=True):
        T_wb = se3_from_planar(*pose)
        right = sim.arena.render(sim.rig.right, T_wb @ T_br) * 255.0
        right = np.clip(np.rint(right + sim.rng.normal(0.0, sim.noise_std, right.shape)), 0, 255).astype(np.uint8)
        st.process(left, right)
    est_body = st.trajectory  # (N, 4, 4) body poses in the map frame (the first body pose)
    est_cam = np.einsum("nij,jk->nik", est_body, T_bl)
    est_cam = np.einsum("ij,njk->nik", se3_inverse(est_cam[0]), est_cam)
    ok = np.ones(len(poses), bool)
    from ...evaluation import Trajectory, ate

    ts = np.arange(len(poses)) * 0.1
    ref = Trajectory(mono.truth[:, :3, 3], mono.truth[:, :3, :3], ts)
    est = Trajectory(est_cam[:, :3, 3], est_cam[:, :3, :3], ts)
    a_se3 = float(ate(ref, est, align="se3").rmse)
    a_sim3, r_st = trajectory_errors(mono.truth, est_cam, ok)
    return MonoVsStereo(mono, a_se3, a_sim3, r_st)


@dataclass(frozen=True)
class MonoVsStereo:
    """The monocular run and Ch. 5's stereo pipeline on the same rendered poses.

    Attributes
    ----------
    mono : MonoRunResult
        The monocular run.
    stereo_ate_se3_m, stereo_ate_sim3_m : float
        ATE of the stereo pipeline after SE(3) and after Sim(3) alignment [m].
    stereo_rpe_m : float
        RPE of the stereo pipeline [m].
    """

    mono: MonoRunResult
    stereo_ate_se3_m: float
    stereo_ate_sim3_m: float
    stereo_rpe_m: float

    def table(self) -> str:
        m = self.mono
        rows = [["monocular (left camera)", f"{100 * m.fraction_tracked:.0f}", "-", f"{m.ate_m:.3f}", f"{m.rpe_m:.3f}"],  # all frames
                # 2 decimals: the stereo pipeline's last digit changes with the number of BLAS threads
                ["stereo pipeline of Ch. 5", "100", f"{self.stereo_ate_se3_m:.2f}", f"{self.stereo_ate_sim3_m:.2f}",
                 f"{self.stereo_rpe_m:.2f}"]]
        return format_table(["pipeline", "correctly tracked, %", "ATE SE(3), m", "ATE Sim(3), m", "RPE (Sim(3) scale), m"], rows,
                            title=f"{m.name.split(' ')[0]}, {len(m.tracked)} frames, same poses")
