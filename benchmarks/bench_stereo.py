"""Benchmark Ch. 4: stereo SLAM frame rate and per-stage times at 768×576 (000 §3: 2-3 Hz).

Frames of the 360° turn in place are rendered first (rendering is not timed), then
:class:`slamlab.stereo.StereoSLAM` runs on them with each detector. Per stage we print
the mean wall time; the frame rate is given by wall clock and by this process's CPU
time (other jobs share this 2-core machine; OpenCV may use both cores, so CPU time can
exceed wall time). Two stages are also timed against an OpenCV reference in the same
process: midpoint triangulation vs ``cv2.triangulatePoints`` (DLT) and the exact store
query vs ``cv2.BFMatcher.knnMatch``.

    python benchmarks/bench_stereo.py                    # 30 frames, ORB, SIFT and our SURF
    python benchmarks/bench_stereo.py --drift            # + calibration drift on the loop (SURF, ~2 min)
    python benchmarks/bench_stereo.py --long             # + the ~80 m run of 000 §4.2 (slow)
    python benchmarks/bench_stereo.py --kitti            # + the 20 KITTI frames, issue 17's changes off (before) and on (after)
    python benchmarks/bench_stereo.py --kitti51          # + the 51-frame KITTI 06 set, issue 25's changes off and on
    python benchmarks/bench_stereo.py --detectors surf,orb --frames 2 --kitti-sets  # + KITTI 06 and 01: table, ablation
    python benchmarks/bench_stereo.py --highway --seeds 8  # + the scale ablation on the simulated highway (51 frames)
    python benchmarks/bench_stereo.py --detectors orb --frames 2 --conditions --seeds 3  # + the highway's scene conditions

Every run uses the pipeline's defaults (oldest-landmark policy; store: multi kd-tree for SURF/SIFT,
exact Hamming brute force for ORB; the two images detected in two threads). ORB's Hamming two-nearest
searches (stereo matching, the last frame's landmarks, the window search) and the sub-pixel disparity's patch
costs run compiled (numba); with ``SLAMLAB_NO_NUMBA=1`` they run the numpy versions (same results), for a row
beside the compiled one.
"""

from __future__ import annotations

import argparse
import os
import platform
import time

import cv2
import numpy as np

import slamlab as sl
from slamlab.stereo import STAGES, StereoSLAM, detect_features, stereo_match, triangulate_local

SOURCE_HZ = 2.5  # 000 §3, conclusions: "about 2.5 Hz on average"
GOAL_FPS = {"orb": 15.0, "sift": 3.0, "surf": 3.0}


def best_wall(fn, repeat=5):
    times, out = [], None
    for _ in range(repeat):
        t0 = time.perf_counter()
        out = fn()
        times.append(time.perf_counter() - t0)
    return min(times), out


def run_pipeline(frames, sim, detector):
    slam = StereoSLAM(sim.rig, sim.T_body_left, detector=detector, rng=0)
    c0, t0 = time.process_time(), time.perf_counter()
    for left, right in frames:
        slam.process(left, right)
    wall, cpu = time.perf_counter() - t0, time.process_time() - c0
    return slam, wall, cpu


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--frames", type=int, default=30)
    ap.add_argument("--detectors", default="orb,sift,surf")
    ap.add_argument("--drift", action="store_true", help="also run the calibration-drift study on the small loop")
    ap.add_argument("--long", action="store_true", help="also run the ~80 m path in the 10x12 m room")
    ap.add_argument("--kitti", action="store_true", help="also run the 20 KITTI frames with issue 17's changes off (before) and on (after)")
    ap.add_argument("--kitti51", action="store_true", help="also run the 51-frame KITTI 06 set, issue 25's changes off and on")
    ap.add_argument("--kitti-sets", action="store_true",
                    help="also run KITTI_PARAMS on KITTI 06 (51 frames) and KITTI 01 and the ablation of its last changes")
    ap.add_argument("--highway", action="store_true", help="also run the scale ablation on the simulated highway scene")
    ap.add_argument("--seeds", type=int, default=8, help="scenes per setting of --highway")
    ap.add_argument("--highway-frames", type=int, default=51, help="frames per run of --highway")
    ap.add_argument("--highway-noise", type=float, default=0.5, help="keypoint noise [px] of --highway's scene")
    ap.add_argument("--conditions", action="store_true",
                    help="also run the highway scene's conditions (noise, pyramid, disparity, vehicles, aliasing) x "
                         "{old defaults, KITTI_PARAMS}, --seeds scenes each")
    ap.add_argument("--markdown", default=None, help="write the tables to this file")
    args = ap.parse_args(argv)

    out = []

    def say(s=""):
        print(s)
        out.append(s)

    say(f"load average at start: {' '.join(f'{x:.2f}' for x in os.getloadavg())}")
    say(f"machine: {platform.processor() or platform.machine()}, {os.cpu_count()} cores, Python {platform.python_version()}, "
        f"numpy {np.__version__}, OpenCV {cv2.__version__}")  # fmt: skip
    arena = sl.sim.StereoArena(texture_seed=0)
    sim = sl.sim.StereoSim(arena, rng=0)
    poses = sl.sim.turn_in_place(np.deg2rad(5.0))[: args.frames]
    t_render, frames = best_wall(lambda: [sim.render_pair(p) for p in poses], repeat=1)
    say(f"render: {1000 * t_render / len(poses):.0f} ms per 768x576 stereo pair ({len(poses)} frames of the turn in place)")
    say()
    say("| detector | " + " | ".join(f"{s} ms" for s in STAGES) + " | frames/s (wall) | frames/s (CPU) | 000 | goal |")
    say("|---|" + "---|" * (len(STAGES) + 4))
    for det in args.detectors.split(","):
        slam, wall, cpu = run_pipeline(frames, sim, det)
        st = slam.stage_times()
        cells = [f"{1000 * st[s][1:].mean():.1f}" for s in STAGES]
        say(f"| {det} | " + " | ".join(cells) + f" | {len(frames) / wall:.2f} | {len(frames) / cpu:.2f} | {SOURCE_HZ} | {GOAL_FPS.get(det, '')} |")
    say()
    # stage micro-benchmarks against OpenCV, on one frame
    left, right = frames[len(frames) // 2]
    fl, fr = detect_features(left, detector="orb"), detect_features(right, detector="orb")
    sm = stereo_match(fl, fr, sim.rig)
    cloud = triangulate_local(sim.rig, fl, fr, sm)
    uvl, uvr = fl.uv[sm.left], fr.uv[sm.right]
    P1 = sim.rig.left.K @ np.hstack([np.eye(3), np.zeros((3, 1))])
    P2 = sim.rig.right.K @ np.hstack([sim.rig.R_rl, sim.rig.t_rl[:, None]])
    t_ours, _ = best_wall(lambda: sl.geometry.triangulate_stereo(sim.rig, uvl, uvr))
    t_cv, _ = best_wall(lambda: cv2.triangulatePoints(P1, P2, uvl.T.copy(), uvr.T.copy()))
    slam, *_ = run_pipeline(frames, sim, "orb")
    store = slam.store
    Q = fl.descriptors[cloud.left]
    t_store, _ = best_wall(lambda: store.query(Q, k=2), repeat=3)
    bf = cv2.BFMatcher(cv2.NORM_HAMMING)
    t_bf, _ = best_wall(lambda: bf.knnMatch(Q, store.points, k=2), repeat=3)
    say("| stage | ours ms | OpenCV ms | ratio |")
    say("|---|---|---|---|")
    say(f"| midpoint triangulation, {len(uvl)} matches (vs cv2.triangulatePoints) | {1000 * t_ours:.2f} | {1000 * t_cv:.2f} | {t_ours / t_cv:.2f} |")
    say(f"| exact store 2-NN, {len(Q)} queries x {len(store)} landmarks (vs BFMatcher.knnMatch) | {1000 * t_store:.1f} | {1000 * t_bf:.1f} | {t_store / t_bf:.2f} |")
    if args.drift:
        say()
        study = sl.studies.stereo.run_drift_study((0.0, 0.2e-3, 0.5e-3, 1e-3, 2e-3), "closed loop", rng=0)
        say("```")
        say(study.table())
        say("```")
    if args.long:
        say()
        room = sl.sim.StereoArena(10.0, 12.0, texture_seed=0)
        path = sl.sim.long_path(0.25, np.deg2rad(15.0))
        length_m = float(np.sum(np.hypot(*np.diff(path[:, :2], axis=0).T)))
        for det in args.detectors.split(","):
            t0 = time.perf_counter()
            variants = {"oldest": {"detector": det}, "all": {"detector": det, "policy": "all"}}
            if det == "orb":  # before issue 17: the global search, and before it also no sub-pixel disparity
                variants["oldest, global search (before the window search)"] = {"detector": det, "map_search": "global"}
                variants["oldest, before (global search, no sub-pixel disparity, no duplicate check)"] = {
                    "detector": det, "map_search": "global", "subpixel_stereo": False, "duplicate_gap_m": None}
            runs = sl.studies.stereo.run_stereo_slam_variants(path, variants, name="long path", arena=room, rng=0)
            for label, res in runs.items():
                say(f"long path ({length_m:.0f} m, {len(path)} frames), {det}, policy {label}: max position error "
                    f"{res.pos_err_m.max():.2f} m, final {res.pos_err_m[-1]:.2f} m, mean {res.pos_err_m.mean():.3f} m, "
                    f"max heading error {np.rad2deg(np.abs(res.yaw_err_rad).max()):.1f} deg, {len(res.degenerate)} "
                    f"degenerate frames; SLAM {res.fps:.2f} frames/s, map query "
                    f"{1000 * res.stage_time_s['map_match'][1:].mean():.0f} ms/frame, {res.counts['n_landmarks'][-1]} "
                    f"landmarks at the end ({np.median(res.counts['n_new'][1:]):.0f} new per frame, median)")  # fmt: skip
                say("    ms/frame: " + ", ".join(f"{s} {1000 * res.stage_time_s[s][1:].mean():.1f}" for s in STAGES))
            say(f"  ({time.perf_counter() - t0:.0f} s for these runs incl. rendering; load average "
                f"{' '.join(f'{x:.2f}' for x in os.getloadavg())})")
    if args.kitti:
        say()
        say("| KITTI 06, 20 frames | ATE m | SE(3)-aligned m | final m | path length est./true | start-end distance est./true "
            "| step est./true mean ± s.e. | sd |")
        say("|---|---|---|---|---|---|---|---|")
        for det in args.detectors.split(","):
            variants = [("before (keypoint disparities, 8 ORB levels)", {"subpixel_stereo": False, "duplicate_gap_m": None,
                                                                          "orb_levels": 8}),
                        ("refined disparities, 8 ORB levels", {"orb_levels": 8}), ("after (KITTI_PARAMS)", {})]
            for label, over in variants if det == "orb" else [("before", {"subpixel_stereo": False}), ("after", {})]:
                k = sl.studies.stereo.run_kitti(rng=0, detector=det, progress=False, **over)
                st = k.step_ratios
                say(f"| {det}, {label} | {k.ate_m:.3f} | {k.ate_se3_m:.3f} | {k.final_error_m:.3f} | "
                    f"{k.length_ratio:.4f} | {k.end_distance_ratio:.4f} | {st.mean():.4f} ± "
                    f"{st.std(ddof=1) / np.sqrt(st.size):.4f} | {st.std(ddof=1):.4f} |")
    if args.kitti51:
        say()
        folder = sl.data.find_data("kitti-odometry-06-stereo-51")
        for det in args.detectors.split(","):
            t0 = time.perf_counter()
            fix_off = sl.studies.stereo.PROPOSED_FIX_OFF
            variants = {"before (issue 25: global search, measured-depth weights)": {
                "detector": det, "map_search": "global", "weight_depth": "measured", "update_cov_depth": "measured",
                **fix_off},
                "stop 36 (KITTI_PARAMS without the stop-37 fix)": {"detector": det, **fix_off},
                "after (KITTI_PARAMS)": {"detector": det}}
            say("```")
            say(sl.studies.stereo.kitti_comparison(variants, folder))
            say("```")
            say(f"  ({det}: {time.perf_counter() - t0:.0f} s for both runs; load average "
                f"{' '.join(f'{x:.2f}' for x in os.getloadavg())})")
    if args.kitti_sets:
        say()
        t0 = time.perf_counter()
        dets = tuple(d for d in args.detectors.split(",") if d in ("surf", "orb"))
        say("```")
        runs = sl.studies.stereo.kitti_set_runs(sl.studies.stereo.KITTI_ABLATION, detectors=dets, rng=0)
        say(sl.studies.stereo.kitti_sets_table(runs))
        say()
        say(sl.studies.stereo.kitti_ablation_table(runs))
        say("```")
        say(f"  ({time.perf_counter() - t0:.0f} s; load average {' '.join(f'{x:.2f}' for x in os.getloadavg())})")
    if args.highway:
        say()
        t0 = time.perf_counter()
        abl = sl.studies.stereo.run_scale_ablation(lambda rng: sl.sim.HighwayScene(rng=rng), sl.sim.highway_path(args.highway_frames),
                                           n_seeds=args.seeds, pixel_std_obs=args.highway_noise, rng=0)
        say("```")
        say(abl.table(end=True))
        say("```")
        say(f"  ({time.perf_counter() - t0:.0f} s; load average {' '.join(f'{x:.2f}' for x in os.getloadavg())})")
    if args.conditions:
        from slamlab.sim.highway import HIGHWAY_CONDITIONS
        from slamlab.studies.stereo.scale_ablation import run_condition_ablation

        say()
        t0 = time.perf_counter()
        conds = {lab: ((lambda rng, kw=kw: sl.sim.HighwayScene(rng=rng, **kw)), sigma)
                 for lab, (kw, sigma) in HIGHWAY_CONDITIONS.items()}
        res = run_condition_ablation(conds, sl.sim.highway_path(args.highway_frames), n_seeds=args.seeds, rng=0)
        say("```")
        say(res.table())
        say("```")
        say(f"  ({time.perf_counter() - t0:.0f} s; load average {' '.join(f'{x:.2f}' for x in os.getloadavg())})")
    say(f"load average at end: {' '.join(f'{x:.2f}' for x in os.getloadavg())}")
    if args.markdown:
        with open(args.markdown, "w") as f:
            f.write("\n".join(out) + "\n")


if __name__ == "__main__":
    main()
