"""Odometry along a path of true poses: measured increments with noise and drift (004 §8; our model).

One place for the odometry noise model: the simulator (:mod:`slamlab.sim.rangefinder` re-exports it)
and the experiments on corrected real logs (``slamlab.studies.localisation.logs``) both draw odometry with it.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .._validate import as_rng, check_positive, check_real
from .se2 import check_poses, se2_integrate, se2_relative

__all__ = ["Odometry", "simulate_odometry"]


@dataclass(frozen=True)
class Odometry:
    """Odometry along a path: measured increments and the pose integrated from the true start (004 §8).

    Attributes
    ----------
    increments : ndarray, shape (n-1, 3)
        Measured body-frame increments ``(dx_m, dy_m, dtheta_rad)``.
    poses : ndarray, shape (n, 3)
        Integrated odometry poses; ``poses[0]`` is the true start.
    true_increments : ndarray, shape (n-1, 3)
        The noise-free increments between the true poses.
    """

    increments: np.ndarray  # (n-1, 3) measured body-frame (dx, dy, dθ)
    poses: np.ndarray  # (n, 3) integrated odometry, poses[0] = the true start
    true_increments: np.ndarray  # (n-1, 3)

    def __str__(self) -> str:
        return f"Odometry over {self.increments.shape[0]} steps"


def simulate_odometry(poses, *, trans_std_frac: float = 0.0, rot_std_rad: float = 0.0,
                      scale_error: float = 0.0, drift_rad_per_cell: float = 0.0, rng=None) -> Odometry:
    """Noisy odometry with systematic drift along a path of true poses (our model; 004 only argues drift).

    Each true increment ``(dx, dy, dθ)`` over a step of length ``d = |(dx, dy)|``
    is measured as ``((1 + scale_error)·dx + n_x, (1 + scale_error)·dy + n_y,
    dθ + drift_rad_per_cell·d + n_θ)`` with ``n_x, n_y ~ N(0, (trans_std_frac·d)²)``
    and ``n_θ ~ N(0, rot_std_rad²)``; the measured increments are integrated
    from the true start pose.

    Parameters
    ----------
    poses : array_like, shape (n, 3)
        True poses.
    trans_std_frac : float
        Translation noise σ as a fraction of the step length.
    rot_std_rad : float
        Heading noise σ per step.
    scale_error : float
        Systematic relative error of travelled distance (e.g. 0.02 = wheels 2 % too big).
    drift_rad_per_cell : float
        Systematic heading drift per cell travelled.
    rng : Generator, int or None

    Examples
    --------
    >>> P = np.array([[0, 0, 0], [1, 0, 0], [2, 0, 0.0]])
    >>> simulate_odometry(P, scale_error=0.5).poses[:, 0].tolist()
    [0.0, 1.5, 3.0]
    """
    P = check_poses(poses)
    sf = check_positive(trans_std_frac, "trans_std_frac", allow_zero=True)
    sr = check_positive(rot_std_rad, "rot_std_rad", allow_zero=True)
    for name, val in (("scale_error", scale_error), ("drift_rad_per_cell", drift_rad_per_cell)):
        check_real(val, name)
    rng = as_rng(rng)
    U = se2_relative(P[:-1], P[1:])
    d = np.hypot(U[:, 0], U[:, 1])
    noise = rng.standard_normal(U.shape)
    meas = np.column_stack([
        (1 + scale_error) * U[:, 0] + sf * d * noise[:, 0],
        (1 + scale_error) * U[:, 1] + sf * d * noise[:, 1],
        U[:, 2] + drift_rad_per_cell * d + sr * noise[:, 2],
    ])
    return Odometry(meas, se2_integrate(P[0], meas), U)
