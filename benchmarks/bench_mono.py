"""Benchmark Ch. 9 (003 §4, §5.5.2): monocular tracking at 768×576 and the depth-filter update.

1. Depth filter: one update of 10 000 seeds (goal ≤ 5 ms), ours (vectorised) vs the same
   update seed by seed in Python (a transcription of SVO's scalar ``updateSeed``); both must
   give the same numbers.
2. Tracking: :class:`slamlab.mono.MonoSLAM` on a rendered 768×576 arena sequence (003's rig),
   frames per second of tracking (align + match + refine; goal ≥ 15) and of the whole loop
   (tracking + mapping), per-stage times; beside it, a feature-based reference on the same
   frames: ``cv2.calcOpticalFlowPyrLK`` frame to frame + ``cv2.solvePnPRansac`` on the same map.

3. ``--kitti``: the monocular pipeline with its defaults on the shared KITTI 06 (51 frames) and KITTI 01
   (51 frames) sets: correct share and ATE against the goal (>= 80 %, <= 2 % of the path), frames/s.

    python benchmarks/bench_mono.py [--frames 40] [--kitti]
"""

from __future__ import annotations

import argparse
import math
import os
import platform
import time

import numpy as np

from slamlab.mono import depth_filter as df
from slamlab.mono.slam import STAGES, MonoSLAM
from slamlab.studies.mono.experiments import mono_sim, render_sequence, sequence_poses


def update_loop(mu, sigma2, a, b, x, tau2, rho_range):
    """SVO's updateSeed, one seed at a time (the reference)."""
    out = np.empty((4, mu.size))
    for i in range(mu.size):
        s_tot = math.sqrt(sigma2[i] + tau2[i])
        pdf = math.exp(-0.5 * ((x[i] - mu[i]) / s_tot) ** 2) / (math.sqrt(2 * math.pi) * s_tot)
        s2 = 1.0 / (1.0 / sigma2[i] + 1.0 / tau2[i])
        m = s2 * (mu[i] / sigma2[i] + x[i] / tau2[i])
        C1 = a[i] / (a[i] + b[i]) * pdf
        C2 = b[i] / (a[i] + b[i]) / rho_range[i]
        C1, C2 = C1 / (C1 + C2), C2 / (C1 + C2)
        ab = a[i] + b[i]
        f = C1 * (a[i] + 1) / (ab + 1) + C2 * a[i] / (ab + 1)
        e = C1 * (a[i] + 1) * (a[i] + 2) / ((ab + 1) * (ab + 2)) + C2 * a[i] * (a[i] + 1) / ((ab + 1) * (ab + 2))
        mu_new = C1 * m + C2 * mu[i]
        out[1, i] = C1 * (s2 + m * m) + C2 * (sigma2[i] + mu[i] ** 2) - mu_new**2
        out[0, i] = mu_new
        out[2, i] = (e - f) / (f - e / f)
        out[3, i] = out[2, i] * (1 - f) / f
    return out


def bench_filter(n=10_000, repeat=20):
    rng = np.random.default_rng(0)
    args = (rng.uniform(0.2, 1, n), rng.uniform(1e-4, 0.05, n), rng.uniform(5, 30, n), rng.uniform(5, 30, n),
            rng.uniform(0, 2, n), rng.uniform(1e-5, 1e-3, n), np.full(n, 2.0))
    t_ours = min(_time(lambda: df.update_seeds(*args)) for _ in range(repeat))
    t_ref = _time(lambda: update_loop(*args))
    ours = np.array(df.update_seeds(*args))
    ref = update_loop(*args)
    err = float(np.max(np.abs(ours - ref) / np.maximum(np.abs(ref), 1e-12)))
    print(f"depth filter, {n} seeds: ours {1e3 * t_ours:.2f} ms, per-seed loop {1e3 * t_ref:.1f} ms, "
          f"ratio {t_ref / t_ours:.0f}x, max relative difference {err:.1e}  (goal <= 5 ms)")


def _time(fn):
    t = time.perf_counter()
    fn()
    return time.perf_counter() - t


def bench_tracking(n_frames):
    import cv2

    sim = mono_sim("full", noise_std=1.0, rng=0)
    poses = sequence_poses("strafe", n_frames)
    imgs, _ = render_sequence(sim, poses, progress=False)
    K = sim.rig.left.K
    slam = MonoSLAM(K)
    wall = []
    for img in imgs:
        t = time.perf_counter()
        slam.process(img)
        wall.append(time.perf_counter() - t)
    recs = [r for r in slam.records if r["status"] in ("tracked", "lost")]
    st = {s: float(np.mean([r["times"][s] for r in recs])) for s in STAGES}
    t_track = st["align"] + st["match"] + st["refine"]
    t_all = float(np.mean([w for w, r in zip(wall, slam.records, strict=True) if r["status"] in ("tracked", "lost")]))
    print(f"tracking at {imgs.shape[2]}x{imgs.shape[1]}, {len(recs)} tracked frames of {n_frames}: "
          f"{1 / t_track:.1f} frames/s tracking (goal >= 15), {1 / t_all:.1f} frames/s with mapping")
    print("  per stage, ms: " + ", ".join(f"{s} {1e3 * v:.1f}" for s, v in st.items()))
    # reference: LK frame to frame + PnP RANSAC on the same map points
    T_cw = se3_from(slam.records[recs[0]["frame"] - 1]["T_wc"])
    prev = imgs[recs[0]["frame"] - 1]
    Xc = slam.points @ T_cw[:3, :3].T + T_cw[:3, 3]
    ok = Xc[:, 2] > 0
    uv = (Xc[ok, :2] / Xc[ok, 2:3]) * K[0, 0] + K[:2, 2]
    inside = (uv[:, 0] > 5) & (uv[:, 0] < imgs.shape[2] - 5) & (uv[:, 1] > 5) & (uv[:, 1] < imgs.shape[1] - 5)
    X, uv = slam.points[ok][inside][:120], uv[inside][:120].astype(np.float32)
    times = []
    for r in recs:
        img = imgs[r["frame"]]
        t = time.perf_counter()
        uv1, stt, _ = cv2.calcOpticalFlowPyrLK(prev, img, uv.reshape(-1, 1, 2), None, winSize=(11, 11), maxLevel=2)
        good = stt.ravel() == 1
        if good.sum() >= 6:
            cv2.solvePnPRansac(X[good], uv1.reshape(-1, 2)[good], K, None)
        times.append(time.perf_counter() - t)
        prev, uv, X = img, uv1.reshape(-1, 2)[good], X[good]
    t_ref = float(np.mean(times))
    print(f"  reference (cv2 LK + solvePnPRansac, {len(X)} points left): {1e3 * t_ref:.1f} ms/frame; "
          f"ours / reference = {t_track / t_ref:.1f}")


def se3_from(T_wc):
    from slamlab.geometry.se3 import se3_inverse

    return se3_inverse(T_wc)


def bench_kitti():
    from slamlab.data import find_data
    from slamlab.studies.mono.kitti import run_kitti_mono
    from slamlab.studies.mono.kitti_goal import kitti_goal_table

    runs = {}
    for label, name in (("KITTI 06", "kitti-odometry-06-stereo-51"), ("KITTI 01", "kitti-odometry-01-stereo")):
        t = time.perf_counter()
        runs[label] = run_kitti_mono(find_data(name))
        dt = time.perf_counter() - t
        print(f"  {label}: {len(runs[label].claimed)} frames in {dt:.1f} s ({len(runs[label].claimed) / dt:.1f} frames/s)")
    print(kitti_goal_table(runs))


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--frames", type=int, default=40)
    ap.add_argument("--kitti", action="store_true", help="also the KITTI 06 and 01 goal runs")
    args = ap.parse_args()
    os.environ.setdefault("SLAMLAB_PROGRESS", "0")
    print(f"machine: {platform.machine()}, {os.cpu_count()} cores, Python {platform.python_version()}, "
          f"load average {os.getloadavg()[0]:.2f} {os.getloadavg()[1]:.2f} {os.getloadavg()[2]:.2f}")
    bench_filter()
    bench_tracking(args.frames)
    if args.kitti:
        bench_kitti()
    print(f"load average after: {os.getloadavg()[0]:.2f}")


if __name__ == "__main__":
    main()
