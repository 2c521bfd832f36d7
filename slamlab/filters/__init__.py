"""Recursive filters (000 §1.2, §3.6): KF, EKF, UKF (augmented and additive), landmark filter.

Functions carry the maths (``kf_predict``, ``ekf_update``, ``ukf_predict``…);
thin classes keep state (``KalmanFilter``, ``ExtendedKalmanFilter``,
``UnscentedKalmanFilter``, ``LandmarkFilter``).
"""

from .._lazy import lazy_exports
from ._linalg import CholeskyError, symmetrize
from .consistency import chi2_interval, nees, nis
from .ekf import ExtendedKalmanFilter, check_jacobian, ekf_predict, ekf_update, numerical_jacobian
from .experiments import (
    default_landmarks,
    ours_vs_source,
    run_cv_target,
    run_joseph_vs_short,
    run_landmark_filter,
    run_sigma_alpha_study,
    run_stabilising_noise,
    run_unicycle_comparison,
)
from .kalman import KalmanFilter, Update, kf_predict, kf_update
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

# plots (pyplot) and widgets (ipywidgets) load on first use: `import slamlab.filters` stays light
_PLOT = ("cv_figure", "plot_cv_example", "plot_joseph", "plot_nees", "plot_unicycle_paths", "unicycle_figure")
__getattr__, __dir__ = lazy_exports(__name__, {**dict.fromkeys(_PLOT, ".plot"),
                                               **dict.fromkeys(("explore_cv_target", "explore_unicycle"), ".widgets")})

__all__ += [
    "cv_figure",
    "default_landmarks",
    "explore_cv_target",
    "explore_unicycle",
    "ours_vs_source",
    "plot_cv_example",
    "plot_joseph",
    "plot_nees",
    "plot_unicycle_paths",
    "run_cv_target",
    "run_joseph_vs_short",
    "run_landmark_filter",
    "run_sigma_alpha_study",
    "run_stabilising_noise",
    "run_unicycle_comparison",
    "unicycle_figure",
]
