"""Ch. 5 experiments (004 §7): Table 1, a Monte Carlo study, the constants a_c/a_p, the corridor tie (the real
CARMEN log: :mod:`~slamlab.studies.correlation.log_experiments`; the closing table: :mod:`~slamlab.studies.correlation.source_table`).

Every ``run_*`` takes ``params=`` (a :class:`~slamlab.correlation.LocaliseParams`, the
same settings and defaults as :func:`~slamlab.correlation.localise`) plus overrides
of its fields.

Each ``run_*`` returns a frozen dataclass: ``str(result)`` is a one-line summary,
``result.table()`` a fixed-precision text table (what the notebook prints and
nbval compares); arrays for plotting live in fields, timings in ``time_s``
(never in the table).

This module builds the simulated worlds (the test room, its clutter, the rangefinder) and runs the
experiments on them, each localisation on :func:`slamlab.sweep.sweep`; the result dataclasses live in
:mod:`~slamlab.studies.correlation.study_results`, the sim-free helpers (the success criterion, errors, Table 1's
source values, the corridor, the timing) in :mod:`~slamlab.studies.correlation.studies` (re-exported here).
"""

from __future__ import annotations

import time

import numpy as np

from ..._validate import as_finite_array, as_rng, check_choice, check_int, check_positive
from ...correlation.algorithm import (
    LocaliseParams,
    heading_candidates,
    heading_error,
    localise,
    localise_joined,
    scan_stamps,
)
from ...scans.logmap import log_grid  # log_grid re-exported (one place: scans)
from ...sim.grid import add_clutter, free_cells, measurement_room_200, test_room_200
from ...sim.paths import random_free_poses
from ...sim.rangefinder import Rangefinder
from .aperture import ApertureResult
from .batch import localise_scans, scan_estimates
from .stamp_trim import StampTrimResult, trim_scan
from .studies import (
    FAIL_CELLS,
    FAIL_DEG,
    SOURCE_TABLE1,
    absolute_errors,
    corridor_grid,
    time_localise,
    within_tolerance,
)
from .study_results import ConstantsResult, CorridorResult, MonteCarloResult, Table1Result

__all__ = [
    "CORRIDOR_PARAMS",
    "FAIL_CELLS",
    "FAIL_DEG",
    "SOURCE_TABLE1",
    "ConstantsResult",
    "CorridorResult",
    "MonteCarloResult",
    "Table1Result",
    "corridor_grid",
    "log_grid",
    "random_clutter",
    "run_aperture_study",
    "run_constants_study",
    "run_corridor_tie",
    "run_monte_carlo",
    "run_stamp_trim_study",
    "run_table1",
    "time_localise",
]


def _sensor(n_beams, max_range_cells, range_std_cells, quantum_cells=0.1) -> Rangefinder:
    return Rangefinder(n_beams=n_beams, fov_rad=2 * np.pi, max_range_cells=max_range_cells,
                       range_std_cells=range_std_cells, quantum_cells=quantum_cells)


def _worlds(clutter: bool, extra_clutter: int, rng):
    M = test_room_200()
    W = measurement_room_200() if clutter else M.copy()
    if extra_clutter:
        W = add_clutter(W, random_clutter(W, extra_clutter, rng=rng))
    return M, W


def random_clutter(grid, n: int, *, radius_cells: float = 1.5, margin_cells: int = 3, rng=None) -> list[tuple]:
    """``n`` extra unmapped discs ("people's legs", bins) on free cells of ``grid`` (our addition).

    Parameters
    ----------
    grid : array_like of int, shape (H, W)
        Cell codes; discs are centred on free cells.
    n : int
        Number of discs.
    radius_cells : float, default 1.5
        Disc radius [cells].
    margin_cells : int, default 3
        Centres keep this many cells from obstacles (see :func:`slamlab.sim.grid.free_cells`).
    rng : int or numpy.random.Generator, optional
        Seed or generator of the centres.

    Returns
    -------
    list of tuple
        ``("disc", col, row, radius_cells)`` shapes for :func:`slamlab.sim.grid.add_clutter`.

    Examples
    --------
    >>> len(random_clutter(test_room_200(), 5, rng=0))
    5
    """
    n = check_int(n, "n", minimum=0)
    r = check_positive(radius_cells, "radius_cells")
    rng = as_rng(rng)
    cells = free_cells(grid, margin_cells)
    pick = cells[rng.integers(0, cells.shape[0], n)]
    return [("disc", int(c), int(rw), r) for rw, c in pick]


def run_table1(n_poses: int = 10, *, range_std_cells: float = 0.3, n_beams: int = 360,
               max_range_cells: float = 100.0, clutter: bool = True, params: LocaliseParams | None = None,
               rng=2010, n_jobs: int = 1, progress: bool | None = None, **overrides) -> Table1Result:
    """Localise the robot from no prior at ``n_poses`` random free poses of the test room (004 Table 1).

    The robot stands on whole cells with a uniform random heading; the scan is
    cast in the measurement room (unmapped clutter) with Gaussian range noise and
    0.1-cell quantisation, and localised on the mapped room M by the full 360°
    search. 004 does not give σ, the beam count or the range limit: ours are
    parameters. ``params`` / ``**overrides``: the :class:`LocaliseParams` of every localisation.
    ``n_jobs`` / ``progress``: the localisations run on :func:`slamlab.sweep.sweep` (same result for any ``n_jobs``).

    Parameters
    ----------
    n_poses : int, default 10
        Random free poses.
    range_std_cells : float, default 0.3
        Range noise std [cells].
    n_beams : int, default 360
        Beams over 360°.
    max_range_cells : float, default 100.0
        Range limit [cells].
    clutter : bool, default True
        Cast in the measurement room (unmapped clutter of 004 Fig. 3b); False casts in the map itself.
    params : LocaliseParams, optional
        Settings of every localisation (default :class:`LocaliseParams`).
    rng : int or numpy.random.Generator, default 2010
        Seed or generator of poses and scan noise.
    n_jobs : int, default 1
        Worker processes for the localisations (same result for any value).
    progress : bool or None
        Progress bar: None shows one in a notebook only.
    **overrides
        :class:`LocaliseParams` fields to change.

    Returns
    -------
    Table1Result
    """
    p = LocaliseParams.resolve(params, **overrides)
    n = check_int(n_poses, "n_poses", minimum=1)
    rf = _sensor(n_beams, max_range_cells, range_std_cells)
    rng = as_rng(rng)
    M, W = _worlds(clutter, 0, rng)
    poses = random_free_poses(W, n, margin_cells=2, rng=rng)
    scans = [rf.scan(W, pose, rng) for pose in poses]  # every draw here, in the order of the sequential loop
    t0 = time.perf_counter()
    est = scan_estimates(localise_scans(M, scans, (p,), n_jobs=n_jobs, progress=progress))
    ea, ex, ey = absolute_errors(poses, est)
    return Table1Result(poses, est, ea, ex, ey, float(range_std_cells), int(n_beams), p, time.perf_counter() - t0)

_SIZES = {"small": 12, "full": 200}


def run_monte_carlo(size: str | int = "small", *, range_std_cells: float = 0.3, n_beams: int = 360,
                    max_range_cells: float = 100.0, extra_clutter: int = 0, params: LocaliseParams | None = None,
                    rng=2011, n_jobs: int = 1, progress: bool | None = None, **overrides) -> MonteCarloResult:
    """Full 360° localisation at many random poses: error distribution and failure rate (our addition).

    ``size``: ``"small"`` (12 poses, the notebook), ``"full"`` (200) or an int.
    ``params`` / ``**overrides``: the :class:`LocaliseParams` of every localisation.

    The random part (clutter, poses, then one scan per pose, in that order from ``rng``)
    runs here; the localisations, which draw nothing, run on :func:`slamlab.sweep.sweep`
    with ``n_jobs`` workers (one task per pose; the result is the same for any ``n_jobs``)
    and a progress bar unless ``progress=False`` or ``$SLAMLAB_PROGRESS=0``.

    Parameters
    ----------
    size : {"small", "full"} or int
        Number of poses: "small" 12, "full" 200, or the int itself.
    range_std_cells : float, default 0.3
        Range noise std [cells].
    n_beams : int, default 360
        Beams over 360°.
    max_range_cells : float, default 100.0
        Range limit [cells].
    extra_clutter : int, default 0
        Random unmapped discs added (:func:`random_clutter`).
    params : LocaliseParams, optional
        Settings of every localisation (default :class:`LocaliseParams`).
    rng : int or numpy.random.Generator, default 2011
        Seed or generator of clutter, poses and scan noise.
    n_jobs : int, default 1
        Worker processes for the localisations (same result for any value).
    progress : bool or None
        Progress bar: None shows one in a notebook only.
    **overrides
        :class:`LocaliseParams` fields to change.

    Returns
    -------
    MonteCarloResult
    """
    p = LocaliseParams.resolve(params, **overrides)
    n = _SIZES[check_choice(size, "size", _SIZES)] if isinstance(size, str) else check_int(size, "size",
                                                                                                 minimum=1)
    ec = check_int(extra_clutter, "extra_clutter", minimum=0)
    rf = _sensor(n_beams, max_range_cells, range_std_cells)
    rng = as_rng(rng)
    M, W = _worlds(True, ec, rng)
    poses = random_free_poses(W, n, margin_cells=2, rng=rng)
    scans = [rf.scan(W, pose, rng) for pose in poses]  # every draw here, in the order of the sequential loop
    t0 = time.perf_counter()
    est = scan_estimates(localise_scans(M, scans, (p,), n_jobs=n_jobs, progress=progress))
    ea, ex, ey = absolute_errors(poses, est)
    ep = np.hypot(ex, ey)
    failed = ~within_tolerance(ep, ea)
    return MonteCarloResult(n, ea, ep, failed, float(range_std_cells), ec, time.perf_counter() - t0, params=p)


def run_constants_study(n_poses: int = 12, *, extra_clutter: int = 60, range_std_cells: float = 0.3,
                        n_beams: int = 360, max_range_cells: float = 100.0,
                        choices=((-1.0, 1.0, 0.0), (0.0, 1.0, 0.0)), params: LocaliseParams | None = None,
                        rng=2012, n_jobs: int = 1, progress: bool | None = None, **overrides) -> ConstantsResult:
    """Compare 004's constant choices on the same cluttered scans (004 §7).

    004: the peak is sharpest at ``a_p = -a_c``; with unmapped objects,
    ``a_c = a_n = 0, a_p > 0`` can be more robust. Each choice localises the same
    scans (cast in the room with 004's clutter plus ``extra_clutter`` random
    discs). Our sharpness measures: the half-maximum area of the score map at the
    best heading (cells scoring at least halfway from the median to the peak), the
    heading margin (peak minus the best score ≥ 3° away, over peak minus the median
    over headings), and the failure rate. ``params`` / ``**overrides``: the other
    :class:`LocaliseParams` fields; ``a_c, a_p, a_n`` are this study's axis (``choices``), so setting one of
    them there is a ``ValueError``.

    The scans are drawn here; the ``len(choices) × n_poses`` localisations run on
    :func:`slamlab.sweep.sweep` with ``n_jobs`` workers (same result for any ``n_jobs``)
    and a progress bar unless ``progress=False`` or ``$SLAMLAB_PROGRESS=0``.

    Parameters
    ----------
    n_poses : int, default 12
        Random free poses, the same scans for every choice.
    extra_clutter : int, default 60
        Random unmapped discs added to 004's clutter.
    range_std_cells : float, default 0.3
        Range noise std [cells].
    n_beams : int, default 360
        Beams over 360°.
    max_range_cells : float, default 100.0
        Range limit [cells].
    choices : sequence of tuple of float
        ``(a_c, a_p, a_n)`` triples to compare.
    params : LocaliseParams, optional
        Settings of every localisation (default :class:`LocaliseParams`) but ``a_c, a_p, a_n``, which must keep
        their defaults (each choice sets them).
    rng : int or numpy.random.Generator, default 2012
        Seed or generator of clutter, poses and scan noise.
    n_jobs : int, default 1
        Worker processes for the localisations (same result for any value).
    progress : bool or None
        Progress bar: None shows one in a notebook only.
    **overrides
        :class:`LocaliseParams` fields to change (not ``a_c, a_p, a_n``).

    Returns
    -------
    ConstantsResult
    """
    base = LocaliseParams.resolve(params, **overrides)
    default = LocaliseParams()
    for name in ("a_c", "a_p", "a_n"):
        if getattr(base, name) != getattr(default, name):
            raise ValueError(f"`{name}` is set by `choices` in run_constants_study (each choice is one "
                             f"(a_c, a_p, a_n)); got {name} = {getattr(base, name)} in the settings")
    n = check_int(n_poses, "n_poses", minimum=1)
    ec = check_int(extra_clutter, "extra_clutter", minimum=0)
    settings = tuple(base.replace(a_c=float(c[0]), a_p=float(c[1]), a_n=float(c[2])) for c in choices)
    consts = tuple((q.a_c, q.a_p, q.a_n) for q in settings)
    if not consts:
        raise ValueError("`choices` must hold at least one (a_c, a_p, a_n) triple")
    rf = _sensor(n_beams, max_range_cells, range_std_cells)
    rng = as_rng(rng)
    M, W = _worlds(True, ec, rng)
    poses = random_free_poses(W, n, margin_cells=2, rng=rng)
    scans = [rf.scan(W, p, rng) for p in poses]
    k = len(consts)
    t0 = time.perf_counter()
    table = localise_scans(M, scans, settings, margins=True, n_jobs=n_jobs, progress=progress)
    est = scan_estimates(table).reshape(k, n, 3)
    pm = table["half_max_area"].to_numpy(dtype=float).reshape(k, n)
    hm = table["heading_margin"].to_numpy(dtype=float).reshape(k, n)
    ep = np.hypot(est[..., 0] - poses[:, 0], est[..., 1] - poses[:, 1])
    failed = ~within_tolerance(ep, heading_error(est[..., 2], poses[:, 2]))
    h0 = np.radians(np.round(np.degrees(poses[0, 2])))
    maps = [localise(M, scans[0], params=q, prior_heading_rad=h0, window_rad=0.0).score_map for q in settings]
    labels = tuple(f"a_c={c[0]:g}, a_p={c[1]:g}, a_n={c[2]:g}" for c in consts)
    return ConstantsResult(labels, consts, pm, hm, failed.mean(axis=1), ep, ec, tuple(maps), poses[0].copy(),
                           time.perf_counter() - t0, params=base)


#: The settings of :func:`run_corridor_tie` when it is given no ``params``: float64 FFTs and Δα = 10° (ours).
CORRIDOR_PARAMS = LocaliseParams(dtype="float64", delta_alpha_rad=float(np.radians(10.0)))


def run_corridor_tie(*, max_range_cells: float = 25.0, spacing_cells: float = 30.0,
                     params: LocaliseParams | None = None, **overrides) -> CorridorResult:
    """The half-turn tie of one scan in a corridor, broken by joining the scan before it (ours).

    The robot drives towards −x along :func:`corridor_grid`; the last scan, at (100, 25), sees a plain
    corridor (every shift and the half turn score alike: ambiguity 1, and the tie rule picks heading 0°,
    180° off); the scan ``spacing_cells`` before it sees the dead end, which pins the pose once both are
    joined by (exact) odometry. ``params`` / ``**overrides``: :class:`LocaliseParams`; without ``params`` the
    study's own, :data:`CORRIDOR_PARAMS` (float64 and Δα = 10°, for exact scores).

    Parameters
    ----------
    max_range_cells : float, default 25.0
        Range limit of the noise-free scans [cells].
    spacing_cells : float, default 30.0
        Distance between the two scans [cells].
    params : LocaliseParams, optional
        Settings of both localisations, used as given (default :data:`CORRIDOR_PARAMS`).
    **overrides
        :class:`LocaliseParams` fields to change.

    Returns
    -------
    CorridorResult
    """
    p = LocaliseParams.resolve(CORRIDOR_PARAMS if params is None else params, **overrides)
    rmax = check_positive(max_range_cells, "max_range_cells")
    step = check_positive(spacing_cells, "spacing_cells")
    g = corridor_grid()
    poses = np.array([[100.0, 25.0, np.pi], [100.0 + step, 25.0, np.pi]])
    rf = Rangefinder(n_beams=360, max_range_cells=rmax, quantum_cells=0.0)
    scans = [rf.scan(g, q) for q in poses]
    return CorridorResult(poses[0].copy(), poses, localise(g, scans[0], params=p),
                          localise_joined(g, scans, poses, params=p), params=p)


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
    M, W = _worlds(True, 0, rng)
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


def _timed_localise(M, scan, p):
    """One localisation (no rival search) and its CPU time."""
    t0 = time.process_time()
    loc = localise(M, scan, params=p)
    return time.process_time() - t0, loc.pose


def run_stamp_trim_study(quantiles=(1.0, 0.75, 0.5), n_poses: int = 6, *, range_std_cells: float = 0.3,
                         n_beams: int = 360, max_range_cells: float = 100.0, params: LocaliseParams | None = None,
                         rng=2010, **overrides) -> StampTrimResult:
    """Localise the same random poses with scans trimmed to quantiles of their ranges (004 §7's advice; ours).

    Table 1's set-up (:func:`~slamlab.studies.correlation.run_table1`: unmapped clutter, Gaussian range noise,
    0.1-cell rounding, the full 360° search, no rival search); each scan trimmed by :func:`trim_scan`. Runs in this
    process, one localisation at a time, so that the CPU times compare.

    Parameters
    ----------
    quantiles : sequence of float, default (1, 0.75, 0.5)
        Shares of each scan's returns kept, each in (0, 1]; the first row is the reference of the cell ratio.
    n_poses : int, default 6
        Random free poses.
    range_std_cells, n_beams, max_range_cells
        The rangefinder, as in :func:`~slamlab.studies.correlation.run_table1`.
    params : LocaliseParams, optional
        Settings of every localisation (the rival search off).
    rng : int or numpy.random.Generator, default 2010
        Seed or generator of the poses and the scans' noise.
    **overrides
        :class:`LocaliseParams` fields to change.

    Returns
    -------
    StampTrimResult
    """
    p = LocaliseParams.resolve(params, **overrides).replace(ambiguity=False)
    qs = as_finite_array(quantiles, "quantiles")
    if qs.ndim != 1 or qs.size == 0 or np.any(qs <= 0) or np.any(qs > 1):
        raise ValueError(f"`quantiles` must be a non-empty list of shares in (0, 1]; got {quantiles!r}")
    n = check_int(n_poses, "n_poses", minimum=1)
    rf = Rangefinder(n_beams=n_beams, max_range_cells=max_range_cells, range_std_cells=range_std_cells)
    rng = as_rng(rng)
    M, W = _worlds(True, 0, rng)
    poses = random_free_poses(W, n, margin_cells=2, rng=rng)
    scans = [rf.scan(W, q, rng) for q in poses]
    heads = heading_candidates(p.delta_alpha_rad)
    est = np.empty((qs.size, n, 3))
    side = np.empty((qs.size, n), dtype=int)
    cpu = np.empty((qs.size, n))
    for j, q in enumerate(qs):
        for i, s in enumerate(scans):
            t = trim_scan(s, float(q))
            side[j, i] = scan_stamps(t, heads[:1], params=p)[0].shape[1]
            cpu[j, i], est[j, i] = _timed_localise(M, t, p)
    ea, ex, ey = absolute_errors(np.tile(poses, (qs.size, 1)), est.reshape(-1, 3))
    return StampTrimResult(qs, poses, np.hypot(ex, ey).reshape(qs.size, n), ea.reshape(qs.size, n), side,
                           np.median(cpu, axis=1), p)
