"""Benchmark Ch. 5: correlation of all 360 headings with the 200×200 test room.

Ours (one batched ``scipy.fft`` call per chunk of headings against the map's
spectrum computed once, pruned transforms, quarter-turn reuse of T_n) vs the same
correlation done per heading with ``scipy.signal.fftconvolve``, and vs the direct
definition on a small case; every pair must give the identical peak.

    python benchmarks/bench_correlation.py            # timings
    python benchmarks/bench_correlation.py --monte-carlo   # + the 200-pose Monte Carlo of the notebook
    python benchmarks/bench_correlation.py --intel         # + every 25th Intel scan: 1 scan vs 2, 3 joined
    python benchmarks/bench_correlation.py --logs --set 'joined=(1, 3)'   # + the goal protocol: every 10th scan of
                                                   # each shared CARMEN log, coverage, the goal, the logged poses
    python benchmarks/bench_correlation.py --logs --every 100 --only intel,seattle   # smaller / fewer logs
    python benchmarks/bench_correlation.py --logs --map-check   # + is each log's beam layout read right? (issue 25)
    python benchmarks/bench_correlation.py --logs --failures    # + each failure: score failure or search failure?
    python benchmarks/bench_correlation.py --logs --set 'joined=(1, 3)' --leave-out used   # each mode's own scans out
    python benchmarks/bench_correlation.py --logs --failures --terms   # + the score's terms at estimate and truth
    python benchmarks/bench_correlation.py --refine-cost        # + CPU time of refine=10 (issue 25)
"""

from __future__ import annotations

import argparse
import ast
import os
import platform
import time

import numpy as np
import scipy
from scipy.signal import fftconvolve

import slamlab as sl
from slamlab.correlation._fft import MapSpectrum, Stamps, peak_search
from slamlab.correlation.samples import scan_samples


def best_of(fn, repeat=3):
    """Best CPU time of this process (``time.process_time``) over ``repeat`` runs, and the last result.

    CPU time rather than wall time: other jobs share this 2-core machine, and CPU time of a
    single-threaded computation is far less sensitive to them (multi-threaded runs are timed by wall clock).
    """
    times = []
    out = None
    for _ in range(repeat):
        t0 = time.process_time()
        out = fn()
        times.append(time.process_time() - t0)
    return min(times), out


def best_wall(fn, repeat=3):
    times = []
    out = None
    for _ in range(repeat):
        t0 = time.perf_counter()
        out = fn()
        times.append(time.perf_counter() - t0)
    return min(times), out


def first_peak(D, heads=None, tol=1e-6):
    """Tie rule of localise(): the smallest heading, then the first row and column within ``tol`` of the max."""
    m = float(D.max())
    flat = int(np.argmax(D.ravel() >= m - tol))
    return m, tuple(int(i) for i in np.unravel_index(flat, D.shape))


def peak_batched(Mv, T, o, dtype, chunk=8, workers=None):
    """Ours, batched: the same search as localise(), on prebuilt stamps (rasterisation excluded)."""
    return peak_ours(Mv, T, o, dtype, chunk, workers, quarter_trick=False)


def peak_ours(Mv, T, o, dtype, chunk=8, workers=None, quarter_trick=True, stamps=None, headings=None):
    if not quarter_trick:
        spec = MapSpectrum(Mv, T.shape[1], o, dtype, workers)
        best = (-np.inf, None)
        for s in range(0, T.shape[0], chunk):
            val, (k, r, c) = first_peak(spec.scores(T[s:s + chunk]))
            if val > best[0] + 1e-3:
                best = (val, (s + k, r, c))
        return best
    tol = 1e-9 * 4e4 if np.dtype(dtype) == np.float64 else 0.5
    val, idx, _m, _b, _a = peak_search(Mv, stamps, headings, T.shape[1], o, dtype=dtype, workers=workers, chunk=chunk,
                                       tol=tol)
    return val, idx


def peak_fftconvolve(Mv, T, o):
    H, W = Mv.shape
    S = T.shape[1]
    a0 = S - 1 - o
    best = (-np.inf, None)
    for n in range(T.shape[0]):
        full = fftconvolve(Mv, T[n, ::-1, ::-1], mode="full")
        val, (r, c) = first_peak(full[a0:a0 + H, a0:a0 + W])
        if val > best[0] + 1e-3:
            best = (val, (n, r, c))
    return best


def peak_direct(Mv, T, o):
    return first_peak(sl.correlation.score_maps(Mv, T, o, method="direct"))


def same_peak(a, b, tol=1e-3):
    return a[1] is not None and tuple(int(i) for i in a[1]) == tuple(int(i) for i in b[1]) and abs(a[0] - b[0]) < tol


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--monte-carlo", action="store_true", help="also run the 200-pose Monte Carlo")
    ap.add_argument("--intel", action="store_true",
                    help="also localise every 25th scan of the Intel log, one scan vs 2 and 3 joined by odometry")
    ap.add_argument("--logs", action="store_true",
                    help="also localise every --every-th scan of each shared CARMEN log (run_log_suite's defaults)")
    ap.add_argument("--every", type=int, default=10, help="scan step of the --logs run (default 10, the goal's)")
    ap.add_argument("--exclude", type=int, default=None,
                    help="scans left out on either side of each --logs scan (default: run_log_localisation's, 2)")
    ap.add_argument("--max-range", type=float, default=None, help="range limit [m] of the --logs run (default 10)")
    ap.add_argument("--leave-out", choices=("window", "used"), default=None,
                    help="which scans each --logs grid lacks: 'window' (±exclude, the default) or 'used' (each "
                         "mode's own scans only; issue 25)")
    ap.add_argument("--set", action="append", default=[], metavar="NAME=VALUE",
                    help="any other setting of the --logs run (run_log_localisation's arguments, LocaliseParams "
                         "fields), a Python literal: --set 'odom_std=(0, 0)' --set a_p=4 --set hit_ratio=0.1")
    ap.add_argument("--map-check", action="store_true",
                    help="with --logs: first print the end points on the other scans' walls per beam layout and log")
    ap.add_argument("--failures", action="store_true",
                    help="with --logs: score each scan near its logged pose too and print the failures by kind "
                         "(score failure or search failure, issue 25)")
    ap.add_argument("--terms", action="store_true",
                    help="with --logs --failures: print the score's four terms at the estimate and near the truth "
                         "for every failure and each mode's median success (issue 25)")
    ap.add_argument("--refine-cost", action="store_true",
                    help="CPU time of run_log_localisation with refine=10 vs without, every 25th csail scan, modes "
                         "1 and 3 (issue 25)")
    ap.add_argument("--compare", action="append", default=[], metavar="NAME=VALUE",
                    help="with --logs: run the suite again with these settings added (a Python literal, e.g. "
                         "--compare score_norm='explored') and print per log the successes of both and the scans "
                         "gained / lost (issue 25)")
    ap.add_argument("--only", default=None, help="comma-separated short log names for --logs (default all five)")
    ap.add_argument("--jobs", type=int, default=1, help="sweep workers of the --intel/--logs runs (same result for any)")
    args = ap.parse_args()
    print(f"machine: {platform.processor() or platform.machine()}, {os.cpu_count()} CPUs; numpy {np.__version__}, "
          f"scipy {scipy.__version__}; load average {os.getloadavg()[0]:.1f}")
    M = sl.sim.test_room_200()
    W = sl.sim.measurement_room_200()
    rf = sl.sim.Rangefinder(n_beams=360, max_range_cells=100.0, range_std_cells=0.3)
    truth = np.array([60.0, 40.0, np.radians(30.0)])
    scan = rf.scan(W, truth, rng=1)
    headings = sl.correlation.heading_candidates(np.radians(1.0))
    t_rast, (T, o) = best_of(lambda: sl.correlation.scan_stamps(scan, headings, dtype="float64"))
    Mv = sl.sim.grid_to_values(M)
    print(f"\nCase 1: 360 headings, map 200x200, T_n {T.shape[1]}x{T.shape[1]}; rasterising all T_n took {t_rast:.3f} s")
    t_ref, p_ref = best_of(lambda: peak_fftconvolve(Mv, T, o), repeat=2)
    t_ref32, p_ref32 = best_of(lambda: peak_fftconvolve(Mv.astype(np.float32), T.astype(np.float32), o), repeat=2)
    rows = [("per-heading scipy.signal.fftconvolve (reference)", t_ref, p_ref),
            ("per-heading fftconvolve on float32 arrays", t_ref32, p_ref32)]
    samples = scan_samples(scan)
    free, obs = samples.free, samples.obs
    for label, dt, workers, trick in (("ours, batched float64, no quarter-turn reuse", np.float64, None, False),
                                      ("ours, batched float64", np.float64, None, True),
                                      ("ours, batched float32", np.float32, None, True),
                                      ("ours, batched float64, 2 threads", np.float64, 2, True),
                                      ("ours, batched float32, 2 threads", np.float32, 2, True)):
        st = Stamps(free, obs, headings, -1.0, 1.0, 0.0, o, dt)
        timer = best_wall if workers else best_of
        t, p = timer(lambda dt=dt, workers=workers, trick=trick, st=st: peak_ours(
            Mv, T, o, dt, workers=workers, quarter_trick=trick, stamps=st, headings=headings))
        rows.append((label, t, p))
    print("times: best CPU time of 3 runs (2-thread rows: wall time); speed-up vs the float64 reference")
    print(f"{'method':>50}  {'time [s]':>9}  {'speed-up':>8}  peak (n, row, col) / score / same")
    for label, t, p in rows:
        print(f"{label:>50}  {t:9.3f}  {t_ref / t:8.2f}  {tuple(int(i) for i in p[1])} / {p[0]:.1f} / "
              f"{same_peak(p, p_ref)}")
    t_loc, loc = best_of(lambda: sl.correlation.localise(M, scan, dtype="float64"))
    t_loc32, _loc32 = best_of(lambda: sl.correlation.localise(M, scan, dtype=np.float32))
    print(f"\nend to end localise() (rasterise + correlate + peak), CPU time: float64 {t_loc:.3f} s, float32 {t_loc32:.3f} s; "
          f"pose {loc.col}, {loc.row}, {np.degrees(loc.pose[2]):.0f} deg (truth 60, 40, 30)")

    # small case: the definition
    Ms = M[20:80, 0:60]
    s_small = sl.sim.Rangefinder(n_beams=90, max_range_cells=15.0).scan(Ms, [20.0, 25.0, np.radians(30.0)])
    hs = sl.correlation.heading_candidates(np.radians(10.0))
    Ts, os_ = sl.correlation.scan_stamps(s_small, hs, dtype="float64")
    Mvs = sl.sim.grid_to_values(Ms)
    t_dir, p_dir = best_of(lambda: peak_direct(Mvs, Ts, os_), repeat=1)
    t_fc, p_fc = best_of(lambda: peak_fftconvolve(Mvs, Ts, os_))
    t_b, p_b = best_of(lambda: peak_batched(Mvs, Ts, os_, np.float64))
    print(f"\nCase 2 (small): 36 headings, map 60x60, T_n {Ts.shape[1]}x{Ts.shape[1]}")
    print(f"{'method':>50}  {'time [s]':>9}  {'speed-up':>8}  peak / same as direct")
    for label, t, p in (("direct definition (reference)", t_dir, p_dir), ("per-heading fftconvolve", t_fc, p_fc),
                        ("ours, batched float64", t_b, p_b)):
        print(f"{label:>50}  {t:9.4f}  {t_dir / t:8.1f}  {tuple(int(i) for i in p[1])} / {same_peak(p, p_dir)}")

    if args.monte_carlo:
        t0 = time.perf_counter()
        mc = sl.studies.correlation.run_monte_carlo("full", rng=2011)
        print(f"\nMonte Carlo (200 poses, float32), took {time.perf_counter() - t0:.1f} s")
        print(mc.table())
        mc2 = sl.studies.correlation.run_monte_carlo("full", extra_clutter=60, rng=2011)
        print(mc2.table())


    if args.intel:
        intel(args.jobs)
    if args.refine_cost:
        refine_cost()
    if args.logs:
        settings = {k: val for k, val in (("exclude", args.exclude), ("max_range_m", args.max_range),
                                          ("leave_out", args.leave_out)) if val is not None}
        for item in args.set:
            name, sep, value = item.partition("=")
            if not sep:
                ap.error(f"--set takes NAME=VALUE; got {item!r}")
            settings[name.strip()] = ast.literal_eval(value.strip())
        compare = {}
        for item in args.compare:
            name, sep, value = item.partition("=")
            if not sep:
                ap.error(f"--compare takes NAME=VALUE; got {item!r}")
            compare[name.strip()] = ast.literal_eval(value.strip())
        if compare:
            compare_logs(args.every, args.only, args.jobs, settings, compare)
        else:
            if args.terms and not args.failures:
                ap.error("--terms needs --failures (the truth check computes the terms)")
            logs(args.every, args.only, args.jobs, settings, args.map_check, args.failures, args.terms)


def compare_logs(every: int, only: str | None, n_jobs: int, settings: dict, extra: dict) -> None:
    """Issue 25: the log suite with ``settings`` and with ``settings`` + ``extra``; per log and mode the successes
    of both and the scans gained / lost."""
    from slamlab.studies.correlation.log_suite import SHARED_CARMEN_LOGS

    paths = [p for p in SHARED_CARMEN_LOGS if only is None or p.split("/")[1].split("-")[0] in only.split(",")]
    runs = []
    for kw in (settings, {**settings, **extra}):
        print(f"\nShared CARMEN logs, every {every}th scan, settings {kw or 'defaults'}, "
              f"load average {os.getloadavg()[0]:.1f}")
        t0 = time.perf_counter()
        r = sl.studies.correlation.run_log_suite([sl.data.find_data(p) for p in paths], every, n_jobs=n_jobs,
                                         progress=False, **kw)
        print(f"took {time.perf_counter() - t0:.1f} s wall ({n_jobs} job(s)); load average now "
              f"{os.getloadavg()[0]:.1f}")
        print(r.table())
        runs.append(r)
    base, new = runs
    print(f"\n{extra} against {settings or 'defaults'}: successes per log and mode, scans gained / lost")
    print("| log | mode | base | with | gained | lost |\n|---|---|---:|---:|---|---|")
    tot = np.zeros((2, len(base.results[0].joined)), dtype=int)
    for name, rb, rn in zip(base.names, base.results, new.results, strict=True):
        for m, k in enumerate(rb.joined):
            sb, sn = rb.success[m], rn.success[m]
            tot[:, m] += sb.sum(), sn.sum()
            gained = ", ".join(str(int(i)) for i in rb.scan_indices[~sb & sn]) or "-"
            lost = ", ".join(str(int(i)) for i in rb.scan_indices[sb & ~sn]) or "-"
            print(f"| {name} | {k} | {sb.sum()}/{sb.size} | {sn.sum()}/{sn.size} | {gained} | {lost} |")
    n = sum(r.success.shape[1] for r in base.results)
    for m, k in enumerate(base.results[0].joined):
        print(f"| all | {k} | {tot[0, m]}/{n} | {tot[1, m]}/{n} | | |")


def logs(every: int, only: str | None, n_jobs: int, settings: dict, map_check: bool = False,
         failures: bool = False, terms: bool = False) -> None:
    """Every ``every``-th scan of each shared CARMEN log with the real-log defaults: the per-log table, the scans
    not covered, the goal (with modes 1 and 3), the logged poses' check, then the failure flags."""
    from slamlab.studies.correlation.log_suite import SHARED_CARMEN_LOGS

    paths = [p for p in SHARED_CARMEN_LOGS if only is None or p.split("/")[1].split("-")[0] in only.split(",")]
    if map_check:
        t0 = time.perf_counter()
        print(f"\nBeam layout check (every 5th scan, ±2 scans left out, 0.2 m cells, ranges < 10 m), load average "
              f"{os.getloadavg()[0]:.1f}")
        print(sl.studies.correlation.map_check([sl.data.find_data(p) for p in paths]))
        print(f"took {time.perf_counter() - t0:.1f} s wall")
    print(f"\nShared CARMEN logs, every {every}th scan, settings {settings or 'defaults'}, "
          f"load average {os.getloadavg()[0]:.1f}")
    t0 = time.perf_counter()
    r = sl.studies.correlation.run_log_suite([sl.data.find_data(p) for p in paths], every, n_jobs=n_jobs, progress=False,
                                     **settings, **({"truth_check": True} if failures else {}))
    print(f"took {time.perf_counter() - t0:.1f} s wall ({n_jobs} job(s)); load average now {os.getloadavg()[0]:.1f}")
    print(r.table())
    print(r.coverage_table())
    if 1 in r.results[0].joined and 3 in r.results[0].joined:
        print(r.goal_table())
    print(r.truth_table())
    if failures:
        print(r.failure_table())
        for res in r.results:
            print(res.failure_table())
    if terms:
        for res in r.results:
            print(res.terms_table())
    for t in (0.75, 0.8, 0.85, 0.9):
        print(r.ambiguity_table(t))
    for t in (1.0, 1.2, 1.3):  # issue 25: the margin, threshold 1.2 tuned on csail, orebro and seattle
        print(r.margin_table(t))
    if r.results[0].votes is not None:  # --set votes=True (issue 25): the neighbours' single-scan votes
        for t in (2, 1, 3):
            print(r.votes_table(t))
    if 1 in r.results[0].joined and 3 in r.results[0].joined:  # issue 25: per scan the answer with the larger margin
        print(r.confident_table((1, 3)))
    for res in r.results:
        print(res.table())


def refine_cost(repeat: int = 2) -> None:
    """Issue 25: CPU time of ``run_log_localisation(refine=10)`` against the defaults, every 25th csail scan."""
    log = sl.io.read_carmen(sl.data.find_data("carmen-radish-corrected/csail-corrected.log.gz"))
    idx = range(25, log.n_scans, 25)
    print(f"\nrefine cost: csail, every 25th scan ({len(idx)} scans), modes 1 and 3, best CPU time of {repeat} "
          f"(alternating), load average {os.getloadavg()[0]:.1f}")
    times = {0: [], 10: []}
    for _ in range(repeat):
        for k, ts in times.items():
            t0 = time.process_time()
            r = sl.studies.correlation.run_log_localisation(log, idx, joined=(1, 3), refine=k, progress=False)
            ts.append(time.process_time() - t0)
            print(f"  refine={k}: {ts[-1]:.1f} s CPU, localised {r.success.sum(axis=1).tolist()} (1 / 3 scans)")
    t0, t10 = min(times[0]), min(times[10])
    print(f"best: defaults {t0:.1f} s, refine=10 {t10:.1f} s, ratio {t10 / t0:.2f}; load average now "
          f"{os.getloadavg()[0]:.1f}")


def intel(n_jobs: int) -> None:
    """Issue 17: every 25th scan of the corrected Intel log, from no prior, one scan and 2/3 joined by odometry."""
    log = sl.io.read_carmen(sl.data.find_data(sl.studies.correlation.DEFAULT_CARMEN_LOG))
    idx = range(25, log.n_scans, 25)
    print(f"\nIntel log, every 25th scan ({len(idx)} scans), load average {os.getloadavg()[0]:.1f}")
    t0 = time.perf_counter()
    r = sl.studies.correlation.run_log_localisation(log, idx, joined=(1, 2, 3), exclude=10, n_jobs=n_jobs)  # issue 17's
    t = time.perf_counter() - t0
    print(f"took {t:.1f} s wall ({t / len(idx):.2f} s per scan for the three modes, {n_jobs} job(s)); "
          f"load average now {os.getloadavg()[0]:.1f}")
    print(r.summary_table())
    print(r.ambiguity_table())
    print(r.table())
    r0 = sl.studies.correlation.run_log_localisation(log, idx, joined=(1, 2, 3), exclude=10, odom_std=(0.0, 0.0),
                                             n_jobs=n_jobs)
    print("\nthe same without odometry noise (the logged relative poses):")
    print(r0.summary_table())
    # cost of the ambiguity: the peak search alone vs the peak plus its rival, on one scan
    G, _frame, scans_c, _Pc = sl.scans.log_grid(log, leave_out=range(140, 161))
    t_plain, _ = best_of(lambda: sl.correlation.localise(G, scans_c[150], ambiguity=False))
    t_amb, loc = best_of(lambda: sl.correlation.localise(G, scans_c[150]))
    print(f"\none Intel scan, CPU time: localise without the rival {t_plain:.3f} s, with it {t_amb:.3f} s "
          f"(ratio {t_amb / t_plain:.2f}); {loc}")


if __name__ == "__main__":
    main()
