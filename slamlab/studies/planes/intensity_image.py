"""002 Fig. 3: the image made of the scan lines' intensities, beside the room it shows (ours: the room model).

002 Fig. 3 shows "a photo of a part of the room and its view obtained by collecting the lines of reflected-signal
intensities of the laser rangefinder". Ours: the intensities of a run of consecutive lines of a simulated flight
(rows: scan lines, columns: beam index), and in place of the photo the room model's reflectance panels seen from
one point (the scanner at the middle line) along the same beam directions: no noise, no incidence factor, no
motion of the vehicle during the lines. The image is made from a flight by
:func:`~slamlab.studies.planes.scan_intensity_image` (the experiments module, which simulates).
"""

from __future__ import annotations

import textwrap
from dataclasses import dataclass

import numpy as np

__all__ = ["IntensityImage"]


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
