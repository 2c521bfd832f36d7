"""Occupancy grids with 004's three cell values and the 200×200 test room (004 §7, Fig. 3).

API summary
-----------
- Cell codes: :data:`FREE` (= 0, 004's a_c), :data:`OBSTACLE` (= 1, a_p),
  :data:`UNEXPLORED` (= -1, a_n); grids are ``int8`` arrays ``grid[row, col]``.
- :func:`world_to_cell` / :func:`cell_to_world`: the ONE grid ↔ world mapping.
- :func:`make_grid`, :func:`check_grid`, :func:`free_cells`, :func:`grid_to_values`.
- :func:`test_room_200` (the mapped room, read from ``data/test_room_200.txt``),
  :func:`build_test_room_200` (how that file was made), :func:`add_clutter` and
  :func:`measurement_room_200` (the room with unmapped chair legs, people's legs
  and bins, 004 Fig. 3b), :data:`TEST_ROOM_CLUTTER`.
- :func:`grid_to_text` / :func:`grid_from_text`: the text format of the data file.

Conventions (used by every ``slamlab.sim`` module)
--------------------------------------------------
Everything is in **cell units**. A world point is ``(x, y)`` with ``x`` along the
columns and ``y`` along the rows: cell ``grid[row, col]`` is the unit square
centred on ``(x, y) = (col, row)``, i.e. covering ``[col - 0.5, col + 0.5) ×
[row - 0.5, row + 0.5)``. A pose is ``(x, y, heading_rad)``; the heading is
measured from the +x axis towards +y (counter-clockwise when the map is drawn
with ``origin="lower"``, as every slamlab plot does).
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

import numpy as np

from .. import _validate as v

__all__ = [
    "FREE",
    "OBSTACLE",
    "TEST_ROOM_CLUTTER",
    "UNEXPLORED",
    "add_clutter",
    "build_test_room_200",
    "cell_to_world",
    "check_grid",
    "free_cells",
    "grid_from_text",
    "grid_to_text",
    "grid_to_values",
    "make_grid",
    "measurement_room_200",
    "test_room_200",
    "world_to_cell",
]

#: Free space (004's a_c, white in Fig. 3).
FREE = 0
#: Known obstacle: walls, furniture (004's a_p, black in Fig. 3).
OBSTACLE = 1
#: Unexplored space (004's a_n).
UNEXPLORED = -1

_CHARS = {FREE: ".", OBSTACLE: "#", UNEXPLORED: "~"}
_CODES = {c: k for k, c in _CHARS.items()}

#: Unmapped clutter of the measurement room (004 Fig. 3b), our choice of objects:
#: ``("disc", x, y, radius)`` or ``("rect", x0, y0, x1, y1)`` (inclusive cells).
TEST_ROOM_CLUTTER: tuple[tuple, ...] = (
    # four chairs (legs: single cells at the corners of a 6-cell square)
    ("rect", 30, 80, 30, 80), ("rect", 36, 80, 36, 80), ("rect", 30, 86, 30, 86), ("rect", 36, 86, 36, 86),
    ("rect", 140, 60, 140, 60), ("rect", 146, 60, 146, 60), ("rect", 140, 66, 140, 66), ("rect", 146, 66, 146, 66),
    ("rect", 120, 30, 120, 30), ("rect", 126, 30, 126, 30), ("rect", 120, 36, 120, 36), ("rect", 126, 36, 126, 36),
    ("rect", 60, 100, 60, 100), ("rect", 66, 100, 66, 100), ("rect", 60, 106, 60, 106), ("rect", 66, 106, 66, 106),
    # people's legs: pairs of small discs
    ("disc", 80, 60, 1.5), ("disc", 84, 61, 1.5),
    ("disc", 160, 140, 1.5), ("disc", 163, 143, 1.5),
    ("disc", 40, 150, 1.5), ("disc", 44, 150, 1.5),
    # bins
    ("disc", 10, 100, 2.5), ("disc", 190, 60, 2.5), ("disc", 110, 185, 2.5),
)


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
    xy = v.as_finite_array(xy, "xy")
    if xy.ndim == 0 or xy.shape[-1] != 2:
        raise ValueError(f"`xy` must have shape (..., 2); got shape {xy.shape}")
    rc = np.floor(xy[..., ::-1] + 0.5)
    return rc.astype(np.int64)


def cell_to_world(rc) -> np.ndarray:
    """Integer ``(row, col)`` → the world point ``(x, y)`` at the cell centre (inverse of :func:`world_to_cell`).

    >>> cell_to_world([[8, 3]]).tolist()
    [[3.0, 8.0]]
    """
    rc = v.as_finite_array(rc, "rc")
    if rc.ndim == 0 or rc.shape[-1] != 2:
        raise ValueError(f"`rc` must have shape (..., 2); got shape {rc.shape}")
    return rc[..., ::-1].copy()


def make_grid(n_rows: int, n_cols: int, fill: int = FREE) -> np.ndarray:
    """A new ``int8`` grid of the given size filled with one cell code (004 §7).

    >>> make_grid(2, 3, UNEXPLORED)
    array([[-1, -1, -1],
           [-1, -1, -1]], dtype=int8)
    """
    n_rows = v.check_int(n_rows, "n_rows", minimum=1)
    n_cols = v.check_int(n_cols, "n_cols", minimum=1)
    if fill not in _CHARS:
        raise ValueError(f"`fill` must be FREE (0), OBSTACLE (1) or UNEXPLORED (-1); got {fill!r}")
    return np.full((n_rows, n_cols), fill, dtype=np.int8)


def check_grid(grid, name: str = "grid") -> np.ndarray:
    """Validate an occupancy grid: 2-D, integer codes in {FREE, OBSTACLE, UNEXPLORED}; returned as ``int8``.

    >>> check_grid([[0, 1], [-1, 0]]).dtype
    dtype('int8')
    """
    arr = v.as_image(grid, name)
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

    >>> grid_to_values([[0, 1, -1]], a_c=-1, a_p=1, a_n=0)
    array([[-1.,  1.,  0.]])
    """
    g = check_grid(grid)
    for name, val in (("a_c", a_c), ("a_p", a_p), ("a_n", a_n)):
        if isinstance(val, bool) or not isinstance(val, (int, float, np.integer, np.floating)) \
                or not np.isfinite(val):
            raise TypeError(f"`{name}` must be a finite real number; got {val!r}")
    lut = np.array([a_n, a_c, a_p], dtype=dtype)  # index = code + 1
    return lut[g.astype(np.intp) + 1]


def free_cells(grid, margin_cells: int = 0) -> np.ndarray:
    """``(row, col)`` of the free cells at least ``margin_cells`` (Chebyshev) from any non-free cell.

    Returns
    -------
    numpy.ndarray of int64, shape (K, 2)

    Examples
    --------
    >>> g = make_grid(5, 5, OBSTACLE); g[1:4, 1:4] = FREE
    >>> free_cells(g, margin_cells=1).tolist()
    [[2, 2]]
    """
    g = check_grid(grid)
    m = v.check_int(margin_cells, "margin_cells", minimum=0)
    ok = g == FREE
    if m:
        # erosion by a (2m+1)² square, separable, via cumulative sums; outside the grid counts as not free
        pad = np.pad(ok, m, constant_values=False).astype(np.int32)
        k = 2 * m + 1
        c = np.cumsum(np.pad(pad, ((1, 0), (0, 0))), axis=0)
        rows = c[k:] - c[:-k]
        c = np.cumsum(np.pad(rows, ((0, 0), (1, 0))), axis=1)
        ok = (c[:, k:] - c[:, :-k]) == k * k
    return np.argwhere(ok).astype(np.int64)


def _draw_rect(g, x0, y0, x1, y1, code):
    g[max(y0, 0):y1 + 1, max(x0, 0):x1 + 1] = code


def _draw_disc(g, xc, yc, r, code):
    rows, cols = np.ogrid[: g.shape[0], : g.shape[1]]
    g[(cols - xc) ** 2 + (rows - yc) ** 2 <= r * r] = code


def add_clutter(grid, clutter: Sequence[tuple] = TEST_ROOM_CLUTTER) -> np.ndarray:
    """A copy of ``grid`` with unmapped objects drawn as obstacles (004 Fig. 3b).

    Parameters
    ----------
    grid : array_like of int, shape (H, W)
    clutter : sequence of tuples
        ``("disc", x, y, radius)`` or ``("rect", x0, y0, x1, y1)`` in cells (inclusive).

    Examples
    --------
    >>> g = add_clutter(make_grid(5, 5), [("rect", 1, 2, 1, 2)])
    >>> int(g[2, 1]), int(g.sum())
    (1, 1)
    """
    g = check_grid(grid).copy()
    for i, item in enumerate(clutter):
        if not isinstance(item, tuple) or not item or item[0] not in ("disc", "rect"):
            raise ValueError(f"`clutter[{i}]` must be ('disc', x, y, r) or ('rect', x0, y0, x1, y1); got {item!r}")
        if item[0] == "disc" and len(item) == 4:
            _draw_disc(g, *item[1:], OBSTACLE)
        elif item[0] == "rect" and len(item) == 5:
            _draw_rect(g, *(int(t) for t in item[1:]), OBSTACLE)
        else:
            raise ValueError(f"`clutter[{i}]` has the wrong number of fields; got {item!r}")
    return g


def build_test_room_200() -> np.ndarray:
    """Build the 200×200 test room from its floor plan (our redraw of 004 Fig. 3a).

    004 shows its test map only as a picture; this floor plan is ours: an
    L-shaped room with 2-cell walls, the corner outside the L left unexplored,
    two partition walls with doorways and furniture of several shapes (desks,
    a round column, shelves, a sofa), placed without symmetry so that the
    correlation has a single best match. ``data/test_room_200.txt`` holds its
    output (:func:`test_room_200` reads it; a test checks they agree).
    """
    g = make_grid(200, 200, OBSTACLE)
    _draw_rect(g, 152, 162, 199, 199, UNEXPLORED)  # outside the L: never seen
    _draw_rect(g, 2, 2, 197, 197, FREE)
    _draw_rect(g, 150, 160, 199, 199, OBSTACLE)  # the notch's walls
    _draw_rect(g, 152, 162, 199, 199, UNEXPLORED)
    # partition walls with doorways
    _draw_rect(g, 100, 2, 101, 90, OBSTACLE)
    _draw_rect(g, 100, 30, 101, 45, FREE)
    _draw_rect(g, 2, 120, 60, 121, OBSTACLE)
    _draw_rect(g, 25, 120, 40, 121, FREE)
    # furniture
    _draw_rect(g, 20, 60, 45, 72, OBSTACLE)  # desk
    _draw_rect(g, 128, 40, 158, 52, OBSTACLE)  # table
    _draw_rect(g, 170, 100, 197, 108, OBSTACLE)  # cabinet
    _draw_rect(g, 60, 150, 64, 190, OBSTACLE)  # bookshelf
    _draw_rect(g, 75, 172, 98, 181, OBSTACLE)  # sofa
    _draw_rect(g, 175, 18, 185, 28, OBSTACLE)  # block
    _draw_rect(g, 2, 20, 12, 35, OBSTACLE)  # cupboard against the wall
    _draw_disc(g, 125, 135, 6, OBSTACLE)  # round column
    _draw_rect(g, 118, 180, 145, 185, OBSTACLE)  # bench near the notch
    _draw_rect(g, 165, 130, 170, 150, OBSTACLE)  # slanted-ish stand: a thin block
    return g


def grid_to_text(grid) -> str:
    """Text form of a grid: one line per row (row 0 first), ``.`` free, ``#`` obstacle, ``~`` unexplored.

    >>> grid_to_text([[0, 1, -1]])
    '.#~\\n'
    """
    g = check_grid(grid)
    table = np.array(["~", ".", "#"])
    return "".join("".join(row) + "\n" for row in table[g.astype(np.intp) + 1])


def grid_from_text(text: str) -> np.ndarray:
    """Inverse of :func:`grid_to_text`.

    >>> grid_from_text(".#~\\n..~\\n").tolist()
    [[0, 1, -1], [0, 0, -1]]
    """
    if not isinstance(text, str):
        raise TypeError(f"`text` must be a str; got {type(text).__name__}")
    lines = [ln for ln in text.splitlines() if ln]
    if not lines:
        raise ValueError("`text` must hold at least one row; got an empty text")
    widths = {len(ln) for ln in lines}
    if len(widths) != 1:
        raise ValueError(f"`text` rows must all have the same length; got lengths {sorted(widths)}")
    bad = set("".join(lines)) - set(_CODES)
    if bad:
        raise ValueError(f"`text` may hold only '.', '#' and '~'; got {sorted(bad)!r}")
    lut = np.zeros(128, dtype=np.int8)
    for ch, code in _CODES.items():
        lut[ord(ch)] = code
    raw = np.frombuffer("".join(lines).encode("ascii"), dtype=np.uint8)
    return lut[raw].reshape(len(lines), -1)


def _room_path() -> Path:
    from ..data import find_data

    return find_data("test_room_200.txt")


def test_room_200() -> np.ndarray:
    """The 200×200 test room M that the robot keeps in memory (004 Fig. 3a), from ``data/test_room_200.txt``.

    Examples
    --------
    >>> M = test_room_200()
    >>> M.shape, M.dtype, sorted(np.unique(M).tolist())
    ((200, 200), dtype('int8'), [-1, 0, 1])
    """
    return grid_from_text(_room_path().read_text(encoding="ascii"))


test_room_200.__test__ = False  # not a pytest test despite the name


def measurement_room_200(clutter: Sequence[tuple] = TEST_ROOM_CLUTTER) -> np.ndarray:
    """The test room with unmapped clutter, the world the rangefinder measures (004 Fig. 3b).

    >>> int((measurement_room_200() != test_room_200()).sum()) > 0
    True
    """
    return add_clutter(test_room_200(), clutter)
