"""The one grid ray caster: exact ranges from poses along beams to the first OBSTACLE cell (004 §7).

API summary
-----------
- :func:`cast_rays` ``(grid, poses, angles_rad, max_range) -> (ranges, hit)``: Amanatides-Woo
  grid traversal of every pose × beam at once; ``poses`` of shape ``(3,)`` gives ``(B,)``
  arrays, ``(N, 3)`` gives ``(N, B)``.

The simulator's rangefinder (:func:`slamlab.sim.cast_rays`, one pose) and the beam model's
expected ranges (:mod:`slamlab.localisation.models`, many particles) use it.

Conventions are those of :mod:`slamlab.scans.grid`: cell ``(row, col)`` is the unit square
centred on ``(x, y) = (col, row)``; a beam at angle ``α`` from pose ``(x, y, θ)`` points along
``θ + α``. A beam stops on the face of the first OBSTACLE cell it enters (free and
unexplored cells are transparent; a pose inside an obstacle cell gives range 0); one that
meets none within ``max_range`` or leaves the grid returns ``max_range`` with ``hit = False``.
Lengths are in cells.
"""

from __future__ import annotations

import numpy as np

from .._validate import as_vector, check_positive
from ..geometry.se2 import check_pose, check_poses
from .grid import OBSTACLE, check_grid

__all__ = ["cast_rays"]


def cast_rays(grid, poses, angles_rad, max_range: float) -> tuple[np.ndarray, np.ndarray]:
    """Exact ranges from every pose along every beam to the first OBSTACLE cell (004 §7; Amanatides & Woo 1987).

    All ``N·B`` rays advance together, one crossed cell face per loop step (at most
    ``2·max_range + 4`` steps, each vectorised over the rays still travelling). A ray
    keeps the parameter ``t`` of the next x face and of the next y face; the nearer one
    is crossed (the y face on a tie, i.e. through a corner), and a ray stops when the
    cell it enters is an OBSTACLE (range = ``t`` at that face), lies off the grid, or is
    entered beyond ``max_range``.

    Parameters
    ----------
    grid : array_like of int, shape (H, W)
        Occupancy grid of cell codes (:data:`~slamlab.scans.OBSTACLE` cells stop a ray).
    poses : array_like, shape (3,) or (N, 3)
        ``(x, y, heading_rad)`` of the sensor in cells, one pose or a row per pose.
    angles_rad : array_like, shape (B,)
        Beam angles relative to the heading.
    max_range : float
        Maximum range in cells (> 0); a face entered exactly at ``max_range`` still counts.

    Returns
    -------
    ranges : numpy.ndarray of float, shape (B,) or (N, B)
        Distance to the obstacle face entered; ``max_range`` when there is no return.
    hit : numpy.ndarray of bool, shape (B,) or (N, B)
        Whether the beam returned (met an OBSTACLE cell within ``max_range``).

    Examples
    --------
    >>> g = np.zeros((5, 9), dtype=np.int8); g[:, 8] = 1
    >>> r, hit = cast_rays(g, [2.0, 2.0, 0.0], [0.0, np.pi], 20.0)
    >>> r.tolist(), hit.tolist()
    ([5.5, 20.0], [True, False])
    >>> cast_rays(g, [[2, 2, 0], [4, 2, 0]], [0.0, np.pi], 20.0)[0].tolist()
    [[5.5, 20.0], [3.5, 20.0]]
    """
    g = check_grid(grid)
    one = np.ndim(poses) == 1
    P = check_pose(poses, "poses")[None, :] if one else check_poses(poses, "poses")
    ang = as_vector(angles_rad, "angles_rad")
    rmax = check_positive(max_range, "max_range")
    H, W = g.shape
    solid = (g == OBSTACLE).ravel()
    # one ray per pose × beam: origin, direction, the cell it starts in, its steps ±1
    th = (P[:, 2:3] + ang[None, :]).ravel()
    ox = np.repeat(P[:, 0], ang.size)
    oy = np.repeat(P[:, 1], ang.size)
    ux, uy = np.cos(th), np.sin(th)
    cx = np.floor(ox + 0.5).astype(np.int64)
    cy = np.floor(oy + 0.5).astype(np.int64)
    sx = np.where(ux > 0, 1, -1)
    sy = np.where(uy > 0, 1, -1)
    # t along the ray between two x faces (y faces), and t of the first x face (y face) ahead
    with np.errstate(divide="ignore", invalid="ignore"):
        step_tx = np.where(ux != 0, np.abs(1.0 / ux), np.inf)
        step_ty = np.where(uy != 0, np.abs(1.0 / uy), np.inf)
        next_tx = np.where(ux != 0, (cx + 0.5 * sx - ox) / ux, np.inf)
        next_ty = np.where(uy != 0, (cy + 0.5 * sy - oy) / uy, np.inf)
    t = np.zeros(th.size)  # t at which the ray entered its current cell
    ranges = np.full(th.size, rmax)
    hit = np.zeros(th.size, dtype=bool)
    live = np.arange(th.size)  # the rays still travelling
    for _ in range(int(np.ceil(2 * rmax)) + 4):
        ok = (cy[live] >= 0) & (cy[live] < H) & (cx[live] >= 0) & (cx[live] < W) & (t[live] <= rmax)
        stop = np.zeros(live.size, dtype=bool)
        stop[ok] = solid[cy[live[ok]] * W + cx[live[ok]]]
        ranges[live[stop]] = t[live[stop]]
        hit[live[stop]] = True
        live = live[ok & ~stop]
        if live.size == 0:
            break
        # cross the nearer face (the y face on a tie)
        go_x = next_tx[live] < next_ty[live]
        lx, ly = live[go_x], live[~go_x]
        t[lx] = next_tx[lx]
        cx[lx] += sx[lx]
        next_tx[lx] += step_tx[lx]
        t[ly] = next_ty[ly]
        cy[ly] += sy[ly]
        next_ty[ly] += step_ty[ly]
    shape = (ang.size,) if one else (P.shape[0], ang.size)
    return ranges.reshape(shape), hit.reshape(shape)
