"""Where ORB's new landmarks come from on the ~80 m run (issue 17): every point that becomes a landmark, by cause.

Runs one variant (``StereoParams`` overrides as JSON, global map search: the descriptor store's 2-NN of
every point is what is classified) on the frames of ``ablate_stereo_long.py`` (same cache, seeds and
trajectory) and sorts each new landmark, after the frame's pose, by where its two nearest landmarks by
descriptor lie: both within ``r`` of the point (twins: the same point added twice, so the ratio rule
fails), only the first / only the second, both elsewhere but within ``r`` of each other, neither but
another live landmark within ``r`` (the same place under another descriptor), or nothing within ``r``.
At the end: pairs of live landmarks closer than 1 / 3 / 10 cm and the Hamming distance between them.

    python benchmarks/orb_map_growth.py '{"detector": "orb", "map_search": "global"}'
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

import numpy as np
from scipy.spatial import cKDTree

import slamlab.stereo.slam as slam_module
from slamlab.features.matching import ratio_rule
from slamlab.stereo import StereoParams, StereoSLAM

sys.path.insert(0, str(Path(__file__).parent))
from ablate_stereo_long import load

CAUSES = ("both NN here (twins)", "first NN here only", "second NN here only", "NN twins elsewhere",
          "a live landmark here, not an NN", "nothing here")


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("variant", nargs="?", default='{"detector": "orb", "map_search": "global"}')
    ap.add_argument("--frames", type=int, default=None)
    ap.add_argument("--radius", type=float, default=0.03, help="'here' = within this distance, m")
    ap.add_argument("--cache", type=Path, default=Path("/tmp/slamlab-stereo-long"))
    args = ap.parse_args(argv)
    path, sim, L, R, r_slam = load(args.frames, args.cache)
    p = StereoParams(**json.loads(args.variant))
    if p.search != "global":
        raise SystemExit("classify the global search (map_search='global'): the window search has no store 2-NN")
    slam = StereoSLAM(sim.rig, sim.T_body_left, params=p, rng=np.random.default_rng(r_slam))
    seen = {}
    core = slam_module.match_to_map

    def spy(D, store, *a, **k):  # keep the store's 2-NN of every point
        query = store.query

        def q(Q, k=2):
            seen["knn"] = query(Q, k=k)
            return seen["knn"]

        store.query = q
        try:
            seen["mm"] = core(D, store, *a, **k)
        finally:
            del store.query
        return seen["mm"]

    slam_module.match_to_map = spy
    r = args.radius
    totals = np.zeros(len(CAUSES), dtype=np.int64)
    n_ratio_fail = 0
    for i in range(len(path)):
        seen.clear()
        n0, alive0 = len(slam.X), slam.alive.copy()
        rec = slam.process(np.asarray(L[i]), np.asarray(R[i]))
        if rec.status != "ok" or "knn" not in seen or rec.n_new == 0:
            continue
        dist, ids = seen["knn"]
        new_pts = slam.X[n0:]  # the frame's new landmarks, in the order of its unmatched points
        unmatched = seen["mm"].unmatched
        if len(unmatched) != len(new_pts):  # duplicate check on: classify only when every unmatched point was added
            continue
        n_ratio_fail += int((~ratio_rule(dist[unmatched, 0], dist[unmatched, 1], p.map_ratio)).sum())
        X = slam.X
        live = np.flatnonzero(alive0[:n0])
        near = cKDTree(X[live]).query(new_pts, k=1)[0] <= r
        i1, i2 = np.maximum(ids[unmatched, 0], 0), np.maximum(ids[unmatched, 1], 0)
        g1 = np.linalg.norm(X[i1] - new_pts, axis=1) <= r
        g2 = np.linalg.norm(X[i2] - new_pts, axis=1) <= r
        twin = np.linalg.norm(X[i1] - X[i2], axis=1) <= r
        totals += [(g1 & g2).sum(), (g1 & ~g2).sum(), (~g1 & g2).sum(), (twin & ~g1 & ~g2).sum(),
                   (near & ~g1 & ~g2 & ~twin).sum(), (~near & ~g1 & ~g2 & ~twin).sum()]
    n = int(totals.sum())
    print(f"{p.detector}, {p.search} search, {len(path)} frames: {n} new landmarks classified, {n_ratio_fail} of them "
          f"failed the ratio rule ('here' = within {100 * r:.0f} cm of the point, after the pose)")
    for name, k in zip(CAUSES, totals, strict=True):
        print(f"  {name}: {k} ({100 * k / max(n, 1):.0f} %)")
    alive = np.flatnonzero(slam.alive)
    tree = cKDTree(slam.X[alive])
    for rr in (0.01, 0.03, 0.1):
        pairs = tree.query_pairs(rr, output_type="ndarray")
        d = np.unpackbits(slam.desc[alive[pairs[:, 0]]] ^ slam.desc[alive[pairs[:, 1]]], axis=1).sum(axis=1)
        print(f"  live landmarks at the end {len(alive)}: {len(pairs)} pairs within {100 * rr:.0f} cm "
              f"({len(np.unique(pairs))} landmarks in one), Hamming distance in a pair: median {np.median(d):.0f}")


if __name__ == "__main__":
    main()
