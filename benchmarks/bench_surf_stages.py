"""Benchmark Ch. 2 (issue 17): our SURF stage by stage, beside OpenCV SIFT in the same process.

For graf img1 resized to 768x576 (threshold 4e-4, the ``bench_features.py`` case) the script prints,
best of ``--repeat`` runs each, the CPU time (``time.process_time``: all threads of the process) and the
wall time of every SURF stage with 1 and with 2 worker threads, the whole ``detect`` call (64-d
descriptors and keypoints only), OpenCV SIFT's time, and the ratios to SIFT. CPU times are the
figure to compare on a shared machine (other processes inflate wall times and SIFT's two threads
most); the load average is printed before and after.

``--before PATH`` also times another version of ``slamlab/features/surf.py`` (e.g. main's, from
``git show main:slamlab/features/surf.py > /tmp/surf_before.py``) on the same image in the same
process, and checks that it finds the same keypoints and descriptors; with ``--compare-all`` it
compares the two versions on images 1, 3 and 6 of every Oxford sequence at hand (full size) with
five settings (default, 128-d, upright, 5 octaves from step 1, threshold 1e-4) and on 20 renders of
the stereo arena (5 poses, left and right, with and without noise; 3 settings) and prints the largest
differences.

Usage: ``python benchmarks/bench_surf_stages.py [--repeat N] [--before PATH [--compare-all]]``.
"""

from __future__ import annotations

import argparse
import importlib.util
import os
import platform
import time

import cv2
import numpy as np

import slamlab.features as F
from slamlab.features import surf as S
from slamlab.features._padded_ii import PaddedIntegralImage
from slamlab.features.base import to_gray_float


def _load(path):
    spec = importlib.util.spec_from_file_location("slamlab.features._surf_other", path)
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def _stages(img, workers):
    """(name, cpu s, wall s) of each stage of one ``surf_detect`` (the same calls, timed apart)."""
    out = []
    c, w = time.process_time(), time.perf_counter()

    def mark(name):
        nonlocal c, w
        c1, w1 = time.process_time(), time.perf_counter()
        out.append((name, c1 - c, w1 - w))
        c, w = c1, w1

    g = to_gray_float(img)
    mark("grey")
    P = PaddedIntegralImage(image=g, workers=workers)
    II = P.II
    mark("padded integral image")
    ext = S.hessian_maxima(II, threshold=4e-4, n_octaves=4, init_step=2, workers=workers, _padded=P)
    mark("response maps + NMS + interp.")
    uv = np.column_stack([ext["u"], ext["v"]])
    sigma = 1.2 * ext["L"] / 9.0
    ori = S.surf_orientation(II, uv, sigma, _padded=P)
    mark("orientation")
    S.surf_describe(II, uv, sigma, ori, _padded=P)
    mark("descriptors (64-d)")
    return out


def compare_all(other):
    """Largest differences between our SURF and ``other``'s on the Oxford images at hand and arena renders."""
    settings = [({}, 4e-4), ({"extended": True}, 4e-4), ({"upright": True}, 4e-4),
                ({"n_octaves": 5, "init_step": 1}, 4e-4), ({}, 1e-4)]
    worst, n_sets, n_points = {"uv": 0.0, "orientation": 0.0, "response (rel.)": 0.0, "descriptor": 0.0}, 0, 0
    images = []
    for seq in F.OXFORD_SEQUENCES:
        for i in (1, 3, 6):
            try:
                images.append((f"{seq} img{i}", to_gray_float(F.load_oxford_image(seq, i)), settings))
            except (ValueError, FileNotFoundError):
                break
    from slamlab import sim  # the stereo arena's renders (flat fences and floor: ties in the orientation)

    for noise in (0.0, 2.0):
        rig = sim.StereoSim(sim.StereoArena(texture_seed=0), noise_std=noise, rng=0)
        for pose in ([2.0, 2.0, 0.3], [4.0, 3.0, 1.2], [3.0, 5.0, -2.0], [1.0, 1.0, 0.0], [4.5, 4.5, 2.5]):
            for side, im in zip("LR", rig.render_pair(pose), strict=True):
                images.append((f"arena {pose} {side}", to_gray_float(im), settings[2:3] + settings[0:1] + settings[4:]))
    for name, img, sets in images:
        for kw, thr in sets:
            a, b = F.surf_detect(img, thr, **kw), other.surf_detect(img, thr, **kw)
            n_sets += 1
            if len(a) != len(b) or not np.array_equal(a.octave, b.octave):
                print(f"  {name} {kw} {thr}: keypoint sets differ ({len(a)} vs {len(b)})")
                continue
            n_points += len(a)
            d_ori = np.angle(np.exp(1j * (a.orientation_rad - b.orientation_rad)))
            for k, d in (("uv", a.uv - b.uv), ("orientation", d_ori), ("response (rel.)", a.response / b.response - 1),
                         ("descriptor", a.descriptors - b.descriptors)):
                worst[k] = max(worst[k], float(np.abs(d).max(initial=0.0)))
    print(f"compared on {n_sets} (image, setting) pairs, {n_points} keypoints; largest differences: "
          + ", ".join(f"{k} {val:.1e}" for k, val in worst.items()) + "\n")


def best(fn, repeat):
    """(best CPU time, best wall time) over ``repeat`` calls."""
    bc = bw = np.inf
    for _ in range(repeat):
        c, w = time.process_time(), time.perf_counter()
        fn()
        bc, bw = min(bc, time.process_time() - c), min(bw, time.perf_counter() - w)
    return bc, bw


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--repeat", type=int, default=7)
    ap.add_argument("--before", help="another surf.py to time beside ours")
    ap.add_argument("--compare-all", action="store_true", help="with --before: same results on every sequence?")
    args = ap.parse_args()
    if args.before and args.compare_all:
        compare_all(_load(args.before))
    print(f"machine: {platform.machine()}, python {platform.python_version()}, numpy {np.__version__}, "
          f"opencv {cv2.__version__} ({cv2.getNumThreads()} threads); load average {os.getloadavg()[0]:.2f}")
    img = cv2.resize(F.load_oxford_image("graf", 1), (768, 576), interpolation=cv2.INTER_AREA)
    f = F.detect(img, "surf", threshold=4e-4)
    print(f"graf img1 768x576, threshold 4e-4: {len(f)} keypoints; best of {args.repeat}\n")

    print(f"{'stage':32s} {'CPU 1 thr':>10s} {'wall 1 thr':>11s} {'CPU 2 thr':>10s} {'wall 2 thr':>11s}  [ms]")
    per = {}
    for workers in (1, 2):
        for _ in range(args.repeat):
            for name, c, w in _stages(img, workers):
                bc, bw = per.get((name, workers), (np.inf, np.inf))
                per[name, workers] = (min(bc, c), min(bw, w))
    for name in dict.fromkeys(n for n, _ in per):
        (c1, w1), (c2, w2) = per[name, 1], per[name, 2]
        print(f"{name:32s} {1e3 * c1:10.1f} {1e3 * w1:11.1f} {1e3 * c2:10.1f} {1e3 * w2:11.1f}")

    cases = {
        "SIFT OpenCV (128-d)": lambda: F.detect(img, "sift"),
        "SURF ours 64-d, 2 threads": lambda: F.detect(img, "surf", threshold=4e-4),
        "SURF ours 64-d, 1 thread": lambda: F.detect(img, "surf", threshold=4e-4, workers=1),
        "SURF ours keypoints only": lambda: F.detect(img, "surf", threshold=4e-4, descriptors=False),
    }
    if args.before:
        other = _load(args.before)
        g = to_gray_float(img)
        fb = other.surf_detect(g, 4e-4)
        same = len(fb) == len(f) and np.array_equal(fb.octave, f.octave)
        dmax = float(np.abs(fb.descriptors - f.descriptors).max()) if same else float("nan")
        print(f"\n--before {args.before}: {len(fb)} keypoints, same set: {same}, "
              f"largest position difference {np.abs(fb.uv - f.uv).max() if same else float('nan'):.1e} px, "
              f"largest descriptor difference {dmax:.1e}")
        cases["SURF before 64-d (its default threads)"] = lambda: other.surf_detect(g, 4e-4)
        cases["SURF before keypoints only"] = lambda: other.surf_detect(g, 4e-4, descriptors=False)
    times = {}
    for _ in range(2):  # interleaved rounds: a load change hits every case
        for k, fn in cases.items():
            c, w = best(fn, (args.repeat + 1) // 2)
            bc, bw = times.get(k, (np.inf, np.inf))
            times[k] = (min(bc, c), min(bw, w))
    sc, sw = times["SIFT OpenCV (128-d)"]
    print(f"\n{'detector':40s} {'CPU [ms]':>9s} {'wall [ms]':>10s} {'CPU / SIFT':>11s} {'wall / SIFT':>12s}")
    for k, (c, w) in times.items():
        print(f"{k:40s} {1e3 * c:9.1f} {1e3 * w:10.1f} {c / sc:11.2f} {w / sw:12.2f}")
    print(f"\nload average after: {os.getloadavg()[0]:.2f}")


if __name__ == "__main__":
    main()
