"""004's one requirement on the sensor, measured (004 §7): a narrow beam aperture.

After Table 1, 004 states that the method asks only one thing of the rangefinder, a small aperture angle: laser
rangefinders meet it, while ultrasonic ones, "usually with an aperture wider than 10°", distort the measurements
and do not allow accurate localisation. 004 shows no experiment for it.
:func:`~slamlab.studies.correlation.run_aperture_study` (in the experiments module, which simulates) localises the
same random poses of Table 1's room with beams of several apertures: each beam of
:class:`~slamlab.sim.rangefinder.Rangefinder` returns the nearest echo in its cone (our model of an ultrasonic
rangefinder; it ignores specular reflection, which makes real sonar worse).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..._table import format_table
from ...correlation.algorithm import LocaliseParams
from .studies import FAIL_CELLS, FAIL_DEG, within_tolerance

__all__ = ["ApertureResult"]


@dataclass(frozen=True)
class ApertureResult:
    """Localisation errors at the same poses for beams of several apertures (004 §7's sensor requirement; ours).

    Attributes
    ----------
    apertures_deg : numpy.ndarray, shape (a,)
        Full cone angle of every beam [deg]; 0 is a laser's thin ray.
    true_poses : numpy.ndarray, shape (n, 3)
        The random free poses ``(x, y)`` [cells], heading [rad], the same for every aperture.
    err_pos_cells : numpy.ndarray, shape (a, n)
        Position errors [cells].
    err_heading_rad : numpy.ndarray, shape (a, n)
        Wrapped heading errors [rad].
    range_error_cells : numpy.ndarray, shape (a,)
        Median over the scans' returns of the noise-free range's shortfall against the thin ray's [cells]: how
        much the cone shortens a beam.
    range_std_cells : float
        Range noise σ [cells] of every scan.
    n_beams : int
        Beams per scan.
    params : LocaliseParams
        Settings of the localisations.
    time_s : float
        Wall time [s] (not compared).
    """

    apertures_deg: np.ndarray
    true_poses: np.ndarray
    err_pos_cells: np.ndarray
    err_heading_rad: np.ndarray
    range_error_cells: np.ndarray
    range_std_cells: float
    n_beams: int
    params: LocaliseParams = field(default_factory=LocaliseParams, repr=False)
    time_s: float = field(default=0.0, compare=False)

    @property
    def success(self) -> np.ndarray:
        """``(a, n)``: within 2 cells and 5° of the true pose."""
        return within_tolerance(self.err_pos_cells, self.err_heading_rad)

    def table(self) -> str:
        """One row per aperture: the beam's median shortfall, the localised poses, the largest position and heading
        errors among them and the median position error.

        Returns
        -------
        str
        """
        rows = []
        for j, a in enumerate(self.apertures_deg):
            ok = self.success[j]
            rows.append([f"{a:g}", f"{self.range_error_cells[j]:.2f}", f"{ok.sum()}/{ok.size}",
                         f"{self.err_pos_cells[j][ok].max():.1f}" if ok.any() else "-",
                         f"{np.degrees(self.err_heading_rad[j][ok]).max():.2f}" if ok.any() else "-",
                         f"{np.median(self.err_pos_cells[j]):.1f}"])
        n = self.true_poses.shape[0]
        return format_table(["aperture [°]", "beam shortfall [cells]", "localised", "max err [cells]", "max err [°]",
                             "median err [cells]"], rows,
                            title=(f"Beam aperture: the same {n} random poses of Table 1's room, {self.n_beams} beams, "
                                   f"σ {self.range_std_cells:g} cell, unmapped clutter;\nlocalised = within "
                                   f"{FAIL_CELLS:g} cells and {FAIL_DEG:g}°; max err among the localised; shortfall: "
                                   "median over returns, noise-free"))
