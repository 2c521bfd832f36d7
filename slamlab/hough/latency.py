"""How far a log's odometry runs ahead of its scans, measured from the lines (our addition, not in 004).

A log line pairs a scan with an odometry reading, but the scan may be older than the
reading (a rangefinder hands over its sweep after it ends; the logger reads the wheels
later). Hough SLAM predicts each scan's lines with the odometry increment and takes the
translation from odometry when the lines give none, so a scan paired with odometry a scan
period late gets the wrong prediction in every turn. The lag is measured without
odometry: the heading change between consecutive scans from their lines alone
(:func:`line_rotation_steps`) is compared with the odometry's heading changes shifted by
0, ¼, ½ … scan periods (:func:`odometry_lag`); :func:`retime_poses` then gives each scan the
odometry pose of its own time.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np

from .._validate import as_finite_array, check_positive, check_real
from .lines import Lines, line_difference
from .pose import weighted_median

__all__ = ["LAGS_SCANS", "line_rotation_steps", "odometry_lag", "retime_poses"]

#: Lags tried by :func:`odometry_lag` [scan periods] (ours): -1 to 3 in quarters.
LAGS_SCANS = np.arange(-4, 13) / 4.0


def line_rotation_steps(lines: Sequence[Lines], *, theta_window_rad: float = math.radians(10.0),
                        rho_window: float = 0.3) -> np.ndarray:
    """Heading change between consecutive scans from their lines alone, no odometry (ours).

    Each line of scan k is paired with the line of scan k-1 nearest in
    ``|Δθ|/theta_window_rad + |Δrho|/rho_window`` when that sum is below 1; the step's
    heading change is the vote-weighted median of ``θ_{k-1} - θ_k`` over the pairs.

    Parameters
    ----------
    lines : sequence of Lines
        Each scan's lines (:func:`~slamlab.hough.scan_lines`), at least two scans.
    theta_window_rad : float
        Largest heading change between two scans [rad].
    rho_window : float
        Largest change of a line's distance between two scans (the scans' unit).

    Returns
    -------
    numpy.ndarray, shape (n - 1,)
        Heading change of each step [rad]; NaN where no pair of lines was found.

    Examples
    --------
    >>> a = Lines(np.array([2.0, 3.0]), np.radians([0.0, 90.0]), np.array([50, 40]))
    >>> b = Lines(np.array([2.0, 3.0]), np.radians([-2.0, 88.0]), np.array([50, 40]))
    >>> np.degrees(line_rotation_steps([a, b])).round(6).tolist()
    [2.0]
    """
    lines = list(lines)
    if len(lines) < 2:
        raise ValueError(f"`lines` must hold at least two scans' lines; got {len(lines)}")
    for k, item in enumerate(lines):
        if not isinstance(item, Lines):
            raise TypeError(f"`lines[{k}]` must be Lines; got {type(item).__name__}")
    w_theta = check_positive(theta_window_rad, "theta_window_rad")
    w_rho = check_positive(rho_window, "rho_window")
    out = np.full(len(lines) - 1, np.nan)
    for k in range(1, len(lines)):
        old, new = lines[k - 1], lines[k]
        if len(old) == 0 or len(new) == 0:
            continue
        d_rho, d_theta = line_difference(new.rho[:, None], new.theta_rad[:, None], old.rho[None, :],
                                         old.theta_rad[None, :])
        cost = np.abs(d_theta) / w_theta + np.abs(d_rho) / w_rho
        j = cost.argmin(axis=1)
        rows = np.arange(len(new))
        ok = cost[rows, j] < 1.0
        if ok.any():
            votes = np.minimum(new.votes[ok], old.votes[j[ok]]).astype(float)
            out[k - 1] = -weighted_median(d_theta[rows, j][ok], votes)
    return out


def odometry_lag(rotation_steps_rad, odometry_poses, *, lags_scans=None) -> tuple[float, np.ndarray]:
    """Lag of a scan behind its odometry reading [scan periods] (ours): the best-matching shift.

    For each lag L the odometry's heading change of step k is read at k - L (linear
    interpolation between steps); the lag kept is the one with the smallest median
    ``|odometry - lines|`` over the steps the lines measured.

    Parameters
    ----------
    rotation_steps_rad : array_like, shape (n - 1,)
        Heading change per step from the lines (:func:`line_rotation_steps`; NaN: not measured).
    odometry_poses : array_like, shape (n, 3)
        The odometry pose paired with each scan ``(x, y, φ_rad)``.
    lags_scans : array_like, optional
        Lags to try (default :data:`LAGS_SCANS`).

    Returns
    -------
    lag_scans : float
        The best lag; positive: each scan was taken that many periods before its odometry reading.
    cost_rad : numpy.ndarray
        Median absolute difference per lag tried [rad].

    Examples
    --------
    >>> k = np.arange(40)
    >>> odo = np.column_stack([np.zeros(41), np.zeros(41), np.r_[0.0, np.cumsum(0.1 * np.sin(0.5 * k))]])
    >>> lines = 0.1 * np.sin(0.5 * (k - 1))  # the scans see each turn a step after the odometry
    >>> odometry_lag(lines, odo)[0]
    1.0
    """
    try:
        z = np.asarray(rotation_steps_rad, dtype=float)
    except (TypeError, ValueError) as err:
        raise TypeError(f"`rotation_steps_rad` must be an array of numbers; got {type(rotation_steps_rad).__name__}") \
            from err
    if z.ndim != 1 or np.isinf(z).any():
        raise ValueError(f"`rotation_steps_rad` must be 1-dimensional, finite or NaN; got shape {z.shape}")
    P = as_finite_array(odometry_poses, "odometry_poses", ndim=2)
    if P.shape != (z.size + 1, 3):
        raise ValueError(f"`odometry_poses` must have shape ({z.size + 1}, 3) = one pose per scan; got {P.shape}")
    lags = LAGS_SCANS if lags_scans is None else as_finite_array(lags_scans, "lags_scans", ndim=1)
    use = np.isfinite(z)
    if lags.size == 0 or not use.any():
        raise ValueError("`lags_scans` and the measured steps of `rotation_steps_rad` must not be empty")
    d_phi = np.diff(np.unwrap(P[:, 2]))
    k = np.arange(d_phi.size, dtype=float)
    cost = np.array([np.median(np.abs(np.interp(k - lag, k, d_phi)[use] - z[use])) for lag in lags])
    return float(lags[int(np.argmin(cost))]), cost


def retime_poses(poses, lag_scans: float) -> np.ndarray:
    """Each scan's pose read ``lag_scans`` periods earlier along the pose sequence (ours).

    ``out[k] = poses(k - lag)``, linear between neighbours (heading unwrapped), held at the
    first or last pose beyond the ends.

    Parameters
    ----------
    poses : array_like, shape (n, 3)
        ``(x, y, φ_rad)`` per scan.
    lag_scans : float
        Lag [scan periods] (:func:`odometry_lag`); 0 returns a copy.

    Returns
    -------
    numpy.ndarray, shape (n, 3)

    Examples
    --------
    >>> retime_poses([[0.0, 0, 0], [1.0, 0, 0], [2.0, 0, 0]], 0.5)[:, 0].tolist()
    [0.0, 0.5, 1.5]
    """
    P = as_finite_array(poses, "poses", ndim=2)
    if P.shape[1] != 3 or P.shape[0] < 1:
        raise ValueError(f"`poses` must have shape (n, 3); got {P.shape}")
    lag = check_real(lag_scans, "lag_scans")
    k = np.arange(P.shape[0], dtype=float)
    src = k - lag
    phi = np.unwrap(P[:, 2])
    return np.column_stack([np.interp(src, k, P[:, 0]), np.interp(src, k, P[:, 1]), np.interp(src, k, phi)])
