"""The simulated lunar arena of 000 §3.2/§3.7: a textured fence and floor seen by a stereo pair.

World frame: ``x`` along the arena width, ``y`` along its length, ``z`` up; the
arena is the box ``[0, W] × [0, L]`` closed by a vertical fence ``H`` high
(000 §3.7: ~0.5 m, covered with photographs of the lunar surface — here the
procedural textures of :mod:`slamlab.sim.textures`). Above the fence lies a
featureless dark background.

Robot (body) frame: ``x`` forward, ``y`` left, ``z`` up, origin on the floor
below the middle of the stereo rig. The left camera sits ``baseline / 2`` to
the left of it at ``camera_height_m`` and looks forward (000 §3.2: 768×576,
40° field of view; the baseline is not given in 000 — ours 0.2 m).

Rendering casts the ray of every pixel against the five planes (four fence
walls and the floor) at once and samples the textures bilinearly.
"""

from __future__ import annotations

import functools

import numpy as np

from .._threads import run_tasks
from .._validate import as_finite_array, as_matrix, as_rng, as_vector, check_int, check_positive
from ..geometry.camera import PinholeCamera, StereoRig, rotation_xyz
from ..geometry.se3 import rotate_components, se3, se3_from_planar
from .textures import lunar_texture

__all__ = ["R_BODY_CAM", "StereoArena", "StereoSim"]

#: camera axes (x right, y down, z forward) expressed in the body frame (x forward, y left, z up)
R_BODY_CAM = np.array([[0.0, 0.0, 1.0], [-1.0, 0.0, 0.0], [0.0, -1.0, 0.0]])

SKY, FLOOR, WALL = 0, 1, 2
MIP_LEVELS = 4  # texture pyramid levels: a pixel samples the level matching its footprint


def _mip_levels(tex, n):
    """Gaussian pyramid ``[tex, pyrDown(tex), ...]`` (pixel ``i`` of level ``k`` sits at ``2^k i``)."""
    import cv2  # lazy: `import slamlab.sim` must not load OpenCV

    levels = [tex]
    for _ in range(n - 1):
        if min(levels[-1].shape) < 4:
            break
        levels.append(cv2.pyrDown(levels[-1]))
    return levels


def _sample_mip(levels, r, c, footprint_texels, wrap_cols):
    """Bilinear sample of the pyramid level whose texel matches the pixel footprint (anti-aliasing)."""
    # floor(log2(x)) from the binary exponent: exact on every machine (np.log2's last bit is not)
    _, exponent = np.frexp(np.maximum(footprint_texels, 1.0))
    lvl = np.clip(exponent - 1, 0, len(levels) - 1).astype(np.intp)
    out = np.empty(r.shape, dtype=np.float32)
    for k, tex in enumerate(levels):
        m = lvl == k
        if m.any():
            scale = 0.5**k
            out[m] = _bilinear(tex, r[m] * scale, c[m] * scale, wrap_cols)
    return out


def _bilinear(tex, r, c, wrap_cols: bool):
    """Sample ``tex`` at fractional (row, col); rows clamped, columns wrapped or clamped."""
    rows, cols = tex.shape
    r = np.clip(r, 0.0, rows - 1.000001)
    r0 = r.astype(np.intp)
    fr = r - r0
    if wrap_cols:
        c = np.mod(c, cols)
        c0 = c.astype(np.intp)
        c1 = c0 + 1
        c1[c1 == cols] = 0
    else:
        c = np.clip(c, 0.0, cols - 1.000001)
        c0 = c.astype(np.intp)
        c1 = c0 + 1
    fc = c - c0
    # flat indices into the texture: the same texels as tex[r0, c0] etc., gathered faster
    flat = tex.ravel()
    i00 = r0 * cols
    i10 = i00 + cols
    top = flat.take(i00 + c0) * (1 - fc) + flat.take(i00 + c1) * fc
    bot = flat.take(i10 + c0) * (1 - fc) + flat.take(i10 + c1) * fc
    return top * (1 - fr) + bot * fr


#: arenas whose textures are kept (our addition, speed: a study builds the same arena once per run;
#: generating the default arena's textures takes about 1.4 s, keeping them about 8 MiB)
TEXTURE_CACHE_SIZE = 4


@functools.lru_cache(maxsize=TEXTURE_CACHE_SIZE)
def _arena_textures(width_m, length_m, fence_height_m, texel_m, floor_texel_m, floor_contrast, seed):
    """Fence and floor textures and their pyramids, deterministic from the arguments; read-only (shared)."""
    perimeter_m = 2.0 * (width_m + length_m)
    r_wall, r_floor = np.random.default_rng(seed).spawn(2)
    rows = max(round(fence_height_m / texel_m), 2)
    cols = max(round(perimeter_m / texel_m), 2)
    # crater sizes in metres (1-12 cm on the fence, 2-30 cm on the floor) -> texels
    n_wall = int(40 * perimeter_m * fence_height_m / 0.5)
    wall_texture = lunar_texture(
        (rows, cols), n_craters=n_wall, radius_px=(0.01 / texel_m, 0.12 / texel_m), noise_amp_px=1.0 / (texel_m / 0.004), rng=r_wall
    ).astype(np.float32)
    frows = max(round(length_m / floor_texel_m), 2)
    fcols = max(round(width_m / floor_texel_m), 2)
    n_floor = int(12 * width_m * length_m)
    floor_texture = lunar_texture(
        (frows, fcols),
        n_craters=n_floor,
        radius_px=(0.015 / floor_texel_m, 0.2 / floor_texel_m),
        noise_amp_px=1.0,
        contrast=floor_contrast,
        rng=r_floor,
    ).astype(np.float32)
    wall_mips = _mip_levels(wall_texture, MIP_LEVELS)
    floor_mips = _mip_levels(floor_texture, MIP_LEVELS)
    for a in (*wall_mips, *floor_mips):
        a.setflags(write=False)
    return wall_mips[0], floor_mips[0], wall_mips, floor_mips


class StereoArena:
    """Closed rectangular arena with a textured fence and floor (000 §3.2, §3.7).

    Parameters
    ----------
    width_m, length_m : arena size along ``x`` and ``y`` (000 §3.7: a 6×8 m visible area).
    fence_height_m : fence height (000: ~0.5 m).
    texel_m, floor_texel_m : texture resolution of the fence and of the floor.
    floor_contrast : contrast of the floor texture relative to the fence (our choice: 0.6).
    sky : brightness of the featureless background above the fence, in ``[0, 1]``.
    texture_seed : int
        The seed of the procedural textures: everything in the scene is deterministic from it (an int, not a
        Generator: the textures are cached by it). The renderer's noise streams come from ``StereoSim(rng=)``.

    Examples
    --------
    >>> arena = StereoArena(2.0, 3.0, texel_m=0.01, texture_seed=1)
    >>> arena.wall_texture.shape, arena.perimeter_m
    ((50, 1000), 10.0)
    """

    def __init__(
        self,
        width_m: float = 6.0,
        length_m: float = 8.0,
        *,
        fence_height_m: float = 0.5,
        texel_m: float = 0.004,
        floor_texel_m: float = 0.01,
        floor_contrast: float = 0.6,
        sky: float = 0.12,
        texture_seed: int = 0,
    ):
        self.width_m = check_positive(width_m, "width_m")
        self.length_m = check_positive(length_m, "length_m")
        self.fence_height_m = check_positive(fence_height_m, "fence_height_m")
        self.texel_m = check_positive(texel_m, "texel_m")
        self.floor_texel_m = check_positive(floor_texel_m, "floor_texel_m")
        self.floor_contrast = check_positive(floor_contrast, "floor_contrast")
        self.sky = float(np.clip(check_positive(sky, "sky", allow_zero=True), 0.0, 1.0))
        self.seed = check_int(texture_seed, "texture_seed", minimum=0)
        self.wall_texture, self.floor_texture, self._wall_mips, self._floor_mips = _arena_textures(
            self.width_m, self.length_m, self.fence_height_m, self.texel_m, self.floor_texel_m, self.floor_contrast,
            self.seed)
        self._ray_cache: dict = {}

    @property
    def perimeter_m(self) -> float:
        """Length of the fence; the fence texture's column axis runs along it."""
        return 2.0 * (self.width_m + self.length_m)

    def contains(self, xy_m) -> np.ndarray:
        """True where the points ``(N, 2)`` lie strictly inside the arena.

        Parameters
        ----------
        xy_m : array_like, shape (N, 2)
            Points in the arena frame [m].

        Returns
        -------
        numpy.ndarray of bool, shape (N,)
        """
        xy = as_finite_array(xy_m, "xy_m", ndim=2)
        return (xy[:, 0] > 0) & (xy[:, 0] < self.width_m) & (xy[:, 1] > 0) & (xy[:, 1] < self.length_m)

    def _rays(self, camera: PinholeCamera) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The camera's pixel rays (z = 1) as three contiguous float32 coordinate arrays (cached)."""
        rays = self._ray_cache.get(camera)
        if rays is None:
            r = camera.pixel_rays().reshape(-1, 3).astype(np.float32)
            rays = tuple(np.ascontiguousarray(r[:, k]) for k in range(3))
            self._ray_cache = {camera: rays}
        return rays

    def cast(self, camera: PinholeCamera, T_world_cam) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Cast every pixel's ray (000 §3.2): ``(surface (H, W), t (H, W), points (H, W, 3))``.

        ``surface`` is 0 (background), 1 (floor) or 2 (fence); ``t`` the ray parameter
        (depth ``z`` in the camera frame, rays have ``z = 1``); ``points`` world hits (NaN on the background).

        Parameters
        ----------
        camera : PinholeCamera
            The camera (image size, intrinsics).
        T_world_cam : array_like, shape (4, 4)
            Camera pose in the arena frame.

        Returns
        -------
        surface : numpy.ndarray of int, shape (H, W)
        t : numpy.ndarray, shape (H, W)
        points : numpy.ndarray, shape (H, W, 3)
        """
        surface, t, d, o = self._cast(camera, T_world_cam)
        pts = o + t[:, None].astype(np.float64) * np.stack(d, axis=1)
        pts[surface == SKY] = np.nan
        shape = (camera.height_px, camera.width_px)
        return surface.reshape(shape), t.reshape(shape), pts.reshape((*shape, 3))

    def _cast(self, camera, T_world_cam):
        """``surface``, ``t``, the world ray directions ``(dx, dy, dz)`` (float32) and the camera centre ``o``."""
        if not isinstance(camera, PinholeCamera):
            raise TypeError(f"`camera` must be a PinholeCamera; got {type(camera).__name__}")
        T = as_matrix(T_world_cam, "T_world_cam", (4, 4))
        o = T[:3, 3]
        if not (0 < o[0] < self.width_m and 0 < o[1] < self.length_m and o[2] > 0):
            raise ValueError(f"the camera must be inside the arena above the floor; got position {np.round(o, 3).tolist()}")
        # not `rays @ R.T`: BLAS rounds by kernel and machine, and a last-bit change moves a grey level
        dx, dy, dz = rotate_components(T[:3, :3], *self._rays(camera))
        W, L, H = self.width_m, self.length_m, self.fence_height_m
        # ray parameters of the exits through the x-walls, the y-walls and the floor (camera inside
        # the box, so every distance is positive; a zero direction component gives +inf)
        with np.errstate(divide="ignore"):
            tx = np.where(dx > 0, W - o[0], o[0]) / np.abs(dx)
            ty = np.where(dy > 0, L - o[1], o[1]) / np.abs(dy)
            tf = o[2] / np.maximum(-dz, 0.0)
        tw = np.minimum(tx, ty)
        floor = tf < tw
        wall = ~floor & (o[2] + tw * dz <= H)
        surface = floor.view(np.uint8) + 2 * wall.view(np.uint8)
        t = np.where(floor, tf, tw)
        t[surface == SKY] = np.inf
        return surface, t, (dx, dy, dz), o

    def wall_coordinate(self, points_m) -> np.ndarray:
        """Arc length ``s`` along the fence (y=0 wall, then x=W, y=L, x=0) of points on it.

        Parameters
        ----------
        points_m : array_like, shape (N, 2) or (N, 3)
            Points on the fence (x, y used) [m].

        Returns
        -------
        numpy.ndarray, shape (N,)
            Arc length [m].
        """
        P = as_finite_array(points_m, "points_m", ndim=2)
        return self._wall_coordinate(P[:, 0], P[:, 1])[0]

    def _wall_coordinate(self, x, y):
        """:meth:`wall_coordinate` of the points ``(x, y)``, and whether each lies on an x = const wall."""
        W, L = self.width_m, self.length_m
        dist = (np.abs(y), np.abs(x - W), np.abs(y - L), np.abs(x))
        # argmin over the four distances: the first smallest (a later side wins only when strictly nearer)
        side = np.zeros(x.shape, dtype=np.intp)
        best = dist[0]
        for k in (1, 2, 3):
            nearer = dist[k] < best
            side[nearer] = k
            best = np.where(nearer, dist[k], best)
        s = np.choose(side, [x, W + y, W + L + (W - x), 2 * W + L + (L - y)])
        on_x_wall = np.minimum(dist[3], dist[1]) < np.minimum(dist[0], dist[2])
        return s, on_x_wall

    def render(self, camera: PinholeCamera, T_world_cam) -> np.ndarray:
        """Noise-free float32 image ``(H, W)`` in ``[0, 1]`` seen by ``camera`` at pose ``T_world_cam``.

        Parameters
        ----------
        camera : PinholeCamera
            The camera (image size, intrinsics).
        T_world_cam : array_like, shape (4, 4)
            Camera pose in the arena frame.

        Returns
        -------
        numpy.ndarray of float32, shape (H, W)

        Examples
        --------
        >>> arena = StereoArena(2.0, 3.0, texel_m=0.01, texture_seed=1)
        >>> cam = PinholeCamera.from_hfov(64, 48)
        >>> T = se3(R_BODY_CAM, [1.0, 1.0, 0.3])
        >>> img = arena.render(cam, T); img.shape, img.dtype
        ((48, 64), dtype('float32'))
        """
        surface, t, (dx, dy, dz), o = self._cast(camera, T_world_cam)
        img = np.full(surface.shape, self.sky, dtype=np.float32)
        f = surface == FLOOR
        # pixel footprint on the surface (m): t |d|^2 / (f |d . n|) along the steepest direction
        dn2 = dx * dx + dy * dy + dz * dz
        pix = 1.0 / min(camera.fx, camera.fy)
        if f.any():
            tf = t[f]
            px, py = o[0] + tf * dx[f], o[1] + tf * dy[f]
            fp = tf * dn2[f] * pix / (np.abs(dz[f]) * self.floor_texel_m)
            img[f] = _sample_mip(self._floor_mips, py / self.floor_texel_m, px / self.floor_texel_m, fp, False)
        w = surface == WALL
        if w.any():
            tw, dwx, dwy = t[w], dx[w], dy[w]
            px, py, pz = o[0] + tw * dwx, o[1] + tw * dwy, o[2] + tw * dz[w]
            s, hit_x = self._wall_coordinate(px, py)
            dnorm = np.where(hit_x, np.abs(dwx), np.abs(dwy))
            fp = tw * dn2[w] * pix / (np.maximum(dnorm, 1e-6) * self.texel_m)
            img[w] = _sample_mip(self._wall_mips, (self.fence_height_m - pz) / self.texel_m, s / self.texel_m, fp, True)
        return img.reshape(camera.height_px, camera.width_px)


class StereoSim:
    """A stereo rig on a robot in a :class:`StereoArena`: renders image pairs for body poses (000 §3.2).

    Parameters
    ----------
    arena : the scene.
    rig : the *calibrated* (nominal) rig; default :meth:`StereoRig.parallel` (0.2 m, 768×576, 40°).
    camera_height_m : height of the optical centres above the floor.
    noise_std : standard deviation of additive Gaussian image noise, in grey levels (0-255).
    drift_std_rad : calibration drift (000 §3.2: "the calibration tends to change while
        filming"): the true right-camera orientation takes a random-walk step of this standard
        deviation per rendered frame about each axis, while the pipeline keeps the nominal ``rig``.
    rng : Generator, int or None — the noise and drift streams.

    Examples
    --------
    >>> sim = StereoSim(StereoArena(2.0, 3.0, texel_m=0.01), StereoRig.parallel(0.2, 64, 48), rng=0)
    >>> left, right = sim.render_pair([1.0, 1.5, 0.0])
    >>> left.shape, left.dtype
    ((48, 64), dtype('uint8'))
    """

    def __init__(
        self,
        arena: StereoArena,
        rig: StereoRig | None = None,
        *,
        camera_height_m: float = 0.4,
        noise_std: float = 0.0,
        drift_std_rad: float = 0.0,
        rng=None,
    ):
        if not isinstance(arena, StereoArena):
            raise TypeError(f"`arena` must be a StereoArena; got {type(arena).__name__}")
        self.arena = arena
        self.rig = StereoRig.parallel() if rig is None else rig
        if not isinstance(self.rig, StereoRig):
            raise TypeError(f"`rig` must be a StereoRig; got {type(rig).__name__}")
        self.camera_height_m = check_positive(camera_height_m, "camera_height_m")
        if self.camera_height_m >= arena.fence_height_m * 4:
            raise ValueError(f"`camera_height_m` must be below {4 * arena.fence_height_m} m; got {camera_height_m}")
        self.noise_std = check_positive(noise_std, "noise_std", allow_zero=True)
        self.drift_std_rad = check_positive(drift_std_rad, "drift_std_rad", allow_zero=True)
        self.rng = as_rng(rng)
        self.drift_rad = np.zeros(3)
        # left camera: baseline/2 to the left of the body origin; right camera from the rig
        b = self.rig.baseline_m
        self.T_body_left = se3(R_BODY_CAM, [0.0, 0.5 * b, self.camera_height_m])

    def T_body_right(self, drift_rad=None) -> np.ndarray:
        """Pose of the right camera in the body frame (with a drift rotation, if given).

        Parameters
        ----------
        drift_rad : array_like, shape (3,), optional
            Rotation ``(rx, ry, rz)`` [rad] applied to the right camera on top of the calibration.

        Returns
        -------
        numpy.ndarray, shape (4, 4)
        """
        R_rl = self.rig.R_rl if drift_rad is None else rotation_xyz(*drift_rad) @ self.rig.R_rl
        T_right_left = se3(R_rl, self.rig.t_rl)
        # T_body_right = T_body_left @ inv(T_right_left)
        Rt = T_right_left[:3, :3].T
        return self.T_body_left @ se3(Rt, -Rt @ T_right_left[:3, 3])

    def render_pair(self, pose) -> tuple[np.ndarray, np.ndarray]:
        """Left and right uint8 images for the body pose ``(x_m, y_m, yaw_rad)``; advances the drift.

        Parameters
        ----------
        pose : array_like, shape (3,)
            Body pose ``(x_m, y_m, yaw_rad)``.

        Returns
        -------
        left, right : numpy.ndarray of uint8, shape (H, W)
        """
        pose = as_vector(pose, "pose", 3)
        T_wb = se3_from_planar(*pose)
        if self.drift_std_rad > 0:
            self.drift_rad = self.drift_rad + self.rng.normal(0.0, self.drift_std_rad, 3)
        views = ((self.rig.left, T_wb @ self.T_body_left), (self.rig.right, T_wb @ self.T_body_right(self.drift_rad)))
        # the two renders in two threads (numpy releases the GIL); the noise is drawn in order afterwards
        images = run_tasks([lambda cam=cam, T=T: self.arena.render(cam, T) for cam, T in views], 2)
        out = []
        for img in images:
            img *= 255.0
            if self.noise_std > 0:
                img += self.rng.normal(0.0, self.noise_std, img.shape).astype(np.float32)
            out.append(np.clip(np.rint(img), 0, 255).astype(np.uint8))
        return out[0], out[1]

    def ground_truth_se3(self, pose) -> np.ndarray:
        """4×4 world pose of the body for ``(x_m, y_m, yaw_rad)``.

        Parameters
        ----------
        pose : array_like, shape (3,)
            ``(x_m, y_m, yaw_rad)``.

        Returns
        -------
        numpy.ndarray, shape (4, 4)
        """
        return se3_from_planar(*as_vector(pose, "pose", 3))
