"""The pieces of one frame of the stereo loop (000 §3.3-3.6): both images' features in two threads, the stage
names and clock, the frame record, the default landmark store, the input checks and the frame's stereo points
in the body frame (with the ablation oracle's truth). Split from :mod:`slamlab.stereo.slam` (which
re-exports the public names)."""

from __future__ import annotations

import time
from concurrent.futures import ThreadPoolExecutor

import numpy as np

from ..features.base import to_gray_uint8
from ..features.detect import detect
from ..kdtree.stores import ExactStore, LandmarkStore, make_store
from .local_stages import _triangulate_local, stereo_point_cov
from .params import StereoParams

__all__ = ["STAGES", "FrameRecord", "default_store"]


_EXECUTOR: ThreadPoolExecutor | None = None


def _detect_pair(left, right, method, kwargs, parallel):
    """Features of both images by :func:`slamlab.features.detect`; in two threads when ``parallel``
    (OpenCV and numpy release the GIL)."""
    global _EXECUTOR
    if not parallel:
        return detect(left, method, **kwargs), detect(right, method, **kwargs)
    if _EXECUTOR is None:
        _EXECUTOR = ThreadPoolExecutor(max_workers=2, thread_name_prefix="slamlab-detect")
    fut = _EXECUTOR.submit(detect, right, method, **kwargs)
    return detect(left, method, **kwargs), fut.result()


def default_store(params: StereoParams | None = None) -> LandmarkStore:
    """The landmark store the pipeline uses unless told otherwise (000 §3.4, §4).

    Float descriptors (SURF, SIFT): 000's multi kd-tree (n1 = 3500, q = 5.5, BBF with 200
    checks) behind the non-base buffer (:func:`slamlab.kdtree.make_store`). Binary descriptors
    (ORB, Hamming distance): a kd-tree does not apply, so :class:`~slamlab.kdtree.ExactStore`
    (brute force). Both apply the base rule with ``params``' ``base_seen_times`` / ``max_non_base_time``.

    Parameters
    ----------
    params : StereoParams, optional
        Settings (``detector``, ``base_seen_times``, ``max_non_base_time``); default :class:`StereoParams`.

    Returns
    -------
    LandmarkStore
    """
    p = StereoParams.resolve(params)
    if p.binary:
        return ExactStore(p.base_seen_times, p.max_non_base_time)
    return make_store("multi", base_seen_times=p.base_seen_times, max_non_base_time=p.max_non_base_time)


def _resolve_store(store, p: StereoParams) -> LandmarkStore:
    """``StereoSLAM``'s ``store`` argument: None (:func:`default_store`), a store, or a class / factory of one."""
    if store is None:
        store = default_store(p)
    elif isinstance(store, type) or (callable(store) and not isinstance(store, LandmarkStore)):
        store = store()  # a class or a factory
    if not isinstance(store, LandmarkStore):
        raise TypeError(f"`store` must be a slamlab.kdtree.LandmarkStore or a factory of one; "
                        f"got {type(store).__name__}")
    return store


def _check_pair(left, right, image_shape):
    """The images' shapes: equal to each other and to the rig's image size (grey or colour)."""
    sl, sr = np.shape(left), np.shape(right)
    if len(sl) not in (2, 3) or len(sr) not in (2, 3):
        raise ValueError(f"`left` and `right` must be (H, W) or (H, W, 3) images; got shapes {sl} and {sr}")
    if sl != sr:
        raise ValueError(f"`left` and `right` must have the same shape; got {sl} and {sr}")
    if sl[:2] != image_shape:
        raise ValueError(f"images must be {image_shape[0]}x{image_shape[1]} (rows x columns) like "
                         f"the rig's cameras; got {sl[0]}x{sl[1]}")



def _local_cloud(rig, fl, fr, sm, p: StereoParams, refine, oracle, truth):
    """The frame's stereo points (000 §3.3) and the mask of those that may become landmarks: ``(cloud,
    may_be_new)``; with the 'cut' oracle (ablation) the depth cut is on the true depths ``truth``."""
    if "cut" in oracle and truth is not None:  # the depth cut on the true depth (ablation)
        cloud = _triangulate_local(rig, fl, fr, sm, p.min_depth_m, 1e12, p.pixel_std, refine)
        zt = truth[cloud.left, 2]
        keep = (zt >= p.min_depth_m) & (zt <= p.max_depth_m)
        cloud = type(cloud)(cloud.points[keep], cloud.cov[keep], cloud.left[keep], cloud.gap_m[keep])
        return cloud, np.ones(len(cloud.points), bool)  # the oracle's cut replaces the one below
    cloud = _triangulate_local(rig, fl, fr, sm, p.min_depth_m, p.max_depth_m * p.reobserve_depth_factor,
                               p.pixel_std, refine)
    # beyond max_depth_m a point may match a landmark but does not become one (reobserve_depth_factor > 1)
    return cloud, cloud.points[:, 2] <= p.max_depth_m


def _frame_points(rig, T_body_left, fl, fr, sm, p: StereoParams, images, oracle, truth):
    """The frame's stereo points (000 §3.3) in the body frame: ``(cloud, may_be_new, pts_body, cov_body, cov_init,
    true_cam)``; ``cov_init`` the new landmarks' first covariances, ``true_cam`` the points' true left-camera
    positions (from ``truth``, the ablation oracle; None when no setting asks for them). ``images``: the
    ``(left, right)`` pair whose disparities are refined first (None: not refined)."""
    refine = None
    if images is not None:
        refine = (to_gray_uint8(images[0], "left", channel_order=p.channel_order),
                  to_gray_uint8(images[1], "right", channel_order=p.channel_order), p.subpixel_half_px,
                  p.subpixel_search_px)
    cloud, may_be_new = _local_cloud(rig, fl, fr, sm, p, refine, oracle, truth)
    Rb, tb = T_body_left[:3, :3], T_body_left[:3, 3]
    pts_body = cloud.points @ Rb.T + tb
    cov_body = Rb @ cloud.cov @ Rb.T
    true_cam = None
    if "true" in (p.weight_depth, p.update_cov_depth, p.init_cov_depth) or oracle:
        if truth is None or len(truth) != len(fl.uv):
            raise ValueError("a depth source 'true' (an ablation oracle) needs `truth_left_cam_m`: the true "
                             "left-camera position of every left keypoint, set before each frame")
        true_cam = np.asarray(truth, dtype=float)[cloud.left]
    cov_init = cov_body
    if p.init_cov_depth == "true":
        cov_init = Rb @ stereo_point_cov(true_cam, rig.left.fx, rig.baseline_m, p.pixel_std) @ Rb.T
    return cloud, may_be_new, pts_body, cov_body, cov_init, true_cam


def _append_rows(buffers, name, old, rows):
    """``old`` (None: empty) with ``rows`` appended, as a view of the first rows of ``buffers[name]``, a buffer that
    doubles when full (the landmark arrays grow every frame; concatenating copied all of them each time). An ``old``
    that is not a view of that buffer (set from outside) starts a new one."""
    n = 0 if old is None else len(old)
    buf = buffers.get(name)
    if old is not None and (buf is None or old.base is not buf):
        buf = None
    need = n + len(rows)
    dtype = rows.dtype if old is None else np.result_type(old, rows)
    if buf is None or len(buf) < need or buf.dtype != dtype or buf.shape[1:] != rows.shape[1:]:
        new = np.empty((max(need, 2 * len(buf) if buf is not None else 0, 256), *rows.shape[1:]), dtype)
        if n:
            new[:n] = old
        buf = buffers[name] = new
    buf[n:need] = rows
    return buf[:need]


#: the per-frame stages whose times are recorded
STAGES = ("detect", "stereo", "triangulate", "map_match", "pose", "update")


class _StageClock:
    """Wall-clock and process CPU time per stage: ``lap(stage)`` adds the time since the last lap."""

    def __init__(self):
        self.wall = dict.fromkeys(STAGES, 0.0)
        self.cpu = dict.fromkeys(STAGES, 0.0)
        self._w, self._c = time.perf_counter(), time.process_time()

    def lap(self, stage):
        w, c = time.perf_counter(), time.process_time()
        self.wall[stage] += w - self._w
        self.cpu[stage] += c - self._c
        self._w, self._c = w, c


class FrameRecord(dict):
    """Counts of one frame (a plain dict with attribute access)."""

    __getattr__ = dict.__getitem__
