"""A highway-like stereo scene at the level of keypoints (issue 25): open road, far points, guard-rail posts.

The scene reproduces the conditions of a KITTI highway sequence where our stereo SLAM overestimated
the path by 6-12 %: few near structures, most points tens of metres away, repeated vertical structure
(guard-rail posts every ``post_spacing_m`` on both sides, all looking alike) and about 1 m of forward
motion per frame. It is simulated at the level of keypoints, not images: every landmark visible in a
camera gives a keypoint at its projection plus Gaussian pixel noise and a descriptor (the landmark's
own plus noise; the posts share a few descriptors). The features go to
:meth:`slamlab.stereo.StereoSLAM.process_features`, so stereo matching, triangulation, map matching,
the pose and the landmark filter are the pipeline's own; only detection is replaced.

World frame: ``x`` along the road, ``y`` left, ``z`` up, the ground at ``z = 0``. Body frame: ``x``
forward, ``y`` left, ``z`` up, on the ground below the left camera (KITTI: 1.65 m high, 0.54 m
baseline, 1226 × 370 px, f = 718 px). Our construction throughout.
"""

from __future__ import annotations

import numpy as np

from .._validate import as_finite_array, as_rng, as_vector, check_int, check_positive
from ..features.base import Features
from ..geometry.camera import PinholeCamera, StereoRig, project_points
from ..geometry.se3 import se3_from_planar
from .arena import R_BODY_CAM

__all__ = ["HIGHWAY_CONDITIONS", "HighwayScene", "highway_path"]

#: realistic conditions tried alone on the highway scene (issue 25; ours): label -> (scene options of
#: :class:`HighwayScene`, keypoint noise ``pixel_std`` [px] of :meth:`HighwayScene.observe`)
HIGHWAY_CONDITIONS = {
    "plain scene (0.5 px)": ({}, 0.5),
    "keypoint noise 1 px": ({}, 1.0),
    "keypoint noise 2 px": ({}, 2.0),
    "ORB pyramid 8 x 1.2, ORB's level shares": ({"pyramid_levels": 8}, 0.5),
    "ORB pyramid 8 x 1.2, level grows beyond 10 m": ({"pyramid_levels": 8, "level_ref_m": 10.0}, 0.5),
    "disparity locked halfway to integers": ({"disparity_locking": 0.5}, 0.5),
    "disparity bias -0.2 px": ({"disparity_bias_px": -0.2}, 0.5),
    "6 oncoming vehicles": ({"n_oncoming": 6}, 0.5),
    "4 vehicles ahead, our speed": ({"n_ahead": 4}, 0.5),
    "posts share 1 look (stereo aliasing)": ({"n_post_looks": 1}, 0.5),
}


def highway_path(n_frames: int = 51, *, step_m: float = 1.0, curvature_per_m: float = 0.002) -> np.ndarray:
    """Planar poses ``(x_m, y_m, yaw_rad)`` along a gently curving road, ``step_m`` per frame (our construction).

    Parameters
    ----------
    n_frames : int, default 51
        Number of poses (≥ 2).
    step_m : float, default 1.0
        Arc length per frame [m] (KITTI's highway: about 1 m at 10 Hz).
    curvature_per_m : float, default 0.002
        Road curvature [1/m] (a 500 m radius).

    Returns
    -------
    numpy.ndarray, shape (n_frames, 3)

    Examples
    --------
    >>> p = highway_path(3, curvature_per_m=0.0)
    >>> p.tolist()
    [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [2.0, 0.0, 0.0]]
    """
    n = check_int(n_frames, "n_frames", minimum=2)
    step = check_positive(step_m, "step_m")
    kappa = float(curvature_per_m)
    if not np.isfinite(kappa):
        raise ValueError(f"`curvature_per_m` must be finite; got {curvature_per_m}")
    s = np.arange(n) * step
    yaw = kappa * s
    if kappa == 0.0:
        return np.column_stack([s, np.zeros(n), yaw])
    return np.column_stack([np.sin(yaw) / kappa, (1.0 - np.cos(yaw)) / kappa, yaw])


class HighwayScene:
    """Landmarks of an open road seen by a KITTI-like stereo rig, observed as keypoints (issue 25; ours).

    Parameters
    ----------
    length_m : float, default 60.0
        Road length the landmarks cover beyond the start (the path plus the view ahead is added).
    post_spacing_m : float, default 2.0
        Distance between guard-rail posts along the road [m].
    rail_offsets_m : tuple of float, default (4.0, -6.0)
        Lateral positions of the guard rails [m] (left positive).
    n_far : int, default 1500
        Points of distant structure (trees, hills, bridges) 15-260 m ahead (log-uniform in distance).
    n_near : int, default 30
        Scattered near points (road marks, signs) 5-20 m from the road.
    n_post_looks : int, default 3
        Distinct descriptors among the posts (the rest repeat them: repeated structure).
    pyramid_levels : int, default 1
        Scene option (issue 25; ours): keypoints come from a detector pyramid of this many levels,
        ``pyramid_scale`` apart, and a keypoint of level ``l`` has noise ``pixel_std * pyramid_scale**l``
        (ORB: 8 levels x 1.2). 1: every keypoint at level 0 (the plain scene).
    pyramid_scale : float, default 1.2
        Scale between pyramid levels (> 1).
    level_ref_m : float or None, default None
        None: each observation's level is drawn with ORB's share per level (proportional to
        ``pyramid_scale**(-2 l)``), the same in both images; a depth [m]: the level grows with the
        landmark's depth, ``floor(log(z / level_ref_m) / log(pyramid_scale))`` clipped to the pyramid
        (far keypoints from coarse levels).
    disparity_locking : float, default 0.0
        Scene option (issue 25; ours): share in [0, 1] by which each measured disparity is pulled toward
        the nearest integer (sub-pixel "pixel locking"; 1: integer disparities).
    disparity_bias_px : float, default 0.0
        Scene option (issue 25; ours): added to every measured disparity [px] (a systematic bias; it
        matters most on small, far disparities).
    n_oncoming : int, default 0
        Scene option (issue 25; ours): vehicles in the oncoming lane (3.5 m left of ours), coming toward
        us at ``vehicle_speed`` times our speed; their points are not static.
    n_ahead : int, default 0
        Scene option (issue 25; ours): vehicles ahead in our lane and the one to its right, moving with
        us at ``vehicle_speed`` times our speed.
    vehicle_speed : float, default 1.0
        Speed of the vehicles as a share of ours (the scene has no clock: a vehicle moves
        ``vehicle_speed`` metres along the road per metre we travel, ``pose[0]``).
    rng : int or numpy.random.Generator, optional
        Seed of the scene's layout and descriptors.

    Attributes
    ----------
    rig : StereoRig
        KITTI-like rectified pair: f = 718 px, 1226 × 370 px, baseline 0.537 m.
    T_body_left : numpy.ndarray, shape (4, 4)
        Left camera in the body frame (1.65 m above the ground).
    points_m : numpy.ndarray, shape (K, 3)
        Landmarks in the world frame.
    kind : numpy.ndarray of str, shape (K,)
        'post', 'far', 'near' or 'vehicle'.
    velocity : numpy.ndarray, shape (K,)
        Motion of each landmark along the world ``x`` axis per metre we travel (0: static).
    descriptors : numpy.ndarray of float32, shape (K, 64)
        Unit-norm descriptor of each landmark.
    last_observed : tuple of numpy.ndarray or None
        The landmark index of every left and right keypoint of the last :meth:`observe` (the truth an
        ablation oracle needs; None before the first call).

    Examples
    --------
    >>> sc = HighwayScene(rng=0)
    >>> fl, fr = sc.observe(highway_path(2)[0], rng=1)
    >>> len(fl) > 100, fl.descriptors.shape[1]
    (True, 64)
    """

    def __init__(self, length_m: float = 60.0, *, post_spacing_m: float = 2.0, rail_offsets_m=(4.0, -6.0),
                 n_far: int = 1500, n_near: int = 30, n_post_looks: int = 3, pyramid_levels: int = 1,
                 pyramid_scale: float = 1.2, level_ref_m: float | None = None, disparity_locking: float = 0.0,
                 disparity_bias_px: float = 0.0, n_oncoming: int = 0, n_ahead: int = 0, vehicle_speed: float = 1.0,
                 rng=None):
        length = check_positive(length_m, "length_m")
        spacing = check_positive(post_spacing_m, "post_spacing_m")
        rails = as_finite_array(rail_offsets_m, "rail_offsets_m", ndim=1)
        n_far = check_int(n_far, "n_far", minimum=0)
        n_near = check_int(n_near, "n_near", minimum=0)
        n_looks = check_int(n_post_looks, "n_post_looks", minimum=1)
        self.pyramid_levels = check_int(pyramid_levels, "pyramid_levels", minimum=1)
        self.pyramid_scale = check_positive(pyramid_scale, "pyramid_scale")
        if self.pyramid_scale <= 1:
            raise ValueError(f"`pyramid_scale` must exceed 1; got {pyramid_scale}")
        self.level_ref_m = None if level_ref_m is None else check_positive(level_ref_m, "level_ref_m")
        self.disparity_locking = check_positive(disparity_locking, "disparity_locking", allow_zero=True)
        if self.disparity_locking > 1:
            raise ValueError(f"`disparity_locking` must be in [0, 1]; got {disparity_locking}")
        self.disparity_bias_px = float(disparity_bias_px)
        if not np.isfinite(self.disparity_bias_px):
            raise ValueError(f"`disparity_bias_px` must be finite; got {disparity_bias_px}")
        n_oncoming = check_int(n_oncoming, "n_oncoming", minimum=0)
        n_ahead = check_int(n_ahead, "n_ahead", minimum=0)
        speed = check_positive(vehicle_speed, "vehicle_speed", allow_zero=True)
        g = as_rng(rng)
        f, b, h = 718.856, 0.537, 1.65
        cam = PinholeCamera(1226, 370, f, f, 607.19, 185.22)
        self.rig = StereoRig(cam, cam, np.eye(3), np.array([-b, 0.0, 0.0]))
        self.T_body_left = np.eye(4)
        self.T_body_left[:3, :3] = R_BODY_CAM
        self.T_body_left[2, 3] = h
        ahead = length + 200.0
        # guard-rail posts: three points each (foot of the rail, rail, post top), alike along the road
        xs = np.arange(-10.0, length + 60.0, spacing)
        heights = np.array([0.3, 0.55, 0.8])
        posts = np.array([[x, y, z] for y in rails for x in xs for z in heights])
        looks = g.standard_normal((n_looks * len(heights), 64))
        post_look = (np.rint(posts[:, 0] / spacing).astype(int) % n_looks) * len(heights) + np.tile(
            np.arange(len(heights)), len(posts) // len(heights))
        post_desc = looks[post_look] + 0.15 * g.standard_normal((len(posts), 64))
        # distant structure: trees and hills at 20-200 m ahead of the path, spread sideways
        far = np.column_stack([np.exp(g.uniform(np.log(15.0), np.log(ahead), n_far)), g.uniform(-1.0, 1.0, n_far) * g.uniform(10.0, 120.0, n_far),
                               g.uniform(0.0, 12.0, n_far)])
        # a few near points: road marks and signs
        side = np.where(g.random(n_near) < 0.5, -1.0, 1.0)
        near = np.column_stack([g.uniform(0.0, length + 20.0, n_near), side * g.uniform(5.0, 20.0, n_near),
                                g.uniform(0.0, 3.0, n_near)])
        self.points_m = np.concatenate([posts, far, near])
        self.kind = np.array(["post"] * len(posts) + ["far"] * n_far + ["near"] * n_near)
        desc = np.concatenate([post_desc, g.standard_normal((n_far + n_near, 64))]).astype(np.float32)
        self.velocity = np.zeros(len(self.points_m))
        if n_oncoming + n_ahead:  # drawn after the static scene: without vehicles the scene is unchanged
            cars, vel = _vehicles(g, n_oncoming, n_ahead, speed, length)
            self.points_m = np.concatenate([self.points_m, cars])
            self.kind = np.concatenate([self.kind, ["vehicle"] * len(cars)])
            self.velocity = np.concatenate([self.velocity, vel])
            desc = np.concatenate([desc, g.standard_normal((len(cars), 64)).astype(np.float32)])
        self.descriptors = desc / np.linalg.norm(desc, axis=1, keepdims=True)
        self.last_observed: tuple | None = None

    def points_at(self, pose) -> np.ndarray:
        """Landmarks in the world frame when we are at ``pose`` (vehicles moved along the road; issue 25).

        Parameters
        ----------
        pose : array_like, shape (3,)
            Body pose ``(x_m, y_m, yaw_rad)``; the vehicles have moved ``velocity * x_m`` along ``x``.

        Returns
        -------
        numpy.ndarray, shape (K, 3)
        """
        x = as_vector(pose, "pose", 3)[0]
        if not self.velocity.any():
            return self.points_m
        out = self.points_m.copy()
        out[:, 0] += self.velocity * x
        return out

    def _levels(self, depth_m, g) -> np.ndarray:
        """Pyramid level of each landmark's keypoint (see ``pyramid_levels``; both images share it)."""
        L, s = self.pyramid_levels, self.pyramid_scale
        if self.level_ref_m is None:  # ORB's share of features per level: proportional to s^(-2 l)
            w = s ** (-2.0 * np.arange(L))
            return g.choice(L, size=len(depth_m), p=w / w.sum())
        lev = np.floor(np.log(np.maximum(depth_m, 1e-9) / self.level_ref_m) / np.log(s))
        return np.clip(lev, 0, L - 1).astype(int)

    def ground_truth_se3(self, pose) -> np.ndarray:
        """Body pose ``(x_m, y_m, yaw_rad)`` as a (4, 4) transform (body to world).

        Parameters
        ----------
        pose : array_like, shape (3,)
            Planar pose.

        Returns
        -------
        numpy.ndarray, shape (4, 4)
        """
        x, y, yaw = as_vector(pose, "pose", 3)
        return se3_from_planar(x, y, yaw)

    def observe(self, pose, *, pixel_std: float = 0.3, detect_prob: float = 0.9, descriptor_noise: float = 0.05,
                rng=None) -> tuple[Features, Features]:
        """Keypoints of the left and right images at body pose ``pose`` (issue 25; ours).

        Each landmark in front of a camera and inside its image is detected with probability
        ``detect_prob`` in each image independently, at its projection plus Gaussian noise of
        ``pixel_std`` per coordinate, with its descriptor plus Gaussian noise (renormalised).

        Parameters
        ----------
        pose : array_like, shape (3,)
            Body pose ``(x_m, y_m, yaw_rad)``.
        pixel_std : float, default 0.3
            Keypoint position noise per coordinate [px] at pyramid level 0 (the scene's options add
            pyramid levels, disparity locking and bias, moving vehicles).
        detect_prob : float, default 0.9
            Chance that a visible landmark gives a keypoint in one image.
        descriptor_noise : float, default 0.05
            Standard deviation of the noise added to each descriptor component.
        rng : int or numpy.random.Generator, optional
            Noise source.

        Returns
        -------
        left, right : Features
        """
        sigma = check_positive(pixel_std, "pixel_std", allow_zero=True)
        p_det = check_positive(detect_prob, "detect_prob")
        if p_det > 1:
            raise ValueError(f"`detect_prob` must be in (0, 1]; got {detect_prob}")
        d_noise = check_positive(descriptor_noise, "descriptor_noise", allow_zero=True)
        g = as_rng(rng)
        T_wl = self.ground_truth_se3(pose) @ self.T_body_left
        points = self.points_at(pose)
        level = np.zeros(len(points), int)
        if self.pyramid_levels > 1:  # noise grows with the keypoint's pyramid level
            level = self._levels((points - T_wl[:3, 3]) @ T_wl[:3, 2], g)
            sigma = sigma * self.pyramid_scale ** level[:, None]
        out, uv_left, ids = [], None, []
        for cam, t_cam in ((self.rig.left, np.zeros(3)), (self.rig.right, self.rig.t_rl)):
            Xc = (points - T_wl[:3, 3]) @ T_wl[:3, :3] + t_cam
            z = Xc[:, 2]
            front = z > 0.5
            uv = np.full((len(Xc), 2), -1.0)
            uv[front] = project_points(cam.K, Xc[front])
            uv += sigma * g.standard_normal(uv.shape)
            if uv_left is None:
                uv_left = uv
            elif self.disparity_locking or self.disparity_bias_px:  # the measured disparity, locked and biased
                d = uv_left[:, 0] - uv[:, 0]
                d = d + self.disparity_locking * (np.rint(d) - d) + self.disparity_bias_px
                uv[:, 0] = np.where(front, uv_left[:, 0] - d, uv[:, 0])
            keep = front & (uv[:, 0] >= 0) & (uv[:, 0] < cam.width_px) & (uv[:, 1] >= 0) & (uv[:, 1] < cam.height_px)
            keep &= g.random(len(Xc)) < p_det
            idx = g.permutation(np.flatnonzero(keep))
            ids.append(idx)
            d = self.descriptors[idx] + d_noise * g.standard_normal((idx.size, 64)).astype(np.float32)
            d /= np.linalg.norm(d, axis=1, keepdims=True)
            n = idx.size
            out.append(Features(uv[idx], 2.0 * self.pyramid_scale ** level[idx], np.zeros(n), np.ones(n), level[idx],
                                d.astype(np.float32), "highway-sim"))
        self.last_observed = (ids[0], ids[1])
        return out[0], out[1]


def _vehicles(g, n_oncoming, n_ahead, speed, length_m):
    """Points of vehicles on the road and their motion per metre we travel (issue 25; ours).

    Each vehicle is 8 points on the corners of its visible face, 1.8 m wide, 0.3-1.5 m high, 0.5 m deep.
    Oncoming vehicles drive 3.5 m left of our lane toward us (velocity ``-speed``), starting 20 m to
    ``2 length_m`` ahead so that they pass us during the run; vehicles ahead keep 12-40 m in our lane or
    the one to its right (``+speed``).

    Parameters
    ----------
    g : numpy.random.Generator
        Layout source.
    n_oncoming, n_ahead : int
        Vehicles of each kind.
    speed : float
        Their speed as a share of ours.
    length_m : float
        Road length of the scene [m].

    Returns
    -------
    points : numpy.ndarray, shape (8 (n_oncoming + n_ahead), 3)
        Positions when we are at ``x = 0``.
    velocity : numpy.ndarray, shape (8 (n_oncoming + n_ahead),)
        Motion along ``x`` per metre we travel.
    """
    x0 = np.concatenate([g.uniform(20.0, 2.0 * length_m + 20.0, n_oncoming), g.uniform(12.0, 40.0, n_ahead)])
    lane = np.concatenate([np.full(n_oncoming, 3.5), np.where(g.random(n_ahead) < 0.5, 0.0, -3.5)])
    corner = np.array([[dx, dy, dz] for dx in (0.0, 0.5) for dy in (-0.9, 0.9) for dz in (0.3, 1.5)])
    pts = (np.column_stack([x0, lane, np.zeros(len(x0))])[:, None, :] + corner[None]).reshape(-1, 3)
    vel = np.repeat(np.concatenate([np.full(n_oncoming, -speed), np.full(n_ahead, speed)]), len(corner))
    return pts, vel
