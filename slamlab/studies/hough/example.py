"""004's example line (004 Fig. 5-8: both transforms, their sizes and costs), the transforms' timing and the
exact check of the two-line pose formula. Split from :mod:`slamlab.studies.hough.experiments` (which re-exports
every name here)."""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field

import numpy as np

from ..._table import format_table
from ..._validate import as_rng, check_int
from ...hough.lines import canonical_lines, find_peaks
from ...hough.transform import (
    HoughAccumulator,
    hough_classic,
    hough_cost,
    hough_polar,
    line_scan,
    lines_about_centre,
    rasterise_scan,
)

__all__ = ["ExampleLineResult", "check_pose_from_two_lines", "run_example_line", "time_polar_vs_opencv"]


@dataclass(frozen=True)
class ExampleLineResult:
    """Polar vs classic Hough transform of 004's example line (004 Fig. 5-8).

    Attributes
    ----------
    n_points : int
        Beams that hit the line.
    polar_size, classic_size : tuple of int
        Accumulator sizes ``(n_theta, n_rho)``, 004's order.
    image_size : tuple of int
        Size of the rasterised scan [px].
    polar_line : tuple of float
        ``(rho, θ_deg)`` of the polar transform's strongest peak.
    classic_line : tuple of float
        The classic transform's peak, origin at the image corner.
    classic_line_centred : tuple of float
        The same re-expressed about the sensor.
    polar_cost, classic_cost : float
        004's operation counts (eq. (8), (6)).
    polar_votes, classic_votes : int
        Votes of the two peaks.
    timing_s : dict
        Mean time per transform [s] (not compared).
    polar, classic : HoughAccumulator or None
        The accumulators.
    image : numpy.ndarray or None
        The rasterised scan.
    scan : tuple or None
        ``(bearings_rad, ranges)``.
    """

    n_points: int
    polar_size: tuple[int, int]  # (n_theta, n_rho), 004's order
    classic_size: tuple[int, int]
    image_size: tuple[int, int]
    polar_line: tuple[float, float]  # (rho, θ_deg) of the strongest peak
    classic_line: tuple[float, float]  # as found, origin at the image corner
    classic_line_centred: tuple[float, float]  # re-expressed about the sensor
    polar_cost: float
    classic_cost: float
    polar_votes: int
    classic_votes: int
    timing_s: dict = field(default_factory=dict, compare=False)
    polar: HoughAccumulator | None = field(default=None, repr=False, compare=False)
    classic: HoughAccumulator | None = field(default=None, repr=False, compare=False)
    image: np.ndarray | None = field(default=None, repr=False, compare=False)
    scan: tuple | None = field(default=None, repr=False, compare=False)

    def __str__(self) -> str:
        return (f"004's line (θ = 45°, rho = 10): polar accumulator {self.polar_size[0]}×{self.polar_size[1]}, "
                f"classic {self.classic_size[0]}×{self.classic_size[1]}")

    def table(self) -> str:
        """004's sizes and lines beside ours (fixed precision).

        Returns
        -------
        str
        """
        rows = [
            ["scan points N", "-", f"{self.n_points}"],
            ["input image (classic)", "33×33", f"{self.image_size[0]}×{self.image_size[1]}"],
            ["accumulator, polar (θ × rho)", "180×33", f"{self.polar_size[0]}×{self.polar_size[1]}"],
            ["accumulator, classic (θ × rho)", "180×93", f"{self.classic_size[0]}×{self.classic_size[1]}"],
            ["line found, polar (rho, θ°)", "(10, 45)", f"({self.polar_line[0]:.1f}, {self.polar_line[1]:.1f})"],
            ["line found, classic, image corner", "-", f"({self.classic_line[0]:.1f}, {self.classic_line[1]:.1f})"],
            ["line found, classic, about the sensor", "(10, 45)",
             f"({self.classic_line_centred[0]:.1f}, {self.classic_line_centred[1]:.1f})"],
            ["votes of the peak, polar / classic", "-", f"{self.polar_votes} / {self.classic_votes}"],
            ["cost N·180/Δθ (eq. 8)", "-", f"{self.polar_cost:.0f}"],
            ["cost (r_max/Δr)²·180/Δθ, image side (eq. 6)", "-", f"{self.classic_cost:.0f}"],
        ]
        return format_table(["quantity", "004", "ours"], rows)


def run_example_line(rho: float = 10.0, theta_deg: float = 45.0, r_max: float = 16.0,
                     delta_phi_deg: float = 1.0, n_repeat: int = 200) -> ExampleLineResult:
    """004's example: ranges to the line θ = 45°, p = 10, both transforms, their sizes and costs.

    The beam step (1°) is ours: 004 does not give it. ``n_repeat`` sets how many times
    each transform is timed (``timing_s``).

    Parameters
    ----------
    rho : float, default 10.0
        Distance of the line [cells].
    theta_deg : float, default 45.0
        Direction of its normal [deg].
    r_max : float, default 16.0
        Longest range [cells].
    delta_phi_deg : float, default 1.0
        Beam step [deg].
    n_repeat : int, default 200
        Timing repetitions.

    Returns
    -------
    ExampleLineResult
    """
    phi, r = line_scan(rho, math.radians(theta_deg), r_max=r_max, delta_phi_rad=math.radians(delta_phi_deg))
    n_repeat = check_int(n_repeat, "n_repeat", minimum=1)
    polar = hough_polar(phi, r, r_max=r_max)
    img, c = rasterise_scan(phi, r, r_max=r_max)
    classic = hough_classic(img)
    lp = find_peaks(polar, max(2, phi.size // 2), max_lines=1)
    lc = find_peaks(classic, 2, max_lines=1)
    rc, tc = lines_about_centre(lc.rho, lc.theta_rad, c)
    rc, tc = canonical_lines(rc, tc)
    timing = {}
    for name, fn in (("polar", lambda: hough_polar(phi, r, r_max=r_max)),
                     ("rasterise + classic", lambda: hough_classic(rasterise_scan(phi, r, r_max=r_max)[0]))):
        t0 = time.perf_counter()
        for _ in range(n_repeat):
            fn()
        timing[name] = (time.perf_counter() - t0) / n_repeat
    return ExampleLineResult(
        int(phi.size), polar.size_theta_rho, classic.size_theta_rho, img.shape,
        (float(lp.rho[0]), math.degrees(float(lp.theta_rad[0]))),
        (float(lc.rho[0]), math.degrees(float(lc.theta_rad[0]))),
        (float(rc[0]), math.degrees(float(tc[0]))),
        hough_cost(n_points=int(phi.size)), hough_cost(r_max=float(img.shape[0])),
        int(lp.votes[0]), int(lc.votes[0]), timing, polar, classic, img, (phi, r))


def check_pose_from_two_lines(n_cases: int = 1000, *, rng=2010) -> float:
    """Largest error of :func:`~slamlab.hough.pose.pose_from_two_lines` on exact random cases (004; our check).

    Each case: a random pose change and two non-parallel lines; the lines seen
    after the move are put into the flipped ``(-rho, theta + 180°)`` form and
    back, then the pose is recovered. Returns ``max |estimate - truth|``.

    Parameters
    ----------
    n_cases : int, default 1000
        Random cases.
    rng : int or numpy.random.Generator, default 2010
        Seed or generator.

    Returns
    -------
    float
        Largest absolute error over cases and pose components.
    """
    from ...hough.lines import align_lines, transform_lines
    from ...hough.pose import pose_from_two_lines

    n_cases = check_int(n_cases, "n_cases", minimum=1)
    g = as_rng(rng)
    worst = 0.0
    for _ in range(n_cases):  # a closed-form check per case, cheap
        pose = g.uniform([-2, -2, -0.5], [2, 2, 0.5])
        ri, ti = g.uniform(-8, 8, 2), g.uniform(-1.5, 1.5) + np.array([0.0, g.uniform(0.6, 2.5)])
        rj, tj = transform_lines(ri, ti, pose)
        rj, tj = canonical_lines(-rj, tj + np.pi)  # the flipped form
        rj, tj = align_lines(rj, tj, ti - pose[2])  # back to the continuous one
        got = pose_from_two_lines((ri[0], ti[0]), (ri[1], ti[1]), (rj[0], tj[0]), (rj[1], tj[1]))
        worst = max(worst, float(np.abs(got - pose).max()))
    return worst


def time_polar_vs_opencv(*, cell_m: float = 0.05, r_max_m: float = 30.0, room_half_m: float = 5.0,
                         n_beams: int = 1081, repeats: int = 20) -> dict:
    """Median times of our polar transform and ``cv2.HoughLines`` on the same 1081-beam scan (004; our addition).

    The scan is a square room (``room_half_m`` to each wall) seen over 270°;
    OpenCV gets the scan rasterised at ``cell_m``. Returns the times in seconds,
    the image size and the ratio OpenCV / ours (volatile: print only in ignored cells).

    Parameters
    ----------
    cell_m : float, default 0.05
        Pixel size of OpenCV's image and our Δrho [m].
    r_max_m : float, default 30.0
        Longest range [m].
    room_half_m : float, default 5.0
        Distance to each wall [m].
    n_beams : int, default 1081
        Beams over 270°.
    repeats : int, default 20
        Timed repetitions.

    Returns
    -------
    dict
        ``ours_s``, ``opencv_s``, ``image_px``, ``ratio``.
    """
    import cv2

    phi = np.linspace(-0.75 * np.pi, 0.75 * np.pi, check_int(n_beams, "n_beams", minimum=2))
    r = room_half_m / np.maximum(np.abs(np.cos(phi)), np.abs(np.sin(phi)))
    img, _ = rasterise_scan(phi, r, cell=cell_m, r_max=r_max_m)

    def median_s(fn):
        fn()
        t = []
        for _ in range(check_int(repeats, "repeats", minimum=1)):
            t0 = time.perf_counter()
            fn()
            t.append(time.perf_counter() - t0)
        return float(np.median(t))

    ours = median_s(lambda: hough_polar(phi, r, delta_rho=cell_m, r_max=r_max_m))
    ref = median_s(lambda: cv2.HoughLines(img, 1, np.pi / 180, 30))
    return {"ours_s": ours, "opencv_s": ref, "image_px": img.shape[0], "ratio": ref / ours}
