"""Scoring a monocular run against ground truth (003 §5.2 and ours): which frames are *correctly* tracked.

003 §5.2 measures the ATE after an SVD alignment; 003 §5.5.1 marks a run by the share of the
time it tracked the robot. A tracker's own "not lost" is not the same as a right pose, so
(ours) a frame counts as **correctly tracked** only when the tracker claims it *and* its
position, after the run's one Sim(3) alignment, is within ``tol_frac`` of the path length of
the truth (the fit that puts most claimed frames within tolerance among fits to all of them and to each
half and third, refitted on those frames: a few gross errors do not condemn the rest). The ATE (plain Sim(3) fit on the claimed frames, as evo) is taken over **all** frames: a frame the tracker did not track counts with
the pose the tracker reports for it (the last tracked pose; before the initialisation, the
first keyframe's). Scale drift: a Sim(3) fitted to the first and to the last third of the
claimed frames separately gives the metres per map unit of each; their ratio is the drift.
Every scale here is supplied by the ground truth (a monocular map has none of its own).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from .._validate import as_finite_array, check_positive

__all__ = ["RunScore", "score_run", "sim3_fit"]

#: default tolerance of a correctly tracked frame: position error ≤ 5 % of the path (ours)
TRACK_TOL_FRAC = 0.05


def sim3_fit(est_xyz, ref_xyz):
    """``(c, R, t)`` of the Sim(3) mapping ``est_xyz`` onto ``ref_xyz`` (Umeyama), or None when degenerate.

    Degenerate: fewer than 3 positions, or the estimate (or the truth) does not move.

    Parameters
    ----------
    est_xyz : array_like, shape (N, 3)
        Estimated positions (map units).
    ref_xyz : array_like, shape (N, 3)
        True positions [m].

    Returns
    -------
    tuple or None
        ``(c, R, t)``: scale [m per map unit], rotation (3, 3), translation (3,) [m]; ``None`` when degenerate.
    """
    from ..geometry.registration import umeyama

    est_xyz = np.asarray(est_xyz, dtype=np.float64).reshape(-1, 3)
    ref_xyz = np.asarray(ref_xyz, dtype=np.float64).reshape(-1, 3)
    if est_xyz.shape[0] < 3:
        return None
    spread = lambda P: float(np.sqrt(np.mean(np.sum((P - P.mean(axis=0)) ** 2, axis=1))))
    if spread(est_xyz) < 1e-9 or spread(ref_xyz) < 1e-9:
        return None
    S = umeyama(est_xyz, ref_xyz, with_scale=True)
    return float(S.c), S.R, S.t


def _apply(S, P):
    c, R, t = S
    return c * np.einsum("ij,nj->ni", R, P) + t


@dataclass(frozen=True)
class RunScore:
    """Per-frame position errors and the summary figures of one run (see the module docstring).

    ``pos_err_m`` (N,) error of every frame after the run's Sim(3) fitted on the claimed frames
    (``inf`` everywhere when fewer than 3 frames are claimed); ``claimed`` (N,) the tracker's own
    flags; ``correct`` (N,) claimed and ``pos_err_m <= tol_m``; ``tol_m = tol_frac × path_m``.

    Attributes
    ----------
    pos_err_m : ndarray, shape (N,)
        Position error of every frame after the Sim(3) fit [m].
    claimed : ndarray of bool, shape (N,)
        The tracker's own "tracking" flags.
    correct : ndarray of bool, shape (N,)
        Claimed and within ``tol_m`` of the truth.
    tol_frac : float
        Tolerance as a fraction of the path length.
    tol_m : float
        ``tol_frac × path_m`` [m].
    path_m : float
        Length of the true path [m].
    ate_all_m, ate_claimed_m : float
        RMS position error over every frame and over the claimed frames [m].
    scale_first, scale_last : float
        Metres per map unit fitted on the first and last third of the claimed frames.
    """

    pos_err_m: np.ndarray = field(repr=False)
    claimed: np.ndarray = field(repr=False)
    correct: np.ndarray = field(repr=False)
    tol_frac: float
    tol_m: float
    path_m: float
    ate_all_m: float
    ate_claimed_m: float
    scale_first: float
    scale_last: float

    @property
    def scale_drift(self) -> float:
        """Metres per map unit of the last third over that of the first (1 = no drift)."""
        return self.scale_last / self.scale_first if np.isfinite(self.scale_first) and self.scale_first > 0 else float("nan")


def score_run(truth, estimate, claimed, *, tol_frac: float = TRACK_TOL_FRAC, refits: int = 3) -> RunScore:
    """Score a run: correctly tracked frames, ATE over all frames and over the claimed ones, scale drift.

    Parameters
    ----------
    truth, estimate : (N, 4, 4) camera-to-world poses (the truth in metres, the estimate in map units).
    claimed : (N,) bool, the frames the tracker reports as tracked.
    tol_frac : a claimed frame is correct when its position error after the Sim(3) is at most
        ``tol_frac`` times the path length of ``truth`` (ours; default 5 %).
    refits : rounds of refitting the Sim(3) on the claimed frames found within tolerance before the
        correct frames are decided (0: the plain fit to all claimed frames); the start is the best of
        the fits to all claimed frames, to each half and to each third of them. The ATEs use the plain fit on the claimed
        frames (as ``evo_ape -as``), so that they compare with other tools.
    """
    truth = as_finite_array(truth, "truth", ndim=3)
    estimate = as_finite_array(estimate, "estimate", ndim=3)
    if truth.shape != estimate.shape or truth.shape[1:] != (4, 4):
        raise ValueError(f"`truth` and `estimate` must both have shape (N, 4, 4); got {truth.shape} and {estimate.shape}")
    claimed = np.asarray(claimed, dtype=bool).reshape(-1)
    if claimed.shape[0] != truth.shape[0]:
        raise ValueError(f"`claimed` must have one flag per frame ({truth.shape[0]}); got {claimed.shape[0]}")
    tol_frac = check_positive(tol_frac, "tol_frac")
    P_ref, P_est = truth[:, :3, 3], estimate[:, :3, 3]
    path_m = float(np.sum(np.linalg.norm(np.diff(P_ref, axis=0), axis=1))) if len(P_ref) > 1 else 0.0
    tol_m = tol_frac * path_m
    idx = np.flatnonzero(claimed)
    S = sim3_fit(P_est[idx], P_ref[idx])
    n = truth.shape[0]
    err = np.full(n, np.inf) if S is None else np.linalg.norm(_apply(S, P_est) - P_ref, axis=1)
    # which frames are right (ours): the Sim(3) that puts the most claimed frames within tolerance among
    # the fits to all claimed frames, to each half and to each third of them in time order, refitted on
    # its frames within tolerance until the set is stable (at most `refits` rounds), so that a few gross
    # errors (a wrong re-initialisation, a kidnap) do not condemn the rest
    good = claimed & (err <= tol_m)
    if refits and good.sum() < claimed.sum() and idx.size >= 6:
        for part in (*np.array_split(idx, 2), *np.array_split(idx, 3)):
            Sp = sim3_fit(P_est[part], P_ref[part])
            if Sp is not None:
                cand = claimed & (np.linalg.norm(_apply(Sp, P_est) - P_ref, axis=1) <= tol_m)
                if cand.sum() > good.sum():
                    good = cand
    for _ in range(refits):
        if good.sum() < 3 or good.sum() == claimed.sum():
            break
        Sg = sim3_fit(P_est[good], P_ref[good])
        if Sg is None:
            break
        new_good = claimed & (np.linalg.norm(_apply(Sg, P_est) - P_ref, axis=1) <= tol_m)
        if np.array_equal(new_good, good):
            break
        good = new_good
    correct = good
    rmse = lambda e: float(np.sqrt(np.mean(e * e))) if e.size else float("inf")
    ate_all = rmse(err)
    ate_claimed = rmse(err[idx]) if S is not None else float("inf")
    scales = []
    for part in (np.array_split(idx, 3)[0], np.array_split(idx, 3)[-1]) if idx.size >= 9 else ():
        Sp = sim3_fit(P_est[part], P_ref[part])
        scales.append(Sp[0] if Sp is not None else float("nan"))
    s_first, s_last = (scales if scales else [float("nan"), float("nan")])
    return RunScore(err, claimed, correct, tol_frac, tol_m, path_m, ate_all, ate_claimed, s_first, s_last)
