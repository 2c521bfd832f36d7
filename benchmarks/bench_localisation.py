"""Benchmark Ch. 8: one MCL update and one Markov grid update on the 200×200 test room.

Goals (issue 12): one MCL update (odometry motion + likelihood-field weights +
low-variance resampling) of 10 000 particles × 60 beams in ≤ 15 ms, reported as
particle-beams per second and as a ratio against the same update written with a
per-particle Python loop (same arithmetic, the same log-likelihoods: checked on every particle against RTOL, the
benchmark raises when one differs); one Markov
grid update (motion + sensor) on 200×200 cells × 72 headings in ≤ 1 s.

    python benchmarks/bench_localisation.py
"""

from __future__ import annotations

import argparse
import math
import os
import platform
import time

import numpy as np

from slamlab import localisation as L
from slamlab import sim as S


def best_cpu(fn, repeat=5):
    """Best CPU time (``time.process_time``) over ``repeat`` runs and the last result (single-threaded code)."""
    times, out = [], None
    for _ in range(repeat):
        t0 = time.process_time()
        out = fn()
        times.append(time.process_time() - t0)
    return min(times), out


def loop_log_likelihood(model: L.LikelihoodFieldModel, X, beams: L.Beams) -> np.ndarray:
    """The reference: the likelihood-field weight computed particle by particle, beam by beam, with the end
    point's cell as ``LikelihoodFieldModel`` defines it (``floor(x + cos θ·bx − sin θ·by + 0.5)``, float64, left
    to right), so that it must give the batched log-likelihoods bit for bit."""
    T = model._padded.reshape(model._padded_shape)
    Hp, Wp = model._padded_shape
    out = np.empty(len(X))
    bx, by = beams.end_xy[:, 0], beams.end_xy[:, 1]
    used = model.used(beams)
    for i, (x, y, th) in enumerate(X):
        c, s = math.cos(th), math.sin(th)
        acc = 0.0
        for k in range(beams.n):
            if not used[k]:
                continue
            col = min(max(math.floor(x + c * bx[k] - s * by[k] + 0.5) + model.pad, 0), Wp - 1)
            row = min(max(math.floor(y + s * bx[k] + c * by[k] + 0.5) + model.pad, 0), Hp - 1)
            acc += float(T[row, col])
        out[i] = acc
    return out


#: tolerance of the batched log-likelihoods against the loop's, relative: both pick the same cell for every beam
#: (same float64 operations in the same order; LikelihoodFieldModel's docstring), so only the summation order of
#: 60 float32 terms in float64 may differ (≤ 60 ulps, ~1e-14); a beam in another cell moves the sum by at least a
#: float32 step of one term (~1e-7 of it), far above this
RTOL = 1e-13


def check_agreement(ll: np.ndarray, ll_loop: np.ndarray) -> float:
    """The largest relative difference of the batched log-likelihoods from the loop's; ``RuntimeError`` when a
    particle's exceeds :data:`RTOL`."""
    rel = np.abs(ll - ll_loop) / np.maximum(np.abs(ll_loop), np.finfo(float).tiny)
    bad = np.flatnonzero(~(rel <= RTOL))
    if bad.size:
        i = int(bad[0])
        raise RuntimeError(f"batched and loop log-likelihoods differ on {bad.size} of {ll.size} particles beyond "
                           f"rtol {RTOL:g} (first: particle {i}, {ll[i]!r} against {ll_loop[i]!r})")
    return float(rel.max())


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--particles", type=int, default=10_000)
    ap.add_argument("--beams", type=int, default=60)
    ap.add_argument("--loop-particles", type=int, default=1000, help="particles timed in the Python loop")
    args = ap.parse_args(argv)
    print(f"machine: {platform.processor() or platform.machine()}, {os.cpu_count()} cores; "
          f"load average {os.getloadavg()[0]:.2f} {os.getloadavg()[1]:.2f} {os.getloadavg()[2]:.2f}")
    M = S.test_room_200()
    P = S.path_004(121)
    scan = S.Rangefinder(n_beams=args.beams, max_range_cells=300, range_std_cells=0.5).scan(M, P[30], rng=0)
    params = L.MCLParams(n_particles=args.particles, max_beams=args.beams, alpha_slow=0.0, alpha_fast=0.0,
                         resample_threshold=1.0)
    model = params.model(M, 300.0)
    beams = L.scan_beams(scan, args.beams)
    if beams.n != args.beams:
        raise RuntimeError(f"the scan has {beams.n} returns, not {args.beams}")
    X = L.uniform_free_particles(M, args.particles, 0)
    state = L.MCLState(X, np.full(len(X), 1 / len(X)))
    n, b = len(X), beams.n

    t_w, ll = best_cpu(lambda: model.log_likelihood(X, beams))
    t_step, _ = best_cpu(lambda: L.mcl_step(state, P[29], P[30], beams, model, params, np.random.default_rng(1)))
    m = args.loop_particles
    t_loop, _ = best_cpu(lambda: loop_log_likelihood(model, X[:m], beams), repeat=2)
    rel = check_agreement(ll, loop_log_likelihood(model, X, beams))  # every particle, not only the timed ones
    t_loop_full = t_loop * n / m
    print(f"\nMCL update, {n} particles × {b} beams (CPU time, best of 5)")
    print(f"  weights only (likelihood field):  {t_w * 1e3:8.2f} ms   {n * b / t_w / 1e6:7.1f} M particle-beams/s")
    print(f"  full update (motion+weights+resample): {t_step * 1e3:8.2f} ms   goal ≤ 15 ms: "
          f"{'met' if t_step <= 0.015 else 'NOT met'} (at this load)")
    print(f"  per-particle loop, weights: {t_loop_full * 1e3:8.1f} ms (timed on {m} particles, scaled)   "
          f"{n * b / t_loop_full / 1e6:7.3f} M particle-beams/s")
    print(f"  ratio loop / ours (weights): {t_loop_full / t_w:6.0f}x")
    print(f"  log-likelihoods as the loop's on all {n} particles: largest relative difference {rel:.1e} "
          f"(tolerance {RTOL:g})")

    print("\nMarkov grid update, 200×200 cells × 72 headings, 30 beams (CPU time, best of 3)")
    mg = L.MarkovGrid(M, 300.0, resolution=1, n_headings=72, max_beams=30)
    bel0 = mg.belief.copy()

    def markov_update():
        mg.belief = bel0.copy()
        mg.predict(P[29], P[30])
        mg.correct(scan)

    t_mk, _ = best_cpu(markov_update, repeat=3)
    t_pred, _ = best_cpu(lambda: L.markov_predict(bel0, P[29], P[30], resolution=1, alpha=mg.params.alpha,
                                                  free_mask=mg.free_mask), repeat=3)
    print(f"  motion + sensor: {t_mk:6.3f} s (motion alone {t_pred:6.3f} s)   goal ≤ 1 s: "
          f"{'met' if t_mk <= 1.0 else 'NOT met'} (at this load); belief {mg.nbytes / 2**20:.1f} MiB")
    print(f"\nload average after: {os.getloadavg()[0]:.2f}")


if __name__ == "__main__":
    main()
