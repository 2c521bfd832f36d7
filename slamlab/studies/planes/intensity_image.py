"""002 Fig. 3: the image made of the scan lines' intensities, beside the room it shows (ours: the room model).

002 Fig. 3 shows "a photo of a part of the room and its view obtained by collecting the lines of reflected-signal
intensities of the laser rangefinder". Ours: the intensities of a run of consecutive lines of a simulated flight
(rows: scan lines, columns: beam index), and in place of the photo the room model's reflectance panels seen from
one point (the scanner at the middle line) along the same beam directions: no noise, no incidence factor, no
motion of the vehicle during the lines.
"""

from __future__ import annotations

import textwrap
from dataclasses import dataclass

import numpy as np

from ..._validate import as_vector, check_positive
from ...sim.planes_room import Flight, cast_rays_planes, scanner_beam_directions

__all__ = ["IntensityImage", "scan_intensity_image"]


@dataclass(frozen=True)
class IntensityImage:
    """The intensity image of a run of scan lines and the model's rendering on the same grid (002 Fig. 3; ours).

    Attributes
    ----------
    image : (L, B) float
        Intensities of the lines (rows) and beams (columns); NaN without a return.
    render : (L, B) float
        Reflectance ρ of the model's panel each beam direction meets from ``origin_m`` (NaN: none).
    lines : (L,) int
        Scan line indices in the flight.
    beams : (B,) int
        Beam indices in a line.
    beam_deg : (B,) float
        Beam angles from the body's up axis (90: forward, horizontal), degrees.
    times_s : (2,) float
        Times of the first and the last line, seconds.
    deg_per_line : float
        Median yaw between consecutive lines, degrees.
    step_deg : float
        Angle between beams, degrees.
    origin_m : (3,) float
        Scanner position of the middle line (the rendering's viewpoint), map frame, metres.
    planes : tuple of str
        Names of the room's planes in the rendering.
    render_plane : (L, B) int
        Index (into ``planes``) of the plane each rendered beam meets (-1: none).
    gain : float
        ``I0`` of the scanner's intensity model ``I = I0·ρ·|cos θ|``.
    """

    image: np.ndarray
    render: np.ndarray
    lines: np.ndarray
    beams: np.ndarray
    beam_deg: np.ndarray
    times_s: np.ndarray
    deg_per_line: float
    step_deg: float
    origin_m: np.ndarray
    planes: tuple
    render_plane: np.ndarray
    gain: float

    def correlation(self) -> float:
        """Pearson correlation of the intensities and the rendered reflectances where both exist.

        Returns
        -------
        float
        """
        ok = np.isfinite(self.image) & np.isfinite(self.render)
        return float(np.corrcoef(self.image[ok], self.render[ok])[0, 1])

    def attenuation(self) -> np.ndarray:
        """Per plane in view, the median of ``I / (I0·ρ)`` over its pixels: the intensity against the model's
        reflectance, 1 for a beam square to the surface (``|cos θ|`` of the intensity model, plus noise and the
        pixels the vehicle's motion shifts onto another panel).

        Returns
        -------
        (len(planes),) float
        """
        ok = np.isfinite(self.image) & np.isfinite(self.render) & (self.render > 0)
        q = np.where(ok, self.image / (self.gain * np.where(ok, self.render, 1.0)), np.nan)
        return np.array([np.nanmedian(q[self.render_plane == j]) for j in range(len(self.planes))])

    def __str__(self) -> str:
        L, B = self.image.shape
        return (f"Fig. 3 (ours): {L} scan lines x {B} beams: lines {self.lines[0]}-{self.lines[-1]} "
                f"({self.times_s[0]:.2f}-{self.times_s[1]:.2f} s, {L * self.deg_per_line:.0f} deg of yaw)\n"
                f"beams {self.beams[0]}-{self.beams[-1]} ({self.beam_deg[0]:.0f}-{self.beam_deg[-1]:.0f} deg from "
                f"up); intensity {np.nanmin(self.image):.0f} .. {np.nanmax(self.image):.0f}; model reflectance "
                f"{np.nanmin(self.render):.2f} .. {np.nanmax(self.render):.2f}; correlation {self.correlation():.2f}\n"
                + textwrap.fill("median I / (I0 rho) on each plane in view: " + ", ".join(
                    f"{n} {a:.2f}" for n, a in zip(self.planes, self.attenuation(), strict=True)), width=108,
                    subsequent_indent="  "))


def scan_intensity_image(flight: Flight, *, start_s: float = 4.0, duration_s: float = 2.0,
                        angles_deg=(45.0, 135.0)) -> IntensityImage:
    """The intensity image of ``duration_s`` of lines from ``start_s`` and the model seen along the same beams
    (002 Fig. 3; ours: the rendering in place of the photo).

    Parameters
    ----------
    flight : slamlab.sim.Flight
        The simulated flight.
    start_s : float
        Time of the first line, seconds from the flight's start.
    duration_s : float
        Length of the run of lines, seconds (at the yaw rate, the horizontal extent of the image).
    angles_deg : (2,) float
        Beams kept, as angles from the body's up axis, degrees (90: forward; the scanner covers -135 .. 135).

    Returns
    -------
    IntensityImage
    """
    if not isinstance(flight, Flight):
        raise TypeError(f"`flight` must be a Flight; got {type(flight).__name__}")
    sc = flight.scanner
    start_s = check_positive(start_s, "start_s", allow_zero=True)
    duration_s = check_positive(duration_s, "duration_s")
    first, n = round(start_s * sc.lines_per_s), round(duration_s * sc.lines_per_s)
    if n < 1 or first + n > len(flight):
        raise ValueError(f"`start_s` + `duration_s` = {start_s + duration_s} s must lie in the flight "
                         f"({len(flight)} lines at {sc.lines_per_s:g} lines/s) and hold a line")
    lo, hi = as_vector(angles_deg, "angles_deg", 2)
    a = np.linspace(-sc.fov_deg / 2, sc.fov_deg / 2, sc.n_beams)
    beams = np.flatnonzero((a >= lo - 1e-9) & (a <= hi + 1e-9))
    if not lo < hi or beams.size == 0:
        raise ValueError(f"`angles_deg` must be (low, high), low < high, within +-{sc.fov_deg / 2:g}; "
                         f"got ({lo}, {hi})")
    lines = np.arange(first, first + n)
    T = flight.poses[lines]
    mid = T[n // 2]
    origin = mid[:3, :3] @ np.asarray(sc.mount_m, dtype=float) + mid[:3, 3]
    d = np.einsum("nij,bj->nbi", T[:, :3, :3], scanner_beam_directions(sc)[beams]).reshape(-1, 3)
    r, k, _ = cast_rays_planes(flight.room, origin, d)
    hit = k >= 0
    rho = np.full(len(d), np.nan)
    rho[hit] = flight.room.reflectance(k[hit], origin + r[hit, None] * d[hit])
    x = T[:, :3, 0]                                                  # body x axis in the map: the yaw
    yaw = np.unwrap(np.arctan2(x[:, 1], x[:, 0]))
    step = float(np.rad2deg(np.median(np.abs(np.diff(yaw))))) if n > 1 else float("nan")
    seen, which = np.unique(k[hit], return_inverse=True)
    plane = np.full(len(d), -1)
    plane[hit] = which.ravel()
    return IntensityImage(flight.intensities[np.ix_(lines, beams)].astype(float), rho.reshape(n, len(beams)),
                          lines, beams, a[beams], flight.times_s[lines[[0, -1]]], step, float(sc.step_deg), origin,
                          tuple(flight.room.names[i] for i in seen), plane.reshape(n, len(beams)),
                          float(sc.intensity_gain))
