"""The one occupancy-grid builder: scans at known poses → 004's three-valued grid; the likelihood field.

API summary
-----------
- :func:`occupancy_grid` ``(scans, poses, shape, *, rule, ...) -> OccupancyGrid``:
  every beam votes "pass" for the cells its samples fall in and "hit" for the cell
  its return falls in (``np.bincount`` over all beams of all scans, in chunks);
  the cell-labelling ``rule`` turns the counts into FREE / OBSTACLE / UNEXPLORED.
- :class:`OccupancyGrid`: ``grid`` (int8 codes), ``hits``, ``passes``.
- :func:`free_space_samples` ``(bearings_rad, ranges, hit, *, step_cells, ...) -> (points, beam)``:
  the points every ``step_cells`` along each beam before its end (the free space a beam
  crossed), written once for the occupancy grid's pass votes and correlation's free marks.
- :func:`likelihood_field` ``(grid, *, cell_m, max_dist) -> (H, W)``: distance from
  every cell to the nearest obstacle cell (``scipy.ndimage.distance_transform_edt``),
  clipped at ``max_dist``: the precomputed table of the likelihood-field sensor model.

Correlation localisation (Ch. 5) uses ``rule="count"`` to build a map of a real log
from its corrected poses; Hough SLAM (Ch. 6) draws its maps with ``"count"``
(simulation) or ``"endpoints"`` (real logs: returns only).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np
from scipy import ndimage

from .._validate import as_vector, check_choice, check_int, check_positive
from ..geometry.se2 import check_poses
from .grid import FREE, OBSTACLE, UNEXPLORED, check_grid
from .scan import Scan

__all__ = ["RULES", "OccupancyGrid", "free_space_samples", "label_counts", "likelihood_field", "occupancy_grid"]

#: Cell-labelling rules of :func:`occupancy_grid`.
RULES = ("count", "endpoints")


@dataclass(frozen=True)
class OccupancyGrid:
    """Hit and pass counts per cell and the three-valued grid they give (cell units).

    Attributes
    ----------
    grid : ndarray of int8, shape (H, W)
        FREE / OBSTACLE / UNEXPLORED codes.
    hits : ndarray of int64, shape (H, W)
        Returns that fell in each cell.
    passes : ndarray of int64, shape (H, W)
        Beam samples that fell in each cell.
    rule : str
        The labelling rule used (``"count"`` or ``"endpoints"``).
    """

    grid: np.ndarray = field(repr=False)  # int8 (H, W): FREE / OBSTACLE / UNEXPLORED
    hits: np.ndarray = field(repr=False)  # int64 (H, W): returns that fell in the cell
    passes: np.ndarray = field(repr=False)  # int64 (H, W): beam samples that fell in it
    rule: str = "count"

    def __str__(self) -> str:
        return (f"Occupancy grid {self.grid.shape[0]}×{self.grid.shape[1]} ({self.rule}): "
                f"{int((self.grid == OBSTACLE).sum())} obstacle, {int((self.grid == FREE).sum())} free cells")


def free_space_samples(bearings_rad, ranges, hit, *, step_cells: float, hit_margin_cells: float = 0.0,
                       misses: bool = True) -> tuple[np.ndarray, np.ndarray]:
    """Points every ``step_cells`` along each beam through the free space before its end (ours; 004 §7's free cells).

    A beam with a return (``hit``) is sampled at ``t = 0, step, 2·step, …`` while
    ``t < range − hit_margin_cells − 10⁻⁶`` (just short of the return, so a range that ends on a cell's face does
    not sample the cell behind it); a beam without a return over ``t < range`` when ``misses``, else not at all.
    The one beam sampler of the 2-D layer: :func:`occupancy_grid` votes "pass" in the cells of these points,
    correlation localisation marks them ``a_c`` in its stamps (:func:`slamlab.correlation.scan_stamps`).

    Parameters
    ----------
    bearings_rad : array_like, shape (n,)
        Beam directions [rad], in the frame the points are wanted in.
    ranges : array_like, shape (n,)
        Beam lengths [cells] (or any unit of ``step_cells``), at least 0.
    hit : array_like of bool, shape (n,)
        Beams with a return.
    step_cells : float
        Spacing of the samples along a beam (> 0), in the unit of ``ranges``.
    hit_margin_cells : float, default 0
        A beam with a return stops this much before it (004's ±Δl; ≥ 0).
    misses : bool, default True
        Sample beams without a return over their whole range.

    Returns
    -------
    points : numpy.ndarray, shape (k, 2)
        ``t·(cos α, sin α)`` of each sample, relative to the beams' origin; ordered by beam, then by ``t``.
    beam : numpy.ndarray of int, shape (k,)
        The index of each sample's beam.

    Examples
    --------
    >>> pts, beam = free_space_samples([0.0, np.pi / 2], [1.5, 1.0], [True, False], step_cells=0.5)
    >>> pts.round(12).tolist(), beam.tolist()
    ([[0.0, 0.0], [0.5, 0.0], [1.0, 0.0], [0.0, 0.0], [0.0, 0.5]], [0, 0, 0, 1, 1])
    """
    a = as_vector(bearings_rad, "bearings_rad")
    r = as_vector(ranges, "ranges", a.size)
    if np.any(r < 0):
        raise ValueError(f"`ranges` must be >= 0; got minimum {r.min()}")
    h = np.asarray(hit)
    if h.dtype != bool or h.shape != a.shape:
        raise ValueError(f"`hit` must be a bool array of shape {a.shape}; got {h.dtype} {h.shape}")
    step = check_positive(step_cells, "step_cells")
    margin = check_positive(hit_margin_cells, "hit_margin_cells", allow_zero=True)
    if not isinstance(misses, (bool, np.bool_)):
        raise TypeError(f"`misses` must be a bool; got {type(misses).__name__}")
    length = np.where(h, np.maximum(r - margin - 1e-6, 0.0), r if misses else 0.0)
    t = step * np.arange(int(np.ceil(float(length.max()) / step)) + 1 if length.size else 1)
    beam, k = np.nonzero(t[None, :] < length[:, None])
    d = t[k]
    return np.column_stack([d * np.cos(a[beam]), d * np.sin(a[beam])]), beam


def _beam_table(scans, P):
    """All beams of all scans as flat arrays: origin x, y, direction, range, valid."""
    n_b = np.array([s.n_beams for s in scans])
    pose = np.repeat(P, n_b, axis=0)
    th = pose[:, 2] + np.concatenate([s.bearings_rad for s in scans])
    r = np.concatenate([s.ranges for s in scans])
    ok = np.concatenate([s.valid for s in scans])
    return pose[:, 0], pose[:, 1], th, r, ok


def occupancy_grid(scans: Sequence[Scan], poses, shape: tuple[int, int], *, rule: str = "count",
                   hit_ratio: float = 0.25, min_hits: int = 1, step_cells: float = 0.5,
                   hit_offset_cells: float = 0.01, misses_free: bool = True) -> OccupancyGrid:
    """Label each cell OBSTACLE, FREE or UNEXPLORED from scans at known poses (our counting model).

    Every beam votes "pass" for the cells of its samples ``t = 0, step, 2·step, …``
    before its return (the whole range for a beam without return when
    ``misses_free``) and "hit" for the cell at ``range + hit_offset_cells`` (a range
    ends on the face of the obstacle cell: the offset puts the vote inside it).

    The labelling ``rule``:

    ``"count"``
        OBSTACLE when ``hits >= min_hits`` and ``hits >= hit_ratio·passes``, else
        FREE when passed, else UNEXPLORED (004's a_n).
    ``"endpoints"``
        OBSTACLE when ``hits >= min_hits``, every other cell UNEXPLORED (returns only;
        no pass is counted).

    Parameters
    ----------
    scans : sequence of Scan
        In cell units (``scan.to_cells(cell_m)`` for a metric scan).
    poses : array_like, shape (n_scans, 3)
        Sensor pose of each scan, in cells (``GridFrame.to_cells`` for metric poses).
    shape : (int, int)
        Grid size (rows, cols); votes outside are dropped.
    rule : str
        ``"count"`` or ``"endpoints"`` (above; default ``"count"``).
    hit_ratio : float
        Smallest ``hits / passes`` of an OBSTACLE cell under ``"count"`` (default 0.25).
    min_hits : int
        Fewest hits of an OBSTACLE cell (default 1).
    step_cells : float
        Spacing of the pass samples along a beam [cells] (default 0.5).
    hit_offset_cells : float
        Distance past the range at which the hit is voted [cells] (default 0.01).
    misses_free : bool
        A beam without return passes the cells up to its (maximum) range (default True).

    Returns
    -------
    OccupancyGrid
        ``grid`` (H, W) int8 codes, ``hits`` and ``passes`` (H, W) counts, ``rule``.

    Examples
    --------
    >>> s = Scan([0.0], [3.5], [True])
    >>> occupancy_grid([s], [[1, 1, 0]], (3, 6)).grid.tolist()
    [[-1, -1, -1, -1, -1, -1], [-1, 0, 0, 0, 0, 1], [-1, -1, -1, -1, -1, -1]]
    >>> occupancy_grid([s], [[1, 1, 0]], (3, 6), rule="endpoints").grid[1].tolist()
    [-1, -1, -1, -1, -1, 1]
    """
    scans = list(scans)
    if not scans:
        raise ValueError("`scans` must hold at least one scan; got 0")
    for k, s in enumerate(scans):
        if not isinstance(s, Scan):
            raise TypeError(f"`scans[{k}]` must be a Scan; got {type(s).__name__}")
        if s.unit != "cell":
            raise ValueError(f"`scans[{k}]` must be in cell units; got unit {s.unit!r} (use scan.to_cells(cell_m))")
    P = check_poses(poses, "poses", n=len(scans))
    if not (isinstance(shape, tuple) and len(shape) == 2):
        raise TypeError(f"`shape` must be a (rows, cols) tuple; got {shape!r}")
    n_rows = check_int(shape[0], "shape[0]", minimum=1)
    n_cols = check_int(shape[1], "shape[1]", minimum=1)
    rule = check_choice(rule, "rule", RULES)
    ratio = check_positive(hit_ratio, "hit_ratio")
    min_hits = check_int(min_hits, "min_hits", minimum=1)
    st = check_positive(step_cells, "step_cells")
    off = check_positive(hit_offset_cells, "hit_offset_cells", allow_zero=True)
    size = n_rows * n_cols

    def flat_index(x, y):
        col = np.floor(x + 0.5).astype(np.int64)
        row = np.floor(y + 0.5).astype(np.int64)
        ok = (row >= 0) & (row < n_rows) & (col >= 0) & (col < n_cols)
        return (row * n_cols + col)[ok]

    x0, y0, th, r, ok = _beam_table(scans, P)
    c, s = np.cos(th), np.sin(th)
    hits = np.bincount(flat_index(x0[ok] + c[ok] * (r[ok] + off), y0[ok] + s[ok] * (r[ok] + off)), minlength=size)
    passes = np.zeros(size, dtype=np.int64)
    if rule == "count":
        per = max(1, int(2e6 // (np.ceil(float(r.max()) / st) + 1)))  # beams per chunk: bounded (beams, samples)
        for b0 in range(0, r.size, per):
            sl = slice(b0, b0 + per)
            pts, beam = free_space_samples(th[sl], r[sl], ok[sl], step_cells=st, misses=bool(misses_free))
            passes += np.bincount(flat_index(x0[sl][beam] + pts[:, 0], y0[sl][beam] + pts[:, 1]), minlength=size)
    hits, passes = hits.reshape(n_rows, n_cols), passes.reshape(n_rows, n_cols)
    return OccupancyGrid(label_counts(hits, passes, rule=rule, hit_ratio=ratio, min_hits=min_hits), hits, passes,
                         rule)


def label_counts(hits, passes, *, rule: str = "count", hit_ratio: float = 0.25, min_hits: int = 1) -> np.ndarray:
    """Cell codes from hit and pass counts by :func:`occupancy_grid`'s ``rule`` (counts add over scans).

    Lets a caller subtract some scans' counts from a whole log's and label the rest
    without recounting (the leave-out maps of Ch. 5).

    Parameters
    ----------
    hits, passes : array_like of int, shape (H, W)
        Hit and pass counts per cell.
    rule : str
        ``"count"`` or ``"endpoints"`` (default ``"count"``).
    hit_ratio : float
        Smallest ``hits / passes`` of an OBSTACLE cell under ``"count"`` (default 0.25).
    min_hits : int
        Fewest hits of an OBSTACLE cell (default 1).

    Returns
    -------
    grid : ndarray of int8, shape (H, W)
        Cell codes.

    Examples
    --------
    >>> label_counts(np.array([[0, 1, 1]]), np.array([[0, 2, 8]])).tolist()
    [[-1, 1, 0]]
    """
    rule = check_choice(rule, "rule", RULES)
    hits = np.asarray(hits)
    passes = np.asarray(passes)
    if hits.shape != passes.shape:
        raise ValueError(f"`hits` and `passes` must have the same shape; got {hits.shape} and {passes.shape}")
    grid = np.full(hits.shape, UNEXPLORED, dtype=np.int8)
    grid[passes > 0] = FREE
    obstacle = hits >= min_hits
    if rule == "count":
        obstacle &= hits >= hit_ratio * passes
    grid[obstacle] = OBSTACLE
    return grid


def likelihood_field(grid, *, cell_m: float = 1.0, max_dist: float | None = None) -> np.ndarray:
    """Distance from each cell centre to the nearest OBSTACLE cell centre, clipped (the likelihood field's table).

    The likelihood-field sensor model scores a return by the distance from its end
    point to the nearest obstacle; this precomputes that distance for every cell
    with ``scipy.ndimage.distance_transform_edt`` (exact Euclidean).

    Parameters
    ----------
    grid : array_like of int, shape (H, W)
        Cell codes; only OBSTACLE cells count as obstacles.
    cell_m : float
        Cell size: the distances come out in its unit (1 = cells).
    max_dist : float, optional
        Clip at this distance (same unit); also the value everywhere when the grid
        holds no obstacle. Default: no clip (``inf`` for a grid without obstacles).

    Returns
    -------
    numpy.ndarray of float, shape (H, W)

    Examples
    --------
    >>> g = np.zeros((1, 5), np.int8); g[0, 0] = 1
    >>> likelihood_field(g, cell_m=0.5, max_dist=1.5).tolist()
    [[0.0, 0.5, 1.0, 1.5, 1.5]]
    """
    g = check_grid(grid)
    cell = check_positive(cell_m, "cell_m")
    clip = np.inf if max_dist is None else check_positive(max_dist, "max_dist", allow_zero=True)
    obstacle = g == OBSTACLE
    if not obstacle.any():
        return np.full(g.shape, clip, dtype=float)
    d = ndimage.distance_transform_edt(~obstacle) * cell
    return np.minimum(d, clip)
