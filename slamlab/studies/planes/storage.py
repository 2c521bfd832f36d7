"""Ch. 10: the bytes of the raw point clouds against those of the plane map (002 "Introduction", "Conclusion").

002 says, without a figure, that representing the map by geometric primitives and averaging what falls on the
same part of space "allows the volume of data stored in the map to be reduced substantially" (its conclusion),
and that the points on no plane "must also be kept" (002 "Updating the database"). The measure is ours: every
stored item is counted in values of one width (4 bytes: float32 / int32, or 8), so that

* a raw frame point is x, y, z and the intensity (4 values); the scanner's own line is a range and an intensity
  per beam (2 values, the beam angle being its index);
* a map plane ``Π = {n, p, T, A}`` is ``n`` (3), ``p`` (1), ``T`` (16, as our map holds it) and the cell side (1):
  21 values; each of its cells (002's parts ``A``) is ``i, j, N_k, ΣI`` (4 values);
* a point on no plane kept as a point is 4 values (002: "the point clouds can be stored directly"); our voxel
  store (002: an octree [11]) keeps 3 indices and a count per voxel (4 values), of every ``thin``-th such point.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..._table import format_table
from ..._validate import as_finite_array, check_int
from ...planes.mapping import PlaneMap
from .reports import FlightResult

__all__ = ["VALUES_PER_CELL", "VALUES_PER_PLANE", "VALUES_PER_POINT", "VALUES_PER_VOXEL", "StorageResult",
           "flight_storage", "map_storage"]

#: values per raw frame point: x, y, z, intensity (ours)
VALUES_PER_POINT = 4
#: values per beam of a scan line as the scanner gives it: range, intensity (ours)
VALUES_PER_BEAM = 2
#: values per map plane: n (3), p, T (4 x 4), the cell side (ours: as our map holds them)
VALUES_PER_PLANE = 21
#: values per cell (002's part): its indices i, j, the count N_k and the intensity sum (ours)
VALUES_PER_CELL = 4
#: values per voxel of the store of points on no plane: three indices and a count (ours)
VALUES_PER_VOXEL = 4


def _cells_merged(plane_map: PlaneMap, factor: int) -> int:
    """Cells of the map's planes if each ``factor × factor`` block of cells were one (exact: the grids nest)."""
    return sum(len(np.unique(np.floor_divide(pl.ij, factor), axis=0)) for pl in plane_map.planes)


def _mb(n: int) -> str:
    return f"{n / 1e6:.3f}"


def _held_bytes(plane_map: PlaneMap) -> int:
    """Bytes of the numpy arrays our :class:`~slamlab.planes.PlaneMap` holds, with its derived keys and means."""
    per_plane = [sum(np.asarray(a).nbytes for a in (pl.n, pl.T, pl.ij, pl.counts, pl.sums, pl.keys,
                                                    pl.mean_intensity)) + 2 * 8      # + p and the cell side
                 for pl in plane_map.planes]
    return int(sum(per_plane) + plane_map.voxels.keys.nbytes + plane_map.voxels.counts.nbytes)


@dataclass(frozen=True)
class StorageResult:
    """Counts behind 002's compression claim; bytes at ``bytes_per_value`` bytes per value (ours).

    Attributes
    ----------
    frame_points : (F,) int
        Points per frame.
    frame_off_plane : (F,) int
        Points per frame on none of its planes.
    n_planes, n_cells : int
        Planes of the map and their cells.
    cell_m : float
        Cell side of the map's planes in metres.
    n_voxels, voxel_points : int
        Voxels of the store of points on no plane and the points counted into them.
    merged_cells : tuple of (int, int)
        ``(factor, cells)``: the map's cells if each ``factor × factor`` block were one cell.
    held_bytes : int
        Bytes of the numpy arrays our map holds (8-byte values, with the derived cell keys and means).
    bytes_per_value : int
        4 (float32 / int32) or 8 (float64 / int64).
    """

    frame_points: np.ndarray
    frame_off_plane: np.ndarray
    n_planes: int
    n_cells: int
    cell_m: float
    n_voxels: int
    voxel_points: int
    merged_cells: tuple
    held_bytes: int
    bytes_per_value: int = 4

    @property
    def n_frames(self) -> int:
        """Frames of the run."""
        return len(self.frame_points)

    @property
    def raw_points(self) -> int:
        """Points of all frames."""
        return int(self.frame_points.sum())

    @property
    def off_plane_points(self) -> int:
        """Points of all frames on none of their frame's planes."""
        return int(self.frame_off_plane.sum())

    def raw_bytes(self) -> int:
        """Bytes of the raw point clouds of all frames (x, y, z, I per point).

        Returns
        -------
        int
        """
        return self.raw_points * VALUES_PER_POINT * self.bytes_per_value

    def plane_bytes(self, n_cells: int | None = None) -> int:
        """Bytes of the map's planes with ``n_cells`` cells (default: the map's own).

        Parameters
        ----------
        n_cells : int, optional
            Cells to count (e.g. a merged count from ``merged_cells``).

        Returns
        -------
        int
        """
        cells = self.n_cells if n_cells is None else n_cells
        return (self.n_planes * VALUES_PER_PLANE + cells * VALUES_PER_CELL) * self.bytes_per_value

    def off_plane_bytes(self) -> int:
        """Bytes of the points on no plane kept as points (x, y, z, I).

        Returns
        -------
        int
        """
        return self.off_plane_points * VALUES_PER_POINT * self.bytes_per_value

    def voxel_bytes(self) -> int:
        """Bytes of our voxel store of points on no plane (3 indices and a count per voxel).

        Returns
        -------
        int
        """
        return self.n_voxels * VALUES_PER_VOXEL * self.bytes_per_value

    def ratio(self, n_cells: int | None = None, *, voxels: bool = False) -> float:
        """Raw bytes over the map's: planes (with ``n_cells`` cells) plus the points on no plane, kept as points
        (``voxels=False``) or as our voxel store.

        Parameters
        ----------
        n_cells : int, optional
            Cells of the planes (default: the map's own).
        voxels : bool
            Count the voxel store instead of the points on no plane.

        Returns
        -------
        float
        """
        rest = self.voxel_bytes() if voxels else self.off_plane_bytes()
        return self.raw_bytes() / (self.plane_bytes(n_cells) + rest)

    def __str__(self) -> str:
        return (f"Storage: raw clouds of {self.n_frames} frames {self.raw_bytes() / 1e6:.3f} MB, plane map and "
                f"points on no plane {(self.plane_bytes() + self.off_plane_bytes()) / 1e6:.3f} MB: "
                f"ratio {self.ratio():.1f}")

    def table(self) -> str:
        """The counts and bytes of the raw clouds and of the map, the ratios, and what they depend on (ours).

        Returns
        -------
        str
            Two fixed-precision text tables and a closing line.
        """
        b = self.bytes_per_value
        bound = f"{self.raw_points / self.off_plane_points:.1f}" if self.off_plane_points else "-"
        rows = [["frames", f"{self.n_frames}", "", ""],
                ["points per frame (mean)", f"{self.frame_points.mean():.0f}", "", ""],
                ["raw point clouds of all frames (x, y, z, I)", f"{self.raw_points}", f"{VALUES_PER_POINT}",
                 _mb(self.raw_bytes())],
                ["  the same as scan lines (range, I per beam)", f"{self.raw_points}", f"{VALUES_PER_BEAM}",
                 _mb(self.raw_points * VALUES_PER_BEAM * b)],
                ["map planes (n, p, T, cell side)", f"{self.n_planes}", f"{VALUES_PER_PLANE}",
                 _mb(self.n_planes * VALUES_PER_PLANE * b)],
                [f"their cells, {self.cell_m:g} m (i, j, N_k, sum I)", f"{self.n_cells}", f"{VALUES_PER_CELL}",
                 _mb(self.n_cells * VALUES_PER_CELL * b)],
                ["points on no plane, kept as points (x, y, z, I)", f"{self.off_plane_points}",
                 f"{VALUES_PER_POINT}", _mb(self.off_plane_bytes())],
                ["plane map + points on no plane", "", "", _mb(self.plane_bytes() + self.off_plane_bytes())],
                ["  or our voxel store instead (3 indices, count)", f"{self.n_voxels}", f"{VALUES_PER_VOXEL}",
                 _mb(self.voxel_bytes())],
                ["ratio raw / (plane map + points on no plane)", "", "", f"{self.ratio():.1f}"],
                ["ratio raw / (plane map + voxel store)", "", "", f"{self.ratio(voxels=True):.1f}"],
                ["bound if the planes cost nothing: raw / points on no plane", "", "", bound]]
        t1 = format_table(["item", "count", "values", "MB"], rows,
                          title=f"002's compression claim measured (ours): {b}-byte values, MB = 10^6 bytes")
        rows2 = [[f"{self.cell_m:.2f} (the run's)", f"{self.n_cells}", _mb(self.plane_bytes()), f"{self.ratio():.1f}",
                  f"{self.ratio(voxels=True):.1f}"]]
        rows2 += [[f"{self.cell_m * f:.2f} ({f} x {f} cells merged)", f"{c}", _mb(self.plane_bytes(c)),
                   f"{self.ratio(c):.1f}", f"{self.ratio(c, voxels=True):.1f}"] for f, c in self.merged_cells]
        t2 = format_table(["cell side [m]", "cells", "planes MB", "ratio, points kept", "ratio, voxels"], rows2,
                          title="The ratio against the cell side (same map, cells merged)")
        raw4 = self.raw_points * VALUES_PER_POINT * 4
        note = (f"voxel store: {self.voxel_points} points counted (every thinned one) in {self.n_voxels} voxels\n"
                f"raw at 4 bytes per value against our map as numpy holds it (8-byte values, derived keys and\n"
                f"  means, voxel store): {self.held_bytes / 1e6:.3f} MB, ratio {raw4 / self.held_bytes:.1f}")
        return f"{t1}\n{t2}\n{note}"


def map_storage(plane_map: PlaneMap, frame_points, frame_off_plane, *, bytes_per_value: int = 4,
                merge_factors=(2, 4)) -> StorageResult:
    """Count the raw clouds of the frames and the plane map that replaces them (002 "Conclusion"; ours).

    Parameters
    ----------
    plane_map : slamlab.planes.PlaneMap
        The map built from the frames.
    frame_points : (F,) int
        Points per frame.
    frame_off_plane : (F,) int
        Points per frame on none of its planes (each at most the frame's points).
    bytes_per_value : {4, 8}
        Bytes per stored value (float32 / int32 or float64 / int64).
    merge_factors : tuple of int
        Block sizes (>= 2) for which the cells are also counted merged.

    Returns
    -------
    StorageResult

    Examples
    --------
    >>> from slamlab.planes import Plane, PlaneMap
    >>> m = PlaneMap()
    >>> m.planes.append(Plane.from_cells([0, 0, 1.0], 0.0, np.eye(4), 0.5, [[0, 0], [1, 0]], [3, 2], [9.0, 8.0]))
    >>> s = map_storage(m, [10, 10], [1, 2])
    >>> s.raw_bytes(), s.plane_bytes(), s.off_plane_bytes()
    (320, 116, 48)
    """
    if not isinstance(plane_map, PlaneMap):
        raise TypeError(f"`plane_map` must be a PlaneMap; got {type(plane_map).__name__}")
    pts = as_finite_array(frame_points, "frame_points", ndim=1)
    off = as_finite_array(frame_off_plane, "frame_off_plane", ndim=1)
    if pts.size == 0 or np.any(pts < 0) or np.any(pts != np.round(pts)):
        raise ValueError(f"`frame_points` must be non-negative whole counts, at least one frame; got {pts}")
    if off.shape != pts.shape or np.any(off < 0) or np.any(off > pts) or np.any(off != np.round(off)):
        raise ValueError(f"`frame_off_plane` must be {pts.shape[0]} whole counts, each in [0, frame_points]; "
                         f"got {off}")
    if check_int(bytes_per_value, "bytes_per_value") not in (4, 8):
        raise ValueError(f"`bytes_per_value` must be 4 or 8; got {bytes_per_value!r}")
    factors = tuple(check_int(f, "merge_factors", minimum=2) for f in merge_factors)
    cells = sum(len(pl.ij) for pl in plane_map.planes)
    cell_m = plane_map.planes[0].cell_m if plane_map.planes else float("nan")
    return StorageResult(pts.astype(np.int64), off.astype(np.int64), len(plane_map), cells, cell_m,
                         len(plane_map.voxels), int(plane_map.voxels.counts.sum()),
                         tuple((f, _cells_merged(plane_map, f)) for f in factors), _held_bytes(plane_map),
                         bytes_per_value)


def flight_storage(result, *, bytes_per_value: int = 4, merge_factors=(2, 4)) -> StorageResult:
    """:func:`map_storage` of a flight: its frames' points, the points on none of their planes, its final map.

    Parameters
    ----------
    result : FlightResult
        From :func:`~slamlab.studies.planes.run_flight`.
    bytes_per_value : {4, 8}
        Bytes per stored value.
    merge_factors : tuple of int
        Block sizes for the merged cell counts.

    Returns
    -------
    StorageResult
    """
    if not isinstance(result, FlightResult):
        raise TypeError(f"`result` must be a FlightResult (see run_flight); got {type(result).__name__}")
    return map_storage(result.map, result.frame_points, result.frame_off_plane, bytes_per_value=bytes_per_value,
                       merge_factors=merge_factors)
