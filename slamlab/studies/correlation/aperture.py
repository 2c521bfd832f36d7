"""004's one requirement on the sensor, measured (004 §7): a narrow beam aperture.

After Table 1, 004 states that the method asks only one thing of the rangefinder, a small aperture angle: laser
rangefinders meet it, while ultrasonic ones, "usually with an aperture wider than 10°", distort the measurements
and do not allow accurate localisation. 004 shows no experiment for it. :func:`run_aperture_study` localises the
same random poses of Table 1's room with beams of several apertures: each beam of
:class:`~slamlab.sim.rangefinder.Rangefinder` returns the nearest echo in its cone (our model of an ultrasonic
rangefinder; it ignores specular reflection, which makes real sonar worse).
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np

from ..._table import format_table
from ..._validate import as_finite_array, as_rng, check_int, check_positive
from ...correlation.algorithm import LocaliseParams
from ...sim.paths import random_free_poses
from ...sim.rangefinder import Rangefinder
from ...sim.grid import measurement_room_200, test_room_200
from .experiments import localise_scans
from .studies import FAIL_CELLS, FAIL_DEG, absolute_errors, within_tolerance

__all__ = ["ApertureResult", "run_aperture_study"]


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


def run_aperture_study(apertures_deg=(0.0, 10.0, 30.0), n_poses: int = 6, *, range_std_cells: float = 0.3,
                       n_beams: int = 360, max_range_cells: float = 100.0, aperture_rays: int = 9,
                       params: LocaliseParams | None = None, rng=2010, n_jobs: int = 1, progress: bool | None = None,
                       **overrides) -> ApertureResult:
    """Localise the same random poses with beams of several apertures (004 §7's sensor requirement; ours).

    Table 1's set-up (:func:`~slamlab.studies.correlation.run_table1`: the measurement room with unmapped clutter,
    the mapped room, Gaussian range noise, 0.1-cell rounding, the full 360° search) with
    ``Rangefinder(aperture_rad=…)``: each beam returns the nearest echo among ``aperture_rays`` rays across its
    cone.

    Parameters
    ----------
    apertures_deg : sequence of float, default (0, 10, 30)
        Full cone angles [deg], each in [0, 180); 0 is a thin ray (a laser). 004: ultrasonic sensors usually over 10°.
    n_poses : int, default 6
        Random free poses (the same for every aperture).
    range_std_cells : float, default 0.3
        Range noise σ [cells].
    n_beams : int, default 360
        Beams over 360°.
    max_range_cells : float, default 100.0
        Range limit [cells].
    aperture_rays : int, default 9
        Rays per cone (at least 2).
    params : LocaliseParams, optional
        Settings of every localisation (default :class:`LocaliseParams`).
    rng : int or numpy.random.Generator, default 2010
        Seed or generator: the poses, then per aperture one child stream for the scans' noise.
    n_jobs : int, default 1
        Workers of the localisations (same result for any).
    progress : bool, optional
        Progress bar (default: in a notebook only).
    **overrides
        :class:`LocaliseParams` fields to change.

    Returns
    -------
    ApertureResult
    """
    p = LocaliseParams.resolve(params, **overrides)
    ap = as_finite_array(apertures_deg, "apertures_deg")
    if ap.ndim != 1 or ap.size == 0 or np.any(ap < 0) or np.any(ap >= 180):
        raise ValueError(f"`apertures_deg` must be a non-empty list of angles in [0, 180) degrees; got {apertures_deg!r}")
    n = check_int(n_poses, "n_poses", minimum=1)
    sd = check_positive(range_std_cells, "range_std_cells", allow_zero=True)
    rng = as_rng(rng)
    M, W = test_room_200(), measurement_room_200()
    poses = random_free_poses(W, n, margin_cells=2, rng=rng)
    streams = rng.spawn(ap.size)
    thin = Rangefinder(n_beams=n_beams, max_range_cells=max_range_cells, quantum_cells=0.0)
    scans, short = [], []
    for a, stream in zip(ap, streams, strict=True):
        rf = Rangefinder(n_beams=n_beams, max_range_cells=max_range_cells, range_std_cells=sd,
                         aperture_rad=float(np.radians(a)), aperture_rays=aperture_rays)
        exact = Rangefinder(n_beams=n_beams, max_range_cells=max_range_cells, quantum_cells=0.0,
                            aperture_rad=float(np.radians(a)), aperture_rays=aperture_rays)
        gaps = []
        for q in poses:
            ray, cone = thin.scan(W, q), exact.scan(W, q)
            both = ray.valid & cone.valid
            gaps.append(ray.ranges[both] - cone.ranges[both])
            scans.append(rf.scan(W, q, stream))
        short.append(float(np.median(np.concatenate(gaps))))
    t0 = time.perf_counter()
    table = localise_scans(M, scans, (p,), n_jobs=n_jobs, progress=progress)
    est = table[["x", "y", "heading_rad"]].to_numpy(dtype=float)
    ea, ex, ey = absolute_errors(np.tile(poses, (ap.size, 1)), est)
    return ApertureResult(ap, poses, np.hypot(ex, ey).reshape(ap.size, n), ea.reshape(ap.size, n), np.array(short),
                          sd, int(n_beams), p, time.perf_counter() - t0)
