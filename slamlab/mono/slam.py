"""The monocular pipeline of 003 §4 (SDVL, after SVO) in one loop: :class:`MonoSLAM`.

Per frame: initialisation until two keyframes exist (003 §4.3.1); then tracking (003
§4.4: constant-velocity prior → sparse direct alignment to the previous frame → map
points projected and refined by Lucas-Kanade from their keyframe → motion-only
refinement), the depth filter of every seed (003 §4.2, §4.3.2) and the keyframe rules
(003 §4.3). SDVL runs tracking and mapping in two threads; we run them in turn (our
simplification: the results do not depend on thread timing). Bad input is counted in
:attr:`MonoSLAM.counts` and never raises or gives a NaN pose; a lost frame keeps the last
tracked pose and is marked ``tracked = False``.
"""

from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np

from .. import _validate as v
from ..geometry.se3 import se3_compose, se3_inverse, transform_points
from .align import build_pyramid, project, refine_pose, sparse_align
from .depth_filter import (
    Seeds,
    compute_tau,
    converged_linearity,
    converged_sigma,
    init_seeds,
    inlier_ratio,
    seed_points,
    tau_inverse,
    update_seeds,
)
from .epipolar import extract_patches, search_epipolar
from .initialise import Initialiser, track_lk
from .params import MonoParams

__all__ = ["STAGES", "Keyframe", "MonoSLAM"]

#: timed stages of a frame: tracking = align + match + refine
STAGES = ("detect", "align", "match", "refine", "mapping", "keyframe")


@dataclass
class Keyframe:
    """A keyframe (003 §4.3): its id, frame index, pose ``T_cw`` (world → camera) and image."""

    id: int
    frame: int
    T_cw: np.ndarray
    image: np.ndarray

    @property
    def center(self) -> np.ndarray:
        return -np.einsum("ji,j->i", self.T_cw[:3, :3], self.T_cw[:3, 3])


class MonoSLAM:
    """Monocular mapping and tracking (003 §4). Feed grey images to :meth:`process`.

    Parameters
    ----------
    K : (3, 3) intrinsic matrix of the (undistorted) camera.
    params : :class:`MonoParams` (default values with their sources).

    The world frame is the first keyframe's camera frame; the map's scale is set by the
    initialisation (median depth 1 of the first map, SVO's convention): compare with ground
    truth after a Sim(3) alignment.
    """

    def __init__(self, K, *, params: MonoParams | None = None, **overrides):
        self.K = v.as_matrix(K, "K", (3, 3))
        self.p = MonoParams.resolve(params, **overrides)
        p = self.p
        self.init = Initialiser(self.K, self._corners, min_corners=p.min_corners,
                                min_disparity_px=p.init_disparity_px, min_tracked_ratio=p.init_min_tracked,
                                method=p.init_method, ransac_px=p.init_ransac_px,
                                min_parallax_deg=p.init_min_parallax_deg)
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
        self._shape = None  # (H, W) of the first frame: every frame must have it
        self._px_angle = 2.0 * np.arctan(p.px_noise / (2.0 * self.K[0, 0]))

    # -- helpers ---------------------------------------------------------------------------
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
        """Process one grey frame; returns its record (status, pose, counts, stage times)."""
        image = v.as_image(image, "image")
        if image.ndim == 3:
            raise ValueError(f"`image` must be a grey image (H, W); got shape {image.shape}")
        if self.records and image.shape != self._shape:
            raise ValueError(f"`image` must have the size of the first frame {self._shape} (H, W); got {image.shape}")
        self._shape = image.shape
        times = dict.fromkeys(STAGES, 0.0)
        idx = len(self.records)
        if not self.initialised:
            status = self.init.add_frame(image)
            self._count(f"init_{status}")
            tracked = False
            n_inl = 0
            if status == "done":
                self._start_map(image, idx)
                tracked = True
                n_inl = len(self.points)
                status = "initialised"
        else:
            status, tracked, n_inl = self._track(image, idx, times)
        T_wc = se3_inverse(self._T_cw)
        rec = {"frame": idx, "status": status, "tracked": tracked, "T_wc": T_wc, "n_inliers": int(n_inl),
               "n_points": len(self.points), "n_seeds": len(self.seeds), "n_keyframes": len(self.keyframes),
               "times": times}
        self.records.append(rec)
        return rec

    def run(self, frames, progress=None) -> MonoSLAM:
        """Process every frame of an iterable (``progress``: an optional wrapper such as a tqdm bar)."""
        it = frames if progress is None else progress(frames)
        for img in it:
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

    # -- initial map -------------------------------------------------------------------------
    def _start_map(self, image, idx):
        res = self.init.result
        R, t = res.pose.R, res.pose.t * res.scale
        kf0 = Keyframe(self._next_kf, res.frame0, np.eye(4), self.init.ref_image)
        T1 = np.eye(4)
        T1[:3, :3], T1[:3, 3] = R, t
        self.keyframes.append(kf0)
        self._next_kf += 1
        self.points = res.X0.copy()
        self.point_kf = np.full(len(res.X0), kf0.id, np.int64)
        self.point_uv = res.uv0.copy()
        self.point_fail = np.zeros(len(res.X0), np.int64)
        self._T_cw = T1
        self._T_cw_prev = None
        self._prev_pyr = build_pyramid(image, self.p.align_max_level)
        self._prev_vis = np.arange(len(self.points))
        self._prev_uv = res.uv1.copy()
        self._prev_img = image
        self.initialised = True
        self._add_keyframe(image, idx, np.arange(len(self.points)), res.uv1)
        self._n_at_kf = min(len(self.points), self.p.max_matches)

    def _add_keyframe(self, image, idx, vis_idx, vis_uv):
        p = self.p
        kf = Keyframe(self._next_kf, idx, self._T_cw.copy(), image)
        self._next_kf += 1
        self.keyframes.append(kf)
        self._count("keyframes")
        # seeds on FAST corners away from the points already seen (003 §4.3: unexplored areas)
        from ..features.opencv import fast_cv

        F = fast_cv(image, threshold=p.fast_threshold)
        uv, resp = F.uv, F.response
        h, w = image.shape
        m = p.patch_px
        keep = (uv[:, 0] >= m) & (uv[:, 0] < w - m) & (uv[:, 1] >= m) & (uv[:, 1] < h - m)
        if len(vis_uv):
            occ = np.zeros((h // 8 + 1, w // 8 + 1), bool)
            q = np.clip((np.asarray(vis_uv) // 8).astype(int), 0, [w // 8, h // 8])
            occ[q[:, 1], q[:, 0]] = True
            keep &= ~occ[(uv[:, 1] // 8).astype(int), (uv[:, 0] // 8).astype(int)]
        uv, resp = uv[keep], resp[keep]
        order = np.argsort(-resp, kind="stable")[: p.max_seeds_per_kf]
        uv = uv[order]
        Xc = transform_points(kf.T_cw, self.points[vis_idx]) if len(vis_idx) else np.zeros((0, 3))
        z = Xc[:, 2][Xc[:, 2] > 0] if len(Xc) else np.zeros(0)
        depth_mean = float(np.median(z)) if z.size else 1.0
        depth_min = float(np.min(z)) if z.size else 0.5
        if len(uv):
            f = np.column_stack([(uv[:, 0] - self.K[0, 2]) / self.K[0, 0], (uv[:, 1] - self.K[1, 2]) / self.K[1, 1],
                                 np.ones(len(uv))])
            new = init_seeds(uv, f, depth_mean, max(depth_min, 1e-3), ref=kf.id)
            self.seeds = Seeds.concat([self.seeds, new])
            self.seed_patches = np.vstack([self.seed_patches, extract_patches(image, uv, p.patch_px)])
        self._n_at_kf = len(vis_idx)
        self._since_kf = 0
        # cap: drop the keyframe farthest from the current position (003 §4.3)
        if len(self.keyframes) > p.max_keyframes:
            c = kf.center
            far = max(self.keyframes[:-1], key=lambda k: float(np.linalg.norm(k.center - c)))
            self.keyframes.remove(far)
            self._count("keyframes_dropped")
            keep_p = self.point_kf != far.id
            self._keep_points(keep_p)
            keep_s = self.seeds.ref != far.id
            self.seeds = self.seeds.take(keep_s)
            self.seed_patches = self.seed_patches[keep_s]

    def _select(self, cand, uv, w, h, n):
        """``n`` of the candidate points spread over an 8×6 grid, round robin over the cells; in a
        cell the fewest recent failures first, then the oldest keyframe (ours)."""
        cell = (np.clip((uv[:, 1] * 6 / h).astype(int), 0, 5) * 8 + np.clip((uv[:, 0] * 8 / w).astype(int), 0, 7))
        order = np.lexsort((cand, self.point_kf[cand], self.point_fail[cand], cell))
        c_sorted = cell[order]
        first = np.searchsorted(c_sorted, c_sorted, side="left")
        rank = np.arange(order.size) - first
        pick = order[np.lexsort((c_sorted, rank))[:n]]
        return np.sort(cand[pick])

    def _keep_points(self, keep):
        old = np.flatnonzero(keep)
        remap = -np.ones(len(self.points), np.int64)
        remap[old] = np.arange(old.size)
        self.points, self.point_kf = self.points[keep], self.point_kf[keep]
        self.point_uv, self.point_fail = self.point_uv[keep], self.point_fail[keep]
        pv = remap[self._prev_vis]
        self._prev_vis, self._prev_uv = pv[pv >= 0], self._prev_uv[pv >= 0]

    # -- tracking (003 §4.4) -------------------------------------------------------------------
    def _track(self, image, idx, times):
        p = self.p
        t0 = time.perf_counter()
        pyr = build_pyramid(image, p.align_max_level)
        h, w = image.shape
        # 1. motion prior: 003's constant velocity or SVO's constant position (our default, see MonoParams)
        T_prev = self._T_cw
        if self._T_cw_prev is None or p.motion_model == "constant_position":
            vel = np.eye(4)
        else:
            vel = se3_compose(T_prev, se3_inverse(self._T_cw_prev))
        T_pred = se3_compose(vel, T_prev)
        # 2. sparse direct alignment to the previous frame
        # every map point in view of the previous frame (at most align_max_points, spread; ours)
        X_prev = transform_points(T_prev, self.points)
        uv_prev = project(self.K, np.where(X_prev[:, 2:3] > 1e-6, X_prev, 1.0))
        in_prev = np.flatnonzero((X_prev[:, 2] > 1e-6) & (uv_prev[:, 0] >= 0) & (uv_prev[:, 0] < w)
                                 & (uv_prev[:, 1] >= 0) & (uv_prev[:, 1] < h))
        if in_prev.size > p.align_max_points:
            in_prev = self._select(in_prev, uv_prev[in_prev], w, h, p.align_max_points)
        X_prev = X_prev[in_prev]
        al = sparse_align(self._prev_pyr, pyr, self.K, X_prev, vel, patch_px=p.align_patch_px,
                          max_level=p.align_max_level, min_level=p.align_min_level, max_iter=p.align_iters)
        T_est = se3_compose(al.T_cur_ref, T_prev) if al.ok else T_pred
        if not al.ok:
            self._count("align_failed")
        t1 = time.perf_counter()
        times["align"] = t1 - t0
        # 3. project the map, refine each projection by LK from its keyframe
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
        t2 = time.perf_counter()
        times["match"] = t2 - t1
        # 4. motion-only refinement of the reprojection error
        mi = cand[ok_m]
        n_inl = 0
        T_new = T_est
        if mi.size >= p.min_inliers:
            T_new, err, ok = refine_pose(self.K, self.points[mi], uv_m[ok_m], T_est, huber_px=1.0)
            inl = ok & (err < p.reproj_inlier_px) if ok else np.zeros(mi.size, bool)
            n_inl = int(inl.sum())
        else:
            inl = np.zeros(mi.size, bool)
        t3 = time.perf_counter()
        times["refine"] = t3 - t2
        self.point_fail[cand] += 1
        self.point_fail[mi[inl]] = 0
        if n_inl < p.min_inliers or not np.all(np.isfinite(T_new)):
            self._count("lost")
            # keep the last pose; the next frame tries again from it (no motion prior)
            self._T_cw_prev = None
            return "lost", False, n_inl
        # a one-frame velocity needs two consecutive tracked frames
        self._T_cw_prev = self._T_cw if self.records and self.records[-1]["tracked"] else None
        self._T_cw = T_new
        self._prev_pyr = pyr
        self._prev_vis = mi[inl]
        self._prev_uv = uv_m[ok_m][inl]
        self._prev_img = image
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
        if bad.any():
            self._count("points_dropped", int(bad.sum()))
            self._keep_points(~bad)
        times["keyframe"] = time.perf_counter() - t4
        return "tracked", True, n_inl

    def _update_seeds(self, image, times):
        p = self.p
        if len(self.seeds) == 0:
            return
        t0 = time.perf_counter()
        from ..features.opencv import fast_cv

        corners = fast_cv(image, threshold=p.fast_threshold).uv
        h, w = image.shape
        mg = (p.patch_px + 1) / 2.0 + 1
        corners = corners[(corners[:, 0] >= mg) & (corners[:, 0] < w - mg) & (corners[:, 1] >= mg) & (corners[:, 1] < h - mg)]
        cur_patches = extract_patches(image, corners, p.patch_px)
        t1 = time.perf_counter()
        times["detect"] = t1 - t0
        s = self.seeds
        T_cw = self._T_cw
        c_w = -np.einsum("ji,j->i", T_cw[:3, :3], T_cw[:3, 3])
        found_all = np.zeros(len(s), bool)
        tried = np.zeros(len(s), bool)
        for kf in self.keyframes:
            sel = np.flatnonzero(s.ref == kf.id)
            if sel.size == 0:
                continue
            T_cur_ref = se3_compose(T_cw, se3_inverse(kf.T_cw))
            # visible: the mean-depth point projects into the image
            Xm = transform_points(T_cur_ref, s.f[sel] / np.maximum(s.mu[sel], 1e-6)[:, None])
            uvm = project(self.K, np.where(Xm[:, 2:3] > 1e-6, Xm, 1.0))
            h, w = image.shape
            visible = (Xm[:, 2] > 1e-6) & (uvm[:, 0] >= 0) & (uvm[:, 0] < w) & (uvm[:, 1] >= 0) & (uvm[:, 1] < h)
            sel = sel[visible]
            if sel.size == 0:
                continue
            m = search_epipolar(self.K, T_cur_ref, s.f[sel], s.mu[sel], np.sqrt(s.sigma2[sel]), self.seed_patches[sel],
                                image, corners, n_sigma=p.n_sigma, tol_px=p.epi_tol_px, patch_px=p.patch_px,
                                zncc_min=p.zncc_min, cur_patches=cur_patches)
            tried[sel] = True
            fi = sel[m.found]
            if fi.size:
                t_ref_cur = se3_inverse(T_cur_ref)[:3, 3]
                z = m.depth_m[m.found]
                tau = compute_tau(t_ref_cur, s.f[fi], z, self._px_angle)
                good = np.isfinite(tau)
                fi, z, tau = fi[good], z[good], tau[good]
                ti = tau_inverse(z, tau)
                s.mu[fi], s.sigma2[fi], s.a[fi], s.b[fi] = update_seeds(
                    s.mu[fi], s.sigma2[fi], s.a[fi], s.b[fi], 1.0 / z, ti**2, s.rho_range[fi])
                s.n_obs[fi] += 1
                s.n_fail[fi] = 0
                found_all[fi] = True
        miss = tried & ~found_all
        s.b[miss] += 1.0  # SVO: a failed search counts as an outlier
        s.n_fail[miss] += 1
        self._count("seed_updates", int(found_all.sum()))
        self._count("seed_misses", int(miss.sum()))
        # convergence (003 §4.3.2 or SVO) and removal
        T_wr = {k.id: se3_inverse(k.T_cw) for k in self.keyframes}
        ids = sorted(T_wr)
        lut = np.full(max(ids) + 1, -1, np.int64)
        lut[ids] = np.arange(len(ids))
        T_stack = np.array([T_wr[i] for i in ids])
        sk = Seeds(**{**s.__dict__, "ref": lut[s.ref]})
        X = seed_points(sk, T_stack)
        if p.convergence == "sigma":
            conv = converged_sigma(s.sigma2, s.rho_range, p.sigma_fraction)
        else:
            ray_w = np.einsum("nij,nj->ni", T_stack[sk.ref][:, :3, :3], s.f)
            dvec = X - c_w
            d = np.linalg.norm(dvec, axis=1)
            cos_a = np.sum(ray_w * dvec, axis=1) / np.maximum(d, 1e-12)
            conv = converged_linearity(s.mu, s.sigma2, d, cos_a, p.L_max)
        conv &= s.n_obs >= 1
        drop = (s.n_fail >= p.max_seed_fail) | (inlier_ratio(s.a, s.b) < p.min_inlier_ratio) | ~np.isfinite(s.mu)
        if conv.any():
            self.points = np.vstack([self.points, X[conv]])
            self.point_kf = np.concatenate([self.point_kf, s.ref[conv]])
            self.point_uv = np.vstack([self.point_uv, s.uv[conv]])
            self.point_fail = np.concatenate([self.point_fail, np.zeros(int(conv.sum()), np.int64)])
            self._count("seeds_converged", int(conv.sum()))
        self._count("seeds_dropped", int((drop & ~conv).sum()))
        keep = ~(conv | drop)
        self.seeds = s.take(keep)
        self.seed_patches = self.seed_patches[keep]
        times["mapping"] = time.perf_counter() - t1
