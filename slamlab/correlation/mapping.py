"""Occupancy grid from scans taken at known poses (for localising real laser logs on a map, 004 §7).

API summary
-----------
- :class:`GridFrame` — metric ↔ cell frame of a grid (origin, cell size): ``to_cells``, ``to_metres``.
- :func:`occupancy_grid_from_scans` ``(angles, ranges_cells, hit, poses_cells, shape) -> grid``:
  count hits and pass-throughs per cell (``np.bincount``) and label cells
  OBSTACLE / FREE / UNEXPLORED with 004's three values.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .. import _validate as v
from ..sim.grid import FREE, OBSTACLE, UNEXPLORED

__all__ = ["GridFrame", "occupancy_grid_from_scans"]


@dataclass(frozen=True)
class GridFrame:
    """A grid over a metric frame: cell ``(row, col)`` is centred on ``(x0_m + col·cell_m, y0_m + row·cell_m)``.

    Examples
    --------
    >>> f = GridFrame(x0_m=-1.0, y0_m=2.0, cell_m=0.5, shape=(10, 10))
    >>> f.to_cells([[0.0, 3.0, 0.3]]).tolist()
    [[2.0, 2.0, 0.3]]
    >>> f.to_metres([[2.0, 2.0, 0.3]]).tolist()
    [[0.0, 3.0, 0.3]]
    """

    x0_m: float
    y0_m: float
    cell_m: float
    shape: tuple[int, int]

    @classmethod
    def around(cls, points_m, cell_m: float, margin_m: float = 1.0) -> GridFrame:
        """The smallest frame holding ``points_m`` (k, 2) plus ``margin_m`` on every side."""
        P = v.as_matrix(points_m, "points_m", (None, 2))
        if P.shape[0] == 0:
            raise ValueError("`points_m` must hold at least one point; got 0")
        cell = v.check_positive(cell_m, "cell_m")
        lo = P.min(axis=0) - margin_m
        hi = P.max(axis=0) + margin_m
        n = np.ceil((hi - lo) / cell).astype(int) + 1
        return cls(float(lo[0]), float(lo[1]), cell, (int(n[1]), int(n[0])))

    def to_cells(self, poses_m) -> np.ndarray:
        """Poses ``(x_m, y_m, heading)`` (n, 3) → cell units (heading unchanged)."""
        P = v.as_matrix(poses_m, "poses_m", (None, 3))
        return np.column_stack([(P[:, 0] - self.x0_m) / self.cell_m, (P[:, 1] - self.y0_m) / self.cell_m, P[:, 2]])

    def to_metres(self, poses_cells) -> np.ndarray:
        """Inverse of :meth:`to_cells`."""
        P = v.as_matrix(poses_cells, "poses_cells", (None, 3))
        return np.column_stack([P[:, 0] * self.cell_m + self.x0_m, P[:, 1] * self.cell_m + self.y0_m, P[:, 2]])


def occupancy_grid_from_scans(angles_rad, ranges_cells, hit, poses_cells, shape, *, step_cells: float = 0.5,
                              hit_ratio: float = 0.25) -> np.ndarray:
    """Label each cell OBSTACLE, FREE or UNEXPLORED from scans at known poses (our simple counting model).

    Every beam votes "free" for the cells it passes (samples every ``step_cells``
    before its range) and "hit" for the cell at its end. A cell with hits becomes
    an obstacle when ``hits >= hit_ratio · passes``; a passed cell otherwise is
    free; a cell no beam reached stays unexplored (004's a_n).

    Parameters
    ----------
    angles_rad : array_like, shape (m,)
        Beam angles (the same for every scan).
    ranges_cells : array_like, shape (n_scans, m)
    hit : array_like of bool, shape (n_scans, m)
        Beams with a return; misses vote "free" along their whole range.
    poses_cells : array_like, shape (n_scans, 3)
    shape : (int, int)
        Grid size (rows, cols); votes outside are dropped.

    Returns
    -------
    numpy.ndarray of int8, shape ``shape``

    Examples
    --------
    >>> g = occupancy_grid_from_scans([0.0], [[3.5]], [[True]], [[1, 1, 0]], (3, 6))
    >>> g.tolist()
    [[-1, -1, -1, -1, -1, -1], [-1, 0, 0, 0, 0, 1], [-1, -1, -1, -1, -1, -1]]
    """
    a = v.as_vector(angles_rad, "angles_rad")
    R = v.as_matrix(ranges_cells, "ranges_cells", (None, a.size))
    Hm = np.asarray(hit)
    if Hm.dtype != bool or Hm.shape != R.shape:
        raise ValueError(f"`hit` must be a bool array of shape {R.shape}; got {Hm.dtype} {Hm.shape}")
    P = v.as_matrix(poses_cells, "poses_cells", (R.shape[0], 3))
    if not (isinstance(shape, tuple) and len(shape) == 2):
        raise TypeError(f"`shape` must be a (rows, cols) tuple; got {shape!r}")
    n_rows = v.check_int(shape[0], "shape[0]", minimum=1)
    n_cols = v.check_int(shape[1], "shape[1]", minimum=1)
    st = v.check_positive(step_cells, "step_cells")
    ratio = v.check_positive(hit_ratio, "hit_ratio")
    size = n_rows * n_cols
    passes = np.zeros(size)
    hits = np.zeros(size)
    t = st * np.arange(int(np.ceil(max(R.max(), 0.0) / st)) + 1)
    per = max(1, int(2e6 // max(a.size * t.size, 1)))

    def flat_index(x, y):
        col = np.floor(x + 0.5).astype(np.int64)
        row = np.floor(y + 0.5).astype(np.int64)
        ok = (row >= 0) & (row < n_rows) & (col >= 0) & (col < n_cols)
        return (row * n_cols + col)[ok]

    for s0 in range(0, R.shape[0], per):
        th = P[s0:s0 + per, 2:3] + a[None, :]  # (k, m)
        c, s = np.cos(th), np.sin(th)
        r = R[s0:s0 + per]
        end = np.where(Hm[s0:s0 + per], r - 1e-6, r)
        m = t[None, None, :] < end[:, :, None]
        x = P[s0:s0 + per, 0, None, None] + c[:, :, None] * t[None, None, :]
        y = P[s0:s0 + per, 1, None, None] + s[:, :, None] * t[None, None, :]
        passes += np.bincount(flat_index(x[m], y[m]), minlength=size)
        h = Hm[s0:s0 + per]
        rh = r[h] + 0.01
        hits += np.bincount(flat_index(P[s0:s0 + per, 0, None].repeat(a.size, 1)[h] + c[h] * rh,
                                       P[s0:s0 + per, 1, None].repeat(a.size, 1)[h] + s[h] * rh), minlength=size)
    grid = np.full(size, UNEXPLORED, dtype=np.int8)
    grid[passes > 0] = FREE
    grid[(hits > 0) & (hits >= ratio * passes)] = OBSTACLE
    return grid.reshape(n_rows, n_cols)
