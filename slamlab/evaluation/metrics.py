"""Absolute and relative trajectory errors (ATE, RPE) with evo's conventions (003 §5.2; our addition).

**Which one to use.** ATE (absolute trajectory error) answers "how far is the
estimated path from the true one, overall?": align the estimate to the ground
truth once, then take the RMSE of the position differences. It mixes early and
late errors (one early heading error bends everything after it). RPE (relative
pose error) answers "how much does the estimate drift over a given stretch?":
compare the motion between poses ``i`` and ``i + delta`` in both trajectories;
no global alignment is needed, except a scale for monocular systems.

**Which alignment.** Ground truth and estimate live in different world frames,
so ATE needs an alignment first: ``"se3"`` (rotation + translation, Umeyama)
for stereo, RGB-D, lidar and odometry; ``"sim3"`` (plus a scale) for monocular
systems whose scale is unknown (003 §5.2 aligns by SVD); ``"none"`` when both
already share a frame (e.g. a simulator's ground truth).

The numbers equal those of the ``evo`` package (``evo_ape`` / ``evo_rpe`` with
``-a`` / ``-as``, translation part, consecutive pairs); the tests check it.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .._table import format_table
from .._validate import check_choice, check_int, check_positive
from ..geometry import rotation_angle, se3_inverse, umeyama
from .trajectory import Trajectory

__all__ = ["ErrorStats", "align_trajectory", "associate", "ate", "rpe"]

ALIGNMENTS = ("se3", "sim3", "none")


@dataclass(frozen=True)
class ErrorStats:
    """Statistics of a per-pose error vector, as evo reports them.

    Attributes
    ----------
    rmse, mean, median, std, min, max : float
        Statistics of the per-pose errors, in ``unit``.
    sse : float
        Sum of squared errors.
    n : int
        Number of errors (poses or pose pairs).
    unit : str
        ``"m"`` or ``"deg"``.
    errors : ndarray, shape (n,)
        The per-pose errors themselves.
    """

    rmse: float
    mean: float
    median: float
    std: float
    min: float
    max: float
    sse: float
    n: int
    unit: str = "m"
    errors: np.ndarray = None

    @classmethod
    def from_errors(cls, errors, unit: str = "m") -> ErrorStats:
        """Statistics of per-pose errors.

        Parameters
        ----------
        errors : array_like of float
            One error per pose pair (non-empty).
        unit : str
            Unit of the errors, for the tables ("m", "deg", "%").

        Returns
        -------
        ErrorStats
        """
        e = np.asarray(errors, dtype=float)
        if e.size == 0:
            raise ValueError("no pose pairs to evaluate (trajectory too short for this delta?)")
        return cls(float(np.sqrt(np.mean(e**2))), float(np.mean(e)), float(np.median(e)), float(np.std(e)),
                   float(np.min(e)), float(np.max(e)), float(np.sum(e**2)), int(e.size), unit, e)

    def __str__(self) -> str:
        return f"RMSE {self.rmse:.4f} {self.unit} over {self.n} poses (mean {self.mean:.4f}, max {self.max:.4f})"

    def table(self) -> str:
        rows = [[k, f"{getattr(self, k):.4f}"] for k in ("rmse", "mean", "median", "std", "min", "max")]
        rows.append(["n", str(self.n)])
        return format_table(["statistic", f"value [{self.unit}]"], rows)


def associate(ref: Trajectory, est: Trajectory, max_diff_s: float = 0.01):
    """Pair poses by nearest timestamp within ``max_diff_s`` (evo's ``associate_trajectories``).

    As evo does, the shorter trajectory is matched against the longer one, so
    none of its poses is used twice. Trajectories without timestamps are paired
    by frame number when one lists ``frame_ids`` (the other then holds every
    frame from 0), otherwise by index (equal length). Returns ``(ref_sub, est_sub)``.

    Parameters
    ----------
    ref, est : Trajectory
        Reference (ground truth) and estimated trajectories.
    max_diff_s : float
        Largest timestamp difference of a pair [s] (default 0.01).

    Returns
    -------
    ref_sub, est_sub : Trajectory
        The paired poses, equal length, in pair order.
    """
    if ref.timestamps_s is None or est.timestamps_s is None:
        for a, b, swap in ((ref, est, False), (est, ref, True)):
            if b.frame_ids is not None and a.frame_ids is None:
                if b.frame_ids.max() >= len(a):
                    raise ValueError(f"frame index {int(b.frame_ids.max())} is beyond the {len(a)} poses it "
                                     "must be paired with")
                a_sub = a.subset(b.frame_ids)
                return (b, a_sub) if swap else (a_sub, b)
        if len(ref) != len(est):
            raise ValueError(f"trajectories without timestamps must have equal length; got {len(ref)} and {len(est)}")
        return ref, est
    max_diff_s = check_positive(max_diff_s, "max_diff_s", allow_zero=True)
    est_longer = len(est) > len(ref)
    short, long_ = (ref, est) if est_longer else (est, ref)
    s1, s2 = short.timestamps_s, long_.timestamps_s
    if np.any(np.diff(s2) < 0):
        raise ValueError("timestamps must be sorted in increasing order")
    j = np.clip(np.searchsorted(s2, s1, side="right"), 0, len(s2) - 1)
    diff_ub = s2[j] - s1
    diff_lb = np.where(j > 0, s1 - s2[np.maximum(j - 1, 0)], np.inf)
    in_range = (s1 >= s2[0] - max_diff_s) & (s1 <= s2[-1] + max_diff_s)
    take_ub = (diff_ub <= max_diff_s) & (diff_ub < diff_lb)
    take_lb = ~take_ub & (diff_lb <= max_diff_s) & (diff_lb <= diff_ub)
    ok = in_range & (take_ub | take_lb)
    i_short = np.nonzero(ok)[0]
    i_long = np.where(take_ub, j, j - 1)[ok]
    if i_short.size == 0:
        raise ValueError(f"no matching timestamps within max_diff_s = {max_diff_s} s")
    a, b = short.subset(i_short), long_.subset(i_long)
    return (a, b) if est_longer else (b, a)


def align_trajectory(est: Trajectory, ref: Trajectory, method: str = "se3"):
    """Align ``est`` to ``ref`` (associated, equal length) by Umeyama on positions.

    Returns ``(aligned_est, transform)``; the transform is applied to the
    whole pose (``R`` to the rotations, scale to the positions).

    Parameters
    ----------
    est : Trajectory
        Estimated trajectory, associated with ``ref``.
    ref : Trajectory
        Reference trajectory of the same length.
    method : str
        ``"se3"`` (rotation and translation), ``"sim3"`` (also scale) or ``"none"`` (default ``"se3"``).

    Returns
    -------
    aligned_est : Trajectory
        ``est`` mapped onto ``ref``.
    transform : RigidTransform or None
        ``R``, ``t``, ``c`` of the alignment; ``None`` for ``method="none"``.
    """
    check_choice(method, "method", ALIGNMENTS)
    if len(est) != len(ref):
        raise ValueError(f"`est` and `ref` must be associated first; lengths {len(est)} and {len(ref)}")
    if method == "none":
        return est, None
    T = umeyama(est.positions_m, ref.positions_m, with_scale=(method == "sim3"))
    pos = T.c * est.positions_m @ T.R.T + T.t
    rot = T.R @ est.rotations
    return Trajectory(pos, rot, est.timestamps_s, est.name), T


def ate(ref: Trajectory, est: Trajectory, *, align: str = "se3", max_diff_s: float = 0.01) -> ErrorStats:
    """Absolute trajectory error: RMSE (and more) of position differences after alignment.

    Associates by timestamp (``max_diff_s``), aligns ``est`` to ``ref``
    (``"se3"``, ``"sim3"`` or ``"none"``) and measures ``|p_est - p_ref|`` per pose,
    in metres. Equal to ``evo_ape ... -a`` (``-as`` for ``"sim3"``).

    Parameters
    ----------
    ref, est : Trajectory
        Reference (ground truth) and estimated trajectories.
    align : str
        ``"se3"``, ``"sim3"`` or ``"none"`` (default ``"se3"``).
    max_diff_s : float
        Largest timestamp difference when pairing poses [s] (default 0.01).

    Returns
    -------
    ErrorStats
        ``rmse``, ``mean``, ``max``, ... of the position errors [m], ``errors`` per pose.
    """
    check_choice(align, "align", ALIGNMENTS)
    r, e = associate(ref, est, max_diff_s)
    e, _ = align_trajectory(e, r, align)
    return ErrorStats.from_errors(np.linalg.norm(e.positions_m - r.positions_m, axis=1), "m")


def _pairs(traj: Trajectory, delta, delta_unit: str, all_pairs: bool):
    n = len(traj)
    if delta_unit == "frames":
        d = check_int(delta, "delta", minimum=1)
        if all_pairs:
            i = np.arange(0, n - d)
            return i, i + d
        ids = np.arange(0, n, d)
        return ids[:-1], ids[1:]
    d = check_positive(delta, "delta")
    if all_pairs:
        raise ValueError("`all_pairs` is only supported with `delta_unit='frames'`")
    # consecutive pairs whose travelled path reaches delta metres (evo's filter_pairs_by_path)
    step = np.linalg.norm(np.diff(traj.positions_m, axis=0), axis=1)
    ids, acc = [0], 0.0
    for k, s in enumerate(step, start=1):  # one pass over poses: cheap, and evo's exact accumulation
        acc += float(s)
        if acc >= d:
            ids.append(k)
            acc = 0.0
    ids = np.asarray(ids)
    return ids[:-1], ids[1:]


def rpe(ref: Trajectory, est: Trajectory, *, delta=1, delta_unit: str = "frames", relation: str = "translation",
        align: str = "none", all_pairs: bool = False, pairs_from: str = "estimate",
        max_diff_s: float = 0.01) -> ErrorStats:
    """Relative pose error over pose pairs ``(i, j)`` a ``delta`` apart (frames, or metres of travel).

    The error of a pair is ``E = (Q_i^-1 Q_j)^-1 (P_i^-1 P_j)`` (``Q`` ground truth,
    ``P`` estimate); ``relation="translation"`` reports ``|t(E)|`` in metres,
    ``"rotation_deg"`` the rotation angle of ``E`` in degrees. Pairs are
    consecutive (``0-d, d-2d, …``) unless ``all_pairs``. With ``delta_unit="m"``
    the pairs follow the travelled path of ``pairs_from``: evo's default is the
    *estimate* (``"estimate"``); ``"reference"`` (evo's ``--pairs_from_reference``)
    makes the pairs independent of the estimate, which is fairer when comparing
    systems. Equal to ``evo_rpe ... --delta d --delta_unit f|m`` (``-as`` with
    ``align="sim3"``).

    Parameters
    ----------
    ref, est : Trajectory
        Reference (ground truth) and estimated trajectories.
    delta : int or float
        Pair spacing, in frames or metres of travel (default 1).
    delta_unit : str
        ``"frames"`` or ``"m"`` (default ``"frames"``).
    relation : str
        ``"translation"`` (error in metres) or ``"rotation_deg"`` (degrees).
    align : str
        ``"se3"``, ``"sim3"`` or ``"none"`` (default ``"none"``).
    all_pairs : bool
        Use every pair ``delta`` apart, not only consecutive ones (default False).
    pairs_from : str
        ``"estimate"`` or ``"reference"``: whose travelled path defines the pairs for ``delta_unit="m"``.
    max_diff_s : float
        Largest timestamp difference when pairing poses [s] (default 0.01).

    Returns
    -------
    ErrorStats
        Statistics of the per-pair errors, ``unit`` ``"m"`` or ``"deg"``.
    """
    check_choice(delta_unit, "delta_unit", ("frames", "m"))
    check_choice(relation, "relation", ("translation", "rotation_deg"))
    check_choice(align, "align", ALIGNMENTS)
    check_choice(pairs_from, "pairs_from", ("estimate", "reference"))
    r, e = associate(ref, est, max_diff_s)
    e, _ = align_trajectory(e, r, align)
    i, j = _pairs(e if pairs_from == "estimate" else r, delta, delta_unit, all_pairs)
    if i.size == 0:
        raise ValueError("no pose pairs to evaluate (trajectory too short for this delta?)")
    Q, P = r.poses, e.poses
    Q_rel = se3_inverse(Q[i]) @ Q[j]
    P_rel = se3_inverse(P[i]) @ P[j]
    E = se3_inverse(Q_rel) @ P_rel
    if relation == "translation":
        return ErrorStats.from_errors(np.linalg.norm(E[:, :3, 3], axis=1), "m")
    # the angle of the rotation nearest to E's (SVD): rotations read from files are orthonormal to their ~9 digits
    # only, where the angle depends on how the matrix is taken onto SO(3); evo (scipy) projects the same way
    U, _, Vt = np.linalg.svd(E[:, :3, :3])
    return ErrorStats.from_errors(np.rad2deg(rotation_angle(U @ Vt)), "deg")
