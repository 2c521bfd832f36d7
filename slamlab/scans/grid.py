"""Occupancy grids: 004's three cell codes, the grid ↔ world mapping and metric grid frames (004 §7).

API summary
-----------
- Cell codes: :data:`FREE` (= 0, 004's a_c), :data:`OBSTACLE` (= 1, a_p),
  :data:`UNEXPLORED` (= -1, a_n); grids are ``int8`` arrays ``grid[row, col]``.
- :func:`world_to_cell` / :func:`cell_to_world`: the ONE grid ↔ world mapping (cell units).
- :func:`make_grid`, :func:`check_grid`, :func:`grid_to_values` (codes → 004's constants).
- :class:`GridFrame`: a grid laid over a metric frame (origin, cell size, shape):
  poses and points metres ↔ cells.

Conventions (used by every 2-D module: scans, sim, correlation, hough)
----------------------------------------------------------------------
In **cell units**, a world point is ``(x, y)`` with ``x`` along the columns and ``y``
along the rows: cell ``grid[row, col]`` is the unit square centred on ``(x, y) =
(col, row)``, i.e. covering ``[col - 0.5, col + 0.5) × [row - 0.5, row + 0.5)``. A
pose is ``(x, y, heading_rad)``; the heading is measured from the +x axis towards
+y (counter-clockwise when the map is drawn with ``origin="lower"``). A metric map
is a cell grid plus a :class:`GridFrame`.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .._validate import as_finite_array, as_image, as_matrix, check_int, check_positive, check_real

__all__ = [
    "CELL_CHARS",
    "CHAR_CODES",
    "FREE",
    "OBSTACLE",
    "UNEXPLORED",
    "GridFrame",
    "cell_to_world",
    "check_grid",
    "grid_to_values",
    "make_grid",
    "world_to_cell",
]

#: Free space (004's a_c, white in Fig. 3).
FREE = 0
#: Known obstacle: walls, furniture (004's a_p, black in Fig. 3).
OBSTACLE = 1
#: Unexplored space (004's a_n).
UNEXPLORED = -1

#: Cell code → its character in a text map (``grid_from_text``/``grid_to_text`` in :mod:`slamlab.sim.grid`).
CELL_CHARS = {FREE: ".", OBSTACLE: "#", UNEXPLORED: "~"}
#: Character of a text map → cell code (the inverse of :data:`CELL_CHARS`).
CHAR_CODES = {c: k for k, c in CELL_CHARS.items()}


def world_to_cell(xy) -> np.ndarray:
    """World point(s) ``(x, y)`` [cells] → integer ``(row, col)`` of the containing cell.

    The one grid ↔ world mapping of slamlab (see the module docstring):
    ``row = floor(y + 0.5)``, ``col = floor(x + 0.5)``.

    Parameters
    ----------
    xy : array_like, shape (..., 2)
        Points in cell units.

    Returns
    -------
    numpy.ndarray of int64, shape (..., 2)
        ``[..., 0]`` = row, ``[..., 1]`` = col (not clipped to any grid).

    Examples
    --------
    >>> world_to_cell([[3.4, 7.6], [0.0, -0.5]]).tolist()
    [[8, 3], [0, 0]]
    """
    xy = as_finite_array(xy, "xy")
    if xy.ndim == 0 or xy.shape[-1] != 2:
        raise ValueError(f"`xy` must have shape (..., 2); got shape {xy.shape}")
    rc = np.floor(xy[..., ::-1] + 0.5)
    return rc.astype(np.int64)


def cell_to_world(rc) -> np.ndarray:
    """Integer ``(row, col)`` → the world point ``(x, y)`` at the cell centre (inverse of :func:`world_to_cell`).

    Parameters
    ----------
    rc : array_like, shape (..., 2)
        Cell indices ``(row, col)``.

    Returns
    -------
    xy : ndarray, shape (..., 2)
        World points ``(x, y)`` in cell units.

    Examples
    --------
    >>> cell_to_world([[8, 3]]).tolist()
    [[3.0, 8.0]]
    """
    rc = as_finite_array(rc, "rc")
    if rc.ndim == 0 or rc.shape[-1] != 2:
        raise ValueError(f"`rc` must have shape (..., 2); got shape {rc.shape}")
    return rc[..., ::-1].copy()


def make_grid(n_rows: int, n_cols: int, fill: int = FREE) -> np.ndarray:
    """A new ``int8`` grid of the given size filled with one cell code (004 §7).

    Parameters
    ----------
    n_rows, n_cols : int
        Grid size, at least 1 each.
    fill : int
        Cell code to fill with: ``FREE`` (0, default), ``OBSTACLE`` (1) or ``UNEXPLORED`` (-1).

    Returns
    -------
    grid : ndarray of int8, shape (n_rows, n_cols)
        The new grid.

    Examples
    --------
    >>> make_grid(2, 3, UNEXPLORED)
    array([[-1, -1, -1],
           [-1, -1, -1]], dtype=int8)
    """
    n_rows = check_int(n_rows, "n_rows", minimum=1)
    n_cols = check_int(n_cols, "n_cols", minimum=1)
    if fill not in CELL_CHARS:
        raise ValueError(f"`fill` must be FREE (0), OBSTACLE (1) or UNEXPLORED (-1); got {fill!r}")
    return np.full((n_rows, n_cols), fill, dtype=np.int8)


def check_grid(grid, name: str = "grid") -> np.ndarray:
    """Validate an occupancy grid: 2-D, integer codes in {FREE, OBSTACLE, UNEXPLORED}; returned as ``int8``.

    Parameters
    ----------
    grid : array_like, shape (H, W)
        Cell codes; whole-number floats and bools are accepted.
    name : str
        Argument name used in the error messages (default ``"grid"``).

    Returns
    -------
    grid : ndarray of int8, shape (H, W)
        The validated codes.

    Examples
    --------
    >>> check_grid([[0, 1], [-1, 0]]).dtype
    dtype('int8')
    """
    arr = as_image(grid, name)
    if not (np.issubdtype(arr.dtype, np.integer) or arr.dtype == np.bool_):
        if np.issubdtype(arr.dtype, np.floating) and np.all(arr == np.round(arr)):
            arr = arr.astype(np.int64)
        else:
            raise TypeError(f"`{name}` must hold integer cell codes (0 free, 1 obstacle, -1 unexplored); "
                            f"got dtype {arr.dtype}")
    bad = ~np.isin(arr, (FREE, OBSTACLE, UNEXPLORED))
    if bad.any():
        raise ValueError(f"`{name}` must hold only 0 (free), 1 (obstacle) or -1 (unexplored); "
                         f"got {int(bad.sum())} other value(s), e.g. {arr[bad][0]}")
    return arr.astype(np.int8, copy=False)


def grid_to_values(grid, a_c: float = -1.0, a_p: float = 1.0, a_n: float = 0.0, dtype=np.float64) -> np.ndarray:
    """Map the cell codes to 004's constants: free → ``a_c``, obstacle → ``a_p``, unexplored → ``a_n`` (004 §7).

    Parameters
    ----------
    grid : array_like, shape (H, W)
        Cell codes (:func:`check_grid`).
    a_c, a_p, a_n : float
        Values of free, obstacle and unexplored cells (defaults -1, 1, 0).
    dtype : numpy dtype
        Output dtype (default float64).

    Returns
    -------
    values : ndarray, shape (H, W)
        One value per cell.

    Examples
    --------
    >>> grid_to_values([[0, 1, -1]], a_c=-1, a_p=1, a_n=0)
    array([[-1.,  1.,  0.]])
    """
    g = check_grid(grid)
    for name, val in (("a_c", a_c), ("a_p", a_p), ("a_n", a_n)):
        check_real(val, name)
    lut = np.array([a_n, a_c, a_p], dtype=dtype)  # index = code + 1
    return lut[g.astype(np.intp) + 1]



@dataclass(frozen=True)
class GridFrame:
    """A grid over a metric frame: cell ``(row, col)`` is centred on ``(x0_m + col·cell_m, y0_m + row·cell_m)``.

    Attributes
    ----------
    x0_m, y0_m : float
        World position [m] of the centre of cell ``(0, 0)``.
    cell_m : float
        Cell size [m], positive.
    shape : tuple of int
        Grid size ``(rows, cols)``.

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

    def __post_init__(self):
        check_positive(self.cell_m, "cell_m")
        if not (isinstance(self.shape, tuple) and len(self.shape) == 2):
            raise TypeError(f"`shape` must be a (rows, cols) tuple; got {self.shape!r}")
        check_int(self.shape[0], "shape[0]", minimum=1)
        check_int(self.shape[1], "shape[1]", minimum=1)

    @classmethod
    def around(cls, points_m, cell_m: float, margin_m: float = 1.0) -> GridFrame:
        """The smallest frame holding ``points_m`` (k, 2) plus ``margin_m`` on every side.

        Parameters
        ----------
        points_m : array_like, shape (k, 2)
            World points, metres.
        cell_m : float
            Cell side, metres.
        margin_m : float
            Free border around the points, metres.

        Returns
        -------
        GridFrame

        Examples
        --------
        >>> GridFrame.around([[0.0, 0.0], [2.0, 1.0]], 0.5, margin_m=0.0)
        GridFrame(x0_m=0.0, y0_m=0.0, cell_m=0.5, shape=(3, 5))
        """
        P = as_matrix(points_m, "points_m", (None, 2))
        if P.shape[0] == 0:
            raise ValueError("`points_m` must hold at least one point; got 0")
        cell = check_positive(cell_m, "cell_m")
        lo = P.min(axis=0) - margin_m
        hi = P.max(axis=0) + margin_m
        n = np.ceil((hi - lo) / cell).astype(int) + 1
        return cls(float(lo[0]), float(lo[1]), cell, (int(n[1]), int(n[0])))

    def to_cells(self, poses_m) -> np.ndarray:
        """Poses ``(x_m, y_m, heading)`` (n, 3) → cell units (heading unchanged).

        Parameters
        ----------
        poses_m : array_like, shape (n, 3)
            Poses ``(x_m, y_m, heading_rad)``.

        Returns
        -------
        poses_cells : ndarray, shape (n, 3)
            ``(x, y)`` in cell units relative to the frame's origin, heading unchanged.
        """
        P = as_matrix(poses_m, "poses_m", (None, 3))
        return np.column_stack([(P[:, 0] - self.x0_m) / self.cell_m, (P[:, 1] - self.y0_m) / self.cell_m, P[:, 2]])

    def to_metres(self, poses_cells) -> np.ndarray:
        """Inverse of :meth:`to_cells`.

        Parameters
        ----------
        poses_cells : array_like, shape (n, 3)
            Poses in cell units ``(x, y, heading_rad)``.

        Returns
        -------
        poses_m : ndarray, shape (n, 3)
            ``(x_m, y_m, heading_rad)``.
        """
        P = as_matrix(poses_cells, "poses_cells", (None, 3))
        return np.column_stack([P[:, 0] * self.cell_m + self.x0_m, P[:, 1] * self.cell_m + self.y0_m, P[:, 2]])
