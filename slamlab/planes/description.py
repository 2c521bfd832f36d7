"""Plane description: the plane's frame and its cell grid of point counts and intensity sums (002 Fig. 6).

002: ``Π = {n, p, T, A}`` — the plane ``n·x − p = 0``, the transform ``T`` from a frame
attached to the plane, and the set ``A`` of parts: the plane's points are moved into
its own frame, projected onto its ``OXY`` plane, and every cell of a grid of a given
size that receives a point becomes a part holding the count ``N_k`` and the sum of
intensities ``Σ I``; the mean ``I_k = Σ I / N_k`` is what the weights compare.

Ours: the plane frame's origin is the centroid of the points projected onto the
plane, its ``z`` axis is ``n``, its ``x`` axis the parent's ``z`` axis projected onto
the plane (the parent's ``x`` axis for floors and ceilings); the incidence-angle
correction (002 after [17]) divides each intensity by ``max(|cos θ|, cos_min)``.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from .._validate import as_finite_array, as_vector, check_positive

__all__ = ["Plane", "cell_keys", "describe_plane", "lookup_mean_intensity", "plane_frame"]

_OFF = 1 << 20   # cell indices in [-2^20, 2^20): ±262 km at 0.25 m cells


def cell_keys(ij) -> np.ndarray:
    """One int64 key per cell index pair ``(M, 2)`` (sortable, for look-ups).

    Parameters
    ----------
    ij : (..., 2) int
        Cell indices, each in [-2^20, 2^20).

    Returns
    -------
    (...) int64
        Keys ordered by ``i`` then ``j``.
    """
    ij = np.asarray(ij, dtype=np.int64)
    return (ij[..., 0] + _OFF) * (2 * _OFF) + (ij[..., 1] + _OFF)


@dataclass(frozen=True)
class Plane:
    """A described plane ``Π = {n, p, T, A}`` (002): ``n (3,)``, ``p``, ``T (4, 4)`` plane frame → parent,
    ``cell_m``, cells ``ij (M, 2)`` (in ascending ``keys`` order) with ``counts (M,)`` and intensity ``sums
    (M,)``; ``mean_intensity`` ``I_k = Σ I / N_k``.

    Attributes
    ----------
    n : (3,) float
        Unit normal in the parent frame.
    p : float
        Distance term of ``n·x − p = 0`` in metres.
    T : (4, 4) float
        Plane frame → parent frame.
    cell_m : float
        Cell side in metres.
    ij : (M, 2) int
        Cell indices in the plane frame's x, y, in ascending key order.
    counts : (M,) int
        Points per cell ``N_k``.
    sums : (M,) float
        Intensity sum per cell.
    """

    n: np.ndarray
    p: float
    T: np.ndarray
    cell_m: float
    ij: np.ndarray
    counts: np.ndarray
    sums: np.ndarray
    keys: np.ndarray = field(init=False, repr=False, compare=False)
    mean_intensity: np.ndarray = field(init=False, repr=False, compare=False)

    def __post_init__(self):
        object.__setattr__(self, "keys", cell_keys(self.ij))
        object.__setattr__(self, "mean_intensity", self.sums / self.counts)   # I_k = sum I / N_k per cell

    @classmethod
    def from_cells(cls, n, p: float, T, cell_m: float, ij, counts, sums) -> Plane:
        """The plane whose parts ``A`` sum ``counts`` and intensity ``sums`` per cell index (002 Fig. 6).

        Entries that share a cell index are added up (a bincount on the cells' bounding box, no sort); the
        cells come out in ascending key order (:func:`cell_keys`), as :func:`lookup_mean_intensity` needs.
        One entry per point (``counts`` all 1: :func:`describe_plane`) or per cell of several planes
        (their counts: :func:`~slamlab.planes.merge_planes`).

        Parameters
        ----------
        n, p, T, cell_m
            The plane's normal, distance term [m], frame and cell side [m], as the attributes of :class:`Plane`.
        ij : (K, 2) int
            Cell index of each entry in the plane frame's x, y (K >= 1).
        counts : (K,) float or int
            Points behind each entry.
        sums : (K,) float
            Intensity sum of each entry.

        Returns
        -------
        Plane
            One cell per distinct index of ``ij``.

        Examples
        --------
        >>> pl = Plane.from_cells(np.array([0, 0, 1.0]), 1.0, np.eye(4), 0.5, [[0, 0], [1, 0], [0, 0]],
        ...                       [1, 1, 1], [10.0, 40.0, 20.0])
        >>> pl.ij.tolist(), pl.counts.tolist(), pl.mean_intensity.tolist()
        ([[0, 0], [1, 0]], [2, 1], [15.0, 40.0])
        """
        ij = np.asarray(ij, dtype=np.int64)
        lo = ij.min(axis=0)
        w = int(ij[:, 1].max() - lo[1]) + 1
        flat = (ij[:, 0] - lo[0]) * w + (ij[:, 1] - lo[1])
        c = np.bincount(flat, weights=counts)
        keep = np.flatnonzero(c)
        s = np.bincount(flat, weights=sums)[keep]
        return cls(n, float(p), T, cell_m, np.c_[keep // w + lo[0], keep % w + lo[1]], c[keep].astype(np.int64), s)

    @property
    def n_points(self) -> int:
        """Points behind the plane (the sum of the cells' counts)."""
        return int(self.counts.sum())

    def cell_centres(self) -> np.ndarray:
        """Cell centres ``(M, 3)`` in the parent frame.

        Returns
        -------
        (M, 3) float
            Metres, parent frame.
        """
        local = np.c_[(self.ij + 0.5) * self.cell_m, np.zeros(len(self.ij))]
        return local @ self.T[:3, :3].T + self.T[:3, 3]

    def moved(self, X) -> Plane:
        """The same plane in another frame: ``X (4, 4)`` maps this plane's parent into the new one.

        Parameters
        ----------
        X : (4, 4) float
            Homogeneous transform from the current parent frame to the new one.

        Returns
        -------
        Plane
            Same cells, with ``n``, ``p`` and ``T`` expressed in the new frame.
        """
        R, t = X[:3, :3], X[:3, 3]
        n = R @ self.n
        return Plane(n, float(self.p + n @ t), X @ self.T, self.cell_m, self.ij, self.counts, self.sums)

    def area_m2(self) -> float:
        """Area of the occupied cells in m².

        Returns
        -------
        float
        """
        return float(len(self.ij) * self.cell_m**2)


def plane_frame(n, p: float, origin_hint) -> np.ndarray:
    """The 4×4 frame of plane ``(n, p)``: origin = ``origin_hint`` projected on the plane, ``z = n`` (ours).

    Parameters
    ----------
    n : (3,) float
        Unit normal.
    p : float
        Distance term in metres.
    origin_hint : (3,) float
        Point projected onto the plane to give the origin (e.g. the points' centroid).

    Returns
    -------
    T : (4, 4) float
        Plane frame → parent; x axis the parent's z projected on the plane (parent's x for
        floors and ceilings).
    """
    n = np.asarray(n, dtype=float)
    ref = np.array([0.0, 0.0, 1.0]) if abs(n[2]) < 0.9 else np.array([1.0, 0.0, 0.0])
    x = ref - (ref @ n) * n
    x /= np.linalg.norm(x)
    T = np.eye(4)
    T[:3, 0], T[:3, 1], T[:3, 2] = x, np.cross(n, x), n
    o = np.asarray(origin_hint, dtype=float)
    T[:3, 3] = o - (n @ o - p) * n
    return T


def describe_plane(points, intensities, n, p: float, *, cell_m: float = 0.25, rays=None,
                   incidence_correction: bool = True, cos_min: float = 0.2) -> Plane:
    """Cell grid of a plane's points: counts and intensity sums (002 "Plane representation", Fig. 6).

    Parameters
    ----------
    points : (K, 3) float
        The plane's points in the parent frame, metres.
    intensities : (K,) float
        Their return intensities.
    n : (3,) float
        Unit normal.
    p : float
        Distance term in metres.
    cell_m : float
        Cell side in metres.
    rays : (K, 3) float, optional
        Unit ray directions of the points (needed for the incidence correction).
    incidence_correction : bool
        Divide each intensity by ``max(|cos θ|, cos_min)``.
    cos_min : float
        Floor of ``|cos θ|`` in the correction.

    Returns
    -------
    Plane
        The plane with its cell counts and intensity sums.

    Examples
    --------
    >>> pts = np.array([[0.1, 0.1, 1.0], [0.2, 0.1, 1.0], [0.6, 0.1, 1.0]])
    >>> pl = describe_plane(pts, [10.0, 20.0, 40.0], [0, 0, 1.0], 1.0, cell_m=0.5, incidence_correction=False)
    >>> pl.counts.tolist(), pl.mean_intensity.tolist()
    ([2, 1], [15.0, 40.0])
    """
    X = as_finite_array(points, "points", ndim=2)
    if X.shape[1] != 3 or X.shape[0] < 1:
        raise ValueError(f"`points` must have shape (K >= 1, 3); got {X.shape}")
    I = as_vector(intensities, "intensities", X.shape[0])
    n = as_vector(n, "n", 3)
    cell_m = check_positive(cell_m, "cell_m")
    if incidence_correction:
        if rays is None:
            raise ValueError("`rays` are needed for the incidence-angle correction (or incidence_correction=False)")
        d = as_finite_array(rays, "rays", ndim=2)
        if d.shape != X.shape:
            raise ValueError(f"`rays` must have shape {X.shape}; got {d.shape}")
        I = I / np.maximum(np.abs(d @ n), cos_min)
    T = plane_frame(n, p, X.mean(axis=0))
    local = (X - T[:3, 3]) @ T[:3, :2]
    return Plane.from_cells(n, p, T, cell_m, np.floor(local / cell_m).astype(np.int64), np.ones(len(X)), I)


def lookup_mean_intensity(plane: Plane, points) -> np.ndarray:
    """Mean intensity of the cell of ``plane`` under each point ``(..., 3)`` (parent frame); NaN off the grid.

    Parameters
    ----------
    plane : Plane
        The described plane.
    points : (..., 3) float
        Points in the plane's parent frame (projected onto the plane along ``n``).

    Returns
    -------
    (...) float
    """
    X = np.asarray(points, dtype=float)
    return lookup_local(plane, (X - plane.T[:3, 3]) @ plane.T[:3, :2])


def lookup_local(plane: Plane, local) -> np.ndarray:
    """Mean intensity of the cell under each in-plane point ``local (..., 2)`` (plane frame); NaN off the grid.

    Parameters
    ----------
    plane : Plane
        The described plane.
    local : (..., 2) float
        In-plane coordinates in metres (plane frame x, y).

    Returns
    -------
    (...) float
    """
    k = cell_keys(np.floor(local / plane.cell_m).astype(np.int64))
    keys = plane.keys
    pos = np.clip(np.searchsorted(keys, k), 0, len(keys) - 1)
    found = keys[pos] == k
    return np.where(found, plane.mean_intensity[pos], np.nan)
