"""Ch. 10 ablations (ours, on 002's questions): one plane pair against two normal directions, the incidence
correction on and off, and where the flight's error comes from (the odometry inside a frame or between frames).

Each ``run_*`` takes a ready :class:`~slamlab.sim.Flight` (or simulates one) and returns a frozen dataclass
whose ``table()`` is printed in the notebook (nbval compares it).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..._params import refuse_set_fields
from ..._table import format_table
from ..._validate import check_int
from ...planes.filter import PlaneSLAMParams
from ...sweep import fresh_seed_sequence
from .experiments import FlightResult, flight_or_simulate, in_frame_rotation_error_deg, run_flight
from .figures import FIG4_PARAMS, IntensityResult, run_intensity_figure

__all__ = [
    "PAIR_VARIANTS",
    "FlightComparison",
    "IncidenceResult",
    "run_frame_source_ablation",
    "run_incidence_ablation",
    "run_pairs_ablation",
]

#: (label, max_planes, min_normal_rank) of :func:`run_pairs_ablation`
PAIR_VARIANTS = (
    ("all planes, >= 2 directions (ours, default)", 10, 2),
    ("all planes, one pair is enough (002)", 10, 1),
    ("2 largest planes, >= 2 directions", 2, 2),
    ("2 largest planes, one pair is enough", 2, 1),
    ("largest plane only, one pair (002's minimum)", 1, 1),
)

#: The settings of the pairs and incidence ablations' flights when no ``params`` is given: 200 particles.
_ABLATION_PARAMS = PlaneSLAMParams(n_particles=200)


def _fmt_rms(r: FlightResult) -> list[str]:
    rms, _ = r.rms()
    return [f"{rms[0]:.3f}", f"{rms[1]:.3f}", f"{rms[2]:.3f}", f"{rms[3]:.2f}", f"{rms[4]:.2f}", f"{rms[5]:.2f}"]


def map_normal_error_deg(result: FlightResult, room) -> float:
    """Median over the map's planes of the angle [deg] between a plane's normal and the nearest normal of the
    room's planes (``room`` a :class:`~slamlab.sim.PlaneRoom`; ours: how tilted the map is).

    Parameters
    ----------
    result : FlightResult
        A run whose ``map`` holds the planes.
    room : slamlab.sim.PlaneRoom
        The true room (its ``normals``).

    Returns
    -------
    float
        Median angle in degrees; NaN for an empty map.
    """
    if len(result.map) == 0:
        return float("nan")
    N = np.array([pl.n for pl in result.map.planes])
    cos = np.clip(np.abs(N @ np.asarray(room.normals).T).max(axis=1), -1.0, 1.0)
    return float(np.rad2deg(np.median(np.arccos(cos))))


@dataclass(frozen=True)
class FlightComparison:
    """Several runs of the filter on one flight: ``labels`` and ``results`` (:class:`FlightResult`), the odometry's
    errors as the last row; ``note`` a line printed under the table.

    Attributes
    ----------
    title : str
        Table title.
    labels : tuple of str
        One label per run.
    results : tuple of FlightResult
        The runs, in ``labels`` order.
    note : str
        Line printed under the table.
    """

    title: str
    labels: tuple
    results: tuple = field(repr=False)
    note: str = ""

    def __str__(self) -> str:
        return f"{self.title}: " + ", ".join(f"{lab}: ATE {r.ate_m:.3f} m" for lab, r in
                                             zip(self.labels, self.results, strict=True))

    def table(self) -> str:
        """RMS errors and ATE per run, the odometry alone as the last row.

        Returns
        -------
        str
            Fixed-precision text table (and ``note``).
        """
        rows = []
        for lab, r in zip(self.labels, self.results, strict=True):
            used = r.n_frames - r.n_kept_prediction
            rows.append([lab, f"{used} / {r.n_kept_prediction}", f"{r.ate_m:.3f}", *_fmt_rms(r)])
        r0 = self.results[0]
        _, rms_o = r0.rms()
        rows.append(["odometry alone", "-", f"{r0.ate_odo_m:.3f}", f"{rms_o[0]:.3f}", f"{rms_o[1]:.3f}",
                     f"{rms_o[2]:.3f}", f"{rms_o[3]:.2f}", f"{rms_o[4]:.2f}", f"{rms_o[5]:.2f}"])
        tab = format_table(["run", "used / kept", "ATE [m]", "x", "y", "z", "roll", "pitch", "yaw"], rows,
                           title=(f"{self.title} ({r0.n_frames} frames, {r0.params.n_particles} particles)\nRMS "
                                  "errors: x, y, z [m], roll, pitch, yaw [deg]\nused / kept: frames that corrected "
                                  "the particles / kept the prediction"))
        return tab + (f"\n{self.note}" if self.note else "")


def run_pairs_ablation(flight=None, *, duration_s: float = 20.0, variants=PAIR_VARIANTS,
                       params: PlaneSLAMParams | None = None, rng=0, **overrides) -> FlightComparison:
    """002 says the filter works "even with only one pair of planes"; ours asks for two normal directions.

    Each variant limits the planes of a frame (``max_planes``: the largest ones RANSAC finds) and sets
    ``min_normal_rank`` (1: any pair corrects, as 002; 2: frames whose normals span one direction keep the
    prediction). Same flight and seed for every variant. The variants set those two fields: ``params`` and the
    overrides must leave them at their defaults (a ``ValueError`` names the field otherwise).

    Parameters
    ----------
    flight : Flight, optional
        A ready flight (default: simulated from ``rng``).
    duration_s : float
        The simulated flight's length.
    variants : sequence of (str, int, int)
        (label, ``max_planes``, ``min_normal_rank``).
    params : PlaneSLAMParams, optional
        Filter settings every variant changes (default: the defaults with ``n_particles=200``).
    rng : int, SeedSequence or Generator
        The flight's and the filter's seed, the same for every run.
    **overrides
        :class:`PlaneSLAMParams` fields under every variant (e.g. ``n_particles``).

    Returns
    -------
    FlightComparison
    """
    refuse_set_fields(PlaneSLAMParams.resolve(params, **overrides), ["max_planes", "min_normal_rank"],
                      "each of `variants` sets them")
    p = PlaneSLAMParams.resolve(_ABLATION_PARAMS if params is None else params, **overrides)
    fl = flight_or_simulate(flight, duration_s, rng)
    labels, res = [], []
    for lab, mp, rank in variants:
        labels.append(lab)
        res.append(run_flight(flight=fl, rng=rng, params=p.replace(max_planes=mp, min_normal_rank=rank),
                              progress=False))
    return FlightComparison("One plane pair vs two normal directions", tuple(labels), tuple(res))


def run_frame_source_ablation(flight=None, *, duration_s: float = 8.0, params: PlaneSLAMParams | None = None,
                              rng=0, **overrides) -> FlightComparison:
    """Where the flight's error comes from (ours): frames built and particles predicted with the odometry (002),
    or with the true poses in one place or the other.

    Parameters
    ----------
    flight : Flight, optional
        A ready flight (default: simulated from ``rng``).
    duration_s : float
        The simulated flight's length.
    params : PlaneSLAMParams, optional
        Filter settings of every run (default: the defaults, 400 particles).
    rng : int, SeedSequence or Generator
        The flight's and the filter's seed, the same for every run.
    **overrides
        :class:`PlaneSLAMParams` fields (e.g. ``n_particles``).

    Returns
    -------
    FlightComparison
    """
    p = PlaneSLAMParams.resolve(params, **overrides)
    fl = flight_or_simulate(flight, duration_s, rng)
    cases = (("002: frames, prediction: odometry", "odometry", "odometry"),
             ("frames: true poses, prediction: odometry", "truth", "odometry"),
             ("frames: odometry, prediction: true poses", "odometry", "truth"),
             ("frames, prediction: true poses", "truth", "truth"))
    res = tuple(run_flight(flight=fl, rng=rng, params=p, frame_poses=a, increment_poses=b, progress=False)
                for _, a, b in cases)
    e = in_frame_rotation_error_deg(fl)
    tilt = [map_normal_error_deg(r, fl.room) for r in res]
    note = ("odometry's rotation error inside a frame (each line against the frame's last line),\n"
            f"  RMS about x / y / z: {e[0]:.2f} / {e[1]:.2f} / {e[2]:.2f} deg\nmap planes' normals against the "
            "room's, median angle [deg], row by row: " + " / ".join(f"{t:.2f}" for t in tilt))
    return FlightComparison("Where the error comes from", tuple(c[0] for c in cases), res, note)


@dataclass(frozen=True)
class IncidenceResult:
    """The incidence-angle correction (002 after [17]) on and off: Fig. 4's first cycle and a flight.

    Attributes
    ----------
    fig4 : tuple of 2 IntensityResult
        Fig. 4's first cycle with and without the correction.
    flights : tuple of 2 FlightResult
        The flight with and without the correction.
    """

    fig4: tuple = field(repr=False)
    flights: tuple = field(repr=False)

    def __str__(self) -> str:
        return (f"Incidence correction on / off: Fig. 4 error {self.fig4[0].error_with_m:.3f} / "
                f"{self.fig4[1].error_with_m:.3f} m, flight ATE {self.flights[0].ate_m:.3f} / "
                f"{self.flights[1].ate_m:.3f} m")

    def table(self) -> str:
        """Fig. 4's error and peak weight, the flight's ATE and RMS errors, with the correction on and off.

        Returns
        -------
        str
            Fixed-precision text table.
        """
        rows = []
        for lab, f4, fl in zip(("on (002 after [17])", "off"), self.fig4, self.flights, strict=True):
            rms, _ = fl.rms()
            rows.append([lab, f"{f4.error_with_m:.3f}", f"{f4.peak:.2f}", f"{fl.ate_m:.3f}", f"{rms[0]:.3f}",
                         f"{rms[1]:.3f}", f"{rms[5]:.2f}"])
        return format_table(["incidence correction", "Fig. 4 error [m]", "Fig. 4 peak", "flight ATE [m]",
                             "x RMS [m]", "y RMS [m]", "yaw RMS [deg]"], rows,
                            title=(f"Incidence correction on / off (Fig. 4: one cycle; flight: "
                                   f"{self.flights[0].n_frames} frames, {self.flights[0].params.n_particles} "
                                   "particles)\nFig. 4 peak: the largest weight / the uniform weight"))


def run_incidence_ablation(flight=None, *, duration_s: float = 20.0, fig4_particles: int = 400,
                           params: PlaneSLAMParams | None = None, fig4_params: PlaneSLAMParams | None = None,
                           rng=0, **overrides) -> IncidenceResult:
    """Fig. 4 (one cycle) and a flight with the incidence-angle correction on and off (same seeds; 002 after [17]).

    The ablation sets ``incidence_correction`` itself: ``params`` and the overrides must leave it at its default
    (a ``ValueError`` names it otherwise).

    Parameters
    ----------
    flight : Flight, optional
        A ready flight (default: simulated from ``rng``).
    duration_s : float
        The simulated flight's length.
    fig4_particles : int
        Particles of Fig. 4 (its ``n_particles``).
    params : PlaneSLAMParams, optional
        Filter settings of the flights (default: the defaults with ``n_particles=200``).
    fig4_params : PlaneSLAMParams, optional
        Settings of Fig. 4's cycle (default: :data:`~slamlab.studies.planes.figures.FIG4_PARAMS`), but for
        ``n_particles`` (``fig4_particles``) and ``incidence_correction``; the overrides do not apply to it.
    rng : int, SeedSequence or Generator
        The flight's and the filter's seed, the same for every run.
    **overrides
        :class:`PlaneSLAMParams` fields of the flights (e.g. ``n_particles``).

    Returns
    -------
    IncidenceResult
    """
    refuse_set_fields(PlaneSLAMParams.resolve(params, **overrides), ["incidence_correction"],
                      "each part runs with the correction and without it")
    p = PlaneSLAMParams.resolve(_ABLATION_PARAMS if params is None else params, **overrides)
    fig4 = FIG4_PARAMS if fig4_params is None else PlaneSLAMParams.resolve(fig4_params)
    refuse_set_fields(fig4_params or PlaneSLAMParams(), ["n_particles", "incidence_correction"],
                      "Fig. 4 runs with `fig4_particles`, with the correction and without it")
    fig4 = fig4.replace(n_particles=check_int(fig4_particles, "fig4_particles", minimum=1))
    fl = flight_or_simulate(flight, duration_s, rng)
    f4: list[IntensityResult] = [run_intensity_figure(params=fig4.replace(incidence_correction=c),
                                                      rng=fresh_seed_sequence(rng)) for c in (True, False)]
    fls = [run_flight(flight=fl, rng=rng, params=p.replace(incidence_correction=c), progress=False)
           for c in (True, False)]
    return IncidenceResult(tuple(f4), tuple(fls))
