"""The room of bounded planes with reflectance panels and the ray caster against them (002 Fig. 7; ours).
Split from :mod:`slamlab.sim.planes_room` (which re-exports every public name here; the scanner, the flight
and the odometry stay there)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .._validate import as_finite_array, as_rng, check_positive, check_probability

__all__ = ["RAY_CHUNK", "PlaneRoom", "build_corridor", "build_plane_room", "cast_rays_planes"]

#: Rays per chunk of :func:`cast_rays_planes` (a (chunk, planes, 3) float64 temporary: ~6 MB for 15 planes). A
#: caller that splits its own rays in multiples of it gets the same chunks, so the same results to the last bit.
RAY_CHUNK = 16384


@dataclass(frozen=True)
class PlaneRoom:
    """Bounded rectangles ``n·x = p`` with in-plane axes and reflectance panels (002 Fig. 7; ours).

    Attributes: ``centres (P, 3)``, ``normals (P, 3)`` (unit, pointing into the free space),
    ``axes_u (P, 3)``, ``axes_v (P, 3)`` (unit, in-plane), ``half_u (P,)``, ``half_v (P,)`` in
    metres, ``panels (P, Nu, Nv)`` reflectance of the panels (index from the ``-u, -v`` corner),
    ``panel_m`` panel size, ``names`` one label per plane.

    Attributes
    ----------
    centres : numpy.ndarray, shape (P, 3)
        Rectangle centres [m].
    normals : numpy.ndarray, shape (P, 3)
        Unit normals, into the free space.
    axes_u, axes_v : numpy.ndarray, shape (P, 3)
        Unit in-plane axes.
    half_u, half_v : numpy.ndarray, shape (P,)
        Half extents along them [m].
    panels : numpy.ndarray, shape (P, Nu, Nv)
        Panel reflectances.
    panel_m : float
        Panel size [m].
    names : tuple of str
        One label per plane.
    """

    centres: np.ndarray
    normals: np.ndarray
    axes_u: np.ndarray
    axes_v: np.ndarray
    half_u: np.ndarray
    half_v: np.ndarray
    panels: np.ndarray
    panel_m: float
    names: tuple[str, ...]

    @property
    def offsets(self) -> np.ndarray:
        """``p`` of each plane in ``n·x = p``."""
        return np.einsum("ij,ij->i", self.normals, self.centres)

    def __len__(self) -> int:
        return self.centres.shape[0]

    def reflectance(self, plane_idx, points) -> np.ndarray:
        """Reflectance of the panel under each point ``(K, 3)`` lying on plane ``plane_idx (K,)``.

        Parameters
        ----------
        plane_idx : array_like of int, shape (K,)
            Plane of each point.
        points : array_like, shape (K, 3)
            Points on those planes [m].

        Returns
        -------
        numpy.ndarray, shape (K,)
        """
        k = np.asarray(plane_idx, dtype=int)
        d = np.asarray(points, dtype=float) - self.centres[k]
        s = np.einsum("ij,ij->i", d, self.axes_u[k]) + self.half_u[k]
        t = np.einsum("ij,ij->i", d, self.axes_v[k]) + self.half_v[k]
        iu = np.clip((s // self.panel_m).astype(int), 0, self.panels.shape[1] - 1)
        iv = np.clip((t // self.panel_m).astype(int), 0, self.panels.shape[2] - 1)
        return self.panels[k, iu, iv]


def _box_faces(lo, hi, inward: bool, skip=()):
    """Six faces of an axis-aligned box (normals into the room: inward for the room, outward for objects)."""
    lo, hi = np.asarray(lo, float), np.asarray(hi, float)
    c, h = (lo + hi) / 2, (hi - lo) / 2
    faces = []
    for ax, nm in ((0, "x"), (1, "y"), (2, "z")):
        u_ax, v_ax = [a for a in range(3) if a != ax]
        for sgn, side in ((-1, "-"), (1, "+")):
            if f"{nm}{side}" in skip:
                continue
            centre = c.copy()
            centre[ax] += sgn * h[ax]
            n = np.zeros(3)
            n[ax] = -sgn if inward else sgn
            u, w = np.zeros(3), np.zeros(3)
            u[u_ax], w[v_ax] = 1.0, 1.0
            faces.append((f"{nm}{side}", centre, n, u, w, h[u_ax], h[v_ax]))
    return faces


def build_plane_room(length_m: float = 20.0, width_m: float = 10.0, height_m: float = 3.0, *,
                     panel_m: float = 1.0, rho_low: float = 0.2, rho_high: float = 0.9, rng=0) -> PlaneRoom:
    """The test room: walls, floor, ceiling, a pillar and a box, with random reflectance panels (002 Fig. 7; ours).

    Parameters
    ----------
    length_m, width_m, height_m : room size (default 20 × 10 × 3 m: 002's ~200 m²).
    panel_m : side of a reflectance panel.
    rho_low, rho_high : reflectance range of the panels (contrasting panels: each panel draws one of the two
        values plus a uniform ±0.05 jitter).
    rng : seed of the panel pattern.

    Returns
    -------
    PlaneRoom

    Examples
    --------
    >>> room = build_plane_room(); len(room), float(room.half_u[0] * 2 * room.half_v[0] * 2)
    (15, 30.0)
    """
    L = check_positive(length_m, "length_m")
    W = check_positive(width_m, "width_m")
    H = check_positive(height_m, "height_m")
    panel_m = check_positive(panel_m, "panel_m")
    lo_r, hi_r = check_probability(rho_low, "rho_low"), check_probability(rho_high, "rho_high")
    rng = as_rng(rng)
    faces = [("room " + f[0], *f[1:]) for f in _box_faces((0, 0, 0), (L, W, H), inward=True)]
    # a pillar (floor to ceiling, its top and bottom hidden) and a box on the floor (its bottom hidden)
    pil_lo, pil_hi = (0.62 * L, 0.55 * W, 0.0), (0.62 * L + 0.8, 0.55 * W + 0.8, H)
    faces += [("pillar " + f[0], *f[1:]) for f in _box_faces(pil_lo, pil_hi, inward=False, skip=("z-", "z+"))]
    box_lo, box_hi = (0.3 * L, 0.15 * W, 0.0), (0.3 * L + 2.0, 0.15 * W + 1.2, 1.0)
    faces += [("box " + f[0], *f[1:]) for f in _box_faces(box_lo, box_hi, inward=False, skip=("z-",))]
    names, c, n, u, w, hu, hv = zip(*faces, strict=True)
    hu, hv = np.array(hu), np.array(hv)
    nu = int(np.ceil(2 * hu.max() / panel_m))
    nv = int(np.ceil(2 * hv.max() / panel_m))
    pick = rng.random((len(faces), nu, nv)) < 0.5
    panels = np.where(pick, hi_r, lo_r) + rng.uniform(-0.05, 0.05, (len(faces), nu, nv))
    return PlaneRoom(np.array(c), np.array(n), np.array(u), np.array(w), hu, hv,
                     np.clip(panels, 0.0, 1.0), panel_m, tuple(names))


def build_corridor(length_m: float = 12.0, width_m: float = 3.0, height_m: float = 3.0, *, panel_m: float = 1.0,
                   rng=0) -> PlaneRoom:
    """A corridor: floor, ceiling and two parallel walls, no end walls (002 Fig. 4's situation; ours).

    Its planes leave the position along the corridor (``x``) free: only the panels' intensities fix it.

    Parameters
    ----------
    length_m, width_m, height_m : float
        Corridor size [m].
    panel_m : float, default 1.0
        Reflectance panel size [m].
    rng : int or numpy.random.Generator, default 0
        Seed of the panel reflectances.

    Returns
    -------
    PlaneRoom

    Examples
    --------
    >>> c = build_corridor(); len(c), c.names
    (4, ('y-', 'y+', 'z-', 'z+'))
    """
    L, W, H = (check_positive(a, n) for a, n in ((length_m, "length_m"), (width_m, "width_m"),
                                                      (height_m, "height_m")))
    room = build_plane_room(L, W, H, panel_m=panel_m, rng=rng)
    keep = [i for i, n in enumerate(room.names) if n in ("room y-", "room y+", "room z-", "room z+")]
    return PlaneRoom(room.centres[keep], room.normals[keep], room.axes_u[keep], room.axes_v[keep],
                     room.half_u[keep], room.half_v[keep], room.panels[keep], room.panel_m,
                     tuple(room.names[i][5:] for i in keep))


def cast_rays_planes(room: PlaneRoom, origins, directions, range_max_m: float = np.inf):
    """Vectorised ray casting against the room's bounded planes (ours).

    Parameters
    ----------
    room : PlaneRoom
        The bounded planes.
    origins : (K, 3) or (3,) array_like
        Ray origins [m].
    directions : (K, 3) array_like
        Unit directions.
    range_max_m : float
        Rays hitting nothing closer return NaN.

    Returns
    -------
    ranges (K,) (NaN: no hit), plane (K,) index of the plane hit (-1: none), cos_incidence (K,) ``|n·d|``.

    Examples
    --------
    >>> room = build_plane_room()
    >>> r, k, c = cast_rays_planes(room, [[5.0, 5.0, 1.0]], [[0.0, 0.0, -1.0]])
    >>> float(r[0]), room.names[k[0]], float(c[0])
    (1.0, 'room z-', 1.0)
    """
    d = as_finite_array(directions, "directions", ndim=2)
    if d.shape[1] != 3:
        raise ValueError(f"`directions` must have shape (K, 3); got {d.shape}")
    o = as_finite_array(origins, "origins")
    o = np.broadcast_to(o, d.shape) if o.shape == (3,) else o
    if o.shape != d.shape:
        raise ValueError(f"`origins` must have shape (3,) or {d.shape}; got {o.shape}")
    out = [_cast_chunk(room, o[i:i + RAY_CHUNK], d[i:i + RAY_CHUNK], range_max_m)
           for i in range(0, max(len(d), 1), RAY_CHUNK)]  # chunks: the (K, P, 3) temporaries stay small
    return tuple(np.concatenate(parts) for parts in zip(*out, strict=True))



def _cast_chunk(room: PlaneRoom, o: np.ndarray, d: np.ndarray, range_max_m: float):
    nd = d @ room.normals.T                                    # (K, P)
    no = o @ room.normals.T
    with np.errstate(divide="ignore", invalid="ignore"):
        t = (room.offsets[None, :] - no) / nd
    t = np.where(np.isfinite(t) & (t > 1e-9), t, np.inf)
    finite = np.isfinite(t)
    tt = np.where(finite, t, 0.0)
    rel = o[:, None, :] + tt[..., None] * d[:, None, :] - room.centres[None]   # hit - centre, (K, P, 3)
    su = np.einsum("kpj,pj->kp", rel, room.axes_u)
    sv = np.einsum("kpj,pj->kp", rel, room.axes_v)
    inside = finite & (np.abs(su) <= room.half_u + 1e-9) & (np.abs(sv) <= room.half_v + 1e-9)
    t = np.where(inside, t, np.inf)
    k = np.argmin(t, axis=1)
    r = t[np.arange(len(k)), k]
    ok = np.isfinite(r) & (r <= range_max_m)
    cos_inc = np.abs(nd[np.arange(len(k)), k])
    return np.where(ok, r, np.nan), np.where(ok, k, -1), np.where(ok, cos_inc, np.nan)
