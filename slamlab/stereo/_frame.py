"""Package-private bookkeeping of one frame of :class:`~slamlab.stereo.slam.StereoSLAM` (000 §3.3-3.6).

The stage clock, the check of the image pair, the frame's stereo points in the body frame, the depth behind each
map match's weight, the matches the pose refinement uses, and the growth of the landmark arrays.
"""

from __future__ import annotations

import time

import numpy as np

from .local_stages import stereo_point_cov, triangulate_local
from .params import StereoParams

__all__ = ["STAGES", "StageClock", "append_rows", "check_pair", "frame_points", "refine_matches", "weight_depth"]


#: the per-frame stages whose times are recorded
STAGES = ("detect", "stereo", "triangulate", "map_match", "pose", "update")


class StageClock:
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


def check_pair(left, right, image_shape):
    """The images' shapes: equal to each other and to the rig's image size (grey or colour)."""
    sl, sr = np.shape(left), np.shape(right)
    if len(sl) not in (2, 3) or len(sr) not in (2, 3):
        raise ValueError(f"`left` and `right` must be (H, W) or (H, W, 3) images; got shapes {sl} and {sr}")
    if sl != sr:
        raise ValueError(f"`left` and `right` must have the same shape; got {sl} and {sr}")
    if sl[:2] != image_shape:
        raise ValueError(f"images must be {image_shape[0]}x{image_shape[1]} (rows x columns) like "
                         f"the rig's cameras; got {sl[0]}x{sl[1]}")


def frame_points(rig, T_body_left, fl, fr, sm, p: StereoParams, images, oracle, truth, extra_offset_px=0.0):
    """The frame's stereo points (000 §3.3) in the body frame: ``(cloud, may_be_new, pts_body, cov_body, cov_init,
    true_cam)``. ``may_be_new``: the points that may become landmarks (within ``max_depth_m``; beyond it, up to
    ``reobserve_depth_factor`` times deeper, a point may match a landmark but not become one); ``cov_init`` the new
    landmarks' first covariances; ``true_cam`` the points' true left-camera positions (from ``truth``, the ablation
    oracle; None when no setting asks for them). ``images``: the ``(left, right)`` pair whose disparities are
    refined first (None: not refined); ``oracle`` 'cut': the depth cut on the true depths ``truth``;
    ``extra_offset_px`` is added to every disparity beside ``disparity_offset_px`` (the online estimate)."""
    if "cut" in oracle and truth is not None:  # the depth cut on the true depth (ablation)
        cloud = triangulate_local(rig, fl, fr, sm, images=images, params=p, max_depth_m=1e12,
                                  extra_offset_px=extra_offset_px)
        zt = truth[cloud.left, 2]
        keep = (zt >= p.min_depth_m) & (zt <= p.max_depth_m)
        cloud = type(cloud)(cloud.points[keep], cloud.cov[keep], cloud.left[keep], cloud.gap_m[keep])
        may_be_new = np.ones(len(cloud.points), bool)  # the oracle's cut replaces the one below
    else:
        cloud = triangulate_local(rig, fl, fr, sm, images=images, params=p,
                                  max_depth_m=p.max_depth_m * p.reobserve_depth_factor, extra_offset_px=extra_offset_px)
        may_be_new = cloud.points[:, 2] <= p.max_depth_m
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


def weight_depth(source, depth, true_depth, X_map, T_wc, min_depth_m):
    """The depth behind each match's RANSAC threshold and weight (``weight_depth``): 'measured' the point's own
    ``depth``, 'true' ``true_depth`` (the ablation oracle: its true depth in this frame), 'map' the depth of the
    landmark ``X_map`` seen from the left camera at ``T_wc`` (the last pose), at least ``min_depth_m``."""
    if source == "true":  # the ablation oracle: the point's true depth in this frame
        return true_depth
    if source == "map":
        # the landmark's depth seen from the last pose: its error is not this frame's (issue 25)
        return np.maximum(((X_map - T_wc[:3, 3]) @ T_wc[:3, :3])[:, 2], min_depth_m)
    return depth


def refine_matches(ids, loc, n_seen, p: StereoParams):
    """The inliers ``(ids, loc)`` the reprojection refinement uses: those whose landmark was seen at least
    ``p.refine_min_seen`` times, or all when fewer than ``p.min_inliers`` were."""
    seen = n_seen[ids] >= p.refine_min_seen
    if seen.sum() >= p.min_inliers:  # too few landmarks seen often enough: refine on all inliers
        ids, loc = ids[seen], loc[seen]
    return ids, loc


def append_rows(buffers, name, old, rows):
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
