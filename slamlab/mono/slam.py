"""The monocular pipeline of 003 §4 (SDVL, after SVO) in one loop: :class:`MonoSLAM`.

Per frame: initialisation until two keyframes exist (003 §4.3.1); then tracking (003
§4.4: constant-velocity prior → sparse direct alignment to the previous frame → map
points projected and refined by Lucas-Kanade from their keyframe → motion-only
refinement), the depth filter of every seed (003 §4.2, §4.3.2) and the keyframe rules
(003 §4.3). SDVL runs tracking and mapping in two threads; we run them in turn (our
simplification: the results do not depend on thread timing). The mapping steps live in
:mod:`slamlab.mono.mapping` (a mixin :class:`MonoSLAM` inherits).

Failure (ours): a frame is *lost* when too few points, or too small a share of the matched
points, reproject within ``reproj_inlier_deg``, or when the alignment's photometric RMS is
too large. A lost frame reports the pose the motion prior predicts (``max_coast`` frames of
coasting), then a new two-view map is started from the last tracked frame, placed at its
pose and scaled by the recent per-frame steps, and accepted only if its motion agrees with
the prior (``reinit_when_lost``; SDVL stays lost until it sees a known place, 003 §5.3).
Bad input never gives a NaN pose; a frame of another size is a ``ValueError``.
"""

from __future__ import annotations

import time

import numpy as np

from .._validate import as_image, as_matrix
from ..geometry.se3 import se3_compose, se3_inverse, transform_points
from ..geometry.so3 import se3_exp, se3_log
from .align import build_pyramid, project, refine_pose, sparse_align
from .depth_filter import init_seeds
from .initialise import Initialiser, track_lk
from .mapping import Keyframe, MappingMixin, orthonormalise
from .params import MonoParams

__all__ = ["STAGES", "Keyframe", "MonoSLAM"]

#: timed stages of a frame: tracking = align + match + refine
STAGES = ("detect", "align", "match", "refine", "mapping", "keyframe")


class MonoSLAM(MappingMixin):
    """Monocular mapping and tracking (003 §4). Feed grey images to :meth:`process`.

    The world frame is the first keyframe's camera frame; the map's scale is set by the
    initialisation (median depth 1 of the first map, SVO's convention): compare with ground
    truth after a Sim(3) alignment.

    Parameters
    ----------
    K : array_like, shape (3, 3)
        Intrinsic matrix of the (undistorted) camera.
    params : MonoParams, optional
        Settings (default: :class:`MonoParams`' values with their sources).
    **overrides
        Fields of :class:`MonoParams` to change (``MonoParams.resolve(params, **overrides)``).
    """

    def __init__(self, K, *, params: MonoParams | None = None, **overrides):
        self.K = as_matrix(K, "K", (3, 3))
        self.p = MonoParams.resolve(params, **overrides)
        p = self.p
        self.init = self._new_initialiser()
        self._last_idx = -1  # index of the last tracked (or initialised) frame
        self._steps: list[float] = []  # recent per-frame steps (map units) of tracked frames
        self._twists: list[np.ndarray] = []  # and their one-frame motions (se3_log of the velocity)
        self._reinit = None  # while re-initialising after a loss (ours): velocity, predicted poses, frame offset
        self.initialised = False
        self.keyframes: list[Keyframe] = []
        self._next_kf = 0
        self.points = np.zeros((0, 3))  # world positions of converged points
        self.point_kf = np.zeros(0, np.int64)  # their reference keyframe id
        self.point_uv = np.zeros((0, 2))  # their pixel in the reference keyframe
        self.point_fail = np.zeros(0, np.int64)
        self.seeds = init_seeds(np.zeros((0, 2)), np.zeros((0, 3)), 1.0, 1.0)
        self.seed_patches = np.zeros((0, p.patch_px**2))
        self.records: list[dict] = []
        self.counts: dict[str, int] = {}
        self._T_cw = np.eye(4)
        self._T_cw_prev = None
        self._prev_pyr = None
        self._prev_vis = np.zeros(0, np.int64)  # point indices seen in the previous frame
        self._prev_uv = np.zeros((0, 2))  # and where
        self._prev_img = None
        self._n_at_kf = 0
        self._since_kf = 0
        self._n_coast = 0  # frames lost since the last tracked one, coasting on the velocity
        self._T_show = None  # the pose reported for a lost frame when coasting
        self._diag: dict = {}  # the last frame's matched count and alignment residual
        self._shape = None  # (H, W) of the first frame: every frame must have it
        self._inlier_px = float(self.K[0, 0] * np.tan(np.deg2rad(p.reproj_inlier_deg)))
        self._px_angle = 2.0 * np.arctan(p.px_noise / (2.0 * self.K[0, 0]))

    # -- helpers ---------------------------------------------------------------------------
    def _new_initialiser(self) -> Initialiser:
        p = self.p
        return Initialiser(self.K, self._corners, min_corners=p.min_corners,
                           min_disparity_px=p.init_disparity_px, min_tracked_ratio=p.init_min_tracked,
                           method=p.init_method, ransac_px=p.init_ransac_px,
                           min_parallax_deg=p.init_min_parallax_deg,
                           min_point_parallax_deg=p.init_min_point_parallax_deg, plane_share=p.init_plane_share,
                           plane_share_of=p.init_plane_share_of)

    def _corners(self, image):
        from ..features.opencv import fast_cv

        return fast_cv(image, threshold=self.p.fast_threshold).uv

    def _count(self, key, n=1):
        self.counts[key] = self.counts.get(key, 0) + n

    def _kf(self, kf_id) -> Keyframe:
        for k in self.keyframes:
            if k.id == kf_id:
                return k
        raise KeyError(kf_id)

    # -- public ----------------------------------------------------------------------------
    def process(self, image) -> dict:
        """Process one grey frame; returns its record (status, pose, counts, stage times).

        Parameters
        ----------
        image : array_like, shape (H, W)
            Next grey frame, the size of the first one.

        Returns
        -------
        record : dict
            ``frame``, ``status``, ``tracked``, ``T_wc`` (4, 4), ``n_inliers``, ``n_matched``, ``align_rms``,
            ``n_points``, ``n_seeds``, ``n_keyframes``, ``times`` (seconds per stage).
        """
        image = as_image(image, "image")
        if image.ndim == 3:
            raise ValueError(f"`image` must be a grey image (H, W); got shape {image.shape}")
        if self.records and image.shape != self._shape:
            raise ValueError(f"`image` must have the size of the first frame {self._shape} (H, W); got {image.shape}")
        self._shape = image.shape
        times = dict.fromkeys(STAGES, 0.0)
        self._diag = {}
        idx = len(self.records)
        if not self.initialised:
            if self._reinit is not None:  # the pose predicted for this frame, and its place in the initialiser
                r = self._reinit
                r["T_pred"][idx] = orthonormalise(se3_compose(r["vel"], r["T_pred"][max(r["T_pred"])]))
                r["frames"].append(idx)
            status = self.init.add_frame(image)
            self._count(f"init_{status}")
            tracked = False
            n_inl = self._start_map(image, idx) if status == "done" else None
            if n_inl is not None:
                tracked = True
                status = "initialised"
            elif status == "done":
                status, n_inl = "reinit_rejected", 0
            elif self._reinit is not None:  # re-initialising: the pose moves on with the velocity
                self._T_show = self._reinit["T_pred"][idx]
            n_inl = n_inl or 0
        else:
            status, tracked, n_inl = self._track(image, idx, times)
        T_wc = se3_inverse(self._T_cw if self._T_show is None else self._T_show)
        rec = {"frame": idx, "status": status, "tracked": tracked, "T_wc": T_wc, "n_inliers": int(n_inl),
               "n_matched": self._diag.get("n_matched", 0), "align_rms": self._diag.get("align_rms", float("nan")),
               "n_points": len(self.points), "n_seeds": len(self.seeds), "n_keyframes": len(self.keyframes),
               "times": times}
        self.records.append(rec)
        return rec

    def run(self, frames, progress=False) -> MonoSLAM:
        """Process every frame of an iterable.

        Parameters
        ----------
        frames : iterable of ndarray
            Grey images.
        progress : bool, callable or None
            The one contract of :mod:`slamlab._progress`: a bar (True; None: unless ``$SLAMLAB_PROGRESS=0``),
            none (False, the default), or a callable ``progress(i)`` called after frame ``i``.

        Returns
        -------
        MonoSLAM
            ``self``.
        """
        from .._progress import progress_bar

        for img in progress_bar(frames, desc="mono SLAM", progress=progress):
            self.process(img)
        return self

    @property
    def trajectory(self) -> np.ndarray:
        """(N, 4, 4) camera-to-world poses of every frame (untracked frames keep the last pose)."""
        return np.array([r["T_wc"] for r in self.records]) if self.records else np.zeros((0, 4, 4))

    @property
    def tracked(self) -> np.ndarray:
        """(N,) True where the frame's pose was tracked (or initialised)."""
        return np.array([r["tracked"] for r in self.records], bool)

    def stage_times(self) -> dict:
        """Mean seconds per tracked frame of each stage."""
        recs = [r for r in self.records if r["status"] in ("tracked", "lost")] or self.records
        return {s: float(np.mean([r["times"][s] for r in recs])) if recs else 0.0 for s in STAGES}

    # -- tracking (003 §4.4) -------------------------------------------------------------------
    def _track(self, image, idx, times):
        p = self.p
        t0 = time.perf_counter()
        pyr = build_pyramid(image, p.align_max_level)
        h, w = image.shape
        # 1. motion prior: 003's constant velocity or SVO's constant position (our default, see MonoParams)
        T_prev = self._T_cw
        vel1, vel, T_pred = self._motion_prior()
        # 2. sparse direct alignment to the previous frame
        al = self._align(pyr, T_prev, vel, w, h)
        T_est = se3_compose(al.T_cur_ref, T_prev) if al.ok else T_pred
        if not al.ok:
            self._count("align_failed")
        # failure detection (ours): a photometric residual too large for the patches to be the same
        align_bad = al.ok and al.rms > p.max_align_rms
        t1 = time.perf_counter()
        times["align"] = t1 - t0
        # 3. project the map, refine each projection by LK from its keyframe
        cand, vis, uvp, uv_m, ok_m = self._match_map(image, T_est, w, h)
        t2 = time.perf_counter()
        times["match"] = t2 - t1
        # 4. motion-only refinement of the reprojection error
        mi = cand[ok_m]
        T_new, inl, n_inl = self._refine(T_est, mi, uv_m[ok_m])
        t3 = time.perf_counter()
        times["refine"] = t3 - t2
        self.point_fail[cand] += 1
        self.point_fail[mi[inl]] = 0
        self._diag = {"n_matched": int(mi.size), "align_rms": float(al.rms)}
        share_bad = n_inl < p.min_inlier_share * max(mi.size, 1)
        if n_inl < p.min_inliers or share_bad or align_bad or not np.all(np.isfinite(T_new)):
            return self._lost(image, idx, n_inl, share_bad, align_bad, vel1, T_prev, T_pred)
        self._accept(image, idx, pyr, vel1, T_new, mi[inl], uv_m[ok_m][inl])
        # mapping: the depth filter on this frame (003 §4.3.2)
        self._update_seeds(image, times)
        t4 = time.perf_counter()
        # keyframe rules (003 §4.3)
        self._since_kf += 1
        # points lost since the last keyframe: matched now vs matched then (003 §4.3)
        lost = 1.0 - n_inl / max(self._n_at_kf, 1)
        if (self._since_kf >= p.kf_min_frames and lost >= p.kf_lost_ratio) or lost > p.kf_max_lost_ratio:
            self._add_keyframe(image, idx, np.flatnonzero(vis), uvp[vis])
            self._n_at_kf = n_inl
        # drop points that keep failing (a simple outlier rejection, ours)
        bad = self.point_fail > p.max_seed_fail
        if bad.any() and p.outlier_rejection:
            self._count("points_dropped", int(bad.sum()))
            self._keep_points(~bad)
        times["keyframe"] = time.perf_counter() - t4
        return "tracked", True, n_inl

    def _motion_prior(self):
        """The last one-frame velocity ``vel1``, the velocity over the coasted frames, the predicted pose."""
        p = self.p
        T_prev = self._T_cw
        if self._T_cw_prev is None or p.motion_model == "constant_position":
            vel1 = np.eye(4)
        else:
            vel1 = se3_compose(T_prev, se3_inverse(self._T_cw_prev))
        vel = vel1  # motion from the last tracked frame: one velocity step per frame since (ours: coasting)
        for _ in range(self._n_coast):
            vel = se3_compose(vel1, vel)
        return vel1, vel, se3_compose(vel, T_prev)

    def _align(self, pyr, T_prev, vel, w, h):
        """Sparse direct alignment of the previous frame's visible map points to this frame (003 §4.4 step 1)."""
        p = self.p
        # every map point in view of the previous frame (at most align_max_points, spread; ours)
        X_prev = transform_points(T_prev, self.points)
        uv_prev = project(self.K, np.where(X_prev[:, 2:3] > 1e-6, X_prev, 1.0))
        in_prev = np.flatnonzero((X_prev[:, 2] > 1e-6) & (uv_prev[:, 0] >= 0) & (uv_prev[:, 0] < w)
                                 & (uv_prev[:, 1] >= 0) & (uv_prev[:, 1] < h))
        if in_prev.size > p.align_max_points:
            in_prev = self._select(in_prev, uv_prev[in_prev], w, h, p.align_max_points)
        X_prev = X_prev[in_prev]
        return sparse_align(self._prev_pyr, pyr, self.K, X_prev, vel, patch_px=p.align_patch_px,
                            max_level=p.align_max_level, min_level=p.align_min_level, max_iter=p.align_iters)

    def _match_map(self, image, T_est, w, h):
        """Project the map at ``T_est``; LK-refine each projection from its source (003 §4.4 step 3)."""
        p = self.p
        Xc = transform_points(T_est, self.points)
        front = Xc[:, 2] > 1e-6
        uvp = project(self.K, np.where(front[:, None], Xc, 1.0))
        mrg = p.match_win_px
        vis = front & (uvp[:, 0] >= mrg) & (uvp[:, 0] < w - mrg) & (uvp[:, 1] >= mrg) & (uvp[:, 1] < h - mrg)
        cand = np.flatnonzero(vis)
        if cand.size > p.max_matches:  # 003 §5.1.1: a cap on the matches
            cand = self._select(cand, uvp[cand], w, h, p.max_matches)
        uv_m = np.zeros((cand.size, 2))
        ok_m = np.zeros(cand.size, bool)
        # points seen in the previous frame: LK from there (small viewpoint change, ours); the others
        # from their reference keyframe (003 §4.4 step 3, unwarped patches)
        prev_pos = -np.ones(len(self.points), np.int64)
        prev_pos[self._prev_vis] = np.arange(self._prev_vis.size)
        pp = prev_pos[cand]
        sources = [(self._prev_img, np.flatnonzero(pp >= 0), self._prev_uv[pp[pp >= 0]])]
        for kf in self.keyframes:
            sel = np.flatnonzero((self.point_kf[cand] == kf.id) & (pp < 0))
            sources.append((kf.image, sel, self.point_uv[cand[sel]]))
        for src_img, sel, uv_src in sources:
            if sel.size == 0 or src_img is None:
                continue
            u1, ok = track_lk(src_img, image, uv_src, win_px=p.match_win_px, levels=2, uv1_guess=uvp[cand[sel]])
            ok &= np.linalg.norm(u1 - uvp[cand[sel]], axis=1) < 3 * p.match_win_px
            uv_m[sel], ok_m[sel] = u1, ok
        return cand, vis, uvp, uv_m, ok_m

    def _refine(self, T_est, mi, uv):
        """Motion-only refinement of the reprojection error of map points ``mi`` seen at ``uv`` (003 §4.4 step 4)."""
        p = self.p
        n_inl = 0
        T_new = T_est
        if mi.size >= p.min_inliers and p.refine:
            T_new, err, ok = refine_pose(self.K, self.points[mi], uv, T_est, huber_px=1.0, max_iter=p.refine_iters,
                                         reject_px=3.0 if p.outlier_rejection else None)
            inl = ok & (err < self._inlier_px) if ok else np.zeros(mi.size, bool)
            n_inl = int(inl.sum())
        elif mi.size >= p.min_inliers:  # no refinement: the alignment's pose, inliers counted there
            Xm = transform_points(T_est, self.points[mi])
            Xm[:, 2] = np.maximum(Xm[:, 2], 1e-6)
            err = np.linalg.norm(project(self.K, Xm) - uv, axis=1)
            inl = err < self._inlier_px
            n_inl = int(inl.sum())
        else:
            inl = np.zeros(mi.size, bool)
        return T_new, inl, n_inl

    def _lost(self, image, idx, n_inl, share_bad, align_bad, vel1, T_prev, T_pred):
        """A frame that failed the tracking tests: coast, start a new map, or wait (ours; counted)."""
        p = self.p
        self._count("lost")
        if n_inl >= p.min_inliers:
            self._count("lost_by_share" if share_bad else ("lost_by_photometric" if align_bad else "lost_nonfinite"))
        if self._T_cw_prev is not None and p.motion_model == "constant_velocity" and self._n_coast < p.max_coast:
            # coast (ours): report the predicted pose and keep the velocity for the next attempt
            self._n_coast += 1
            self._T_show = T_pred = orthonormalise(T_pred)
            self._count("coasted")
        elif p.reinit_when_lost and self._T_cw_prev is not None and p.motion_model == "constant_velocity":
            # ours: a new two-view map, anchored at the predicted pose with the velocity's scale
            # the step: median of the last tracked frames' steps (one velocity can be off)
            steps = self._steps[-5:] or [float(np.sqrt(np.sum(vel1[:3, 3] ** 2)))]
            # the velocity the new map is checked against and moves with: the mean one-frame motion of the
            # last `reinit_velocity_frames` tracked frames (ours: the last one alone can be off by 30°)
            if self._twists:
                vel1 = orthonormalise(se3_exp(np.mean(self._twists[-p.reinit_velocity_frames:], axis=0)))
                T_pred = orthonormalise(se3_compose(vel1, T_prev))
            # the new initialiser starts from the last tracked frame (its pose is known), so that this
            # frame can already complete it
            # the old map's points in the last tracked frame (the anchor): pixels and depths, for the scale
            z_old = transform_points(T_prev, self.points[self._prev_vis])[:, 2]
            self._reinit = {"vel": vel1, "T_pred": {self._last_idx: T_prev, idx: T_pred},
                            "frames": [self._last_idx, idx], "step": float(np.median(steps)),
                            "anchor": self._last_idx, "anchor_uv": self._prev_uv.copy(), "anchor_z": z_old}
            self.init = self._new_initialiser()
            self.init.add_frame(self._prev_img)
            st = self.init.add_frame(image)
            self.initialised = False
            self._T_show = T_pred
            self._count("reinit_started")
            if st == "done":
                n_new = self._start_map(image, idx)
                if n_new is not None:
                    return "initialised", True, n_new
        else:
            # keep the last pose; the next frame tries again from it (no motion prior)
            self._T_cw_prev = None
            self._n_coast = 0
            self._T_show = None
        return "lost", False, n_inl

    def _accept(self, image, idx, pyr, vel1, T_new, tracked_points, tracked_uv):
        """A tracked frame: the velocity, the step, the pose and the previous-frame state for the next frame."""
        if self._n_coast and self._T_cw_prev is not None:
            # back after coasting: keep the velocity of before (ours)
            self._T_cw_prev = se3_compose(se3_inverse(vel1), T_new)
        else:
            # a one-frame velocity needs two consecutive tracked frames
            self._T_cw_prev = self._T_cw if self.records and self.records[-1]["tracked"] else None
        self._n_coast = 0
        self._T_show = None
        if self.records and self.records[-1]["tracked"]:  # a step between two consecutive tracked frames
            v = se3_compose(T_new, se3_inverse(self._T_cw))
            d = v[:3, 3]
            self._steps = [*self._steps[-9:], float(np.sqrt(np.sum(d**2)))]
            self._twists = [*self._twists[-9:], se3_log(v)]
        self._T_cw = orthonormalise(T_new)
        self._last_idx = idx
        self._prev_pyr = pyr
        self._prev_vis = tracked_points
        self._prev_uv = tracked_uv
        self._prev_img = image
