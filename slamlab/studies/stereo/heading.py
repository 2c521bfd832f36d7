"""Which frames of a run carry its heading error, and what the pipeline did on them (issue 25; 000 §4.2's run).

:func:`heading_frames` lists every frame whose heading error exceeds a bound with the true and
estimated motion of its step and the pipeline's record of that frame (matches, inliers, the
rotation standard deviation of the last pose tried against ``max_rot_std_rad``, the searches
tried, in order), and how the error evolves after it.
"""

from __future__ import annotations

import numpy as np

from ..._table import format_table
from ..._validate import as_finite_array, check_positive
from ...geometry import wrap_angle

__all__ = ["heading_frames"]


def heading_frames(slam, truth, min_deg: float = 5.0) -> str:
    """Table of the frames whose heading error exceeds ``min_deg`` and what the pipeline did (issue 25, 000 §4.2).

    Per frame: the true step (distance, turn) and the estimated turn, the heading and position
    errors, the frame's status, map matches, RANSAC inliers, the largest rotation standard
    deviation of the last pose tried (``max_rot_std_rad`` rejects above it; "-" when no pose was
    tried), and the searches tried in order ("last": the last frame's landmarks, "window": the
    window search, "global": the whole store; each with its matches and outcome). The last
    column says when the error fell below ``min_deg`` again; that frame is listed too (marked
    "recovered"), to show by which search it found its pose.

    Parameters
    ----------
    slam : StereoSLAM
        A run (its ``records`` and ``planar_trajectory``).
    truth : array_like, shape (N, 3)
        True ``(x_m, y_m, yaw_rad)`` of each processed frame in the map frame (yaw unwrapped).
    min_deg : float, default 5.0
        Heading error above which a frame is listed [deg].

    Returns
    -------
    str
        The table (one row per listed frame; a line saying none when there is none).
    """
    est = slam.planar_trajectory
    truth = as_finite_array(truth, "truth", ndim=2)
    if truth.shape != est.shape:
        raise ValueError(f"`truth` must have shape {est.shape} (one (x, y, yaw) per processed frame); got {truth.shape}")
    min_deg = check_positive(min_deg, "min_deg")
    yaw = np.rad2deg(np.asarray(wrap_angle(est[:, 2] - truth[:, 2])))
    pos = np.hypot(*(est[:, :2] - truth[:, :2]).T)
    big = np.abs(yaw) > min_deg
    if not big.any():
        return f"no frame with a heading error above {min_deg:g} deg (max {np.abs(yaw).max():.1f} deg)"
    d_true = np.r_[0.0, np.hypot(*np.diff(truth[:, :2], axis=0).T)]
    turn_true = np.rad2deg(np.r_[0.0, np.diff(truth[:, 2])])
    turn_est = np.rad2deg(np.r_[0.0, np.diff(est[:, 2])])
    recovered = np.flatnonzero(~big[1:] & big[:-1]) + 1  # first frame below the bound after a listed one
    rows = []
    for i in np.flatnonzero(big | np.isin(np.arange(len(big)), recovered)):
        r = slam.records[i]
        later = np.flatnonzero(~big[i + 1:])
        back = "recovered" if not big[i] else f"frame {i + 1 + later[0]}" if later.size else "never"
        std = "-" if np.isnan(r["rot_std_rad"]) else f"{np.rad2deg(r['rot_std_rad']):.2f}"
        rows.append([i, f"{d_true[i]:.2f}", f"{turn_true[i]:.1f}", f"{turn_est[i]:.1f}", f"{yaw[i]:.1f}", f"{pos[i]:.2f}",
                     r["status"], r["n_local"], r["n_map_matches"], r["n_inliers"], std, r["trail"].rstrip("; "), back])
    head = ["frame", "step m", "turn deg", "est. turn deg", "heading err deg", "pos err m", "status", "points",
            "map matches", "inliers", "rot std deg", "searches (matches, outcome)", "below again"]
    return format_table(head, rows)
