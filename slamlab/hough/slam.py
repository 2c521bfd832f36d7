"""The Hough-transform SLAM loop (004 Fig. 2 and Fig. 4).

Per scan: polar Hough transform → peaks above H_min → (our addition) a least-squares
refit of each line → association with the previous scan's lines by P_{i,j} → the
line-history matrix L[n, i] → the pose change from lines common to the scan and a
*reference* scan n1 → the map.

Choice of (n1, n2) (004 leaves it open; our rule): n2 is the current scan and n1 the
last *keyframe*; the keyframe moves to the current scan when fewer than ``min_common``
of its lines are still tracked. Between keyframe changes the error does not grow
(004: "the error depends on the rangefinder and the Hough resolution and does not
accumulate"). When no pair of lines works, the previous scan is tried as n1; when the
common lines are all parallel (a corridor), the rotation and the move across them come
from the lines and the move along them from odometry (``partial``, our addition); else
the odometry increment is used (the step is marked ``lost``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace

import numpy as np

from .. import _validate as v
from ..geometry import wrap_angle
from .association import LineHistory, associate, association_probability
from .lines import Lines, find_peaks, merge_duplicates, refine_lines, transform_lines
from .pose import compose, pose_from_lines
from .transform import hough_polar

__all__ = ["HoughSlamParams", "HoughSlamResult", "detect_lines", "hough_slam"]


@dataclass(frozen=True)
class HoughSlamParams:
    """Every knob of the loop; those 004 does not fix are our choices (see each comment)."""

    delta_rho: float = 1.0  # Δrho (004: 1 cell)
    delta_theta_rad: float = math.pi / 180  # Δθ (004: 1°)
    r_max: float | None = None  # longest range used (default: each scan's longest)
    H_min: int = 15  # votes needed for a line (004: a parameter, value not given)
    max_lines: int = 12  # strongest lines kept per scan (ours)
    suppress_rho: float | None = None  # false-neighbour window (ours: 3 Δrho)
    suppress_theta_rad: float | None = None  # (ours: 3 Δθ)
    refine: bool = True  # least-squares refit of each line (ours)
    band: float | None = None  # refit band (ours: Δrho)
    max_gap: float | None = 4.0  # refit: cut the band's points at gaps longer than this (ours)
    a: float = 3.0  # largest displacement between scans (004: a = b)
    b: float | None = None
    a_theta_rad: float = math.radians(4.0)  # largest rotation between scans left after odometry (ours)
    parallel_tol_rad: float = math.radians(3.0)
    p_min: float = 0.05  # below this P a line is new (ours)
    method: str = "least_squares"  # "two_lines" = 004's, "least_squares" = ours
    angle_tol_rad: float = math.radians(0.5)  # "the angle between the lines did not change"
    rho_tol: float | None = 0.3  # least squares: lines with a larger residual are dropped (ours)
    min_angle_rad: float = math.radians(30.0)  # smallest angle of a usable pair (ours)
    min_common: int = 3  # keyframe moves when fewer lines are shared (ours)
    gate: float | None = None  # reject a pose farther than this from odometry's (ours; None: off)
    gate_theta_rad: float = math.radians(10.0)
    partial: bool = True  # only parallel lines: move along them from odometry (ours)

    def validated(self) -> HoughSlamParams:
        """A copy with every field checked (raises ValueError/TypeError naming the field)."""
        v.check_positive(self.delta_rho, "delta_rho")
        v.check_positive(self.delta_theta_rad, "delta_theta_rad")
        if self.r_max is not None:
            v.check_positive(self.r_max, "r_max")
        v.check_int(self.H_min, "H_min", minimum=1)
        v.check_int(self.max_lines, "max_lines", minimum=2)
        v.check_positive(self.a, "a")
        v.check_positive(self.a_theta_rad, "a_theta_rad")
        v.check_choice(self.method, "method", ("two_lines", "least_squares"))
        v.check_int(self.min_common, "min_common", minimum=2)
        if self.gate is not None:
            v.check_positive(self.gate, "gate")
        return self


@dataclass(frozen=True)
class HoughSlamResult:
    """Poses of every scan, how each was obtained, and the line history."""

    poses: np.ndarray = field(repr=False)  # (n, 3) estimated (x, y, φ), φ unwrapped
    lost: np.ndarray = field(repr=False)  # (n,) bool: odometry had to be used
    n_lines: np.ndarray = field(repr=False)  # (n,) lines found per scan
    reference: np.ndarray = field(repr=False)  # (n,) scan n1 each pose was computed from (-1 for scan 0)
    history: LineHistory = field(repr=False)
    params: HoughSlamParams = field(default_factory=HoughSlamParams)
    partial: np.ndarray | None = field(default=None, repr=False)  # (n,) bool: parallel lines + odometry

    def __str__(self) -> str:
        n_part = 0 if self.partial is None else int(self.partial.sum())
        return (f"Hough SLAM over {self.poses.shape[0]} scans: {int(self.lost.sum())} lost, {n_part} partial, "
                f"{self.history.n_ids} lines tracked, {np.unique(self.reference[1:]).size} reference scans")


def detect_lines(bearings_rad, ranges, params: HoughSlamParams) -> Lines:
    """Lines of one scan: polar Hough, peaks above H_min, optional refit (004 §Hough SLAM).

    Examples
    --------
    >>> from slamlab.hough import line_scan
    >>> phi, r = line_scan(10.0, np.radians(45.0), r_max=16.0)
    >>> lines = detect_lines(phi, r, HoughSlamParams(H_min=20))
    >>> round(float(lines.rho[0]), 6), round(float(np.degrees(lines.theta_rad[0])), 6)
    (10.0, 45.0)
    """
    if not isinstance(params, HoughSlamParams):
        raise TypeError(f"`params` must be HoughSlamParams; got {type(params).__name__}")
    acc = hough_polar(bearings_rad, ranges, delta_rho=params.delta_rho, delta_theta_rad=params.delta_theta_rad,
                      r_max=params.r_max)
    lines = find_peaks(acc, params.H_min, suppress_rho=params.suppress_rho,
                       suppress_theta_rad=params.suppress_theta_rad, max_lines=params.max_lines)
    if params.refine and len(lines):
        band = params.delta_rho if params.band is None else params.band
        lines = refine_lines(lines, bearings_rad, ranges, band=band, max_gap=params.max_gap)
        keep = lines.votes >= max(2, params.H_min // 2)  # a peak whose band holds few points is spurious
        lines = merge_duplicates(Lines(lines.rho[keep], lines.theta_rad[keep], lines.votes[keep]),
                                 rho_tol=params.delta_rho, theta_tol_rad=params.delta_theta_rad)
    return lines


def _scan_arrays(scan, n):
    if not (isinstance(scan, tuple) and len(scan) == 3):
        raise TypeError(f"`scans[{n}]` must be a (bearings_rad, ranges, hit) tuple; got {type(scan).__name__}")
    phi = v.as_finite_array(scan[0], f"scans[{n}] bearings_rad", ndim=1)
    r = v.as_finite_array(scan[1], f"scans[{n}] ranges", ndim=1)
    hit = np.asarray(scan[2], dtype=bool)
    if not (phi.shape == r.shape == hit.shape):
        raise ValueError(f"`scans[{n}]` arrays must have one length; got {phi.size}, {r.size}, {hit.size}")
    return phi[hit & (r > 0)], r[hit & (r > 0)]


def _relative(history, n1, n2, params):
    ids1, l1 = history.scan(n1)
    ids2, l2 = history.scan(n2)
    common, i1, i2 = np.intersect1d(ids1, ids2, return_indices=True)
    if common.size < 2:
        return None, common.size
    votes = np.minimum(l1.votes[i1], l2.votes[i2]).astype(float)
    pc = pose_from_lines(l1.rho[i1], l1.theta_rad[i1], l2.rho[i2], l2.theta_rad[i2], votes, method=params.method,
                         angle_tol_rad=params.angle_tol_rad, min_angle_rad=params.min_angle_rad,
                         rho_tol=params.rho_tol)
    return (pc.pose if pc.ok else None), common.size


def _relative_pose(a, b):
    """b's pose in a's frame."""
    c, s_ = math.cos(a[2]), math.sin(a[2])
    d = b[:2] - a[:2]
    return np.array([c * d[0] + s_ * d[1], -s_ * d[0] + c * d[1], b[2] - a[2]])


def _partial(history, n1, n2, prior, params):
    """Degenerate case (our addition): the common lines are all parallel (a corridor).

    Δφ and the move across the lines come from the lines (vote-weighted means), the move
    along them from the odometry ``prior``.
    """
    ids1, l1 = history.scan(n1)
    ids2, l2 = history.scan(n2)
    common, i1, i2 = np.intersect1d(ids1, ids2, return_indices=True)
    if common.size < 1:
        return None
    ti, tj = l1.theta_rad[i1], l2.theta_rad[i2]
    w = np.minimum(l1.votes[i1], l2.votes[i2]).astype(float)
    dphi_all = ti - tj
    order = np.argsort(dphi_all)
    cw = np.cumsum(w[order])
    ref = dphi_all[order][np.searchsorted(cw, 0.5 * cw[-1])]
    use = np.abs(wrap_angle(dphi_all - ref)) <= params.angle_tol_rad
    if w[use].sum() < 2 * params.H_min or abs(float(wrap_angle(ref - prior[2]))) > params.gate_theta_rad:
        return None
    ww = w[use] / w[use].sum()
    normal_angle = float(np.sum(ww * ti[use]))  # the lines are parallel: one normal
    nrm = np.array([math.cos(normal_angle), math.sin(normal_angle)])
    d = l1.rho[i1][use] - l2.rho[i2][use]
    t = prior[:2] - nrm * (nrm @ prior[:2]) + nrm * float(np.sum(ww * d))
    resid = np.abs(np.column_stack([np.cos(ti[use]), np.sin(ti[use])]) @ t - d)
    if params.rho_tol is not None and resid.max() > params.rho_tol:
        return None
    return np.array([t[0], t[1], ref + float(np.sum(w[use] * wrap_angle(dphi_all[use] - ref)) / w[use].sum())])


def hough_slam(scans, start_pose=(0.0, 0.0, 0.0), odometry=None, params: HoughSlamParams | None = None,
               **overrides) -> HoughSlamResult:
    """Run Hough-transform SLAM over a sequence of scans (004 Fig. 2, Fig. 4).

    Parameters
    ----------
    scans : sequence of (bearings_rad, ranges, hit) tuples
        Bearings relative to the sensor heading; ``hit`` marks real returns.
    start_pose : (3,) array_like
        Pose of the first scan (004: given by correlation localisation).
    odometry : (n-1, 3) array_like, optional
        Body-frame increments between scans; used to predict lines for the association,
        for the gate and when a step is lost. Without it, zero motion is predicted.
    params : HoughSlamParams, optional
    **overrides
        Fields of :class:`HoughSlamParams` to change.

    Returns
    -------
    HoughSlamResult
    """
    params = (HoughSlamParams() if params is None else params)
    if not isinstance(params, HoughSlamParams):
        raise TypeError(f"`params` must be HoughSlamParams; got {type(params).__name__}")
    try:
        params = replace(params, **overrides).validated()
    except TypeError as exc:
        raise TypeError(f"unknown HoughSlamParams field in {sorted(overrides)}: {exc}") from None
    scans = list(scans)
    if len(scans) == 0:
        raise ValueError("`scans` must hold at least one scan; got 0")
    n = len(scans)
    U = np.zeros((n - 1, 3)) if odometry is None else v.as_finite_array(odometry, "odometry", ndim=2)
    if U.shape != (n - 1, 3):
        raise ValueError(f"`odometry` must have shape ({n - 1}, 3) = one (dx, dy, dθ) per step; got {U.shape}")
    poses = np.zeros((n, 3))
    poses[0] = v.as_vector(start_pose, "start_pose", 3)
    lost = np.zeros(n, dtype=bool)
    partial = np.zeros(n, dtype=bool)
    ref = np.full(n, -1, dtype=np.int64)
    n_lines = np.zeros(n, dtype=np.int64)
    history = LineHistory()
    keyframe = 0
    for k in range(n):
        phi, r = _scan_arrays(scans[k], k)
        lines = detect_lines(phi, r, params) if phi.size else Lines(np.empty(0), np.empty(0), np.empty(0, int))
        n_lines[k] = len(lines)
        if k == 0:
            history.add_scan(lines, np.full(len(lines), -1))
            continue
        prev_ids, prev = history.scan(k - 1)
        pr, pt = transform_lines(prev.rho, prev.theta_rad, U[k - 1])
        P = association_probability(lines, Lines(pr, pt, prev.votes), a=params.a, b=params.b,
                                    a_theta_rad=params.a_theta_rad, parallel_tol_rad=params.parallel_tol_rad)
        match = associate(P, p_min=params.p_min)
        ids = np.where(match >= 0, prev_ids[np.clip(match, 0, None)] if prev_ids.size else -1, -1)
        history.add_scan(lines, ids)
        guess = compose(poses[k - 1], U[k - 1])
        pose = None
        for n1 in dict.fromkeys((keyframe, k - 1)):
            delta, _ = _relative(history, n1, k, params)
            if delta is None:
                continue
            cand = compose(poses[n1], delta)
            if params.gate is not None and odometry is not None and (
                    math.hypot(*(cand[:2] - guess[:2])) > params.gate
                    or abs(float(wrap_angle(cand[2] - guess[2]))) > params.gate_theta_rad):
                continue
            pose, ref[k] = cand, n1
            break
        if pose is None and params.partial and odometry is not None:
            delta = _partial(history, k - 1, k, U[k - 1], params)
            if delta is not None:
                pose, ref[k], partial[k] = compose(poses[k - 1], delta), k - 1, True
        if pose is None:
            pose, lost[k], ref[k] = guess, True, k - 1
        poses[k] = pose
        _, n_common = _relative(history, keyframe, k, params) if ref[k] == keyframe else (None, 0)
        if lost[k] or ref[k] != keyframe or n_common < params.min_common:
            keyframe = k
    return HoughSlamResult(poses, lost, n_lines, ref, history, params, partial)
