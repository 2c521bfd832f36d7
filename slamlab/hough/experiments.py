"""Ch. 6 experiments (004 §Hough SLAM): 004's example line, the 121-pose run, the real logs.

Each ``run_*`` returns a frozen dataclass: ``str(result)`` is a one-line summary,
``result.table()`` a fixed-precision text table (the source's figure beside ours where
there is one); timings live in their own field, never in the table.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field

import numpy as np

from .. import _validate as v
from .._table import format_table
from ..geometry import wrap_angle
from .icp import icp_odometry
from .lines import canonical_lines, find_peaks
from .mapping import BuiltMap, build_map, map_agreement
from .slam import HoughSlamParams, HoughSlamResult, hough_slam
from .transform import (
    HoughAccumulator,
    hough_classic,
    hough_cost,
    hough_polar,
    line_scan,
    lines_about_centre,
    rasterise_scan,
)

__all__ = [
    "ExampleLineResult",
    "RealLogResult",
    "SimSlamResult",
    "check_pose_from_two_lines",
    "pose_errors",
    "run_example_line",
    "run_real_log",
    "run_sim_slam",
    "time_polar_vs_opencv",
]


def pose_errors(estimate, truth) -> np.ndarray:
    """``(Ex, Ey, Ea)`` per pose: estimate minus truth, heading wrapped (004 Fig. 10).

    >>> pose_errors([[1.0, 2.0, 0.1]], [[0.5, 2.0, 2 * np.pi]]).round(6).tolist()
    [[0.5, 0.0, 0.1]]
    """
    E = v.as_finite_array(estimate, "estimate", ndim=2)
    T = v.as_finite_array(truth, "truth", ndim=2)
    if E.shape != T.shape or E.shape[1] != 3:
        raise ValueError(f"`estimate` and `truth` must both have shape (n, 3); got {E.shape} and {T.shape}")
    err = E - T
    err[:, 2] = wrap_angle(err[:, 2])
    return err


# --- 004's example: the line θ = 45°, p = 10 ---------------------------------------------------


@dataclass(frozen=True)
class ExampleLineResult:
    """Polar vs classic Hough transform of 004's example line (004 Fig. 5-8)."""

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
    """
    phi, r = line_scan(rho, math.radians(theta_deg), r_max=r_max, delta_phi_rad=math.radians(delta_phi_deg))
    n_repeat = v.check_int(n_repeat, "n_repeat", minimum=1)
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


# --- 004's experiment: the 121-pose path on the test room -------------------------------------


@dataclass(frozen=True)
class SimSlamResult:
    """Hough SLAM, integrated odometry and ICP on 004's path (004 Fig. 9-11)."""

    truth: np.ndarray = field(repr=False)  # (n, 3)
    slam: HoughSlamResult = field(repr=False)
    odometry: np.ndarray = field(repr=False)  # (n, 3) integrated odometry
    icp: np.ndarray | None = field(repr=False)  # (n, 3) chained ICP, None when not run
    built_map: BuiltMap = field(repr=False)
    reference_map: np.ndarray = field(repr=False)
    range_std_cells: float = 0.0
    clutter: bool = False
    timing_s: dict = field(default_factory=dict, compare=False)

    @property
    def errors(self) -> dict[str, np.ndarray]:
        """``(n, 3)`` errors (Ex, Ey, Ea) of each method."""
        out = {"Hough SLAM": pose_errors(self.slam.poses, self.truth),
               "odometry": pose_errors(self.odometry, self.truth)}
        if self.icp is not None:
            out["ICP"] = pose_errors(self.icp, self.truth)
        return out

    def __str__(self) -> str:
        e = self.errors["Hough SLAM"]
        return (f"Hough SLAM on {self.truth.shape[0]} poses: max |Ex| {np.abs(e[:, 0]).max():.2f}, "
                f"|Ey| {np.abs(e[:, 1]).max():.2f} cells, |Ea| {np.degrees(np.abs(e[:, 2]).max()):.2f}°; "
                f"{int(self.slam.lost.sum())} lost")

    def table(self) -> str:
        rows = []
        for name, e in self.errors.items():
            rows.append([name, f"{np.abs(e[:, 0]).max():.2f}", f"{np.abs(e[:, 1]).max():.2f}",
                         f"{np.degrees(np.abs(e[:, 2]).max()):.2f}",
                         f"{np.hypot(e[-1, 0], e[-1, 1]):.2f}", f"{np.degrees(abs(e[-1, 2])):.2f}"])
        agree = map_agreement(self.built_map, self.reference_map)
        title = (f"{self.truth.shape[0]} poses, range σ {self.range_std_cells:g} cell, clutter "
                 f"{'on' if self.clutter else 'off'}; {int(self.slam.lost.sum())} lost steps; built map: "
                 f"{agree['precision']:.0%} of obstacle cells on a true obstacle (±1 cell)")
        return format_table(["method", "max |Ex|", "max |Ey|", "max |Ea| [°]", "final pos err", "final |Ea| [°]"],
                            rows, title=title)


def run_sim_slam(n_poses: int = 121, *, range_std_cells: float = 0.1, clutter: bool = False,
                 n_beams: int = 360, max_range_cells: float = 100.0, odometry_noise: float = 1.0,
                 with_icp: bool = True, start: str = "truth", params: HoughSlamParams | None = None,
                 rng=2010, **overrides) -> SimSlamResult:
    """004's experiment: Hough SLAM along the 121-pose path on the test room (004 Fig. 9-11).

    Δθ = 1°, Δrho = 1 cell, ranges quantised to 0.1 cell (004). Our choices (004 gives none):
    360 beams over 360°, range noise σ = ``range_std_cells``, and odometry with 5 % translation
    noise, 0.01 rad heading noise and a drift of 0.002 rad per cell, all times
    ``odometry_noise``. The SLAM starts from the true pose (004: correlation localisation gives
    it). ``clutter`` measures in the room with unmapped chair legs, people and bins.

    Parameters
    ----------
    n_poses : int
        Poses along the path (121 in 004).
    with_icp : bool
        Also run the ICP baseline (scan-to-scan, odometry as the initial guess).
    start : {"truth", "correlation"}
        Where the SLAM starts: the true first pose, or the pose that correlation localisation
        (:func:`slamlab.correlation.localise`, Δα = 1°, on the mapped room) finds from the first
        scan — 004's whole system (Fig. 2). The ICP baseline and odometry start from the truth.
    params, **overrides
        :class:`HoughSlamParams` and fields to change.
    """
    from .. import sim

    n_poses = v.check_int(n_poses, "n_poses", minimum=5)
    sigma = v.check_positive(range_std_cells, "range_std_cells", allow_zero=True)
    start = v.check_choice(start, "start", ("truth", "correlation"))
    noise = v.check_positive(odometry_noise, "odometry_noise", allow_zero=True)
    seeds = np.random.SeedSequence(rng if isinstance(rng, (int, np.integer)) else None).spawn(2) \
        if not isinstance(rng, np.random.Generator) else rng.spawn(2)
    room = sim.test_room_200()
    world = sim.measurement_room_200() if clutter else room
    truth = sim.path_004(n_poses)
    rf = sim.Rangefinder(n_beams=n_beams, max_range_cells=max_range_cells, range_std_cells=sigma,
                         quantum_cells=0.1)
    timing = {}
    t0 = time.perf_counter()
    scans = sim.simulate_scans(world, truth, rf, rng=np.random.default_rng(seeds[0]))
    odo = sim.simulate_odometry(truth, trans_std_frac=0.05 * noise, rot_std_rad=0.01 * noise,
                                drift_rad_per_cell=0.002 * noise, rng=np.random.default_rng(seeds[1]))
    timing["simulate"] = time.perf_counter() - t0
    S = [(s.angles_rad, s.ranges_cells, s.hit) for s in scans]
    start_pose = truth[0]
    if start == "correlation":
        from ..correlation import localise

        t0 = time.perf_counter()
        start_pose = localise(room, scans[0], delta_alpha_rad=math.radians(1.0)).pose
        timing["correlation"] = time.perf_counter() - t0
    t0 = time.perf_counter()
    res = hough_slam(S, start_pose, odo.increments, params, **overrides)
    timing["hough_slam"] = time.perf_counter() - t0
    icp_poses = None
    if with_icp:
        t0 = time.perf_counter()
        pts = [np.column_stack([r[h] * np.cos(a[h]), r[h] * np.sin(a[h])]) for a, r, h in S]
        icp_poses, _ = icp_odometry(pts, truth[0], odo.increments, max_dist=3.0)
        timing["icp"] = time.perf_counter() - t0
    t0 = time.perf_counter()
    built = build_map(S, res.poses, shape=room.shape, origin=(0.0, 0.0), free_step=1.0)
    timing["build_map"] = time.perf_counter() - t0
    return SimSlamResult(truth, res, odo.poses, icp_poses, built, room, sigma, bool(clutter), timing)


# --- real laser logs ---------------------------------------------------------------------------


@dataclass(frozen=True)
class RealLogResult:
    """Hough SLAM on a real log beside integrated odometry (no ground truth in these logs)."""

    name: str
    slam: HoughSlamResult = field(repr=False)
    odometry: np.ndarray = field(repr=False)  # (n, 3)
    scans: list = field(repr=False)
    map_slam: BuiltMap = field(repr=False)
    map_odometry: BuiltMap = field(repr=False)
    scan_index: np.ndarray = field(repr=False)  # which scans of the log were used
    timing_s: dict = field(default_factory=dict, compare=False)

    @property
    def path_length_m(self) -> float:
        """Length of the odometry path."""
        return float(np.hypot(*np.diff(self.odometry[:, :2], axis=0).T).sum())

    def sharpness(self, which: str = "slam") -> float:
        """Obstacle cells per 100 returns in the built map: fewer = walls drawn thinner (our measure)."""
        m = self.map_slam if which == "slam" else self.map_odometry
        return float(100.0 * (m.grid == 1).sum() / max(1, m.hits.sum()))

    def __str__(self) -> str:
        return (f"{self.name}: {self.odometry.shape[0]} scans, {self.path_length_m:.1f} m of odometry path; "
                f"{int(self.slam.lost.sum())} steps fell back on odometry, {int(self.slam.partial.sum())} in part")

    def table(self) -> str:
        d = self.slam.poses[-1] - self.odometry[-1]
        rows = [
            ["scans used", f"{self.odometry.shape[0]}"],
            ["odometry path length [m]", f"{self.path_length_m:.1f}"],
            ["median lines per scan", f"{np.median(self.slam.n_lines):.0f}"],
            ["steps with only parallel lines (move along them from odometry)",
             f"{self.slam.partial.mean():.0%}"],
            ["steps without usable lines (odometry used)", f"{self.slam.lost.mean():.0%}"],
            ["final position, Hough SLAM - odometry [m]", f"{math.hypot(d[0], d[1]):.1f}"],
            ["final heading, Hough SLAM - odometry [°]", f"{math.degrees(float(wrap_angle(d[2]))):.0f}"],
            ["obstacle cells per 100 returns, Hough SLAM map", f"{self.sharpness('slam'):.1f}"],
            ["obstacle cells per 100 returns, odometry map", f"{self.sharpness('odometry'):.1f}"],
        ]
        return format_table(["quantity", "value"], rows, title=self.name)


#: Per-log settings (ours): file, rho resolution, thresholds in metres.
_LOGS = {
    "urg04lx": {"file": "mines-urg04lx-odometry/exp2.dat",
                "params": {"delta_rho": 0.02, "H_min": 15, "a": 0.15, "max_gap": 0.2, "rho_tol": 0.05,
                           "band": 0.03, "r_max": 4.0}},
    "mbicp": {"file": "mbicp-laserazos-sick/laserazosSM3.log",
              "params": {"delta_rho": 0.02, "H_min": 15, "a": 0.15, "max_gap": 0.3, "rho_tol": 0.05,
                         "band": 0.03, "r_max": 8.0}},
}


def _load_log(name):
    from ..data import find_data

    path = find_data(_LOGS[name]["file"])
    if name == "urg04lx":
        from ..io.urg04lx import read_urg04lx_log, urg04lx_odometry, urg04lx_sensor_increments

        log = read_urg04lx_log(path)
        scans = [log.scan(k) for k in range(len(log))]
        start = np.zeros(3)
        from ..sim import compose_poses

        odo = compose_poses(start, urg04lx_sensor_increments(urg04lx_odometry(log.ticks)))
        return scans, odo
    from ..io.carmen import read_carmen

    log = read_carmen(path)
    scans = [log.scan_cells(k, 1.0) for k in range(log.n_scans)]
    return scans, log.odom_poses.copy()


def run_real_log(name: str = "urg04lx", *, n_scans: int | None = None, step: int = 1, cell_m: float = 0.05,
                 params: HoughSlamParams | None = None, **overrides) -> RealLogResult:
    """Hough SLAM on a real log with raw odometry: the URG-04LX log or the MbICP SICK log.

    Parameters
    ----------
    name : {"urg04lx", "mbicp"}
    n_scans : int, optional
        Use only the first ``n_scans`` scans of the log (after ``step``).
    step : int
        Use every ``step``-th scan.
    cell_m : float
        Cell of the built maps.
    params, **overrides
        Defaults are our per-log settings (Δrho = 2 cm, H_min = 15, a = 0.15 m, ...).
    """
    name = v.check_choice(name, "name", tuple(_LOGS))
    step = v.check_int(step, "step", minimum=1)
    cell_m = v.check_positive(cell_m, "cell_m")
    timing = {}
    t0 = time.perf_counter()
    scans, odo = _load_log(name)
    timing["read"] = time.perf_counter() - t0
    idx = np.arange(0, len(scans), step)
    if n_scans is not None:
        idx = idx[: v.check_int(n_scans, "n_scans", minimum=2)]
    scans = [scans[k] for k in idx]
    odo = odo[idx]
    from ..sim import relative_poses

    U = relative_poses(odo)
    base = HoughSlamParams(**_LOGS[name]["params"]) if params is None else params
    t0 = time.perf_counter()
    res = hough_slam(scans, odo[0], U, base, **overrides)
    timing["hough_slam"] = time.perf_counter() - t0
    t0 = time.perf_counter()
    pts = np.concatenate([odo[:, :2], res.poses[:, :2]])
    lo = pts.min(axis=0) - 9.0
    span = np.ceil((pts.max(axis=0) + 9.0 - lo) / cell_m).astype(int)
    shape = (int(span[1]), int(span[0]))
    m_slam = build_map(scans, res.poses, shape=shape, cell=cell_m, origin=tuple(lo), free_space=False)
    m_odo = build_map(scans, odo, shape=shape, cell=cell_m, origin=tuple(lo), free_space=False)
    timing["build_map"] = time.perf_counter() - t0
    title = {"urg04lx": "Mines URG-04LX log exp2.dat (raw wheel odometry)",
             "mbicp": "MbICP SICK log laserazosSM3.log (raw odometry)"}[name]
    return RealLogResult(title, res, odo, scans, m_slam, m_odo, idx, timing)


def check_pose_from_two_lines(n_cases: int = 1000, *, rng=2010) -> float:
    """Largest error of :func:`~slamlab.hough.pose.pose_from_two_lines` on exact random cases (004; our check).

    Each case: a random pose change and two non-parallel lines; the lines seen
    after the move are put into the flipped ``(-rho, theta + 180°)`` form and
    back, then the pose is recovered. Returns ``max |estimate - truth|``.
    """
    from .lines import align_lines, transform_lines
    from .pose import pose_from_two_lines

    n_cases = v.check_int(n_cases, "n_cases", minimum=1)
    g = v.as_rng(rng)
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
    """
    import cv2

    phi = np.linspace(-0.75 * np.pi, 0.75 * np.pi, v.check_int(n_beams, "n_beams", minimum=2))
    r = room_half_m / np.maximum(np.abs(np.cos(phi)), np.abs(np.sin(phi)))
    img, _ = rasterise_scan(phi, r, cell=cell_m, r_max=r_max_m)

    def median_s(fn):
        fn()
        t = []
        for _ in range(v.check_int(repeats, "repeats", minimum=1)):
            t0 = time.perf_counter()
            fn()
            t.append(time.perf_counter() - t0)
        return float(np.median(t))

    ours = median_s(lambda: hough_polar(phi, r, delta_rho=cell_m, r_max=r_max_m))
    ref = median_s(lambda: cv2.HoughLines(img, 1, np.pi / 180, 30))
    return {"ours_s": ours, "opencv_s": ref, "image_px": img.shape[0], "ratio": ref / ours}
