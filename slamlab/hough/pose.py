"""Pose change from lines seen in two scans (004 §Hough SLAM; formulas reconstructed).

A move (Δx, Δy) and a rotation Δφ of the sensor (scan j's pose in scan i's frame)
change every line as ``θ_j = θ_i - Δφ``, ``rho_j = rho_i - (Δx·cos θ_i + Δy·sin θ_i)``
(:func:`~slamlab.hough.transform_lines`). Two non-parallel lines give, with
``d_k = rho_{i,k} - rho_{j,k}`` and ``D = sin(θ_{i,2} - θ_{i,1})``::

    Δφ = θ_{i,1} - θ_{j,1}   (= θ_{i,2} - θ_{j,2}: the angle between the lines is unchanged)
    Δx = (d_1·sin θ_{i,2} - d_2·sin θ_{i,1}) / D
    Δy = (d_2·cos θ_{i,1} - d_1·cos θ_{i,2}) / D

θ must be in one continuous representation in both scans (see
:class:`~slamlab.hough.LineHistory`); otherwise (rho, θ) ≡ (-rho, θ ± π) adds π to Δφ.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .._validate import as_finite_array, check_choice, check_positive
from ..geometry import wrap_angle

__all__ = ["PoseChange", "pose_from_lines", "pose_from_two_lines", "select_line_pair", "weighted_median"]


@dataclass(frozen=True)
class PoseChange:
    """Scan j's pose ``(Δx, Δy, Δφ)`` in scan i's frame, and the lines it used.

    Attributes
    ----------
    pose : numpy.ndarray, shape (3,)
        ``(Δx, Δy, Δφ)`` (range unit, rad).
    ok : bool
        A pose was found.
    used : numpy.ndarray of int
        Indices of the lines used.
    angle_error_rad : float
        How much the angle between the two lines changed [rad].
    message : str
        Why no pose was found.
    """

    pose: np.ndarray
    ok: bool
    used: np.ndarray  # indices of the lines used
    angle_error_rad: float = 0.0  # how much the angle between the two lines changed
    message: str = ""


def _pair(line_i, line_j, name):
    arr = as_finite_array(line_i, f"{name}_i")
    arr2 = as_finite_array(line_j, f"{name}_j")
    if arr.shape != (2,) or arr2.shape != (2,):
        raise ValueError(f"`{name}_i` and `{name}_j` must be (rho, θ) pairs; got shapes {arr.shape} and {arr2.shape}")
    return arr, arr2


def pose_from_two_lines(line_i1, line_i2, line_j1, line_j2, *, angle_tol_rad: float = math.radians(2.0),
                        min_angle_rad: float = math.radians(20.0)) -> np.ndarray:
    """``(Δx, Δy, Δφ)`` of scan j in scan i's frame from two non-parallel lines (004, reconstructed).

    Parameters
    ----------
    line_i1, line_i2 : (2,) array_like
        ``(rho, θ)`` of lines 1 and 2 in scan i.
    line_j1, line_j2 : (2,) array_like
        The same two lines in scan j, in the same continuous representation.
    angle_tol_rad : float
        Largest allowed change of the angle between the lines (004: "check that the angle
        between them did not change").
    min_angle_rad : float
        Smallest angle between the lines (our choice: near-parallel lines make D ≈ 0).

    Returns
    -------
    numpy.ndarray, shape (3,)
        ``(Δx, Δy, Δφ)`` of scan j in scan i's frame.

    Examples
    --------
    >>> from slamlab.hough import transform_lines
    >>> li = np.array([[5.0, 0.2], [3.0, 1.9]])
    >>> rj, tj = transform_lines(li[:, 0], li[:, 1], (0.7, -0.4, 0.15))
    >>> pose_from_two_lines(li[0], li[1], (rj[0], tj[0]), (rj[1], tj[1])).round(12).tolist()
    [0.7, -0.4, 0.15]
    """
    (r_i1, t_i1), (r_j1, t_j1) = _pair(line_i1, line_j1, "line_1")
    (r_i2, t_i2), (r_j2, t_j2) = _pair(line_i2, line_j2, "line_2")
    tol = check_positive(angle_tol_rad, "angle_tol_rad", allow_zero=True)
    min_angle = check_positive(min_angle_rad, "min_angle_rad", allow_zero=True)
    return _pose_from_two_lines(r_i1, t_i1, r_i2, t_i2, r_j1, t_j1, r_j2, t_j2, tol, min_angle)


def _pose_from_two_lines(r_i1, t_i1, r_i2, t_i2, r_j1, t_j1, r_j2, t_j2, tol, min_angle) -> np.ndarray:
    """:func:`pose_from_two_lines` on checked numbers (the geometric conditions are still checked)."""
    D = math.sin(t_i2 - t_i1)
    if abs(D) < math.sin(min_angle) or abs(D) == 0.0:
        raise ValueError(f"the two lines must be at least {math.degrees(min_angle):.1f} degrees apart; "
                         f"got {math.degrees(math.asin(min(1.0, abs(D)))):.2f} degrees")
    change = float(wrap_angle((t_i2 - t_i1) - (t_j2 - t_j1)))
    if abs(change) > tol:
        raise ValueError(f"the angle between the lines must not change by more than "
                         f"{math.degrees(tol):.2f} degrees; got {math.degrees(change):.2f} degrees")
    dphi = t_i1 - t_j1
    d1, d2 = r_i1 - r_j1, r_i2 - r_j2
    dx = (d1 * math.sin(t_i2) - d2 * math.sin(t_i1)) / D
    dy = (d2 * math.cos(t_i1) - d1 * math.cos(t_i2)) / D
    return np.array([dx, dy, dphi])


def select_line_pair(theta_i_rad, theta_j_rad, votes=None, *, angle_tol_rad: float = math.radians(2.0),
                     min_angle_rad: float = math.radians(20.0)) -> tuple[int, int] | None:
    """The pair of common lines to use (our rule: 004 says "choose a non-parallel pair").

    Among the pairs whose angle did not change (within ``angle_tol_rad``) and is at least
    ``min_angle_rad``, take the one maximising ``|sin(angle)|·sqrt(votes_1·votes_2)``.
    Returns ``None`` when no pair qualifies.

    Parameters
    ----------
    theta_i_rad, theta_j_rad : array_like, shape (L,)
        θ of the common lines in scans i and j [rad], paired by index.
    votes : array_like, shape (L,), optional
        Weight of each line (default 1).
    angle_tol_rad : float, default 2°
        Largest change of the pair's angle [rad].
    min_angle_rad : float, default 20°
        Smallest angle between the two lines [rad].

    Returns
    -------
    tuple of int or None
        Indices of the two lines.

    Examples
    --------
    >>> select_line_pair([0.0, 0.1, 1.6], [0.0, 0.1, 1.6], [50, 80, 40])
    (1, 2)
    """
    ti = as_finite_array(theta_i_rad, "theta_i_rad", ndim=1)
    tj = as_finite_array(theta_j_rad, "theta_j_rad", ndim=1)
    if ti.shape != tj.shape:
        raise ValueError(f"`theta_i_rad` and `theta_j_rad` must have the same length; got {ti.size} and {tj.size}")
    w = np.ones_like(ti) if votes is None else as_finite_array(votes, "votes", ndim=1)
    if w.shape != ti.shape:
        raise ValueError(f"`votes` must have one entry per line ({ti.size}); got {w.size}")
    return _select_line_pair(ti, tj, w, angle_tol_rad, min_angle_rad)


def _select_line_pair(ti, tj, w, angle_tol_rad, min_angle_rad) -> tuple[int, int] | None:
    """:func:`select_line_pair` on checked arrays."""
    if ti.size < 2:
        return None
    s = np.abs(np.sin(ti[None, :] - ti[:, None]))
    change = np.abs(wrap_angle((ti[None, :] - ti[:, None]) - (tj[None, :] - tj[:, None])))
    score = s * np.sqrt(np.outer(w, w))
    ok = (s >= math.sin(min_angle_rad)) & (change <= angle_tol_rad) & np.triu(np.ones_like(s, dtype=bool), 1)
    if not ok.any():
        return None
    score = np.where(ok, score, -1.0)
    a, b = np.unravel_index(int(np.argmax(score)), score.shape)
    return int(a), int(b)


def weighted_median(x, weights) -> float:
    """Weighted median: the first value of sorted ``x`` at which the cumulative weight reaches half the total (ours).

    The robust centre of the per-line heading changes ``θ_i − θ_j`` (weights: votes) in :func:`pose_from_lines`
    and in Hough SLAM's partial and heading steps.

    Parameters
    ----------
    x : array_like, shape (L,)
        Values (e.g. heading changes θ_i − θ_j [rad]), at least one.
    weights : array_like, shape (L,)
        Their weights (e.g. votes), >= 0 with a positive sum.

    Returns
    -------
    float
        The weighted median (one of the values of ``x``).

    Examples
    --------
    >>> weighted_median([0.3, 0.1, 0.2], [1.0, 1.0, 5.0])
    0.2
    """
    x = as_finite_array(x, "x", ndim=1)
    w = as_finite_array(weights, "weights", ndim=1)
    if w.shape != x.shape or x.size == 0:
        raise ValueError(f"`x` and `weights` must have one non-zero length; got {x.size} and {w.size}")
    if np.any(w < 0) or not w.sum() > 0:
        raise ValueError("`weights` must be >= 0 with a positive sum")
    order = np.argsort(x)
    cw = np.cumsum(w[order])
    return float(x[order][np.searchsorted(cw, 0.5 * cw[-1])])


def pose_from_lines(rho_i, theta_i_rad, rho_j, theta_j_rad, votes=None, *, method: str = "two_lines",
                    angle_tol_rad: float = math.radians(2.0), min_angle_rad: float = math.radians(20.0),
                    rho_tol: float | None = None) -> PoseChange:
    """Pose change from the lines common to scans i and j (004 §Hough SLAM).

    ``method="two_lines"`` is 004's: one pair chosen by :func:`select_line_pair`, then
    :func:`pose_from_two_lines`. ``method="least_squares"`` (our addition) uses every line
    that agrees: Δφ is the vote-weighted median of ``θ_i - θ_j``, the lines within
    ``angle_tol_rad`` of it are kept, and (Δx, Δy) solves ``cos θ_i·Δx + sin θ_i·Δy =
    rho_i - rho_j`` by weighted least squares, dropping lines whose residual exceeds
    ``rho_tol`` and solving again (lines on round objects or through corners move in
    ways a rigid motion cannot explain).

    Parameters
    ----------
    rho_i, theta_i_rad : array_like, shape (L,)
        Common lines in scan i (range unit, rad).
    rho_j, theta_j_rad : array_like, shape (L,)
        The same lines in scan j.
    votes : array_like, shape (L,), optional
        Weights (default 1).
    method : {"two_lines", "least_squares"}
        004's pair or our weighted least squares.
    angle_tol_rad : float, default 2°
        Angle tolerance [rad] (pair selection, or agreement with the median Δφ).
    min_angle_rad : float, default 20°
        Smallest angle of the pair [rad] (``two_lines``).
    rho_tol : float, optional
        Residual above which a line is dropped (``least_squares``; None keeps all).

    Returns
    -------
    PoseChange
        ``ok`` is False (with ``message``) when no usable pair exists.

    Examples
    --------
    >>> from slamlab.hough import transform_lines
    >>> ri, ti = np.array([5.0, 3.0, -2.0]), np.array([0.2, 1.9, 0.25])
    >>> rj, tj = transform_lines(ri, ti, (0.7, -0.4, 0.15))
    >>> pc = pose_from_lines(ri, ti, rj, tj, method="least_squares")
    >>> pc.ok, pc.pose.round(12).tolist()
    (True, [0.7, -0.4, 0.15])
    """
    ri = as_finite_array(rho_i, "rho_i", ndim=1)
    ti = as_finite_array(theta_i_rad, "theta_i_rad", ndim=1)
    rj = as_finite_array(rho_j, "rho_j", ndim=1)
    tj = as_finite_array(theta_j_rad, "theta_j_rad", ndim=1)
    if not (ri.shape == ti.shape == rj.shape == tj.shape):
        raise ValueError(f"`rho_i`, `theta_i_rad`, `rho_j`, `theta_j_rad` must have one length; got "
                         f"{ri.size}, {ti.size}, {rj.size}, {tj.size}")
    method = check_choice(method, "method", ("two_lines", "least_squares"))
    tol = check_positive(angle_tol_rad, "angle_tol_rad", allow_zero=True)
    rho_tol = np.inf if rho_tol is None else check_positive(rho_tol, "rho_tol")
    w = np.ones_like(ri) if votes is None else as_finite_array(votes, "votes", ndim=1)
    if w.shape != ri.shape:
        raise ValueError(f"`votes` must have one entry per line ({ri.size}); got {w.size}")
    fail = PoseChange(np.full(3, np.nan), False, np.empty(0, dtype=np.int64),
                      message=f"no pair of non-parallel lines with an unchanged angle among {ri.size}")
    if method == "two_lines":
        pair = _select_line_pair(ti, tj, w, tol, min_angle_rad)
        if pair is None:
            return fail
        a, b = pair
        change = float(wrap_angle((ti[b] - ti[a]) - (tj[b] - tj[a])))
        pose = _pose_from_two_lines(ri[a], ti[a], ri[b], ti[b], rj[a], tj[a], rj[b], tj[b], tol, min_angle_rad)
        return PoseChange(pose, True, np.array([a, b]), change)
    if ri.size < 2:
        return fail
    dphi_all = ti - tj
    ref = weighted_median(dphi_all, w)
    use = np.flatnonzero(np.abs(wrap_angle(dphi_all - ref)) <= tol)
    for _ in range(4):
        if _select_line_pair(ti[use], tj[use], w[use], 2 * tol + 1e-12, min_angle_rad) is None:
            return fail
        ww = w[use]
        dphi = ref + float(np.sum(ww * wrap_angle(dphi_all[use] - ref)) / ww.sum())
        A = np.column_stack([np.cos(ti[use]), np.sin(ti[use])])
        d = ri[use] - rj[use]
        t, *_ = np.linalg.lstsq(A * np.sqrt(ww)[:, None], d * np.sqrt(ww), rcond=None)
        resid = np.abs(A @ t - d)
        if resid.max() <= rho_tol:
            break
        use = use[resid <= max(rho_tol, float(np.median(resid)))]
    else:
        return fail
    change = float(np.ptp(wrap_angle(dphi_all[use] - dphi)))
    return PoseChange(np.array([t[0], t[1], dphi]), True, use, change)
