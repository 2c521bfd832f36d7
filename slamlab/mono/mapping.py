"""The mapping half of :class:`~slamlab.mono.MonoSLAM` (003 §4.1-4.3): keyframes and the depth filter.

The first map from the initialiser, new keyframes with their seeds, the choice of seed pixels, the
pruning of map points and the depth-filter update of every seed. SDVL runs this in its own thread;
:class:`~slamlab.mono.MonoSLAM` runs it in turn with tracking (see :mod:`slamlab.mono.slam`). The
methods live on :class:`MappingMixin`, which ``MonoSLAM`` inherits; they use its state (``self.p``,
``self.seeds``, ``self.keyframes``, ...).
"""

from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np

from ..geometry.se3 import se3_compose, se3_inverse, transform_points
from ..geometry.so3 import rotation_angle, se3_exp, se3_log
from .align import build_pyramid, project
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

__all__ = ["Keyframe", "MappingMixin", "orthonormalise"]


def orthonormalise(T) -> np.ndarray:
    """``T`` with its rotation pulled back onto SO(3) by two Newton-Schulz steps ``R ← R (3I − RᵀR) / 2``
    (ours; einsum, no BLAS). A constant-velocity prior composes a pose with the inverse (the transpose)
    of the last one every frame: without this, a 1e-16 departure from orthonormality grows ~2.4× per frame.

    Parameters
    ----------
    T : array_like, shape (4, 4)
        Rigid transform whose rotation has drifted from SO(3).

    Returns
    -------
    T : ndarray, shape (4, 4)
        A copy with the rotation re-orthonormalised (translation unchanged).
    """
    T = np.array(T, dtype=np.float64)
    R = T[:3, :3]
    for _ in range(2):
        R = 0.5 * np.einsum("ij,jk->ik", R, 3.0 * np.eye(3) - np.einsum("ji,jk->ik", R, R))
    T[:3, :3] = R
    return T


@dataclass
class Keyframe:
    """A keyframe (003 §4.3): its id, frame index, pose ``T_cw`` (world → camera) and image.

    Attributes
    ----------
    id : int
        Keyframe number.
    frame : int
        Index of its frame in the sequence.
    T_cw : ndarray, shape (4, 4)
        Pose, world to camera.
    image : ndarray, shape (H, W)
        Its grey image.
    """

    id: int
    frame: int
    T_cw: np.ndarray
    image: np.ndarray

    @property
    def center(self) -> np.ndarray:
        return -np.einsum("ji,j->i", self.T_cw[:3, :3], self.T_cw[:3, 3])




class MappingMixin:
    """The mapping steps of :class:`~slamlab.mono.MonoSLAM` (003 §4.1-4.3): keyframes, seeds and map points.

    SDVL's mapping thread as methods of a mixin: :class:`~slamlab.mono.MonoSLAM` inherits them and holds
    the state they use (its settings ``p``, ``keyframes``, ``seeds``, ``points``...); not used on its own.
    """

    # -- initial map -------------------------------------------------------------------------
    def _start_map(self, image, idx):
        res = self.init.result
        R, t = res.pose.R, res.pose.t * res.scale
        X0 = res.X0
        T0 = np.eye(4)
        vel = None
        f0 = -1
        if self._reinit is not None:
            # ours: the new two-view map is placed at the pose predicted for its first frame and scaled
            # so that its baseline is the velocity's step times the frames between its two keyframes
            r = self._reinit
            f0, f1 = r["frames"][res.frame0], r["frames"][res.frame1]
            T0 = r["T_pred"][f0]
            vel = r["vel"]
            step = r["step"]
            # accept the new map only if its motion agrees with the prior (ours): translation direction
            # within 30° of the velocity's, rotation within 5° of the velocity's over the same frames
            pred = np.eye(4)
            for _ in range(f1 - f0):
                pred = se3_compose(vel, pred)
            tp, tn = pred[:3, 3], res.pose.t
            cos_t = float(np.sum(tp * tn)) / max(float(np.sqrt(np.sum(tp**2) * np.sum(tn**2))), 1e-12)
            dR = np.einsum("ij,kj->ik", R, pred[:3, :3])
            ang = float(np.degrees(rotation_angle(dR)))
            if cos_t < np.cos(np.deg2rad(30.0)) or ang > 5.0:
                self._count("reinit_rejected")
                self.init = self._new_initialiser()
                self.init.add_frame(image)
                r["frames"] = [idx]
                self._T_show = r["T_pred"][idx]
                return None
            s = step * (f1 - f0) / max(float(np.sqrt(np.sum(t**2))), 1e-12)
            s_map = self._map_scale(res, r) if f0 == r["anchor"] and self.p.reinit_scale == "map" else None
            if s_map is not None:
                s = s_map
                self._count("reinit_scaled_by_map")
            t, X0 = t * s, X0 * s
            self._count("reinitialised")
            self._reinit = None
            self._T_show = None
        kf0 = Keyframe(self._next_kf, f0 if vel is not None else idx - (res.frame1 - res.frame0), T0,
                       self.init.ref_image)
        T1 = np.eye(4)
        T1[:3, :3], T1[:3, 3] = R, t
        T1 = se3_compose(T1, T0)
        self.keyframes.append(kf0)
        self._next_kf += 1
        n_old = len(self.points)
        Xw = transform_points(se3_inverse(T0), X0)
        self.points = np.vstack([self.points, Xw])
        self.point_kf = np.concatenate([self.point_kf, np.full(len(X0), kf0.id, np.int64)])
        self.point_uv = np.vstack([self.point_uv, res.uv0])
        self.point_fail = np.concatenate([self.point_fail, np.zeros(len(X0), np.int64)])
        self._T_cw = T1 = orthonormalise(T1)
        self._last_idx = idx
        if vel is None and self.p.init_velocity:
            # ours: the first map's motion per frame, (T1 T0⁻¹)^(1/n) over its n frames, is the velocity of the
            # first tracked frame (a car moving ~1 m per frame leaves the alignment's reach from the last pose)
            n = max(res.frame1 - res.frame0, 1)
            vel = orthonormalise(se3_exp(se3_log(se3_compose(T1, se3_inverse(T0))) / n))
        self._T_cw_prev = None if vel is None else se3_compose(se3_inverse(vel), T1)
        self._n_coast = 0
        self._prev_pyr = build_pyramid(image, self.p.align_max_level)
        self._prev_vis = np.arange(n_old, len(self.points))
        self._prev_uv = res.uv1.copy()
        self._prev_img = image
        self.initialised = True
        self._add_keyframe(image, idx, np.arange(n_old, len(self.points)), res.uv1)
        self._n_at_kf = min(len(X0), self.p.max_matches)
        return len(X0)

    def _map_scale(self, res, r, *, max_px: float = 1.5, min_common: int = 10):
        """Scale of a new two-view map from the old map (ours): the median ratio of an old point's depth to the
        new point's at the same pixel (within ``max_px``) of the anchor frame, the last tracked one; ``None``
        with fewer than ``min_common`` such pairs.

        Brute-force pixel distances, element-wise in float64 (no BLAS: a pair at the threshold is decided the
        same way on every machine).
        """
        uv_old, z_old = r["anchor_uv"], r["anchor_z"]
        if len(uv_old) < min_common or len(res.uv0) < min_common:
            return None
        d2 = np.sum((res.uv0[:, None, :] - uv_old[None, :, :]) ** 2, axis=2)  # (new, old) squared px
        j = np.argmin(d2, axis=1)
        ok = (d2[np.arange(len(j)), j] <= max_px**2) & (res.X0[:, 2] > 1e-9) & (z_old[j] > 1e-9)
        if np.count_nonzero(ok) < min_common:
            return None
        return float(np.median(z_old[j[ok]] / res.X0[ok, 2]))

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
        while len(self.keyframes) > p.max_keyframes:
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
        keys = (cand, self.point_kf[cand], self.point_fail[cand])
        if self.p.prefer_seen:  # points matched in the previous frame first (ours)
            seen = np.zeros(len(self.points), bool)
            seen[self._prev_vis] = True
            keys = (*keys, ~seen[cand])
        order = np.lexsort((*keys, cell))
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
                                zncc_min=p.zncc_min, cur_patches=cur_patches,
                                img_ref=kf.image if p.warp_patches else None, uv_ref=s.uv[sel])
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
        self._converge_seeds(c_w)
        times["mapping"] = time.perf_counter() - t1

    def _converge_seeds(self, c_w):
        """Seeds that converged become map points, failed ones are dropped (003 §4.3.2 or SVO's test).

        ``c_w`` is the current camera centre in the world frame (the linearity test's viewing angle).
        """
        p = self.p
        s = self.seeds
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
