"""The stereo SLAM loop of 000 §3: ``StereoSLAM.process(left, right)`` per frame.

The map frame is the body frame of the first processed frame (000 §3.5: global
coordinates are "relative to the initial position"). Landmarks live in the map
frame, refined by the static-landmark Kalman filter of 000 §3.6
(:class:`slamlab.filters.LandmarkFilter` maths) and indexed by descriptor in a
landmark store (000 §3.4).
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from .._validate import as_matrix, as_rng
from ..geometry.camera import StereoRig
from ..kdtree.stores import base_rule
from ._frame import STAGES, StageClock, append_rows, check_pair, frame_points, refine_matches, weight_depth
from .disparity_offset import DisparityOffsetTracker
from .landmark_filter import duplicate_mask, gated_update, in_view, landmark_observations, pixel_update
from .local_stages import check_features, detect_pair, is_rectified, stereo_match
from .map_stages import match_in_window, match_to_landmarks, match_to_map
from .noise_estimate import KeypointNoiseTracker, disparity_residuals_px
from .params import StereoParams
from .pose_stages import estimate_pose, pose_std, refine_pose_stereo
from .results import RunResults
from .store import default_store, resolve_store

__all__ = ["STAGES", "FrameRecord", "StereoSLAM", "default_store"]


class FrameRecord(dict):
    """Counts of one frame (a plain dict with attribute access)."""

    __getattr__ = dict.__getitem__


class StereoSLAM(RunResults):
    """Stereo SLAM with a landmark map (000 §3.3-3.6).

    Parameters
    ----------
    rig : the calibrated stereo rig; every image must have its size (``rig.left.height_px`` ×
        ``rig.left.width_px``).
    T_body_left : (4, 4) pose of the left camera in the body frame (the map is the first body frame).
    params : :class:`~slamlab.stereo.params.StereoParams` (default ``StereoParams()``): every
        setting, with its source; ``overrides`` change single fields (``detector="orb"``).
    store : a :class:`~slamlab.kdtree.LandmarkStore`, or a factory (class / callable) returning
        one; default :func:`default_store` (multi kd-tree for SURF/SIFT, exact Hamming brute force
        for ORB). ORB matches to the map by the window search by default (``params.map_search``, our
        addition): a first pose from the last frame's landmarks, then each point only against the
        landmarks projected near it; the store serves the global search when that gives no pose.
    rng : RANSAC's random stream.
    **overrides
        :class:`~slamlab.stereo.params.StereoParams` fields to change (``detector="orb"``).

    Examples
    --------
    >>> from slamlab.sim.arena import StereoArena, StereoSim
    >>> sim = StereoSim(StereoArena(2.0, 3.0, texel_m=0.01), rng=0)
    >>> slam = StereoSLAM(sim.rig, sim.T_body_left, params=StereoParams(), rng=0)
    >>> rec = slam.process(*sim.render_pair([1.0, 0.6, np.pi / 2]))
    >>> rec.status, bool(rec.n_stereo > 50)
    ('init', True)
    """

    def __init__(self, rig: StereoRig, T_body_left=None, *, params: StereoParams | None = None, store=None,
                 rng=None, **overrides):
        if not isinstance(rig, StereoRig):
            raise TypeError(f"`rig` must be a StereoRig; got {type(rig).__name__}")
        self.rig = rig
        self.T_body_left = np.eye(4) if T_body_left is None else as_matrix(T_body_left, "T_body_left", (4, 4))
        self.params = p = StereoParams.resolve(params, **overrides)
        self.store = resolve_store(store, p)
        self._noise = KeypointNoiseTracker(p)  # pixel_std: the nominal, or raised to the online estimate
        #: the disparity offset estimated online on top of ``disparity_offset_px`` (``disparity_offset_estimate``;
        #: rectified rigs only; its ``offset_px`` stays 0 otherwise)
        self.disparity_offset = DisparityOffsetTracker(p)
        self._offset_used = 0.0
        self.rng = as_rng(rng)
        self._image_shape = (rig.left.height_px, rig.left.width_px)
        self._refine = p.refine_disparity and is_rectified(rig)
        self._estimate_offset = p.disparity_offset_estimate and is_rectified(rig)
        # the landmark filter in stereo pixels needs a rectified rig with one focal length (else: in x, y, z)
        self._pixel_filter = (p.filter_space == "pixels" and is_rectified(rig)
                              and bool(np.isclose(rig.left.fx, rig.right.fx)))
        # landmarks (ids are row indices): position, covariance, bookkeeping
        self.X = np.empty((0, 3))
        self.P = np.empty((0, 3, 3))
        self.first_seen = np.empty(0, dtype=np.int64)
        self.n_seen = np.empty(0, dtype=np.int64)
        self.alive = np.empty(0, dtype=bool)
        self.desc: np.ndarray | None = None  # descriptor of each landmark (the window search's copy)
        self._buffers: dict[str, np.ndarray] = {}  # the arrays above are views of these (append_rows)
        self._last_ids = np.empty(0, dtype=np.int64)  # landmarks matched or added by the last located frame
        self.T = np.eye(4)  # current pose of the body in the map
        self.poses: list[np.ndarray] = []
        self.records: list[FrameRecord] = []
        self.times: list[dict] = []  # wall-clock seconds per stage and frame
        self.cpu_times: list[dict] = []  # CPU seconds of this process (all threads) per stage and frame
        self.frame = 0
        self.last_cloud_map = np.empty((0, 3))
        self.last_inlier_map = np.empty((0, 3))
        #: an ablation oracle (issue 25; a simulator sets it, never a user): (n_left, 3) true left-camera
        #: position of each left keypoint of the next frame, read by the settings whose depth source is
        #: 'true' (``weight_depth``, ``update_cov_depth``, ``init_cov_depth``) and cleared after the frame
        self.truth_left_cam_m: np.ndarray | None = None
        self._true_cam = None
        #: exploratory oracles (issue 25; set by :func:`~slamlab.studies.stereo.run_scale_ablation`, never a user):
        #: 'cut' (the depth cut on the true depth), 'init_position' (new landmarks at their true position),
        #: 'pose_points' (the pose from the exact local points); each reads ``truth_left_cam_m``
        self.oracles: frozenset = frozenset()

    # -- the loop ------------------------------------------------------------------------------------
    def process(self, left, right) -> FrameRecord:
        """Run all stages on one stereo pair; returns the frame's counts (000 §3.3-3.6).

        ``left`` and ``right`` must have the same shape, the rig's image size; colour images are
        converted with ``params.channel_order``.

        Parameters
        ----------
        left, right : array_like, shape (H, W) or (H, W, 3)
            The stereo pair.

        Returns
        -------
        FrameRecord
            Counts per stage, ``status``, the pose.
        """
        check_pair(left, right, self._image_shape)
        clock = StageClock()
        fl, fr = detect_pair(left, right, params=self.params)
        return self._process(fl, fr, left, right, clock)

    def process_features(self, left_features, right_features) -> FrameRecord:
        """Run the stages after detection on the features of one stereo pair (000 §3.3-3.6).

        For features that come from elsewhere than :func:`slamlab.features.detect` (a point-level
        simulation, say): no images, so no sub-pixel disparity refinement.

        Parameters
        ----------
        left_features, right_features : Features
            Keypoints and descriptors of the left and right images.

        Returns
        -------
        FrameRecord
            Counts per stage, ``status``, the pose.
        """
        check_features(left_features, "left_features")
        check_features(right_features, "right_features")
        return self._process(left_features, right_features, None, None, StageClock())

    def _process(self, fl, fr, left, right, clock) -> FrameRecord:
        """The stages after detection; ``left``/``right`` images (None: no disparity refinement)."""
        p = self._noise.current(self.params)
        self._offset_used = self.disparity_offset.offset_px if self._estimate_offset else 0.0
        clock.lap("detect")
        sm = stereo_match(fl, fr, self.rig, params=p)
        clock.lap("stereo")
        images = (left, right) if self._refine and left is not None else None
        truth, self.truth_left_cam_m, self._true_cam = self.truth_left_cam_m, None, None
        cloud, self._may_be_new, pts_body, cov_body, cov_init, self._true_cam = frame_points(
            self.rig, self.T_body_left, fl, fr, sm, p, images, self.oracles, truth, self._offset_used)
        desc = fl.descriptors[cloud.left]
        clock.lap("triangulate")
        rec = FrameRecord(
            frame=self.frame, n_left=len(fl.uv), n_right=len(fr.uv), n_stereo=len(sm.left),
            n_local=len(pts_body), n_searched=0, n_map_matches=0, n_inliers=0, n_used=0, n_gated=0, n_new=0,
            n_compared=0, n_duplicates=0, window_fallback=False, gate_fallback=False, rot_std_rad=np.nan, status="ok",
            trail="",
        )  # fmt: skip
        no_inliers = np.zeros(len(pts_body), bool)
        if len(self.X) == 0:
            # first frame (or an empty map): it defines the map frame
            first = np.flatnonzero(self._may_be_new)
            if len(first) >= p.min_inliers:
                self._add_landmarks(pts_body[first], cov_init[first], desc[first], self.T)
                self._last_ids = np.arange(len(first))
                rec["n_new"] = len(first)
                rec["status"] = "init"
            else:
                rec["status"] = "too_few_points"
            self._finish(rec, clock, pts_body, no_inliers)
            return rec
        mm = est = None
        if p.search == "window" and self._last_ids.size:
            mm, est = self._locate_window(rec, clock, desc, fl.uv[cloud.left], pts_body, cov_body, cloud.points[:, 2])
            rec["window_fallback"] = est is None
        cand = None
        if est is None and p.view_margin_deg is not None:
            cand = self.landmarks_in_view(p.view_margin_deg)
            mm, est = self._locate(rec, clock, desc, pts_body, cov_body, cloud.points[:, 2], cand)
        elif est is None:
            mm, est = self._locate(rec, clock, desc, pts_body, cov_body, cloud.points[:, 2], None)
        if est is None and cand is not None:
            # the view gate rests on the last pose: when the landmarks in view do not give a pose, search the
            # whole map (our addition; it keeps tracking after frames that kept the last pose while the robot turned)
            rec["gate_fallback"] = True
            mm, est = self._locate(rec, clock, desc, pts_body, cov_body, cloud.points[:, 2], None)
        if est is None:
            if p.degenerate_pose == "constant_velocity" and len(self.poses) >= 2:
                # our option: the last frame's motion once more, not the last pose (a turn goes on; issue 25)
                self.T = self.T @ (np.linalg.inv(self.poses[-2]) @ self.poses[-1])
            self._finish(rec, clock, pts_body, no_inliers)
            return rec
        inl_mask = self._update_map(rec, est, mm, pts_body, cov_body, desc, cov_init)
        self._finish(rec, clock, pts_body, inl_mask)
        return rec

    def _update_map(self, rec, est, mm, pts_body, cov_body, desc, cov_init=None):
        """Take the pose ``est``; refine the re-seen landmarks, add the unmatched points (000 §3.6);
        ``cov_init``: the new landmarks' first covariances (default ``cov_body``).

        Returns the mask of the local points that were inliers of the pose.
        """
        p = self._noise.current(self.params)
        rec["status"] = "ok"
        self.T = est.T
        # refine re-seen landmarks with the static Kalman filter (000 §3.6)
        ids = mm.ids[est.inliers]
        loc = mm.local[est.inliers]
        true_cam = self._true_cam[loc] if p.update_cov_depth == "true" else None
        Z, pose_var, Rz = landmark_observations(pts_body[loc], cov_body[loc], est.T, self.T_body_left, self.rig,
                                                true_cam=true_cam, landmarks_map=self.X[ids], params=p)
        if p.drop_first_sighting:
            # a landmark's first triangulation passed the depth cut on its own noisy depth (selected too near):
            # its second sighting replaces it instead of being fused with it (our option; issue 25)
            second = self.n_seen[ids] == 1
            self.X[ids[second]], self.P[ids[second]] = Z[second], Rz[second]
        else:
            second = np.zeros(len(ids), bool)
        f = ~second  # the landmarks the filter fuses
        if self._pixel_filter:
            T_wc = est.T @ self.T_body_left
            pts_left = (pts_body[loc[f]] - self.T_body_left[:3, 3]) @ self.T_body_left[:3, :3]
            rec["n_gated"] = int((~self._refine_landmarks_in_pixels(ids[f], pts_left, T_wc, pose_var[f])).sum())
        else:
            rec["n_gated"] = int((~self.refine_landmarks(ids[f], Z[f], Rz[f])).sum())
        self.n_seen[ids] += 1
        self.store.observe(ids)
        rec["n_inliers"] = len(ids)
        # unmatched local points become new (non-base) landmarks
        new = mm.unmatched[self._may_be_new[mm.unmatched]]
        if p.duplicate_gap_m is not None and new.size:
            dup = duplicate_mask(pts_body[new], mm.nearest[new], self.X, est.T, p.duplicate_gap_m)
            rec["n_duplicates"] = int(dup.sum())
            new = new[~dup]
        first_new = len(self.X)
        pts_new = pts_body[new]
        if "init_position" in self.oracles:
            pts_new = self._true_cam[new] @ self.T_body_left[:3, :3].T + self.T_body_left[:3, 3]
        self._add_landmarks(pts_new, (cov_body if cov_init is None else cov_init)[new], desc[new], est.T)
        rec["n_new"] = len(new)
        self._last_ids = np.concatenate([ids, np.arange(first_new, len(self.X))])
        if self._estimate_offset:
            self._observe_offset(ids, loc, pts_body, est.T)
        inl_mask = np.zeros(len(pts_body), bool)
        inl_mask[loc] = True
        return inl_mask

    def _observe_offset(self, ids, loc, pts_body, T):
        """``disparity_offset_estimate``: the inliers' stereo pixels, their disparities corrected by
        ``disparity_offset_px`` only (this frame's estimate taken off), to the disparity-offset tracker."""
        pts_left = (pts_body[loc] - self.T_body_left[:3, 3]) @ self.T_body_left[:3, :3]
        z = self.rig.stereo_pixels(pts_left)
        uvd = np.c_[z[:, 0], z[:, 1], z[:, 0] - z[:, 2] - self._offset_used]
        self.disparity_offset.observe(ids, uvd, T @ self.T_body_left, self.rig)

    def _locate_window(self, rec, clock, desc, uv, pts_body, cov_body, depth):
        """The window search (``map_search='window'``, our addition): a first pose from the landmarks of the
        last located frame (000 §3.4-3.5 on that small set), then every landmark in view of that pose
        projected into the left image and matched only to the keypoints within ``window_px`` of it;
        the pose of those matches is the frame's. ``(matches, estimate)`` as :meth:`_locate`."""
        p = self.params
        last = self._last_ids[self.alive[self._last_ids]]
        mm = match_to_landmarks(desc, last, self.desc[last], positions=self.X, params=p)
        clock.lap("map_match")
        rec["n_searched"] += len(last)
        rec["n_compared"] += len(last) * len(desc)
        mm, est = self._pose(rec, clock, mm, pts_body, cov_body, depth, "last")
        if est is None:
            return mm, None
        cand = self.landmarks_in_view(np.rad2deg(p.window_px / self.rig.left.fx), T_body=est.T)
        mm, n_pairs = match_in_window(desc, uv, cand, self.desc[cand], self.X, est.T @ self.T_body_left, self.rig.left,
                                      params=p)
        clock.lap("map_match")
        rec["n_compared"] += n_pairs
        if len(mm.local) < p.window_min_share * len(desc):
            rec["status"] = "too_few_matches"
            rec["trail"] += f"window {len(mm.local)} too_few_matches; "
            return mm, None
        return self._pose(rec, clock, mm, pts_body, cov_body, depth, "window")

    def _locate(self, rec, clock, desc, pts_body, cov_body, depth, cand):
        """Match to the map (the landmarks ``cand``, or all) and estimate the pose (000 §3.4-3.5);
        ``(matches, estimate)``, the estimate None (and ``rec.status`` saying why) when the frame gives no pose."""
        p = self.params
        mm = match_to_map(desc, self.store, params=p, positions=self.X, candidates=cand)
        clock.lap("map_match")
        n = len(self.store) if cand is None else len(cand)
        rec["n_searched"] += n
        rec["n_compared"] += n * len(desc)
        return self._pose(rec, clock, mm, pts_body, cov_body, depth, "global" if cand is None else "in view")

    def _pose(self, rec, clock, mm, pts_body, cov_body, depth, search):
        """The pose of map matches ``mm`` (000 §3.5) with our checks; ``(mm, estimate or None)``, ``rec.status``
        saying why when None. Each attempt goes to ``rec["trail"]``: "search matches outcome" (``search``: which)."""
        p = self._noise.current(self.params)
        rec["n_map_matches"], rec["rot_std_rad"], est = len(mm.local), np.nan, None
        if len(mm.local) < max(3, p.min_inliers):
            rec["status"] = "too_few_matches"
        else:
            true_z = self._true_cam[mm.local, 2] if p.weight_depth == "true" else None
            d_use = weight_depth(p.weight_depth, depth[mm.local], true_z, self.X[mm.ids], self.T @ self.T_body_left,
                                  p.min_depth_m)
            src = pts_body[mm.local]
            if "pose_points" in self.oracles:
                src = self._true_cam[mm.local] @ self.T_body_left[:3, :3].T + self.T_body_left[:3, 3]
            est = estimate_pose(src, self.X[mm.ids], self.first_seen[mm.ids], depth_m=d_use, cov=cov_body[mm.local],
                                params=p, rng=self.rng)
            rec["n_used"] = est.n_used
            if est.converged and p.pose_refine == "reprojection":
                est = est._replace(T=self._refine_pose(est, mm, pts_body))
            if not est.converged:
                rec["status"], est = "ransac_failed", None
            elif p.max_rot_std_rad is not None:
                R, inl = est.T[:3, :3], mm.local[est.inliers]
                rec["rot_std_rad"] = float(np.max(pose_std(self.X[mm.ids[est.inliers]], R @ cov_body[inl] @ R.T)[:3]))
                if not rec["rot_std_rad"] <= p.max_rot_std_rad:
                    rec["status"], est = "ill_conditioned", None
            clock.lap("pose")
        std = "" if np.isnan(rec["rot_std_rad"]) else f" (rot std {np.rad2deg(rec['rot_std_rad']):.2f} deg)"
        rec["trail"] += f"{search} {len(mm.local)} {rec['status'] if est is None else 'ok'}{std}; "
        return mm, est

    def _refine_pose(self, est, mm, pts_body) -> np.ndarray:
        """``pose_refine='reprojection'``: the pose ``est`` refined on the stereo reprojection error of its inliers
        (:func:`~slamlab.stereo.refine_pose_stereo`), whose disparity residuals feed the keypoint-noise estimate
        (``pixel_std_estimate``)."""
        p = self.params
        ids, loc = refine_matches(mm.ids[est.inliers], mm.local[est.inliers], self.n_seen, p)
        pts_left = (pts_body[loc] - self.T_body_left[:3, 3]) @ self.T_body_left[:3, :3]
        X = self.X[ids]
        T = refine_pose_stereo(est.T, X, pts_left, self.rig, self.T_body_left, iters=p.refine_iters,
                               huber_px=p.refine_huber_px, min_depth_m=p.min_depth_m)
        if p.pixel_std_estimate:
            r, q = disparity_residuals_px(T, X, self.P[ids], pts_left, self.rig, self.T_body_left)
            self._noise.observe(r, q, smoothing=p.pixel_std_smoothing)
        return T

    def landmarks_in_view(self, margin_deg: float = 0.0, T_body=None) -> np.ndarray:
        """Ids of live landmarks in front of the left camera at ``T_body`` (default: the last pose),
        within its horizontal field of view widened by ``margin_deg`` per side and up to
        ``params.view_depth_factor × params.max_depth_m`` (1.5 × 10 m by default) away.

        Parameters
        ----------
        margin_deg : float, default 0.0
            Widening of the field of view per side [deg].
        T_body : array_like, shape (4, 4), optional
            Body pose in the map (default the last pose).

        Returns
        -------
        numpy.ndarray of int
            Landmark ids.
        """
        T = self.T if T_body is None else as_matrix(T_body, "T_body", (4, 4))
        live = np.flatnonzero(self.alive)
        p = self.params
        return live[in_view(self.X[live], T @ self.T_body_left, self.rig.left, margin_deg,
                            p.view_depth_factor * p.max_depth_m)]

    def refine_landmarks(self, ids, Z, Rz) -> np.ndarray:
        """Kalman-update landmarks ``ids`` with map-frame observations ``Z`` (covariances ``Rz``) (000 §3.6).

        Observations whose innovation fails ``update_gate`` leave their landmark unchanged;
        returns the mask of the updated ones.

        Parameters
        ----------
        ids : numpy.ndarray of int, shape (M,)
            Landmark ids.
        Z : numpy.ndarray, shape (M, 3)
            Observed positions in the map frame [m].
        Rz : numpy.ndarray, shape (M, 3, 3)
            Their covariances [m²].

        Returns
        -------
        numpy.ndarray of bool, shape (M,)
        """
        ok, X_new, P_new = gated_update(self.X[ids], self.P[ids], Z, Rz, self.params.state_var, self.params.update_gate)
        self.X[ids[ok]], self.P[ids[ok]] = X_new, P_new
        return ok

    def _refine_landmarks_in_pixels(self, ids, pts_left, T_wc, pose_var) -> np.ndarray:
        """``filter_space='pixels'``: landmarks ``ids`` updated in the stereo pixels of the left camera at
        ``T_wc`` (:func:`~slamlab.stereo.landmark_filter.pixel_update`); returns the mask of the updated ones."""
        p = self._noise.current(self.params)
        ok, X_new, P_new = pixel_update(self.X[ids], self.P[ids], pts_left, T_wc, pose_var, self.rig, p.state_var,
                                        p.pixel_std, p.min_depth_m, p.update_gate)
        self.X[ids[ok]], self.P[ids[ok]] = X_new, P_new
        return ok

    def _add_landmarks(self, pts_body, cov_body, desc, T):
        R, t = T[:3, :3], T[:3, 3]
        ids = np.arange(len(self.X), len(self.X) + len(pts_body))
        for name, rows in (("X", pts_body @ R.T + t), ("P", R @ cov_body @ R.T), ("first_seen", np.full(len(ids), self.frame)),
                           ("n_seen", np.ones(len(ids), dtype=np.int64)), ("alive", np.ones(len(ids), dtype=bool)),
                           ("desc", desc)):
            setattr(self, name, append_rows(self._buffers, name, getattr(self, name), rows))
        self.store.add(desc, ids)

    def _finish(self, rec, clock, pts_body, inl_mask):
        self.store.end_iteration()
        # the base rule (the stores' own): non-base landmarks time out
        is_base, late = self._base_rule()
        self.alive[late] = False
        clock.lap("update")
        R, tt = self.T[:3, :3], self.T[:3, 3]
        self.last_cloud_map = pts_body @ R.T + tt
        self.last_inlier_map = self.last_cloud_map[inl_mask]
        rec["n_landmarks"] = int(self.alive.sum())
        rec["n_base"] = int((self.alive & is_base).sum())
        self.poses.append(self.T.copy())
        self.records.append(rec)
        self.times.append(clock.wall)
        self.cpu_times.append(clock.cpu)
        self.frame += 1

    def _base_rule(self):
        p = self.params
        return base_rule(self.n_seen, self.frame - self.first_seen, p.base_seen_times, p.max_non_base_time)

    def run(self, frames, progress: bool | Callable[[int], object] | None = False) -> StereoSLAM:
        """Process an iterable of ``(left, right)`` pairs.

        Parameters
        ----------
        frames : iterable of (ndarray, ndarray)
            The left and right images of each frame.
        progress : bool, callable or None
            The one contract of :mod:`slamlab._progress`: a bar (True; None: unless ``$SLAMLAB_PROGRESS=0``),
            none (False, the default), or a callable ``progress(i)`` called after frame ``i``.

        Returns
        -------
        StereoSLAM
            ``self``.
        """
        from .._progress import progress_bar

        for left, right in progress_bar(frames, desc="stereo SLAM", progress=progress):
            self.process(left, right)
        return self

    # -- results -------------------------------------------------------------------------------------
    def landmark_map(self, base_only: bool = True) -> np.ndarray:
        """(K, 3) landmark positions in the map frame (000's 2D map: the first two columns).

        Parameters
        ----------
        base_only : bool, default True
            Only the base landmarks (seen often enough, 000 §3.4); False adds the live non-base ones.

        Returns
        -------
        numpy.ndarray, shape (K, 3)
        """
        keep = self.alive & self._base_rule()[0] if base_only else self.alive
        return self.X[keep]
