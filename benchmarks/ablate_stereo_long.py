"""Ablations of the stereo pipeline on the ~80 m run of ``bench_stereo.py --long`` (000 §4.2).

The 401 stereo pairs are rendered once into ``--cache`` (2 × 177 MB of .npy) with the same
seeds as :func:`slamlab.studies.stereo.run_stereo_slam_variants` (``rng=0``), so a variant here gives
the same trajectory as that variant in ``bench_stereo.py --long``; each variant is one
``label=JSON`` argument of :class:`slamlab.stereo.StereoParams` overrides. Run several
processes side by side to use both cores.

    python benchmarks/ablate_stereo_long.py 'before={"detector": "orb", "subpixel_stereo": false}' \\
        'after={"detector": "orb"}'
    python benchmarks/ablate_stereo_long.py --heading-frames 5 'orb={"detector": "orb"}' \\
        'orb, constant velocity={"detector": "orb", "degenerate_pose": "constant_velocity"}'

The key ``"numba": false`` in a variant's JSON runs it without the compiled kernels (the numpy path), e.g.
``'numpy={"detector": "orb", "numba": false}' 'compiled={"detector": "orb"}'``.
``--heading-frames DEG`` prints, per variant, the frames whose heading error exceeds DEG with what the
pipeline did on them (:func:`slamlab.studies.stereo.heading_frames`).
"""

from __future__ import annotations

import argparse
import json
import os
import time
from pathlib import Path

import numpy as np

import slamlab as sl
from slamlab.geometry import wrap_angle
from slamlab.geometry.se3 import planar_from_se3, se3_from_planar, se3_inverse
from slamlab.stereo import STAGES, RenderParams, StereoParams, StereoSLAM


def load(n_frames, cache: Path):
    path = sl.sim.long_path(0.25, np.deg2rad(15.0))
    room = sl.sim.StereoArena(10.0, 12.0, texture_seed=0)
    render = RenderParams()
    r_sim, r_slam = np.random.SeedSequence(0).spawn(2)  # as run_stereo_slam_variants(rng=0)
    sim = sl.sim.StereoSim(room, None, camera_height_m=render.camera_height_m, noise_std=render.noise_std,
                           drift_std_rad=render.drift_std_rad, rng=np.random.default_rng(r_sim))
    fl, fr = cache / "long_left.npy", cache / "long_right.npy"
    if not (fl.exists() and fr.exists()):
        cache.mkdir(parents=True, exist_ok=True)
        pairs = [sim.render_pair(p) for p in path]
        np.save(fl, np.array([p[0] for p in pairs]))
        np.save(fr, np.array([p[1] for p in pairs]))
    n = len(path) if n_frames is None else n_frames
    return path[:n], sim, np.load(fl, mmap_mode="r"), np.load(fr, mmap_mode="r"), r_slam


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("variants", nargs="+", help="label=JSON overrides of StereoParams")
    ap.add_argument("--frames", type=int, default=None, help="first frames only (default: all 401)")
    ap.add_argument("--cache", type=Path, default=Path("/tmp/slamlab-stereo-long"))
    ap.add_argument("--heading-frames", type=float, default=None, metavar="DEG",
                    help="list the frames whose heading error exceeds DEG and what the pipeline did on them")
    args = ap.parse_args(argv)
    path, sim, L, R, r_slam = load(args.frames, args.cache)
    T0_inv = se3_inverse(se3_from_planar(*path[0]))
    truth = np.array([planar_from_se3(T0_inv @ se3_from_planar(*p)) for p in path])
    truth[:, 2] = path[:, 2] - path[0, 2]
    length_m = float(np.sum(np.hypot(*np.diff(path[:, :2], axis=0).T)))
    no_numba = os.environ.get("SLAMLAB_NO_NUMBA", "")
    for arg in args.variants:
        label, _, js = arg.partition("=")
        over = json.loads(js) if js else {}
        # "numba": false runs this variant on the numpy path (SLAMLAB_NO_NUMBA=1), for a row beside the compiled one
        os.environ["SLAMLAB_NO_NUMBA"] = no_numba if over.pop("numba", True) else "1"
        p = StereoParams(**over)
        slam = StereoSLAM(sim.rig, sim.T_body_left, params=p, rng=np.random.default_rng(r_slam))
        load0 = os.getloadavg()[0]
        wall = cpu = 0.0
        for i in range(len(path)):
            left, right = np.asarray(L[i]), np.asarray(R[i])
            t0, c0 = time.perf_counter(), time.process_time()
            slam.process(left, right)
            wall += time.perf_counter() - t0
            cpu += time.process_time() - c0
        est = slam.planar_trajectory
        err = np.hypot(*(est[:, :2] - truth[:, :2]).T)
        yaw = np.rad2deg(np.abs(wrap_angle(est[:, 2] - truth[:, 2])))
        c, st, sc = slam.counts(), slam.stage_times(), slam.stage_times(cpu=True)
        print(f"long path ({length_m:.0f} m, {len(path)} frames), {label} ({p.detector}, policy {p.policy}): max position "
              f"error {err.max():.2f} m (frame {int(err.argmax())}), final {err[-1]:.2f} m, mean {err.mean():.3f} m, max "
              f"heading error {yaw.max():.1f} deg, {len(slam.degenerate_frames)} degenerate frames; SLAM {len(path) / wall:.2f} "
              f"frames/s wall, {len(path) / cpu:.2f} frames/s CPU, map query {1000 * st['map_match'][1:].mean():.0f} ms/frame; "
              f"{c['n_landmarks'][-1]} landmarks at the end ({len(slam.X)} ever added, {np.median(c['n_new'][1:]):.0f} new "
              f"per frame (median)); load average {load0:.2f} -> {os.getloadavg()[0]:.2f}", flush=True)
        print(f"  {label}: ms/frame wall (CPU): " + ", ".join(
            f"{s} {1000 * st[s][1:].mean():.1f} ({1000 * sc[s][1:].mean():.1f})" for s in STAGES)
            + f"; landmarks searched {c['n_searched'][1:].mean():.0f} per frame (mean), "
              f"{int(c['gate_fallback'].sum())} whole-map fallbacks, {int(c['window_fallback'].sum())} window "
              f"fallbacks, {c['n_compared'][1:].mean() / 1e6:.2f} M descriptor distances per frame (mean)", flush=True)
        if args.heading_frames is not None:
            print(sl.studies.stereo.heading_frames(slam, truth, args.heading_frames), flush=True)


if __name__ == "__main__":
    main()
