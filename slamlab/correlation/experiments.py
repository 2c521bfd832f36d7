"""Ch. 5 experiments (004 §7): Table 1, a Monte Carlo study, the constants a_c/a_p, the corridor tie (the real
CARMEN log and the closing table: :mod:`.log_experiments`).

Every ``run_*`` takes ``params=`` (a :class:`~slamlab.correlation.LocaliseParams`, the
same settings and defaults as :func:`~slamlab.correlation.localise`) plus overrides
of its fields.

Each ``run_*`` returns a frozen dataclass: ``str(result)`` is a one-line summary,
``result.table()`` a fixed-precision text table (what the notebook prints and
nbval compares); arrays for plotting live in fields, timings in ``time_s``
(never in the table).
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np

from .. import _validate as v
from .._table import format_table
from ..scans import FREE, OBSTACLE, UNEXPLORED, grid_to_values
from ..scans.logmap import log_grid  # log_grid re-exported (one place: scans)
from ..sim.grid import add_clutter, free_cells, measurement_room_200, test_room_200
from ..sim.paths import random_free_poses
from ..sim.rangefinder import Rangefinder
from .algorithm import (
    Localisation,
    LocaliseParams,
    _localise,
    _scan_beams,
    heading_candidates,
    heading_error,
    localise,
    localise_joined,
)

__all__ = [
    "SOURCE_TABLE1",
    "ConstantsResult",
    "CorridorResult",
    "MonteCarloResult",
    "Table1Result",
    "corridor_grid",
    "log_grid",
    "random_clutter",
    "run_constants_study",
    "run_corridor_tie",
    "run_monte_carlo",
    "run_table1",
    "time_localise",
]

#: 004 Table 1: α0, α0 est [rad], X, X est, Y, Y est [cells].
SOURCE_TABLE1 = np.array([
    [1.8812, 1.885, 187, 187, 15, 15],
    [0.5225, 0.5236, 30, 30, 175, 175],
    [3.1297, 3.1241, 173, 173, 94, 94],
    [1.0738, 1.0821, 69, 69, 58, 58],
    [5.1389, 5.1487, 181, 181, 188, 188],
    [3.4681, 3.4732, 167, 167, 103, 102],
    [0.5715, 0.576, 162, 162, 93, 93],
    [5.5558, 5.5501, 63, 63, 81, 81],
    [2.1229, 2.1293, 30, 30, 171, 171],
    [5.2929, 5.2883, 105, 105, 45, 45],
])

FAIL_CELLS = 2.0  # a localisation farther than this from the truth (or > FAIL_DEG off) is a failure
FAIL_DEG = 5.0

_SIZES = {"small": 12, "full": 200}


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
    n = v.check_int(n, "n", minimum=0)
    r = v.check_positive(radius_cells, "radius_cells")
    rng = v.as_rng(rng)
    cells = free_cells(grid, margin_cells)
    pick = cells[rng.integers(0, cells.shape[0], n)]
    return [("disc", int(c), int(rw), r) for rw, c in pick]


def _localise_one(*, beams, choice: int, Mvs, settings, headings, margins: bool = False, pose_index: int = 0) -> dict:
    """One sweep task: localise one scan's ``beams`` on map ``Mvs[choice]`` with ``settings[choice]`` (deterministic)."""
    loc = _localise(Mvs[choice], *beams, headings, settings[choice], tracking=False)
    row = {"x": float(loc.pose[0]), "y": float(loc.pose[1]), "heading_rad": float(loc.pose[2])}
    if margins:
        row["half_max_area"], row["heading_margin"] = _margins(loc)
    return row


def _localise_scans(M, scans, settings, *, margins: bool = False, n_jobs: int = 1, progress: bool | None = None):
    """Localise every scan with every setting on :func:`slamlab.sweep.sweep`: one task per (setting, scan).

    The scans were drawn by the caller (the random part stays in the parent, in its order); a
    localisation draws nothing (``rng_arg=None``), so the table is the same for any ``n_jobs``.
    The map is turned into 004's values once per setting. Returns the table (columns ``choice``,
    ``pose_index``, ``x``, ``y``, ``heading_rad`` and with ``margins`` ``half_max_area``,
    ``heading_margin``), setting-major.
    """
    from ..sweep import sweep

    beams = [_scan_beams(s) for s in scans]
    settings = tuple(q.replace(ambiguity=False) for q in settings)  # these runs report no ambiguity: no rival search
    Mvs = tuple(grid_to_values(M, q.a_c, q.a_p, q.a_n) for q in settings)
    headings = heading_candidates(settings[0].delta_alpha_rad)
    points = [{"choice": j, "pose_index": i, "beams": b} for j in range(len(settings)) for i, b in enumerate(beams)]
    table = sweep(_localise_one, points, rng_arg=None, n_jobs=n_jobs, progress=progress, on_error="raise", desc="correlation localisation",
                  fixed={"Mvs": Mvs, "settings": tuple(settings), "headings": headings, "margins": margins})
    return table.drop(columns=["beams", "replicate", "error"])


def _estimates(table) -> np.ndarray:
    """``(n, 3)`` estimated poses (x, y, heading) of a :func:`_localise_scans` table."""
    return table[["x", "y", "heading_rad"]].to_numpy(dtype=float)


def _errors(true, est):
    ea = heading_error(est[:, 2], true[:, 2])
    ex = np.abs(est[:, 0] - true[:, 0])
    ey = np.abs(est[:, 1] - true[:, 1])
    return ea, ex, ey


# --- Table 1 ----------------------------------------------------------------------------------------


@dataclass(frozen=True)
class Table1Result:
    """004 Table 1 reproduced: 10 random free poses, Δα = 1°, range noise, unmapped clutter.

    Attributes
    ----------
    true_poses, est_poses : numpy.ndarray, shape (n, 3)
        True and estimated poses ``(x, y)`` [cells], heading [rad].
    err_heading_rad : numpy.ndarray, shape (n,)
        Wrapped heading errors [rad].
    err_x_cells, err_y_cells : numpy.ndarray, shape (n,)
        Absolute position errors [cells].
    range_std_cells : float
        Range noise std of the scans [cells].
    n_beams : int
        Beams per scan.
    params : LocaliseParams
        Settings of the localisations.
    time_s : float
        Wall time of the localisations [s] (not compared).
    """

    true_poses: np.ndarray  # (n, 3)
    est_poses: np.ndarray  # (n, 3)
    err_heading_rad: np.ndarray
    err_x_cells: np.ndarray
    err_y_cells: np.ndarray
    range_std_cells: float
    n_beams: int
    params: LocaliseParams = field(default_factory=LocaliseParams, repr=False)
    time_s: float = field(default=0.0, compare=False)

    def __str__(self) -> str:
        return (f"Table 1, {self.true_poses.shape[0]} poses: max heading error {self.err_heading_rad.max():.4f} rad, "
                f"max |dX| {self.err_x_cells.max():.0f}, max |dY| {self.err_y_cells.max():.0f} cells "
                f"(004: 0.0098 rad, 0, 1)")

    def table(self) -> str:
        """Our Table 1 (rows per pose, then our and 004's maximum errors).

        Returns
        -------
        str
        """
        rows = []
        for i, (t, e) in enumerate(zip(self.true_poses, self.est_poses, strict=True)):
            rows.append([i + 1, f"{t[2]:.4f}", f"{e[2]:.4f}", f"{t[0]:.0f}", f"{e[0]:.0f}", f"{t[1]:.0f}",
                         f"{e[1]:.0f}", f"{self.err_heading_rad[i]:.4f}", f"{self.err_x_cells[i]:.0f}",
                         f"{self.err_y_cells[i]:.0f}"])
        rows.append(["max (ours)", "", "", "", "", "", "", f"{self.err_heading_rad.max():.4f}",
                     f"{self.err_x_cells.max():.0f}", f"{self.err_y_cells.max():.0f}"])
        src = SOURCE_TABLE1
        s_ea, s_ex, s_ey = _errors(src[:, [2, 4, 0]], src[:, [3, 5, 1]])
        rows.append(["max (004)", "", "", "", "", "", "", f"{s_ea.max():.4f}", f"{s_ex.max():.0f}",
                     f"{s_ey.max():.0f}"])
        head = ["#", "α0", "α0 est", "X", "X est", "Y", "Y est", "err α0", "err X", "err Y"]
        title = (f"Ours: {self.n_beams} beams over 360°, range σ = {self.range_std_cells:g} cell, 0.1-cell "
                 f"quantisation, Δα = {np.degrees(self.params.delta_alpha_rad):g}°, clutter (rad, cells)")
        return format_table(head, rows, title=title)

    def source_table(self) -> str:
        """004's Table 1 as printed (radians, cells).

        Returns
        -------
        str
        """
        src = SOURCE_TABLE1
        ea, ex, ey = _errors(src[:, [2, 4, 0]], src[:, [3, 5, 1]])
        rows = [[i + 1, f"{r[0]:.4f}", f"{r[1]:.4f}", f"{r[2]:.0f}", f"{r[3]:.0f}", f"{r[4]:.0f}", f"{r[5]:.0f}",
                 f"{ea[i]:.4f}", f"{ex[i]:.0f}", f"{ey[i]:.0f}"] for i, r in enumerate(src)]
        head = ["#", "α0", "α0 est", "X", "X est", "Y", "Y est", "err α0", "err X", "err Y"]
        return format_table(head, rows, title="004 Table 1 (its own map and poses)")


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
    n = v.check_int(n_poses, "n_poses", minimum=1)
    rf = _sensor(n_beams, max_range_cells, range_std_cells)
    rng = v.as_rng(rng)
    M, W = _worlds(clutter, 0, rng)
    poses = random_free_poses(W, n, margin_cells=2, rng=rng)
    scans = [rf.scan(W, pose, rng) for pose in poses]  # every draw here, in the order of the sequential loop
    t0 = time.perf_counter()
    est = _estimates(_localise_scans(M, scans, (p,), n_jobs=n_jobs, progress=progress))
    ea, ex, ey = _errors(poses, est)
    return Table1Result(poses, est, ea, ex, ey, float(range_std_cells), int(n_beams), p, time.perf_counter() - t0)


# --- Monte Carlo -------------------------------------------------------------------------------------


@dataclass(frozen=True)
class MonteCarloResult:
    """Error distribution and failure rate of the full 360° search over many random poses (our addition).

    Attributes
    ----------
    n_poses : int
        Localised poses.
    err_heading_rad : numpy.ndarray, shape (n_poses,)
        Wrapped heading errors [rad].
    err_pos_cells : numpy.ndarray, shape (n_poses,)
        Euclidean position errors [cells].
    failed : numpy.ndarray of bool, shape (n_poses,)
        Position error > 2 cells or heading error > 5°.
    range_std_cells : float
        Range noise std [cells].
    extra_clutter : int
        Random discs added to 004's clutter.
    time_s : float
        Wall time of the localisations [s] (not compared).
    """

    n_poses: int
    err_heading_rad: np.ndarray
    err_pos_cells: np.ndarray  # Euclidean position error
    failed: np.ndarray  # bool
    range_std_cells: float
    extra_clutter: int
    time_s: float = field(default=0.0, compare=False)

    @property
    def failure_rate(self) -> float:
        """Fraction of poses with position error > 2 cells or heading error > 5°."""
        return float(self.failed.mean())

    def __str__(self) -> str:
        return (f"Monte Carlo, {self.n_poses} poses: failure rate {self.failure_rate:.1%}, "
                f"exact position {np.mean(self.err_pos_cells == 0):.0%}")

    def table(self) -> str:
        """Error distribution table (exact, ≤ 1 cell, heading percentiles, failures).

        Returns
        -------
        str
        """
        ok = ~self.failed
        ea = np.degrees(self.err_heading_rad[ok]) if ok.any() else np.array([np.nan])
        ep = self.err_pos_cells
        rows = [
            ["poses", f"{self.n_poses}"],
            ["position exact (0 cells)", f"{np.mean(ep == 0):.1%}"],
            ["position error <= 1 cell", f"{np.mean(ep <= 1.0):.1%}"],
            ["position error <= 1.5 cells (incl. diagonal)", f"{np.mean(ep <= 1.5):.1%}"],
            ["heading error <= 0.5° (half the step)", f"{np.mean(np.degrees(self.err_heading_rad) <= 0.5):.1%}"],
            ["heading error <= 1°", f"{np.mean(np.degrees(self.err_heading_rad) <= 1.0):.1%}"],
            ["heading error median / 95 % / max, successes [deg]",
             f"{np.median(ea):.2f} / {np.percentile(ea, 95):.2f} / {ea.max():.2f}"],
            ["failures (> 2 cells or > 5°)", f"{self.failed.sum()} ({self.failure_rate:.1%})"],
        ]
        title = (f"Range σ = {self.range_std_cells:g} cell, clutter of 004 Fig. 3b"
                 + (f" + {self.extra_clutter} extra discs" if self.extra_clutter else ""))
        return format_table(["quantity", "value"], rows, title=title)


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
    n = _SIZES[v.check_choice(size, "size", _SIZES)] if isinstance(size, str) else v.check_int(size, "size",
                                                                                                 minimum=1)
    ec = v.check_int(extra_clutter, "extra_clutter", minimum=0)
    rf = _sensor(n_beams, max_range_cells, range_std_cells)
    rng = v.as_rng(rng)
    M, W = _worlds(True, ec, rng)
    poses = random_free_poses(W, n, margin_cells=2, rng=rng)
    scans = [rf.scan(W, pose, rng) for pose in poses]  # every draw here, in the order of the sequential loop
    t0 = time.perf_counter()
    est = _estimates(_localise_scans(M, scans, (p,), n_jobs=n_jobs, progress=progress))
    ea, ex, ey = _errors(poses, est)
    ep = np.hypot(ex, ey)
    failed = (ep > FAIL_CELLS) | (np.degrees(ea) > FAIL_DEG)
    return MonteCarloResult(n, ea, ep, failed, float(range_std_cells), ec, time.perf_counter() - t0)


# --- the constants a_c, a_p -------------------------------------------------------------------------


@dataclass(frozen=True)
class ConstantsResult:
    """Peak sharpness and robustness to unmapped clutter of two choices of 004's constants.

    Attributes
    ----------
    labels : tuple of str
        One label per choice of constants.
    constants : tuple of tuple of float
        ``(a_c, a_p, a_n)`` per choice.
    half_max_area : numpy.ndarray, shape (k, n)
        Cells scoring at least halfway from the median to the peak at the best heading.
    heading_margin : numpy.ndarray, shape (k, n)
        (Peak minus the best score ≥ 3° away) over (peak minus the median over headings).
    failure_rate : numpy.ndarray, shape (k,)
        Share of failed poses per choice.
    err_pos_cells : numpy.ndarray, shape (k, n)
        Position errors [cells].
    extra_clutter : int
        Random discs added to 004's clutter.
    example_maps : tuple of numpy.ndarray
        Score maps of the first scan at its true heading, one per choice.
    example_pose : numpy.ndarray, shape (3,)
        The first scan's true pose.
    time_s : float
        Wall time [s] (not compared).
    """

    labels: tuple[str, ...]
    constants: tuple[tuple[float, float, float], ...]
    half_max_area: np.ndarray  # (k, n) cells with score >= median + (peak - median)/2 at the best heading
    heading_margin: np.ndarray  # (k, n) (peak - best >= 3° away) / (peak - median over headings)
    failure_rate: np.ndarray  # (k,)
    err_pos_cells: np.ndarray  # (k, n)
    extra_clutter: int
    example_maps: tuple = field(default=(), repr=False)  # score maps at the truth's heading, one per choice
    example_pose: np.ndarray = field(default=None, repr=False)
    time_s: float = field(default=0.0, compare=False)

    def __str__(self) -> str:
        return "; ".join(f"{lb}: failures {fr:.0%}" for lb, fr in zip(self.labels, self.failure_rate, strict=True))

    def table(self) -> str:
        """Median sharpness measures and failure rate per choice.

        Returns
        -------
        str
        """
        rows = []
        for k, lb in enumerate(self.labels):
            rows.append([lb, f"{np.median(self.half_max_area[k]):.0f}", f"{np.median(self.heading_margin[k]):.3f}",
                         f"{np.mean(self.err_pos_cells[k] <= 1.5):.0%}", f"{self.failure_rate[k]:.0%}"])
        title = (f"{self.err_pos_cells.shape[1]} poses, clutter of 004 Fig. 3b + {self.extra_clutter} extra discs; "
                 "medians; a sharper peak has a smaller half-max area and a larger heading margin")
        return format_table(["constants", "half-max area", "heading margin", "pos. err <= 1.5", "failures"],
                            rows, title=title)


def _margins(loc, heading_window=3):
    """Half-maximum area of the score map [cells] and relative heading margin of one localisation."""
    dmap = loc.score_map
    med = float(np.median(dmap))
    area = float(np.count_nonzero(dmap >= med + 0.5 * (loc.score - med)))
    b = loc.best_per_heading
    n = b.size
    idx = (np.arange(n) - loc.heading_index) % n
    far = np.minimum(idx, n - idx) >= heading_window
    bmed = float(np.median(b))
    head = (loc.score - b[far].max()) / max(loc.score - bmed, 1e-12)
    return area, head


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
    :class:`LocaliseParams` fields (each choice replaces ``a_c, a_p, a_n``).

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
        Settings of every localisation (default :class:`LocaliseParams`).
    rng : int or numpy.random.Generator, default 2012
        Seed or generator of clutter, poses and scan noise.
    n_jobs : int, default 1
        Worker processes for the localisations (same result for any value).
    progress : bool or None
        Progress bar: None shows one in a notebook only.
    **overrides
        :class:`LocaliseParams` fields to change.

    Returns
    -------
    ConstantsResult
    """
    base = LocaliseParams.resolve(params, **overrides)
    n = v.check_int(n_poses, "n_poses", minimum=1)
    ec = v.check_int(extra_clutter, "extra_clutter", minimum=0)
    settings = tuple(base.replace(a_c=float(c[0]), a_p=float(c[1]), a_n=float(c[2])) for c in choices)
    consts = tuple((q.a_c, q.a_p, q.a_n) for q in settings)
    if not consts:
        raise ValueError("`choices` must hold at least one (a_c, a_p, a_n) triple")
    rf = _sensor(n_beams, max_range_cells, range_std_cells)
    rng = v.as_rng(rng)
    M, W = _worlds(True, ec, rng)
    poses = random_free_poses(W, n, margin_cells=2, rng=rng)
    scans = [rf.scan(W, p, rng) for p in poses]
    k = len(consts)
    t0 = time.perf_counter()
    table = _localise_scans(M, scans, settings, margins=True, n_jobs=n_jobs, progress=progress)
    est = _estimates(table).reshape(k, n, 3)
    pm = table["half_max_area"].to_numpy(dtype=float).reshape(k, n)
    hm = table["heading_margin"].to_numpy(dtype=float).reshape(k, n)
    ep = np.hypot(est[..., 0] - poses[:, 0], est[..., 1] - poses[:, 1])
    failed = (ep > FAIL_CELLS) | (np.degrees(heading_error(est[..., 2], poses[:, 2])) > FAIL_DEG)
    h0 = np.radians(np.round(np.degrees(poses[0, 2])))
    maps = [localise(M, scans[0], params=q, prior_heading_rad=h0, window_rad=0.0).score_map for q in settings]
    labels = tuple(f"a_c={c[0]:g}, a_p={c[1]:g}, a_n={c[2]:g}" for c in consts)
    return ConstantsResult(labels, consts, pm, hm, failed.mean(axis=1), ep, ec, tuple(maps), poses[0].copy(),
                           time.perf_counter() - t0)


# --- a constructed corridor: the half-turn tie and how joined scans break it (ours) ----------------------


def corridor_grid() -> np.ndarray:
    """A straight corridor (rows 20..30 free, walls at rows 19 and 31) open at the map's left edge, with a dead
    end at column 150 (52×160 cells; our test case): symmetric under a half turn wherever a 25-cell scan sees
    neither end.

    Returns
    -------
    numpy.ndarray of int8, shape (52, 160)
        Cell codes.

    Examples
    --------
    >>> g = corridor_grid(); g.shape, int(g[25, 150]), int(g[25, 149])
    ((52, 160), 1, 0)
    """
    g = np.full((52, 160), UNEXPLORED, dtype=np.int8)
    g[19:32, :151] = OBSTACLE
    g[20:31, :150] = FREE
    return g


@dataclass(frozen=True)
class CorridorResult:
    """One scan vs two scans joined by odometry in :func:`corridor_grid` (ours).

    Attributes
    ----------
    true_pose : numpy.ndarray, shape (3,)
        Pose of the last scan [cells, rad].
    odom_poses : numpy.ndarray, shape (k, 3)
        The scans' poses, last scan first.
    single : Localisation
        The last scan alone.
    joined : Localisation
        The scans joined by odometry.
    """

    true_pose: np.ndarray  # (3,) cells, rad: the pose of the last scan
    odom_poses: np.ndarray  # (k, 3) the scans' poses, last scan first
    single: Localisation
    joined: Localisation

    def __str__(self) -> str:
        e1 = np.degrees(heading_error(self.single.pose[2], self.true_pose[2]))
        e2 = np.degrees(heading_error(self.joined.pose[2], self.true_pose[2]))
        return f"corridor: one scan {e1:.0f}° off (ambiguity {self.single.ambiguity:.3f}), " \
               f"{self.joined.n_scans} joined {e2:.0f}° off (ambiguity {self.joined.ambiguity:.3f})"

    def table(self) -> str:
        """One row per mode: estimate, errors, score, rival and ambiguity.

        Returns
        -------
        str
        """
        t = self.true_pose
        rows = []
        for label, loc in (("1 scan", self.single), (f"{self.joined.n_scans} scans + odometry", self.joined)):
            rows.append([label, f"{loc.pose[0]:.0f}", f"{loc.pose[1]:.0f}", f"{np.degrees(loc.pose[2]):.0f}",
                         f"{np.hypot(loc.pose[0] - t[0], loc.pose[1] - t[1]):.0f}",
                         f"{np.degrees(heading_error(loc.pose[2], t[2])):.0f}", f"{loc.score:.0f}",
                         f"{loc.rival_score:.0f}", f"{loc.ambiguity:.3f}"])
        title = (f"Corridor with a dead end, truth x = {t[0]:.0f}, y = {t[1]:.0f}, θ = {np.degrees(t[2]):.0f}° "
                 f"(cells, deg); noise-free scans, Δα = {np.degrees(self.single.headings_rad[1] - self.single.headings_rad[0]):g}°")
        return format_table(["mode", "x est", "y est", "θ est", "pos. err", "θ err", "score", "rival", "ambiguity"],
                            rows, title=title)


def run_corridor_tie(*, max_range_cells: float = 25.0, step_cells: float = 30.0,
                     params: LocaliseParams | None = None, **overrides) -> CorridorResult:
    """The half-turn tie of one scan in a corridor, broken by joining the scan before it (ours).

    The robot drives towards −x along :func:`corridor_grid`; the last scan, at (100, 25), sees a plain
    corridor (every shift and the half turn score alike: ambiguity 1, and the tie rule picks heading 0°,
    180° off); the scan ``step_cells`` before it sees the dead end, which pins the pose once both are
    joined by (exact) odometry. ``params`` / ``**overrides``: :class:`LocaliseParams` (default float64,
    Δα = 10°, for exact scores).

    Parameters
    ----------
    max_range_cells : float, default 25.0
        Range limit of the noise-free scans [cells].
    step_cells : float, default 30.0
        Distance between the two scans [cells].
    params : LocaliseParams, optional
        Settings of every localisation (default :class:`LocaliseParams`).
    **overrides
        :class:`LocaliseParams` fields to change.

    Returns
    -------
    CorridorResult
    """
    p = LocaliseParams.resolve(params, **{"dtype": "float64", "delta_alpha_rad": float(np.radians(10.0)),
                                          **overrides})
    rmax = v.check_positive(max_range_cells, "max_range_cells")
    step = v.check_positive(step_cells, "step_cells")
    g = corridor_grid()
    poses = np.array([[100.0, 25.0, np.pi], [100.0 + step, 25.0, np.pi]])
    rf = Rangefinder(n_beams=360, max_range_cells=rmax, quantum_cells=0.0)
    scans = [rf.scan(g, q) for q in poses]
    return CorridorResult(poses[0].copy(), poses, localise(g, scans[0], params=p),
                          localise_joined(g, scans, poses, params=p))


def time_localise(grid, scan, *, dtypes=("float64", "float32")) -> dict:
    """Wall time in seconds of one full 360° :func:`localise` per dtype (volatile: print only in ignored cells).

    Parameters
    ----------
    grid : array_like of int, shape (H, W)
        Map as cell codes.
    scan : Scan
        Scan in cell units.
    dtypes : sequence of str or dtype
        FFT precisions to time.

    Returns
    -------
    dict
        dtype name -> seconds.
    """
    out = {}
    for dt in dtypes:
        t0 = time.perf_counter()
        localise(grid, scan, dtype=np.dtype(dt).name)
        out[np.dtype(dt).name] = time.perf_counter() - t0
    return out
