"""Occupancy grids with 004's three cell values and the 200×200 test room (004 §7, Fig. 3).

API summary
-----------
- Cell codes: :data:`FREE` (= 0, 004's a_c), :data:`OBSTACLE` (= 1, a_p),
  :data:`UNEXPLORED` (= -1, a_n); grids are ``int8`` arrays ``grid[row, col]``.
- Re-exported from :mod:`slamlab.scans.grid` (where they live): the codes,
  :func:`world_to_cell` / :func:`cell_to_world`, :func:`make_grid`, :func:`check_grid`,
  :func:`grid_to_values`.
- :func:`free_cells`.
- :func:`test_room_200` (the mapped room, read from ``slamlab/data/bundled/test_room_200.txt``),
  :func:`build_test_room_200` (how that file was made), :func:`add_clutter` and
  :func:`measurement_room_200` (the room with unmapped chair legs, people's legs
  and bins, 004 Fig. 3b), :data:`TEST_ROOM_CLUTTER`.
- :func:`grid_to_text` / :func:`grid_from_text`: the text format of the data file.

Conventions: those of :mod:`slamlab.scans.grid` (cell units, cell ``(row, col)``
centred on ``(x, y) = (col, row)``, poses ``(x, y, heading_rad)``).
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

import numpy as np

from .._validate import check_int
from ..scans.grid import (
    CHAR_CODES,
    FREE,
    OBSTACLE,
    UNEXPLORED,
    cell_to_world,
    check_grid,
    grid_to_values,
    make_grid,
    world_to_cell,
)

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


def free_cells(grid, margin_cells: int = 0) -> np.ndarray:
    """``(row, col)`` of the free cells at least ``margin_cells`` (Chebyshev) from any non-free cell.

    Parameters
    ----------
    grid : array_like of int, shape (H, W)
        Cell codes.
    margin_cells : int, default 0
        Smallest Chebyshev distance to a non-free cell or the border [cells].

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
    m = check_int(margin_cells, "margin_cells", minimum=0)
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

    Returns
    -------
    numpy.ndarray of int8, shape (H, W)

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
    correlation has a single best match. ``slamlab/data/bundled/test_room_200.txt`` holds its
    output (:func:`test_room_200` reads it; a test checks they agree).

    Returns
    -------
    numpy.ndarray of int8, shape (200, 200)
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

    Parameters
    ----------
    grid : array_like of int, shape (H, W)
        Cell codes.

    Returns
    -------
    str

    Examples
    --------
    >>> grid_to_text([[0, 1, -1]])
    '.#~\\n'
    """
    g = check_grid(grid)
    table = np.array(["~", ".", "#"])
    return "".join("".join(row) + "\n" for row in table[g.astype(np.intp) + 1])


def grid_from_text(text: str) -> np.ndarray:
    """Inverse of :func:`grid_to_text`.

    Parameters
    ----------
    text : str
        One line per row of ``.``, ``#``, ``~``, all of one length.

    Returns
    -------
    numpy.ndarray of int8, shape (H, W)

    Examples
    --------
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
    bad = set("".join(lines)) - set(CHAR_CODES)
    if bad:
        raise ValueError(f"`text` may hold only '.', '#' and '~'; got {sorted(bad)!r}")
    lut = np.zeros(128, dtype=np.int8)
    for ch, code in CHAR_CODES.items():
        lut[ord(ch)] = code
    raw = np.frombuffer("".join(lines).encode("ascii"), dtype=np.uint8)
    return lut[raw].reshape(len(lines), -1)


def _room_path() -> Path:
    from ..data import find_data

    return find_data("test_room_200.txt")


def test_room_200() -> np.ndarray:
    """The 200×200 test room M that the robot keeps in memory (004 Fig. 3a), from ``slamlab/data/bundled/test_room_200.txt``.

    Returns
    -------
    numpy.ndarray of int8, shape (200, 200)

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

    Parameters
    ----------
    clutter : sequence of tuple
        Shapes added to the test room (default ``TEST_ROOM_CLUTTER``, as for :func:`add_clutter`).

    Returns
    -------
    numpy.ndarray of int8, shape (200, 200)

    Examples
    --------
    >>> int((measurement_room_200() != test_room_200()).sum()) > 0
    True
    """
    return add_clutter(test_room_200(), clutter)
