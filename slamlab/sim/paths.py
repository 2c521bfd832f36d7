"""Robot trajectories on the grid maps, in cell units (004 §8, Fig. 9).

API summary
-----------
- :func:`piecewise_path` ``(start_pose, segments) -> (n, 3)``: a path of in-place
  turns ``("turn", dθ_rad, n_steps)`` and straight legs ``("line", length_cells, n_steps)``.
- :func:`path_004` ``(n_poses=121) -> (n, 3)``: 004's test path on the test room:
  a turn at the start, a straight leg, a turn onto a second straight leg.
- :data:`PATH_004_SEGMENTS`, :data:`PATH_004_START`: its (our) coordinates.
- :func:`random_free_poses` ``(grid, n, margin_cells, rng) -> (n, 3)``: whole-cell
  positions in free space with uniform headings (004 Table 1's test poses).

Poses are ``(x, y, heading_rad)`` with x = column, y = row (see :mod:`slamlab.sim.grid`).
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from .._validate import as_rng, as_vector, check_int
from ..geometry import wrap_angle
from ..geometry.se2 import check_pose
from .grid import free_cells

__all__ = ["PATH_004_SEGMENTS", "PATH_004_START", "path_004", "piecewise_path", "random_free_poses"]

#: Start pose of our version of 004's path (Fig. 9 gives no coordinates): x, y [cells], heading [rad].
PATH_004_START = (70.0, 30.0, np.pi)
#: 004's path: turn at the start, first straight leg, turn, second leg; 1 + 10 + 50 + 15 + 45 = 121 poses.
PATH_004_SEGMENTS: tuple[tuple, ...] = (
    ("turn", -np.pi / 2, 10),  # face +y (from 180° to 90°)
    ("line", 80.0, 50),  # up the room along x = 70
    ("turn", -np.pi / 2, 15),  # face +x
    ("line", 80.0, 45),  # across the room along y = 110
)


def piecewise_path(start_pose, segments: Sequence[tuple]) -> np.ndarray:
    """Poses along in-place turns and straight legs, evenly spaced within each segment (004 §8).

    Parameters
    ----------
    start_pose : array_like, shape (3,)
        ``(x, y, heading_rad)``.
    segments : sequence of tuples
        ``("turn", dtheta_rad, n_steps)`` or ``("line", length_cells, n_steps)``;
        each segment adds ``n_steps`` poses after the current one.

    Returns
    -------
    numpy.ndarray, shape (1 + Σ n_steps, 3)
        Headings wrapped to ``[-π, π)``.

    Examples
    --------
    >>> piecewise_path([0, 0, 0], [("line", 2.0, 2), ("turn", np.pi / 2, 1)]).round(6).tolist()
    [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [2.0, 0.0, 0.0], [2.0, 0.0, 1.570796]]
    """
    p = check_pose(start_pose, "start_pose").copy()
    if isinstance(segments, (str, bytes)) or not isinstance(segments, Sequence):
        raise TypeError(f"`segments` must be a sequence of tuples; got {type(segments).__name__}")
    out = [p.copy()]
    for i, seg in enumerate(segments):
        if not (isinstance(seg, tuple) and len(seg) == 3 and seg[0] in ("turn", "line")):
            raise ValueError(f"`segments[{i}]` must be ('turn', dθ_rad, n) or ('line', length, n); got {seg!r}")
        kind, amount, n = seg
        n = check_int(n, f"segments[{i}] n_steps", minimum=1)
        amount = float(as_vector(amount, f"segments[{i}] amount", 1)[0])
        k = np.arange(1, n + 1) / n
        if kind == "turn":
            pts = np.column_stack([np.full(n, p[0]), np.full(n, p[1]), p[2] + amount * k])
        else:
            pts = np.column_stack([p[0] + amount * k * np.cos(p[2]), p[1] + amount * k * np.sin(p[2]),
                                   np.full(n, p[2])])  # unwrapped heading: the path's points are exact
        out.extend(pts)
        p = pts[-1].copy()
    P = np.array(out)
    P[:, 2] = wrap_angle(P[:, 2])
    return P


def path_004(n_poses: int = 121) -> np.ndarray:
    """004's 121-pose test path on the test room: turn, straight leg, turn, second leg (004 §8, Fig. 9).

    004 gives neither coordinates nor speeds; ours are :data:`PATH_004_START` and
    :data:`PATH_004_SEGMENTS` (our choice). ``n_poses`` other than 121 rescales
    the number of steps of every segment (the geometry stays).

    Parameters
    ----------
    n_poses : int, default 121
        Poses along the path (at least 5).

    Returns
    -------
    numpy.ndarray, shape (n_poses, 3)
        ``(x, y)`` [cells] and heading [rad].

    Examples
    --------
    >>> P = path_004()
    >>> P.shape, P[0].round(3).tolist(), P[-1].round(3).tolist()
    ((121, 3), [70.0, 30.0, -3.142], [150.0, 110.0, 0.0])
    """
    n = check_int(n_poses, "n_poses", minimum=5)
    steps = np.array([s[2] for s in PATH_004_SEGMENTS], dtype=float)
    if n != 1 + int(steps.sum()):
        scaled = np.maximum(1, np.round(steps * (n - 1) / steps.sum())).astype(int)
        scaled[1] += (n - 1) - int(scaled.sum())  # put the rounding remainder on the first leg
        if scaled[1] < 1:
            raise ValueError(f"`n_poses` too small for the four segments; got {n}")
        segs = tuple((s[0], s[1], int(k)) for s, k in zip(PATH_004_SEGMENTS, scaled, strict=True))
    else:
        segs = PATH_004_SEGMENTS
    return piecewise_path(PATH_004_START, segs)


def random_free_poses(grid, n: int, *, margin_cells: int = 3, rng=None) -> np.ndarray:
    """``n`` random poses on free whole cells with uniform headings in ``[0, 2π)`` (004 Table 1).

    Parameters
    ----------
    grid : array_like of int, shape (H, W)
    n : int
        Number of poses.
    margin_cells : int
        Minimum (Chebyshev) distance in cells from any non-free cell.
    rng : Generator, int or None

    Returns
    -------
    numpy.ndarray, shape (n, 3)
        ``(x, y, heading_rad)`` with integer x, y.

    Examples
    --------
    >>> g = np.zeros((10, 10), dtype=np.int8)
    >>> P = random_free_poses(g, 3, margin_cells=0, rng=1)
    >>> P.shape, bool(np.all(P[:, :2] == np.round(P[:, :2])))
    ((3, 3), True)
    """
    n = check_int(n, "n", minimum=1)
    cells = free_cells(grid, margin_cells)
    if cells.shape[0] == 0:
        raise ValueError(f"`grid` has no free cell at least {margin_cells} cells from an obstacle")
    rng = as_rng(rng)
    pick = cells[rng.integers(0, cells.shape[0], n)]
    heading = rng.uniform(0.0, 2 * np.pi, n)
    return np.column_stack([pick[:, 1].astype(float), pick[:, 0].astype(float), heading])
