"""Recursive filters (000 §1.2, §3.6): KF, EKF, UKF (augmented and additive), landmark filter.

Functions carry the maths (``kf_predict``, ``ekf_update``, ``ukf_predict``…);
thin classes keep state (``KalmanFilter``, ``LinearisedKalmanFilter``, ``ExtendedKalmanFilter``,
``UnscentedKalmanFilter``, ``LandmarkFilter``). The chapter's Monte Carlo studies of them
are in :mod:`slamlab.studies.filters`.
"""

from .._lazy import lazy_exports
from ._linalg import CholeskyError, symmetrize
from .consistency import chi2_interval, nees, nis
from .ekf import ExtendedKalmanFilter, check_jacobian, ekf_predict, ekf_update, numerical_jacobian
from .kalman import KalmanFilter, LinearisedKalmanFilter, Update, kf_predict, kf_update
from .landmark import LandmarkFilter, landmark_predict, landmark_update
from .ukf import (
    UnscentedKalmanFilter,
    sigma_points,
    sigma_weights,
    ukf_predict,
    ukf_update,
    unscented_transform,
)

__all__ = [
    "CholeskyError",
    "ExtendedKalmanFilter",
    "KalmanFilter",
    "LandmarkFilter",
    "LinearisedKalmanFilter",
    "UnscentedKalmanFilter",
    "Update",
    "check_jacobian",
    "chi2_interval",
    "ekf_predict",
    "ekf_update",
    "kf_predict",
    "kf_update",
    "landmark_predict",
    "landmark_update",
    "nees",
    "nis",
    "numerical_jacobian",
    "sigma_points",
    "sigma_weights",
    "symmetrize",
    "ukf_predict",
    "ukf_update",
    "unscented_transform",
]

# the plot (pyplot) loads on first use: `import slamlab.filters` stays light
__getattr__, __dir__ = lazy_exports(__name__, {"plot_nees": ".plot"})

__all__ += ["plot_nees"]  # loaded on first use
