"""Map building from scans and poses (004 §Hough SLAM, Fig. 11).

"Using the displacement data it is easy to re-project the rangefinder data and build
the map" (004). :func:`build_map` puts every return at its world position through
the estimated pose and marks the cells crossed by the beams as free; cells never
reached stay unexplored. Codes and the grid ↔ world mapping are those of
:mod:`slamlab.sim.grid` (FREE 0, OBSTACLE 1, UNEXPLORED -1; cell (row, col) centred on
(x, y) = (col, row) in cells).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from .. import _validate as v
from ..sim.grid import FREE, OBSTACLE, UNEXPLORED

__all__ = ["BuiltMap", "build_map", "map_agreement", "scan_points_world"]


@dataclass(frozen=True)
class BuiltMap:
    """Hit and pass-through counts per cell and the three-valued grid they give."""

    grid: np.ndarray = field(repr=False)  # int8 (H, W): FREE / OBSTACLE / UNEXPLORED
    hits: np.ndarray = field(repr=False)  # int (H, W): returns that fell in the cell
    passes: np.ndarray = field(repr=False)  # int (H, W): beams that crossed it
    origin: tuple[float, float] = (0.0, 0.0)  # world (x, y) of cell (0, 0)'s centre
    cell: float = 1.0  # cell size in world units

    def __str__(self) -> str:
        return (f"Built map {self.grid.shape[0]}×{self.grid.shape[1]} cells of {self.cell:g}: "
                f"{int((self.grid == OBSTACLE).sum())} obstacle, {int((self.grid == FREE).sum())} free")


def _check_pose_rows(poses, n):
    P = v.as_finite_array(poses, "poses")
    if P.ndim != 2 or P.shape[1] != 3:
        raise ValueError(f"`poses` must have shape (n, 3) = (x, y, heading_rad) rows; got shape {P.shape}")
    if P.shape[0] != n:
        raise ValueError(f"`poses` must have one row per scan ({n}); got {P.shape[0]}")
    return P


def scan_points_world(bearings_rad, ranges, pose) -> np.ndarray:
    """World points ``(x, y)`` of the scan ``(φ_i, r_i)`` seen from ``pose = (x, y, φ)``.

    >>> scan_points_world([0.0], [2.0], (1.0, 1.0, np.pi / 2)).round(12).tolist()
    [[1.0, 3.0]]
    """
    phi = v.as_finite_array(bearings_rad, "bearings_rad", ndim=1)
    r = v.as_finite_array(ranges, "ranges", ndim=1)
    x, y, h = v.as_vector(pose, "pose", 3)
    a = h + phi
    return np.column_stack([x + r * np.cos(a), y + r * np.sin(a)])


def build_map(scans, poses, *, shape: tuple[int, int] | None = None, cell: float = 1.0,
              origin: tuple[float, float] | None = None, free_space: bool = True, min_hits: int = 1,
              free_step: float = 0.5) -> BuiltMap:
    """Occupancy grid built from scans placed at their poses (004 Fig. 11).

    Parameters
    ----------
    scans : sequence of (bearings_rad, ranges, hit) triples
        ``hit`` marks real returns; beams without one only clear free space.
    poses : (n, 3) array_like
        Pose of each scan, in the world units of ``cell``.
    shape : (int, int), optional
        Grid size ``(H, W)``; default: large enough for every return plus a margin.
    cell : float
        Cell size.
    origin : (float, float), optional
        World ``(x, y)`` of the centre of cell ``(0, 0)``; default: from the returns.
    free_space : bool
        Also count the cells crossed by each beam (sampled every ``free_step`` cells).
    min_hits : int
        Returns needed to call a cell an obstacle (our choice; 1 = every return).

    Returns
    -------
    BuiltMap
        A cell is OBSTACLE with ``hits >= min_hits`` and ``hits >= passes/4`` (our rule),
        FREE when only crossed, UNEXPLORED otherwise.

    Examples
    --------
    >>> scan = (np.array([0.0, np.pi]), np.array([3.0, 2.0]), np.array([True, True]))
    >>> m = build_map([scan], [[5.0, 5.0, 0.0]], shape=(10, 10), origin=(0.0, 0.0))
    >>> int(m.grid[5, 8]), int(m.grid[5, 3]), int(m.grid[5, 6]), int(m.grid[0, 0])
    (1, 1, 0, -1)
    """
    scans = list(scans)
    if not scans:
        raise ValueError("`scans` must hold at least one scan; got 0")
    P = _check_pose_rows(poses, len(scans))
    cell = v.check_positive(cell, "cell")
    min_hits = v.check_int(min_hits, "min_hits", minimum=1)
    free_step = v.check_positive(free_step, "free_step")
    pts, rays = [], []
    for n, sc in enumerate(scans):
        if not (isinstance(sc, tuple) and len(sc) == 3):
            raise TypeError(f"`scans[{n}]` must be a (bearings_rad, ranges, hit) tuple; got {type(sc).__name__}")
        phi, r, hit = sc
        hit = np.asarray(hit, dtype=bool)
        world = scan_points_world(phi, r, P[n])
        pts.append(world[hit])
        rays.append((P[n, :2], world))
    hits_xy = np.concatenate(pts) if pts else np.empty((0, 2))
    if origin is None or shape is None:
        lo = hits_xy.min(axis=0) if hits_xy.size else P[:, :2].min(axis=0)
        hi = hits_xy.max(axis=0) if hits_xy.size else P[:, :2].max(axis=0)
        lo, hi = np.minimum(lo, P[:, :2].min(axis=0)), np.maximum(hi, P[:, :2].max(axis=0))
        if origin is None:
            origin = tuple(np.floor(lo / cell) * cell - 2 * cell)
        if shape is None:
            span = np.ceil((hi - np.asarray(origin)) / cell).astype(int) + 3
            shape = (int(span[1]), int(span[0]))
    H, W = v.check_int(shape[0], "shape[0]", minimum=1), v.check_int(shape[1], "shape[1]", minimum=1)
    ox, oy = float(origin[0]), float(origin[1])

    def cells(xy):
        col = np.floor((xy[:, 0] - ox) / cell + 0.5).astype(np.int64)
        row = np.floor((xy[:, 1] - oy) / cell + 0.5).astype(np.int64)
        ok = (row >= 0) & (row < H) & (col >= 0) & (col < W)
        return row[ok] * W + col[ok]

    hits = np.bincount(cells(hits_xy), minlength=H * W).reshape(H, W)
    passes = np.zeros(H * W, dtype=np.int64)
    if free_space:
        for start, ends in rays:  # one vectorised pass per scan
            d = ends - start
            length = np.hypot(d[:, 0], d[:, 1])
            n_s = max(1, math.ceil(float(length.max(initial=0.0)) / (free_step * cell)))
            t = (np.arange(n_s) + 0.5) / n_s
            samples = start + t[None, :, None] * d[:, None, :]  # (beams, n_s, 2)
            # stop one cell short of the return so a wall does not clear itself
            short = (t[None, :] * length[:, None]) < (length[:, None] - cell)
            idx = cells(samples[short])
            passes += np.bincount(np.unique(idx), minlength=H * W)
    passes = passes.reshape(H, W)
    grid = np.full((H, W), UNEXPLORED, dtype=np.int8)
    grid[passes > 0] = FREE
    grid[(hits >= min_hits) & (4 * hits >= passes)] = OBSTACLE
    return BuiltMap(grid, hits, passes, (ox, oy), cell)


def map_agreement(built: BuiltMap, reference, *, tolerance_cells: int = 1) -> dict[str, float]:
    """How well a built map matches a reference grid of the same size and origin (our measure).

    ``precision``: share of built obstacle cells within ``tolerance_cells`` of a reference
    obstacle; ``recall``: share of reference obstacle cells that the built map saw (within
    the tolerance), counted over reference obstacles next to built free space.

    >>> ref = np.zeros((5, 5), np.int8); ref[:, 4] = 1
    >>> b = BuiltMap(ref.copy(), ref.astype(int), np.zeros((5, 5), int))
    >>> map_agreement(b, ref)["precision"]
    1.0
    """
    from scipy import ndimage

    if not isinstance(built, BuiltMap):
        raise TypeError(f"`built` must be a BuiltMap; got {type(built).__name__}")
    ref = v.as_image(reference, "reference")
    if ref.shape != built.grid.shape:
        raise ValueError(f"`reference` must have the built map's shape {built.grid.shape}; got {ref.shape}")
    tol = v.check_int(tolerance_cells, "tolerance_cells", minimum=0)
    size = 2 * tol + 1
    ref_obs = ref == OBSTACLE
    b_obs = built.grid == OBSTACLE
    near_ref = ndimage.maximum_filter(ref_obs, size=size) if tol else ref_obs
    near_b = ndimage.maximum_filter(b_obs, size=size) if tol else b_obs
    seen = ndimage.maximum_filter(built.grid == FREE, size=3) & ref_obs
    precision = float((b_obs & near_ref).sum() / max(1, b_obs.sum()))
    recall = float((seen & near_b).sum() / max(1, seen.sum()))
    return {"precision": precision, "recall": recall}
