"""Ch. 10 experiments (002): the frames of a simulated flight, a flight (Fig. 8, Fig. 9, ATE/RPE), the stage
timing table beside 002's, and Fig. 4's scene; the Fig. 2 and Fig. 4 runs live in
:mod:`slamlab.studies.planes.figures`, the ablations in :mod:`slamlab.studies.planes.ablations` (this is the module
of the package that uses the simulator).

Each ``run_*`` returns a frozen dataclass: ``str()`` a one-line summary, ``.table()`` a
fixed-precision text table (printed in the notebook, compared by nbval); timings live
in their own fields and in ``timing_table()``, never in ``table()``.
"""

from __future__ import annotations

import dataclasses
import time

import numpy as np
from scipy.spatial.transform import Rotation

from ..._progress import progress_bar
from ..._table import format_table
from ..._validate import as_rng, as_vector, check_choice, check_int, check_positive
from ...evaluation import Trajectory, ate, rpe
from ...geometry.so3 import so3_log
from ...planes.extraction import Frame, build_frame
from ...planes.filter import STAGES, PlaneSLAM, PlaneSLAMParams
from ...sim.planes_room import (
    Flight,
    PlaneRoom,
    build_corridor,
    cast_rays_planes,
    scanner_beam_directions,
    simulate_flight,
)
from .intensity_image import IntensityImage
from .reports import GOAL_S, SOURCE_TIMES_S, FlightResult, ours_vs_source, timing_goal, timing_table

__all__ = [
    "GOAL_S",
    "POSE_SOURCES",
    "SOURCE_TIMES_S",
    "FlightResult",
    "euler_errors",
    "flight_frames",
    "flight_head",
    "in_frame_rotation_error_deg",
    "ours_vs_source",
    "run_flight",
    "setup_table",
    "three_plane_room",
    "timing_goal",
    "timing_table",
]

SIZES = {"small": 6.0, "medium": 20.0, "full": 60.0}


#: where the frame building and the odometry increments take their poses from (ours: "truth" is an ablation)
POSE_SOURCES = ("odometry", "truth")


def _poses(flight: Flight, source: str, name: str) -> np.ndarray:
    check_choice(source, name, POSE_SOURCES)
    return flight.odometry if source == "odometry" else flight.poses


def flight_frames(flight: Flight, frame_lines: int = 40, *, frame_poses: str = "odometry",
                  increment_poses: str = "odometry"):
    """Yield ``(k, frame, odometry_increment, true_pose)`` per frame of ``frame_lines`` lines (002).

    002 moves the lines of a frame into the last line's pose with the odometry and predicts with the odometry's
    increment; ``frame_poses="truth"`` / ``increment_poses="truth"`` use the true poses instead (ours: ablations
    that remove the odometry's error from the frame, or from the prediction).

    Parameters
    ----------
    flight : slamlab.sim.Flight
        The simulated flight.
    frame_lines : int
        Scan lines per frame (002: ~1 s = 40 lines).
    frame_poses : {'odometry', 'truth'}
        Poses that move a frame's lines into its last line's pose.
    increment_poses : {'odometry', 'truth'}
        Poses whose increment between frames is the prediction's input.

    Yields
    ------
    k : int
        Frame index.
    frame : Frame
        The frame's points in the last line's body frame.
    odometry_increment : (4, 4) float
        Pose increment since the previous frame (identity for the first).
    true_pose : (4, 4) float
        True pose of the frame's last line.
    """
    frame_lines = check_int(frame_lines, "frame_lines", minimum=1)
    T_frame = _poses(flight, frame_poses, "frame_poses")
    T_inc = _poses(flight, increment_poses, "increment_poses")
    prev = None
    for k in range(len(flight) // frame_lines):
        s = slice(k * frame_lines, (k + 1) * frame_lines)
        last = (k + 1) * frame_lines - 1
        fr = build_frame(flight.body_points(s), flight.intensities[s], T_frame[s], origin_m=flight.scanner.mount_m)
        U = np.eye(4) if prev is None else np.linalg.inv(T_inc[prev]) @ T_inc[last]
        prev = last
        yield k, fr, U, flight.poses[last]


def flight_head(flight: Flight, duration_s: float) -> Flight:
    """The first ``duration_s`` seconds of ``flight`` (the same lines, poses and odometry; ours).

    Parameters
    ----------
    flight : slamlab.sim.Flight
        The flight to cut.
    duration_s : float
        Seconds kept (at most the flight's length).

    Returns
    -------
    slamlab.sim.Flight
    """
    if not isinstance(flight, Flight):
        raise TypeError(f"`flight` must be a Flight; got {type(flight).__name__}")
    n = round(check_positive(duration_s, "duration_s") * flight.scanner.lines_per_s)
    if n > len(flight):
        raise ValueError(f"`duration_s` = {duration_s} s is longer than the flight ({len(flight)} lines)")
    return dataclasses.replace(flight, times_s=flight.times_s[:n], poses=flight.poses[:n],
                               odometry=flight.odometry[:n], ranges_m=flight.ranges_m[:n],
                               intensities=flight.intensities[:n], plane_ids=flight.plane_ids[:n])


def euler_errors(T_est, T_true) -> np.ndarray:
    """Per pose ``(F, 6)``: x, y, z errors [m] (map frame) and roll, pitch, yaw [deg] of ``T_trueᵀ T_est``.

    Parameters
    ----------
    T_est : (F, 4, 4) float
        Estimated poses (body → map).
    T_true : (F, 4, 4) float
        True poses.

    Returns
    -------
    (F, 6) float
        Position errors in metres, then xyz Euler angles of the rotation error in degrees.
    """
    dpos = T_est[:, :3, 3] - T_true[:, :3, 3]
    dR = np.swapaxes(T_true[:, :3, :3], 1, 2) @ T_est[:, :3, :3]
    return np.c_[dpos, np.rad2deg(Rotation.from_matrix(dR).as_euler("xyz"))]


def in_frame_rotation_error_deg(flight: Flight, frame_lines: int = 40) -> np.ndarray:
    """RMS per axis ``(3,)`` [deg] of the odometry's error in the relative pose of each line to its frame's last
    line: the rotation error with which 002's frame building moves the lines (ours).

    Parameters
    ----------
    flight : slamlab.sim.Flight
        The flight (odometry and true poses per line).
    frame_lines : int
        Scan lines per frame.

    Returns
    -------
    (3,) float
        RMS rotation-vector error per axis in degrees.
    """
    frame_lines = check_int(frame_lines, "frame_lines", minimum=1)
    n = (len(flight) // frame_lines) * frame_lines
    last = (np.arange(n) // frame_lines + 1) * frame_lines - 1
    To, Tt = flight.odometry, flight.poses
    Ro = np.swapaxes(To[last, :3, :3], 1, 2) @ To[:n, :3, :3]
    Rt = np.swapaxes(Tt[last, :3, :3], 1, 2) @ Tt[:n, :3, :3]
    e = np.rad2deg(so3_log(np.swapaxes(Rt, 1, 2) @ Ro))
    return np.sqrt(np.mean(e**2, axis=0))


def flight_or_simulate(flight: Flight | None, duration_s: float, rng) -> Flight:
    """``flight`` checked, or a new one of ``duration_s`` seconds simulated from ``rng`` (int, SeedSequence or
    Generator) — the first of two streams spawned from a fresh copy of its SeedSequence, the flight
    :func:`run_flight` simulates for the same ``rng`` (ours).

    Parameters
    ----------
    flight : slamlab.sim.Flight or None
        A ready flight, returned as is.
    duration_s : float
        Seconds to simulate when ``flight`` is None.
    rng : int, numpy.random.SeedSequence or numpy.random.Generator
        Randomness of the simulated flight.

    Returns
    -------
    slamlab.sim.Flight
    """
    from ...sweep import fresh_seed_sequence

    if flight is None:
        seed = fresh_seed_sequence(rng).spawn(2)[0]
        return simulate_flight(check_positive(duration_s, "duration_s"), rng=np.random.default_rng(seed))
    if not isinstance(flight, Flight):
        raise TypeError(f"`flight` must be a Flight or None; got {type(flight).__name__}")
    return flight


# --- 002 Fig. 4's scene (the experiment itself: slamlab.studies.planes.figures) ----------------------------
def three_plane_room(length_m: float = 12.0, width_m: float = 3.0, height_m: float = 3.0, *, panel_m: float = 1.0,
                     rng=0) -> PlaneRoom:
    """002 Fig. 4's scene: "three planes, two of which are parallel" — two parallel walls and the floor (ours:
    :func:`~slamlab.sim.build_corridor` without its ceiling; 1 m panels of two reflectances).

    Parameters
    ----------
    length_m, width_m, height_m : float
        Corridor size in metres.
    panel_m : float
        Side of the reflectance panels in metres.
    rng : numpy.random.Generator, int or None
        Randomness of the panels' reflectances.

    Returns
    -------
    slamlab.sim.PlaneRoom
        Planes "y-", "y+" and "z-".

    Examples
    --------
    >>> three_plane_room().names
    ('y-', 'y+', 'z-')
    """
    c = build_corridor(length_m, width_m, height_m, panel_m=panel_m, rng=rng)
    k = [i for i, n in enumerate(c.names) if n != "z+"]
    return PlaneRoom(c.centres[k], c.normals[k], c.axes_u[k], c.axes_v[k], c.half_u[k], c.half_v[k], c.panels[k],
                     c.panel_m, tuple(c.names[i] for i in k))


def offset_frames(offset_m: float, rng) -> tuple[list[Flight], list[Frame]]:
    """Fig. 4's two one-second hovers in :func:`three_plane_room`: at a start pose and ``offset_m`` further along
    the walls (perfect odometry); their flights and frames (ours).

    Parameters
    ----------
    offset_m : float
        Distance between the two hover positions along the walls, metres.
    rng : numpy.random.Generator, int or None
        Randomness of the room and the flights.

    Returns
    -------
    flights : list of 2 slamlab.sim.Flight
    frames : list of 2 Frame
        The first frame of each flight.
    """
    g = as_rng(rng)
    room = three_plane_room(rng=g.integers(2**31))
    start = np.array([5.0, 1.5, 1.5])
    flights = []
    for x in (0.0, float(offset_m)):
        wp = [start + np.array([x, 0, 0]), start + np.array([x + 1, 0, 0])]
        flights.append(simulate_flight(1.0, room=room, speed_m_s=0.0, waypoints_m=wp, odometry_noise=0.0,
                                       rng=g.integers(2**31)))
    return flights, [next(flight_frames(f, 40))[1] for f in flights]


def run_flight(duration_s: float | None = None, *, size: str = "small", frame_lines: int = 40,
               params: PlaneSLAMParams | None = None, flight: Flight | None = None, rng=0,
               frame_poses: str = "odometry", increment_poses: str = "odometry",
               progress: bool | None = None, **overrides) -> FlightResult:
    """Fly the room and run the filter on every frame (002 "Experimental trial"; ours: the simulator).

    ``duration_s`` (default by ``size``: small 6 s, medium 20 s, full 60 s), ``frame_lines`` lines per frame
    (002: ~1 s = 40 lines), ``params`` plus overrides for :class:`PlaneSLAMParams`, ``flight`` a ready
    :class:`~slamlab.sim.Flight` (else simulated from ``rng``); ``frame_poses``, ``increment_poses``: see
    :func:`~slamlab.studies.planes.flight_frames` ("odometry" is 002's; "truth" an ablation of ours).

    Parameters
    ----------
    duration_s : float, optional
        Flight length in seconds (default by ``size``).
    size : {'small', 'medium', 'full'}
        6, 20 or 60 s when ``duration_s`` is None.
    frame_lines : int
        Scan lines per frame.
    params : PlaneSLAMParams, optional
        Filter settings (defaults when None).
    flight : slamlab.sim.Flight, optional
        A ready flight (else simulated from ``rng``).
    rng : int, numpy.random.SeedSequence or numpy.random.Generator
        Randomness of the simulated flight and of the filter (two spawned streams).
    frame_poses, increment_poses : {'odometry', 'truth'}
        See :func:`flight_frames`.
    progress : bool, callable or None
        Progress bar over the frames.
    **overrides
        :class:`PlaneSLAMParams` fields that replace those of ``params``.

    Returns
    -------
    FlightResult
        Per-frame poses and errors, ATE/RPE, the map, the stage timings.
    """
    p = PlaneSLAMParams.resolve(params, **overrides)
    if duration_s is None:
        check_choice(size, "size", tuple(SIZES))
        duration_s = SIZES[size]
    from ...sweep import fresh_seed_sequence

    seeds = fresh_seed_sequence(rng).spawn(2)  # a fresh copy: the same streams on every call with this `rng`
    flight = flight_or_simulate(flight, duration_s, rng)
    n_frames = len(flight) // check_int(frame_lines, "frame_lines", minimum=1)
    if n_frames < 2:
        raise ValueError(f"the flight has {len(flight)} lines: fewer than two frames of `frame_lines` = {frame_lines}")
    frames = flight_frames(flight, frame_lines, frame_poses=frame_poses, increment_poses=increment_poses)
    slam = PlaneSLAM(flight.poses[frame_lines - 1], params=p, rng=np.random.default_rng(seeds[1]))
    est, true, odo, times, stage, cpu, nplanes, npoints, noff = [], [], [], [], [], [], [], [], []
    for k, fr, U, T in progress_bar(frames, total=n_frames, desc="flight", progress=progress):
        c0 = time.process_time()
        rep = slam.step(fr, U)
        cpu.append(time.process_time() - c0)
        est.append(slam.pose.copy())
        true.append(T)
        odo.append(flight.odometry[(k + 1) * frame_lines - 1])
        times.append(flight.times_s[(k + 1) * frame_lines - 1])
        stage.append([rep.times_s[s] for s in STAGES])
        nplanes.append(rep.n_planes)
        npoints.append(rep.n_points)
        noff.append(rep.n_points - sum(pl.n_points for pl in slam.last_planes))   # points on no plane
    est, true, odo, ts = np.array(est), np.array(true), np.array(odo), np.array(times)
    tr_true = Trajectory.from_poses(true, ts)
    tr_est = Trajectory.from_poses(est, ts)
    tr_odo = Trajectory.from_poses(odo, ts)
    return FlightResult(ts, true, est, odo, euler_errors(est, true), euler_errors(odo, true),
                        ate(tr_true, tr_est, align="none").rmse, ate(tr_true, tr_odo, align="none").rmse,
                        # an SE(3) alignment needs three poses (Umeyama): NaN for shorter flights
                        ate(tr_true, tr_est).rmse if n_frames >= 3 else float("nan"),
                        ate(tr_true, tr_odo).rmse if n_frames >= 3 else float("nan"),
                        rpe(tr_true, tr_est).rmse, rpe(tr_true, tr_est, relation="rotation_deg").rmse,
                        n_frames, slam.n_kept_prediction, float(np.mean(nplanes)), float(np.mean(npoints)), slam.map,
                        p, np.array(stage), np.array(cpu), frame_points=np.array(npoints, dtype=np.int64),
                        frame_off_plane=np.array(noff, dtype=np.int64))


def setup_table(flight: Flight, frame_lines: int = 40) -> str:
    """002's sensor and frame figures beside those of our simulated ``flight`` (002 "Experimental trial").

    Parameters
    ----------
    flight : slamlab.sim.Flight
        The simulated flight.
    frame_lines : int
        Scan lines per frame.

    Returns
    -------
    str
        A table: quantity, 002, ours.
    """
    if not isinstance(flight, Flight):
        raise TypeError(f"`flight` must be a Flight; got {type(flight).__name__}")
    frame_lines = check_int(frame_lines, "frame_lines", minimum=1)
    sc = flight.scanner
    R = flight.poses[:, :3, :3]
    z = R[:, :, 0]                                                   # body x axis in the map
    yaw = np.unwrap(np.arctan2(z[:, 1], z[:, 0]))
    rate = np.rad2deg(np.median(np.diff(yaw))) * sc.lines_per_s
    frame_s = frame_lines / sc.lines_per_s
    n_frame = np.isfinite(flight.ranges_m[:frame_lines]).sum()
    room = flight.room
    floor = [i for i, n in enumerate(room.names) if n.endswith("z-") and n.startswith("room")]
    area = 4 * room.half_u[floor[0]] * room.half_v[floor[0]] if floor else float("nan")
    rows = [["scan lines per second", "40", f"{sc.lines_per_s:g}"],
            ["angular step [deg]", "0.25", f"{sc.step_deg:g}"],
            ["field of view [deg]", "270", f"{sc.fov_deg:g}"],
            ["points per line", "1081", f"{sc.n_beams}"],
            ["yaw rate [deg/s]", "45", f"{rate:.1f}"],
            ["one frame [s]", "about 1", f"{frame_s:g}"],
            ["sector per frame [deg], two sectors 180 deg apart", "45", f"{rate * frame_s:.1f}"],
            ["points per frame (the first frame)", "over 40000", f"{n_frame}"],
            ["room floor area [m^2]", "about 200", f"{area:.0f}"]]
    return format_table(["quantity", "002", "ours"], rows, title="002's sensor and frame beside our simulation")


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
