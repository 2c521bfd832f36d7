"""Benchmark: slamlab's polar Hough transform (004 eq. (7)) vs ``cv2.HoughLines`` on the rasterised scan.

Scans of 1081 beams over 270° (a Hokuyo UTM-30LX layout) cast in a simulated room, at
Δθ = 1° and the same rho resolution for both: the scan is rasterised with a cell equal to
Δrho and OpenCV runs on that image with ``rho = 1`` pixel. For each case the script prints
ours and the reference measured in the same process, and their ratio (reference / ours:
> 1 means ours is faster). Cases:

* ``polar transform`` vs ``cv2.HoughLines`` alone (OpenCV also finds and sorts peaks);
* ``polar transform + find_peaks`` vs ``rasterise + cv2.HoughLines`` (scan in, lines out);
* both of ours on the numpy path (``SLAMLAB_NO_NUMBA=1``) and with the compiled kernels (issue 25), and
  once the first-call time of the kernels in a new process, compiling and loaded from the cache;
* the classic transform of 004 (ours, numpy) vs OpenCV on the same image.

With ``--real-logs`` it runs instead Hough SLAM on every shared real log (``SHARED_LOGS``) and its ablation
(``ablate_real_logs``): per change and log, the sharpness 1 - (obstacle cells per 100 returns, Hough SLAM map) /
(the same, odometry map), against the log's odometry and the re-timed one, and the causes of the steps on odometry alone.

Usage: ``python benchmarks/bench_hough.py [--repeat N] [--real-logs]``.
"""

from __future__ import annotations

import argparse
import math
import os
import platform
import time

import cv2
import numpy as np

import slamlab.hough as h
import slamlab.studies.hough as sh
from slamlab import sim


def best_time(fn, repeat):
    fn()
    times = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t0)
    return float(np.median(times))


def make_scans(n_scans=5, n_beams=1081, cell_m=0.05, max_range_m=30.0, rng=0):
    """Scans of the 200×200 test room scaled to 1 cell = 5 cm (a 10 m room), with 1 cm noise."""
    room = sim.test_room_200()
    rng = np.random.default_rng(rng)
    rf = sim.Rangefinder(n_beams=n_beams, fov_rad=math.radians(270.0), max_range_cells=max_range_m / cell_m,
                         range_std_cells=0.2, quantum_cells=0.0)
    poses = sim.random_free_poses(room, n_scans, margin_cells=5, rng=rng)
    out = []
    for p in poses:
        s = rf.scan(room, p, rng)
        out.append((s.bearings_rad[s.valid], s.ranges[s.valid] * cell_m))
    return out


def numpy_path(on):
    """Switch slamlab's compiled kernels off (``on=True``: SLAMLAB_NO_NUMBA=1) or back on."""
    if on:
        os.environ["SLAMLAB_NO_NUMBA"] = "1"
    else:
        os.environ.pop("SLAMLAB_NO_NUMBA", None)


def compiled_pair(phi, r, d_rho, r_max, repeat):
    """Median times of the compiled transform and transform + find_peaks (issue 25)."""
    numpy_path(False)
    return {
        "nb": best_time(lambda: h.hough_polar(phi, r, delta_rho=d_rho, r_max=r_max), repeat),
        "nb_pk": best_time(lambda: h.find_peaks(h.hough_polar(phi, r, delta_rho=d_rho, r_max=r_max), 30), repeat),
    }


def measure(phi, r, d_rho, d_theta, r_max, repeat):
    """Median times of each case on one scan: ours on the numpy path and compiled, OpenCV."""
    img, _ = h.rasterise_scan(phi, r, cell=d_rho, r_max=r_max)
    # the floor of any numpy vote count: np.bincount alone on the N·180 vote indices (GIL held, one pass)
    acc = h.hough_polar(phi, r, delta_rho=d_rho, r_max=r_max)
    n_cells = acc.H.size
    votes = np.repeat(np.arange(n_cells), acc.H.T.ravel())
    numpy_path(True)
    return {
        "ours": best_time(lambda: h.hough_polar(phi, r, delta_rho=d_rho, r_max=r_max), repeat),
        "cv2": best_time(lambda: cv2.HoughLines(img, 1, d_theta, 30), repeat),
        "ours_pk": best_time(lambda: h.find_peaks(h.hough_polar(phi, r, delta_rho=d_rho, r_max=r_max), 30), repeat),
        "cv2_full": best_time(lambda: cv2.HoughLines(h.rasterise_scan(phi, r, cell=d_rho, r_max=r_max)[0], 1,
                                                     d_theta, 30), repeat),
        "classic": best_time(lambda: h.hough_classic(img), max(3, repeat // 10)),
        "bincount": best_time(lambda: np.bincount(votes, minlength=n_cells), repeat),
        **compiled_pair(phi, r, d_rho, r_max, repeat),
        # votes per θ: ours one per beam (004's transform), OpenCV one per occupied pixel
        "beams": float(acc.H[:, 0].sum()), "pixels": float(np.count_nonzero(img)),
    }


def real_log_ablation():
    """Print the ``--real-logs`` tables: each shared log's default run, the causes of its steps on odometry alone,
    and :data:`slamlab.studies.hough.REAL_LOG_ABLATION` (one change at a time, every log)."""
    from slamlab.data import find_data

    t0 = time.perf_counter()
    runs = [sh.run_real_log(find_data(rel), progress=False) for rel in sh.SHARED_LOGS.values()]
    for r in runs:
        print(r.table())
    print(sh.real_log_cause_table(runs))
    print(sh.ablate_real_logs(runs).table())
    print(f"{time.perf_counter() - t0:.1f} s")


_FIRST_CALL = """
import time, numpy as np, slamlab.hough as h
phi = np.linspace(-2.0, 2.0, 1081); r = 5.0 / np.maximum(np.abs(np.cos(phi)), np.abs(np.sin(phi)))
t0 = time.perf_counter(); h.find_peaks(h.hough_polar(phi, r, delta_rho=0.05, r_max=30.0), 30)
print(time.perf_counter() - t0)
"""


def first_call_times():
    """First call of hough_polar + find_peaks in a fresh process: compiling (empty cache), then from the cache.

    The kernels are cached in a temporary ``NUMBA_CACHE_DIR`` so the project's own cache is not touched.
    """
    import subprocess
    import sys
    import tempfile

    with tempfile.TemporaryDirectory() as cache:
        env = {**os.environ, "NUMBA_CACHE_DIR": cache}
        env.pop("SLAMLAB_NO_NUMBA", None)
        run = [sys.executable, "-c", _FIRST_CALL]
        return tuple(float(subprocess.run(run, env=env, check=True, capture_output=True, text=True).stdout)
                     for _ in range(2))


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=30)
    ap.add_argument("--real-logs", action="store_true", help="Hough SLAM ablation on the shared real logs")
    args = ap.parse_args(argv)
    if args.real_logs:
        print(f"machine: {platform.processor() or platform.machine()}, {os.cpu_count()} cores, "
              f"numpy {np.__version__}, load average {os.getloadavg()[0]:.2f}")
        real_log_ablation()
        print(f"load average {os.getloadavg()[0]:.2f}")
        return
    print(f"machine: {platform.processor() or platform.machine()}, {os.cpu_count()} cores, "
          f"numpy {np.__version__}, opencv {cv2.__version__}, load average {os.getloadavg()[0]:.2f}")
    rows = []
    for d_rho, r_max in ((0.05, 30.0), (0.02, 30.0), (0.05, 10.0)):
        scans = make_scans()
        d_theta = math.radians(1.0)
        res = {}
        for phi, r in scans:
            for key, t in measure(phi, r, d_rho, d_theta, r_max, args.repeat).items():
                res.setdefault(key, []).append(t)
        m = {k: float(np.median(v)) for k, v in res.items()}
        n_pts = int(np.median([p.size for p, _ in scans]))
        side = 2 * math.ceil(r_max / d_rho) + 1
        rows.append((f"Δrho {d_rho * 100:g} cm, r_max {r_max:g} m ({side}² image, {n_pts} returns)", m))
    # the notebook's synthetic square-room scan (noise-free, 1081 beams), 5 cm / 30 m
    phi_sq = np.linspace(-0.75 * np.pi, 0.75 * np.pi, 1081)
    r_sq = 5.0 / np.maximum(np.abs(np.cos(phi_sq)), np.abs(np.sin(phi_sq)))
    rows.append(("square room (notebook 07), Δrho 5 cm, r_max 30 m", measure(phi_sq, r_sq, 0.05, math.radians(1.0),
                                                                          30.0, args.repeat)))
    print(f"load average {os.getloadavg()[0]:.2f}")
    compile_s, cached_s = first_call_times()
    print(f"first call of hough_polar + find_peaks in a new process (compiled kernels): {compile_s:.2f} s "
          f"compiling (empty cache), {cached_s:.2f} s loading them from the cache")
    print()
    print(f"{'case':58s} {'ours [ms]':>10s} {'OpenCV [ms]':>12s} {'ratio':>7s}")
    for label, m in rows:
        for name, ours, ref in (("polar transform (numpy) vs cv2.HoughLines", m["ours"], m["cv2"]),
                                ("polar transform (compiled) vs cv2.HoughLines", m["nb"], m["cv2"]),
                                ("polar + find_peaks (numpy) vs rasterise + HoughLines", m["ours_pk"], m["cv2_full"]),
                                ("polar + find_peaks (compiled) vs rasterise + HoughLines", m["nb_pk"],
                                 m["cv2_full"]),
                                ("classic (numpy) vs cv2.HoughLines", m["classic"], m["cv2"]),
                                ("np.bincount of the votes alone vs cv2.HoughLines", m["bincount"], m["cv2"])):
            print(f"{label}\n  {name:56s} {ours * 1e3:10.3f} {ref * 1e3:12.3f} {ref / ours:7.2f}")
        print(f"  votes per θ (median over the scans): ours {m['beams']:.0f} (every beam), "
              f"OpenCV {m['pixels']:.0f} (occupied pixels of the rasterised scan)")


if __name__ == "__main__":
    main()
