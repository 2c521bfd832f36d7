"""The settings of the Hough-transform SLAM loop (004 §8; our additions marked in each field's source note).

:class:`HoughSlamParams` is what :func:`slamlab.hough.hough_slam` and :func:`slamlab.hough.detect_lines` take as
``params=`` (and as field overrides).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .._params import Params, param
from .._validate import check_choice, check_int, check_positive, check_probability
from .transform import theta_axis

__all__ = ["HoughSlamParams"]


def _optional_positive(value, name):
    if value is not None:
        check_positive(value, name)


@dataclass(frozen=True)
class HoughSlamParams(Params):
    """Every knob of the loop, each with its source; those 004 does not fix are ours.

    Lengths (``delta_rho``, ``r_max``, ``band``, ``max_gap``, ``a``, ``b``, ``rho_tol``,
    ``gate``) are in the scans' unit (cells in simulation, metres on a real log).

    Attributes
    ----------
    delta_rho : float
        rho bin width (004: 1 cell).
    delta_theta_rad : float
        θ bin width [rad] (004: 1°).
    r_max : float or None
        Longest range used (None: each scan's longest).
    H_min : int
        Fewest votes of a line (004 leaves the value open).
    H_min_retry : int or None
        A scan with fewer than two lines at ``H_min`` is searched again with this threshold
        (ours; None, or not below ``H_min``: not).
    max_lines : int
        Strongest lines kept per scan.
    suppress_rho, suppress_theta_rad : float or None
        Window of false neighbours suppressed around a peak (None: 3 Δrho, 3 Δθ).
    refine : bool
        Least-squares refit of each line (:func:`~slamlab.hough.refine_lines`).
    band : float or None
        Refit band (None: Δrho).
    max_gap : float or None
        The refit cuts the band's points at longer gaps.
    a, b : float
        004's association widths in rho and in the along-line direction (b None: b = a).
    a_theta_rad : float
        Association width in θ [rad]: largest rotation left after odometry.
    parallel_tol_rad : float
        Lines this close in θ count as parallel [rad].
    p_min : float
        Below this association probability a line is new.
    method : {"least_squares", "two_lines"}
        Pose from all agreeing lines (ours) or from one pair (004).
    angle_tol_rad : float
        Largest change of the angle between lines [rad].
    rho_tol : float or None
        Least squares drops lines with a larger residual.
    min_angle_rad : float
        Smallest angle of a usable pair [rad].
    min_common : int
        The reference scan moves on when fewer lines are shared.
    gate : float or None
        Reject a pose farther than this from odometry's (None: off).
    gate_theta_rad : float
        Heading gate [rad].
    partial : bool
        With only parallel lines, move along them from odometry.
    heading : bool
        When lines are associated but give no pose, take the heading change from them and the
        translation from odometry (ours; off in simulation, on for the real logs of notebook 07).
    """

    delta_rho: float = param(1.0, "004 §Hough SLAM: Δrho = 1 cell")
    delta_theta_rad: float = param(math.pi / 180, "004 §Hough SLAM: Δθ = 1°")
    r_max: float | None = param(None, "ours: longest range used (None: each scan's longest)")
    H_min: int = param(15, "004 §Hough SLAM: a parameter, value not given")
    H_min_retry: int | None = param(None, "ours: a scan with < 2 lines is searched again at this threshold")
    max_lines: int = param(12, "ours: strongest lines kept per scan")
    suppress_rho: float | None = param(None, "ours: false-neighbour window (None: 3 Δrho)")
    suppress_theta_rad: float | None = param(None, "ours: false-neighbour window (None: 3 Δθ)")
    refine: bool = param(True, "ours: least-squares refit of each line")
    band: float | None = param(None, "ours: refit band (None: Δrho)")
    max_gap: float | None = param(4.0, "ours: refit cuts the band's points at longer gaps")
    a: float = param(3.0, "004 §Hough SLAM: a = b = largest displacement between scans")
    b: float | None = param(None, "004 §Hough SLAM: a = b (None: b = a)")
    a_theta_rad: float = param(math.radians(4.0), "ours: largest rotation left after odometry")
    parallel_tol_rad: float = param(math.radians(3.0), "ours: lines this close in θ are parallel")
    p_min: float = param(0.05, "ours: below this P a line is new")
    method: str = param("least_squares", "ours ('two_lines' = 004's)")
    angle_tol_rad: float = param(math.radians(0.5), "004: the angle between the lines did not change (tol. ours)")
    rho_tol: float | None = param(0.3, "ours: least squares drops lines with a larger residual")
    min_angle_rad: float = param(math.radians(30.0), "ours: smallest angle of a usable pair")
    min_common: int = param(3, "ours: the reference scan moves when fewer lines are shared")
    gate: float | None = param(None, "ours: reject a pose farther than this from odometry's (None: off)")
    gate_theta_rad: float = param(math.radians(10.0), "ours: heading gate")
    partial: bool = param(True, "ours: only parallel lines → move along them from odometry")
    heading: bool = param(False, "ours: no pose from the lines → their heading change, odometry's translation")

    def check(self) -> None:
        check_positive(self.delta_rho, "delta_rho")
        theta_axis(self.delta_theta_rad)  # > 0 and divides 180°
        for name in ("r_max", "suppress_rho", "suppress_theta_rad", "band", "max_gap", "b", "rho_tol", "gate"):
            _optional_positive(getattr(self, name), name)
        check_int(self.H_min, "H_min", minimum=1)
        if self.H_min_retry is not None:
            check_int(self.H_min_retry, "H_min_retry", minimum=1)
        check_int(self.max_lines, "max_lines", minimum=2)
        for name in ("refine", "partial", "heading"):
            if not isinstance(getattr(self, name), (bool, np.bool_)):
                raise TypeError(f"`{name}` must be a bool; got {type(getattr(self, name)).__name__}")
        check_positive(self.a, "a")
        check_positive(self.a_theta_rad, "a_theta_rad")
        check_positive(self.parallel_tol_rad, "parallel_tol_rad", allow_zero=True)
        if check_probability(self.p_min, "p_min") >= 1.0:
            raise ValueError(f"`p_min` must lie in [0, 1); got {self.p_min}")
        check_choice(self.method, "method", ("two_lines", "least_squares"))
        check_positive(self.angle_tol_rad, "angle_tol_rad", allow_zero=True)
        check_positive(self.min_angle_rad, "min_angle_rad", allow_zero=True)
        if self.min_angle_rad > math.pi / 2:
            raise ValueError(f"`min_angle_rad` must be <= π/2; got {self.min_angle_rad}")
        check_int(self.min_common, "min_common", minimum=2)
        check_positive(self.gate_theta_rad, "gate_theta_rad")


