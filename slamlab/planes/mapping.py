"""The plane database and the store of off-plane points (002 "Updating the database").

002: each new plane (moved into the map with the estimated pose) queries the database
for planes with close parameters (within a tolerance); the planes found are grouped by
intersecting borders — also through an intermediate plane — and each group is merged
into one plane whose cells carry the others' counts and intensity sums (averaging).
Points on no plane are kept in an octree-like structure [11]; ours is a voxel store
(counts per voxel, ``voxel_m``).

Ours: two planes are "close" when their normals differ by < ``angle_deg`` and their
offsets by < ``dist_m``; their borders intersect when a cell centre of one falls in,
or next to (one cell), an occupied cell of the other; the merged plane's ``n, p`` are
the point-count-weighted means, its frame that of its largest member.
"""

from __future__ import annotations

import numpy as np

from .description import Plane, cell_keys, lookup_mean_intensity, plane_frame

__all__ = ["PlaneMap", "VoxelStore", "merge_planes", "planes_touch"]


class VoxelStore:
    """Points off every plane, as counts per voxel of side ``voxel_m`` (002 [11]: an octree; ours: a voxel hash).

    Parameters
    ----------
    voxel_m : float
        Voxel side in metres.
    """

    def __init__(self, voxel_m: float = 0.1):
        self.voxel_m = float(voxel_m)
        self.keys = np.zeros((0, 3), dtype=np.int64)
        self.counts = np.zeros(0, dtype=np.int64)

    def add(self, points) -> None:
        """Count ``points`` into their voxels.

        Parameters
        ----------
        points : (K, 3) float
            Points in the map frame, metres.
        """
        X = np.asarray(points, dtype=float).reshape(-1, 3)
        if X.size == 0:
            return
        k = np.floor(X / self.voxel_m).astype(np.int64)
        allk = np.concatenate([self.keys, k])
        allc = np.concatenate([self.counts, np.ones(len(k), dtype=np.int64)])
        u, inv = np.unique(allk, axis=0, return_inverse=True)
        self.keys, self.counts = u, np.bincount(inv.ravel(), weights=allc, minlength=len(u)).astype(np.int64)

    def centres(self) -> np.ndarray:
        """Voxel centres ``(V, 3)``.

        Returns
        -------
        (V, 3) float
            Metres, map frame.
        """
        return (self.keys + 0.5) * self.voxel_m

    def __len__(self) -> int:
        return len(self.counts)


def planes_touch(a: Plane, b: Plane) -> bool:
    """Whether the borders of ``a`` and ``b`` (same parent frame) intersect: a cell centre of one in or next to
    an occupied cell of the other (ours).

    Parameters
    ----------
    a, b : Plane
        Two planes in the same parent frame.

    Returns
    -------
    bool
    """
    c = b.cell_centres()
    local = (c - a.T[:3, 3]) @ a.T[:3, :2]
    ij = np.floor(local / a.cell_m).astype(np.int64)
    keys = a.keys
    for di in (-1, 0, 1):
        for dj in (-1, 0, 1):
            k = cell_keys(ij + np.array([di, dj]))
            pos = np.clip(np.searchsorted(keys, k), 0, len(keys) - 1)
            if np.any(keys[pos] == k):
                return True
    return False


def merge_planes(planes: list[Plane]) -> Plane:
    """One plane from several (same parent): count-weighted ``n, p``; cells re-binned into the largest
    member's frame with their counts and intensity sums (002 "Updating the database").

    Parameters
    ----------
    planes : list of Plane
        Planes in the same parent frame, with the same ``cell_m``.

    Returns
    -------
    Plane
        The merged plane.
    """
    w = np.array([pl.n_points for pl in planes], dtype=float)
    big = planes[int(np.argmax(w))]
    n = np.sum([wi * pl.n for wi, pl in zip(w, planes, strict=True)], axis=0)
    n /= np.linalg.norm(n)
    p = float(np.sum([wi * pl.p for wi, pl in zip(w, planes, strict=True)]) / w.sum())
    T = plane_frame(n, p, big.T[:3, 3])
    cell = big.cell_m
    centres = np.concatenate([pl.cell_centres() for pl in planes])
    counts = np.concatenate([pl.counts for pl in planes])
    sums = np.concatenate([pl.sums for pl in planes])
    local = (centres - T[:3, 3]) @ T[:3, :2]
    return Plane.from_cells(n, p, T, cell, np.floor(local / cell).astype(np.int64), counts, sums)


class PlaneMap:
    """The plane database (map frame) and the voxel store of off-plane points (002).

    Parameters
    ----------
    angle_deg : float
        Largest normal angle of planes that may merge, degrees.
    dist_m : float
        Largest offset difference of planes that may merge, metres.
    voxel_m : float
        Voxel side of the off-plane point store, metres.
    """

    def __init__(self, *, angle_deg: float = 8.0, dist_m: float = 0.15, voxel_m: float = 0.1):
        self.planes: list[Plane] = []
        self.voxels = VoxelStore(voxel_m)
        self.cos_tol = float(np.cos(np.deg2rad(angle_deg)))
        self.dist_m = float(dist_m)
        self._cache = None

    def __len__(self) -> int:
        return len(self.planes)

    def arrays(self):
        """``normals (M, 3)``, ``offsets (M,)`` of the map planes (cached).

        Returns
        -------
        normals : (M, 3) float
        offsets : (M,) float
            Metres.
        """
        if self._cache is None:
            self._cache = (np.array([pl.n for pl in self.planes]).reshape(-1, 3),
                           np.array([pl.p for pl in self.planes], dtype=float))
        return self._cache

    def add(self, new: Plane) -> int:
        """Merge ``new`` (map frame) into the database; returns how many database planes it absorbed.

        Parameters
        ----------
        new : Plane
            A plane in the map frame.

        Returns
        -------
        int
            Database planes merged into it (0: added as a new plane).
        """
        self._cache = None
        if not self.planes:
            self.planes.append(new)
            return 0
        N, Pm = self.arrays()
        close = np.flatnonzero((N @ new.n > self.cos_tol) & (np.abs(Pm - new.p) < self.dist_m))
        # grow the group from the new plane through touching planes (an intermediate plane links two others)
        group, frontier, rest = [], [new], list(close)
        while frontier:
            cur = frontier.pop()
            linked = [k for k in rest if planes_touch(cur, self.planes[k]) or planes_touch(self.planes[k], cur)]
            rest = [k for k in rest if k not in linked]
            group += linked
            frontier += [self.planes[k] for k in linked]
        merged = merge_planes([new] + [self.planes[k] for k in group]) if group else new
        self.planes = [pl for k, pl in enumerate(self.planes) if k not in set(group)] + [merged]
        self._cache = None
        return len(group)

    def mean_intensity_at(self, k: int, points) -> np.ndarray:
        """Mean intensity of map plane ``k`` under map-frame ``points`` (NaN where it has no cell).

        Parameters
        ----------
        k : int
            Index of the map plane.
        points : (..., 3) float
            Points in the map frame, metres.

        Returns
        -------
        (...) float
        """
        return lookup_mean_intensity(self.planes[k], points)
