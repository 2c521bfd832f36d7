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
from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np

from .._progress import progress_bar
from .._validate import as_finite_array
from ..geometry import wrap_angle
from ..geometry.se2 import check_pose, se2_compose
from ..scans import Scan
from .association import LineHistory, associate_lines, association_probability
from .lines import Lines, find_peaks, merge_duplicates, refine_lines, transform_lines
from .params import HoughSlamParams
from .pose import pose_from_lines, weighted_median
from .transform import hough_polar

__all__ = ["STEP_CAUSES", "HoughSlamParams", "HoughSlamResult", "detect_lines", "hough_slam", "scan_lines"]

#: How each step's pose was obtained (ours): the code stored in :attr:`HoughSlamResult.cause`.
#: Codes 0 and 1 use the lines; every other code means the step fell back on odometry, for that cause.
STEP_CAUSES = {
    "lines": "pose from non-parallel lines common with a reference scan",
    "partial": "only parallel lines: rotation and move across them from the lines, along them from odometry",
    "heading": "lines associated but no pose from them: heading from the lines, translation from odometry",
    "few_returns": "fewer returns than H_min: no line can reach the vote threshold",
    "no_lines": "no line found in the scan",
    "not_associated": "lines found, none associated with the previous scan's",
    "one_line": "one line associated, the parallel-line step rejected it (its votes, heading or residual)",
    "pose_rejected": "two or more lines associated, the pose solution rejected them (angle change or residual)",
    "gate": "a pose was found but lay beyond the gate around odometry's",
}
_CODE = {name: k for k, name in enumerate(STEP_CAUSES)}


@dataclass(frozen=True)
class HoughSlamResult:
    """Poses of every scan, how each was obtained, and the line history.

    Attributes
    ----------
    poses : numpy.ndarray, shape (n, 3)
        Estimated ``(x, y, φ)`` per scan (scan unit, rad; φ unwrapped).
    lost : numpy.ndarray of bool, shape (n,)
        Odometry had to be used.
    n_lines : numpy.ndarray of int, shape (n,)
        Lines found per scan.
    reference : numpy.ndarray of int, shape (n,)
        Scan each pose was computed from (-1 for scan 0).
    history : LineHistory
        Every scan's lines under global ids.
    params : HoughSlamParams
        The settings of the run.
    partial : numpy.ndarray of bool, shape (n,) or None
        Pose from parallel lines plus odometry.
    cause : numpy.ndarray of int, shape (n,) or None
        How each step's pose was obtained: an index into :data:`STEP_CAUSES` (ours).
    """

    poses: np.ndarray = field(repr=False)  # (n, 3) estimated (x, y, φ), φ unwrapped
    lost: np.ndarray = field(repr=False)  # (n,) bool: odometry had to be used
    n_lines: np.ndarray = field(repr=False)  # (n,) lines found per scan
    reference: np.ndarray = field(repr=False)  # (n,) scan n1 each pose was computed from (-1 for scan 0)
    history: LineHistory = field(repr=False)
    params: HoughSlamParams = field(default_factory=HoughSlamParams)
    partial: np.ndarray | None = field(default=None, repr=False)  # (n,) bool: parallel lines + odometry
    cause: np.ndarray | None = field(default=None, repr=False)  # (n,) index into STEP_CAUSES

    def cause_counts(self) -> dict:
        """Steps (scan 0 excluded) per entry of :data:`STEP_CAUSES` (ours).

        Returns
        -------
        dict
            ``{cause name: number of steps}`` in the order of :data:`STEP_CAUSES`.
        """
        if self.cause is None:
            raise ValueError("this result carries no per-step `cause` (made without it)")
        counts = np.bincount(self.cause[1:], minlength=len(STEP_CAUSES))
        return {name: int(c) for name, c in zip(STEP_CAUSES, counts, strict=True)}

    def __str__(self) -> str:
        n_part = 0 if self.partial is None else int(self.partial.sum())
        return (f"Hough SLAM over {self.poses.shape[0]} scans: {int(self.lost.sum())} lost, {n_part} partial, "
                f"{self.history.n_ids} lines tracked, {np.unique(self.reference[1:]).size} reference scans")


def _returns(scan, name: str = "scan") -> tuple[np.ndarray, np.ndarray]:
    """Bearings and ranges of the returns of a :class:`~slamlab.scans.Scan` (any unit)."""
    if not isinstance(scan, Scan):
        raise TypeError(f"`{name}` must be a slamlab.scans.Scan; got {type(scan).__name__}")
    use = scan.valid & (scan.ranges > 0)
    return scan.bearings_rad[use], scan.ranges[use]


def detect_lines(scan: Scan, params: HoughSlamParams | None = None, **overrides) -> Lines:
    """Lines of one scan: polar Hough, peaks above H_min, optional refit (004 §Hough SLAM).

    ``params`` / ``**overrides``: the :class:`HoughSlamParams` (lengths in the scan's unit).

    Parameters
    ----------
    scan : Scan
        One scan (cells or metres).
    params : HoughSlamParams, optional
        Settings (default :class:`HoughSlamParams`).
    **overrides
        Fields of :class:`HoughSlamParams` to change.

    Returns
    -------
    Lines
        Strongest first.

    Examples
    --------
    >>> from slamlab.hough import line_scan
    >>> phi, r = line_scan(10.0, np.radians(45.0), r_max=16.0)
    >>> lines = detect_lines(Scan(phi, r, np.ones(phi.size, bool)), H_min=20)
    >>> round(float(lines.rho[0]), 6), round(float(np.degrees(lines.theta_rad[0])), 6)
    (10.0, 45.0)
    """
    return _detect(*_returns(scan), HoughSlamParams.resolve(params, **overrides))


def _detect(bearings_rad, ranges, params: HoughSlamParams) -> Lines:
    """:func:`detect_lines` on the returns of a scan: the pipeline of the public steps, once per scan."""
    if bearings_rad.size == 0:
        return Lines(np.empty(0), np.empty(0), np.empty(0, int))
    acc = hough_polar(bearings_rad, ranges, delta_rho=params.delta_rho, delta_theta_rad=params.delta_theta_rad,
                      r_max=params.r_max)
    lines = find_peaks(acc, params.H_min, suppress_rho=params.suppress_rho,
                       suppress_theta_rad=params.suppress_theta_rad, max_lines=params.max_lines)
    if params.refine and len(lines):
        band = params.delta_rho if params.band is None else params.band
        lines = refine_lines(lines, bearings_rad, ranges, band=band, n_iter=3, max_gap=params.max_gap)
        keep = lines.votes >= max(2, params.H_min // 2)  # a peak whose band holds few points is spurious
        lines = merge_duplicates(Lines(lines.rho[keep], lines.theta_rad[keep], lines.votes[keep]),
                                 rho_tol=params.delta_rho, theta_tol_rad=params.delta_theta_rad)
    return lines


def _retry_params(params: HoughSlamParams) -> HoughSlamParams | None:
    """The settings of the second line search (``H_min_retry`` below ``H_min``), or None."""
    low = params.H_min_retry is not None and params.H_min_retry < params.H_min  # a retry only below H_min
    return params.replace(H_min=params.H_min_retry) if low else None


def _scan_lines(returns, params: HoughSlamParams, retry: HoughSlamParams | None) -> Lines:
    lines = _detect(*returns, params)
    if len(lines) < 2 and retry is not None:  # ours: a sparse scan, searched again at a lower threshold
        lines = _detect(*returns, retry)
    return lines


def scan_lines(scans: Sequence[Scan], params: HoughSlamParams | None = None, **overrides) -> list[Lines]:
    """Each scan's lines as :func:`hough_slam` finds them: :func:`detect_lines`, then the ``H_min_retry`` search.

    Pass the result to ``hough_slam(..., lines=)`` to run the loop again without detecting again.

    Parameters
    ----------
    scans : sequence of Scan
        The scans (one unit).
    params : HoughSlamParams, optional
        Settings (default :class:`HoughSlamParams`).
    **overrides
        Fields of :class:`HoughSlamParams` to change.

    Returns
    -------
    list of Lines
        One per scan, strongest first.

    Examples
    --------
    >>> from slamlab.hough import line_scan
    >>> phi, r = line_scan(10.0, np.radians(45.0), r_max=16.0)
    >>> [len(x) for x in scan_lines([Scan(phi, r, np.ones(phi.size, bool))] * 2, H_min=20)]
    [1, 1]
    """
    params = HoughSlamParams.resolve(params, **overrides)
    retry = _retry_params(params)
    return [_scan_lines(_returns(s, f"scans[{k}]"), params, retry) for k, s in enumerate(scans)]


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


def _common_heading(history, n1, n2, prior, params, min_votes):
    """Lines common to scans n1 and n2 and their heading change (ours; shared by the partial and heading steps).

    The heading change is the vote-weighted mean of θ_{n1} - θ_{n2} over the lines within
    ``angle_tol_rad`` of its weighted median; None when those lines hold fewer than
    ``min_votes`` votes or the change is farther than ``gate_theta_rad`` from ``prior``'s.
    Else ``(l1, i1, l2, i2, w, use, dphi)``: both scans' lines, the common ones' indices,
    their weights and which agree.
    """
    ids1, l1 = history.scan(n1)
    ids2, l2 = history.scan(n2)
    common, i1, i2 = np.intersect1d(ids1, ids2, return_indices=True)
    if common.size < 1:
        return None
    dphi_all = l1.theta_rad[i1] - l2.theta_rad[i2]
    w = np.minimum(l1.votes[i1], l2.votes[i2]).astype(float)
    ref = weighted_median(dphi_all, w)
    use = np.abs(wrap_angle(dphi_all - ref)) <= params.angle_tol_rad
    if w[use].sum() < min_votes or abs(float(wrap_angle(ref - prior[2]))) > params.gate_theta_rad:
        return None
    return l1, i1, l2, i2, w, use, ref + float(np.sum(w[use] * wrap_angle(dphi_all[use] - ref)) / w[use].sum())


def _partial(history, n1, n2, prior, params):
    """Degenerate case (our addition): the common lines are all parallel (a corridor).

    Δφ and the move across the lines come from the lines (vote-weighted means), the move
    along them from the odometry ``prior``.
    """
    found = _common_heading(history, n1, n2, prior, params, 2 * params.H_min)
    if found is None:
        return None
    l1, i1, l2, i2, w, use, dphi = found
    ti = l1.theta_rad[i1]
    ww = w[use] / w[use].sum()
    normal_angle = float(np.sum(ww * ti[use]))  # the lines are parallel: one normal
    nrm = np.array([math.cos(normal_angle), math.sin(normal_angle)])
    d = l1.rho[i1][use] - l2.rho[i2][use]
    t = prior[:2] - nrm * (nrm @ prior[:2]) + nrm * float(np.sum(ww * d))
    resid = np.abs(np.column_stack([np.cos(ti[use]), np.sin(ti[use])]) @ t - d)
    if params.rho_tol is not None and resid.max() > params.rho_tol:
        return None
    return np.array([t[0], t[1], dphi])

def _fallback_cause(n_returns, n_lines, most_common, rejected, gated, H_min) -> str:
    """The :data:`STEP_CAUSES` name of a step that fell back on odometry (the first that applies)."""
    if n_returns < H_min:
        return "few_returns"
    if n_lines == 0:
        return "no_lines"
    if gated:
        return "gate"
    if rejected:
        return "pose_rejected"
    return "not_associated" if most_common == 0 else "one_line"


def _heading(history, n1, n2, prior, params):
    """Last step before odometry alone (our addition): Δφ from the common lines, (Δx, Δy) from ``prior``.

    The heading change as in the partial step (:func:`_common_heading`, needing ``H_min`` votes).
    """
    found = _common_heading(history, n1, n2, prior, params, params.H_min)
    return None if found is None else np.array([prior[0], prior[1], found[-1]])


def hough_slam(scans: Sequence[Scan], start_pose=(0.0, 0.0, 0.0), odometry=None,
               params: HoughSlamParams | None = None, *, progress: bool | None = None,
               lines: Sequence[Lines] | None = None, **overrides) -> HoughSlamResult:
    """Run Hough-transform SLAM over a sequence of scans (004 Fig. 2, Fig. 4).

    Parameters
    ----------
    scans : sequence of Scan
        :class:`~slamlab.scans.Scan` objects, all in one unit (cells or metres); the
        lengths of ``params`` are read in that unit.
    start_pose : (3,) array_like
        Pose of the first scan (004: given by correlation localisation).
    odometry : (n-1, 3) array_like, optional
        Body-frame increments between scans; used to predict lines for the association,
        for the gate and when a step is lost. Without it, zero motion is predicted.
    params : HoughSlamParams, optional
    progress : bool, optional
        A bar over the scans (None: on unless ``$SLAMLAB_PROGRESS=0``).
    lines : sequence of Lines, optional
        Each scan's lines from :func:`scan_lines` with the same detection settings (the
        detection is skipped; ours, for re-running the loop).
    **overrides
        Fields of :class:`HoughSlamParams` to change.

    Returns
    -------
    HoughSlamResult
    """
    params = HoughSlamParams.resolve(params, **overrides)
    scans = list(scans)
    if len(scans) == 0:
        raise ValueError("`scans` must hold at least one scan; got 0")
    units = {s.unit for s in scans if isinstance(s, Scan)}
    if len(units) > 1:
        raise ValueError(f"`scans` must all have one unit; got {sorted(units)}")
    returns = [_returns(s, f"scans[{k}]") for k, s in enumerate(scans)]
    n = len(scans)
    U = np.zeros((n - 1, 3)) if odometry is None else as_finite_array(odometry, "odometry", ndim=2)
    if U.shape != (n - 1, 3):
        raise ValueError(f"`odometry` must have shape ({n - 1}, 3) = one (dx, dy, dθ) per step; got {U.shape}")
    poses = np.zeros((n, 3))
    poses[0] = check_pose(start_pose, "start_pose")
    lost = np.zeros(n, dtype=bool)
    partial = np.zeros(n, dtype=bool)
    ref = np.full(n, -1, dtype=np.int64)
    n_lines = np.zeros(n, dtype=np.int64)
    cause = np.zeros(n, dtype=np.int64)
    history = LineHistory()
    keyframe = 0
    retry = _retry_params(params)
    found = None if lines is None else list(lines)
    if found is not None and (len(found) != n or not all(isinstance(x, Lines) for x in found)):
        raise ValueError(f"`lines` must hold one Lines per scan ({n}); got {len(found)} items")
    for k in progress_bar(range(n), desc="Hough SLAM", progress=progress):
        lines = _scan_lines(returns[k], params, retry) if found is None else found[k]
        n_lines[k] = len(lines)
        if k == 0:
            history.add_scan(lines, np.full(len(lines), -1))
            continue
        prev_ids, prev = history.scan(k - 1)
        pr, pt = transform_lines(prev.rho, prev.theta_rad, U[k - 1])
        P = association_probability(lines, Lines(pr, pt, prev.votes), a=params.a, b=params.b,
                                    a_theta_rad=params.a_theta_rad, parallel_tol_rad=params.parallel_tol_rad)
        match = associate_lines(P, p_min=params.p_min)
        ids = np.where(match >= 0, prev_ids[np.clip(match, 0, None)] if prev_ids.size else -1, -1)
        history.add_scan(lines, ids)
        guess = se2_compose(poses[k - 1], U[k - 1])
        pose = None
        most_common, rejected, gated = 0, False, False  # why no pose: for the cause code
        for n1 in dict.fromkeys((keyframe, k - 1)):
            delta, n_common = _relative(history, n1, k, params)
            most_common = max(most_common, n_common)
            if delta is None:
                rejected |= n_common >= 2
                continue
            cand = se2_compose(poses[n1], delta)
            if params.gate is not None and odometry is not None and (
                    math.hypot(*(cand[:2] - guess[:2])) > params.gate
                    or abs(float(wrap_angle(cand[2] - guess[2]))) > params.gate_theta_rad):
                gated = True
                continue
            pose, ref[k] = cand, n1
            break
        if pose is None and params.partial and odometry is not None:
            delta = _partial(history, k - 1, k, U[k - 1], params)
            if delta is not None:
                pose, ref[k], partial[k] = se2_compose(poses[k - 1], delta), k - 1, True
                cause[k] = _CODE["partial"]
        if pose is None and params.heading and odometry is not None:
            delta = _heading(history, k - 1, k, U[k - 1], params)
            if delta is not None:
                pose, ref[k], cause[k] = se2_compose(poses[k - 1], delta), k - 1, _CODE["heading"]
        if pose is None:
            pose, lost[k], ref[k] = guess, True, k - 1
            cause[k] = _CODE[_fallback_cause(returns[k][1].size, len(lines), most_common, rejected, gated,
                                             params.H_min)]
        poses[k] = pose
        _, n_common = _relative(history, keyframe, k, params) if ref[k] == keyframe else (None, 0)
        if lost[k] or ref[k] != keyframe or n_common < params.min_common:
            keyframe = k
    # headings unwrapped along the run, starting at the given start heading
    poses[:, 2] = np.unwrap(poses[:, 2]) + (poses[0, 2] - np.unwrap(poses[:, 2])[0])
    return HoughSlamResult(poses, lost, n_lines, ref, history, params, partial, cause)
