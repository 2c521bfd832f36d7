"""Trajectories for the stereo arena (000 §3.7, §4.2): turn in place, closed loop, long path.

A trajectory is an ``(N, 3)`` array of body poses ``(x_m, y_m, yaw_rad)``, one per
frame, with the yaw unwrapped (it keeps growing through a full turn). The robot
of 000 drives straight and turns in place, so paths are built from waypoints:
straight steps of ``step_m`` between them and in-place turns of at most
``turn_step_rad`` at each (our construction; 000 gives the shapes only).
"""

from __future__ import annotations

import numpy as np

from .._validate import as_finite_array, as_vector, check_positive
from ..geometry import wrap_angle

__all__ = [
    "LONG_PATH_WAYPOINTS",
    "LOOP_WAYPOINTS",
    "long_path",
    "rectangular_loop",
    "turn_in_place",
    "waypoint_path",
]

#: closed, roughly rectangular loop ~4 m across inside the 6×8 m arena (000 §3.7.2), counter-clockwise
LOOP_WAYPOINTS = ((1.0, 1.5), (5.0, 1.5), (5.0, 6.5), (1.0, 6.5), (1.0, 1.5))

#: ~80 m in a 10×12 m room (000 §4.2, the Table 2 run): a CCW loop, a CW loop, a larger CCW loop
LONG_PATH_WAYPOINTS = (
    (2.0, 2.0), (8.0, 2.0), (8.0, 10.0), (2.0, 10.0), (2.0, 2.0),
    (2.0, 7.0), (6.0, 7.0), (6.0, 2.0), (2.0, 2.0),
    (9.0, 2.0), (9.0, 11.0), (1.5, 11.0), (1.5, 2.0), (2.0, 2.0),
)  # fmt: skip


def turn_in_place(step_rad: float = np.deg2rad(5.0), *, center_m=(3.0, 4.0), start_yaw_rad: float = np.pi / 2, turns: float = 1.0) -> np.ndarray:
    """A turn of ``turns × 360°`` in place, ``step_rad`` per frame, counter-clockwise (000 §3.7.1).

    Parameters
    ----------
    step_rad : float, default 5°
        Turn per frame [rad].
    center_m : array_like, shape (2,)
        Position [m].
    start_yaw_rad : float, default π/2
        First heading [rad].
    turns : float, default 1.0
        Full turns.

    Returns
    -------
    numpy.ndarray, shape (N, 3)
        ``(x_m, y_m, yaw_rad)``, yaw unwrapped.

    Examples
    --------
    >>> p = turn_in_place(np.deg2rad(90.0), start_yaw_rad=0.0)
    >>> np.round(np.rad2deg(p[:, 2])).tolist()
    [0.0, 90.0, 180.0, 270.0, 360.0]
    """
    step_rad = check_positive(step_rad, "step_rad")
    turns = check_positive(turns, "turns")
    c = as_vector(center_m, "center_m", 2)
    n = int(np.ceil(turns * 2 * np.pi / step_rad - 1e-9))
    yaw = start_yaw_rad + np.minimum(np.arange(n + 1) * step_rad, turns * 2 * np.pi)
    return np.column_stack([np.full(n + 1, c[0]), np.full(n + 1, c[1]), yaw])


def waypoint_path(waypoints_m, *, step_m: float = 0.1, turn_step_rad: float = np.deg2rad(10.0), start_yaw_rad: float | None = None, end_yaw_rad: float | None = None) -> np.ndarray:
    """Drive straight between waypoints in steps of at most ``step_m``, turning in place at each (our construction).

    Parameters
    ----------
    waypoints_m : (K, 2) array_like
        Points [m], K >= 2, consecutive points distinct.
    step_m : float, default 0.1
        Largest straight step per frame [m].
    turn_step_rad : float, default 10°
        Largest turn per frame [rad].
    start_yaw_rad : float, optional
        Initial heading (default: towards the second waypoint).
    end_yaw_rad : float, optional
        Final heading to turn to at the last waypoint (default: none).

    Returns
    -------
    numpy.ndarray, shape (N, 3)
        ``(x_m, y_m, yaw_rad)``.

    Examples
    --------
    >>> p = waypoint_path([[0, 0], [1, 0], [1, 1]], step_m=0.5, turn_step_rad=np.pi / 2)
    >>> np.round(p, 3).tolist()
    [[0.0, 0.0, 0.0], [0.5, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 0.0, 1.571], [1.0, 0.5, 1.571], [1.0, 1.0, 1.571]]
    """
    W = as_finite_array(waypoints_m, "waypoints_m", ndim=2)
    if W.shape[0] < 2 or W.shape[1] != 2:
        raise ValueError(f"`waypoints_m` must have shape (K, 2) with K >= 2; got {W.shape}")
    seg = np.diff(W, axis=0)
    length = np.hypot(seg[:, 0], seg[:, 1])
    if np.any(length == 0):
        raise ValueError("`waypoints_m` must not repeat a point consecutively")
    step_m = check_positive(step_m, "step_m")
    turn_step_rad = check_positive(turn_step_rad, "turn_step_rad")
    headings = np.arctan2(seg[:, 1], seg[:, 0])
    yaw = headings[0] if start_yaw_rad is None else float(start_yaw_rad)
    poses = [np.array([W[0, 0], W[0, 1], yaw])]

    def turn_to(target):
        nonlocal yaw
        delta = float(wrap_angle(target - yaw))
        n = int(np.ceil(abs(delta) / turn_step_rad - 1e-9))
        x, y = poses[-1][:2]
        for k in range(1, n + 1):  # a handful of poses per corner
            poses.append(np.array([x, y, yaw + delta * k / n]))
        yaw = yaw + delta

    for i in range(len(seg)):
        turn_to(headings[i])
        n = int(np.ceil(length[i] / step_m - 1e-9))
        f = np.arange(1, n + 1)[:, None] / n
        xy = W[i] + f * seg[i]
        poses.extend(np.column_stack([xy, np.full(n, yaw)]))
    if end_yaw_rad is not None:
        turn_to(float(end_yaw_rad))
    return np.array(poses)


def rectangular_loop(step_m: float = 0.25, turn_step_rad: float = np.deg2rad(15.0)) -> np.ndarray:
    """The closed, roughly rectangular loop of 000 §3.7.2 (4×5 m in the 6×8 m arena), back to the start pose.

    The robot starts facing the ``x = 6`` wall (perpendicular to it, as in 000) and ends at the start
    with the same heading after a full counter-clockwise turn.

    Parameters
    ----------
    step_m : float, default 0.25
        Largest straight step per frame [m].
    turn_step_rad : float, default 15°
        Largest turn per frame [rad].

    Returns
    -------
    numpy.ndarray, shape (N, 3)
        ``(x_m, y_m, yaw_rad)``, yaw unwrapped.

    Examples
    --------
    >>> p = rectangular_loop(1.0, np.pi / 2)
    >>> p[0].tolist(), np.round(p[-1], 6).tolist()
    ([1.0, 1.5, 0.0], [1.0, 1.5, 6.283185])
    """
    return waypoint_path(LOOP_WAYPOINTS, step_m=step_m, turn_step_rad=turn_step_rad, start_yaw_rad=0.0, end_yaw_rad=2 * np.pi)


def long_path(step_m: float = 0.1, turn_step_rad: float = np.deg2rad(10.0)) -> np.ndarray:
    """About 80 m in a 10×12 m room (000 §4.2): loops turning both ways, back to the start.

    Parameters
    ----------
    step_m : float, default 0.1
        Largest straight step per frame [m].
    turn_step_rad : float, default 10°
        Largest turn per frame [rad].

    Returns
    -------
    numpy.ndarray, shape (N, 3)
        ``(x_m, y_m, yaw_rad)``.

    Examples
    --------
    >>> p = long_path(0.5)
    >>> round(float(np.sum(np.hypot(*np.diff(p[:, :2], axis=0).T))), 1)
    79.0
    """
    return waypoint_path(LONG_PATH_WAYPOINTS, step_m=step_m, turn_step_rad=turn_step_rad, start_yaw_rad=0.0)
