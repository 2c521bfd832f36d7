"""ROS 1 amcl's clusters and its published pose (``cluster_labels``, ``best_cluster_estimate``; our addition)."""

import numpy as np
import pytest
from scipy.cluster.hierarchy import fclusterdata

from slamlab.localisation import MCL, MCLParams
from slamlab.localisation.particles import best_cluster_estimate, cluster_labels, pose_estimate


def _same_partition(a, b):
    """Two labellings describe the same partition (labels may differ)."""
    pairs = set(zip(a.tolist(), b.tolist(), strict=True))
    return len(pairs) == len(set(a.tolist())) == len(set(b.tolist()))


@pytest.mark.parametrize("seed", range(5))
def test_clusters_are_single_linkage_of_bins_at_chebyshev_distance_one(seed):
    """Connected occupied bins (26 neighbours) = single-linkage clusters of the bin indices with Chebyshev
    distance <= 1 (scipy), when no heading bin wraps around."""
    rng = np.random.default_rng(seed)
    centres = rng.uniform(0, 40, (6, 2))
    P = np.column_stack([np.repeat(centres, 50, axis=0) + rng.normal(0, 1.5, (300, 2)),
                         rng.uniform(0.5, 2.5, 300)])  # headings far from the wrap at 0 / 2π
    bins = np.floor(P / np.array([1.0, 1.0, 0.2]))
    ref = fclusterdata(bins, t=1.0, criterion="distance", metric="chebyshev", method="single")
    assert _same_partition(cluster_labels(P, (1.0, 1.0, 0.2)), ref)


def test_heading_bins_wrap_around():
    P = np.array([[0.5, 0.5, 0.01], [0.5, 0.5, 2 * np.pi - 0.01], [0.5, 0.5, np.pi]])
    lab = cluster_labels(P, (1.0, 1.0, 0.1))
    assert lab[0] == lab[1] != lab[2]


def test_best_cluster_is_the_heaviest_not_the_largest():
    rng = np.random.default_rng(0)
    a = np.column_stack([rng.normal(0, 0.2, (90, 2)), np.zeros(90)])  # many light particles
    b = np.column_stack([rng.normal(10, 0.2, (10, 2)), np.zeros(10)])  # few heavy ones
    w = np.r_[np.full(90, 0.004), np.full(10, 0.064)]
    mean, cov = best_cluster_estimate(np.vstack([a, b]), w, (1.0, 1.0, 0.5))
    ref_mean, ref_cov = pose_estimate(b, np.full(10, 0.1))
    np.testing.assert_allclose(mean, ref_mean, atol=1e-12)
    np.testing.assert_allclose(cov, ref_cov, atol=1e-12)
    whole, _ = pose_estimate(np.vstack([a, b]), w)
    assert np.hypot(*whole[:2]) > 4.0  # the whole set's mean lies between the two hypotheses


@pytest.mark.parametrize(("call", "match"), [
    (lambda: cluster_labels(np.zeros((3, 2)), (1, 1, 1)), "`particles` must have shape"),
    (lambda: cluster_labels([[0, 0, np.nan]], (1, 1, 1)), "`particles` must be finite"),
    (lambda: cluster_labels([[0, 0, 0]], (1, 0, 1)), "`bin_size` must be three sizes > 0"),
    (lambda: best_cluster_estimate([[0, 0, 0]], [0.5, 0.5], (1, 1, 1)), r"`weights` must have shape \(1,\)"),
    (lambda: best_cluster_estimate([[0, 0, 0]], [0.0], (1, 1, 1)), "positive sum"),
    (lambda: MCLParams(estimate="median"), "`estimate`"),
])
def test_bad_input(call, match):
    with pytest.raises(ValueError, match=match):
        call()


def test_the_filter_reports_the_heaviest_cluster_when_asked():
    """A global start in the 003 room: after a few scans the set holds several hypotheses; with
    ``estimate="best_cluster"`` each record's pose is the heaviest cluster's mean of that step's weighted set, and
    the particles are the same as with the whole set's mean (the estimate draws no random numbers)."""
    from slamlab import sim as S

    M = S.test_room_200()
    P = S.path_004(6)
    scans = S.simulate_scans(M, P, S.Rangefinder(n_beams=60, max_range_cells=60, range_std_cells=0.5), rng=1)
    runs = {}
    for est in ("mean", "best_cluster"):
        f = MCL(M, 60.0, n_particles=3000, rng=0, keep_particles=True, estimate=est)
        recs = [f.step(P[k - 1] if k else None, P[k] if k else None, scans[k]) for k in range(len(P))]
        runs[est] = (f, recs)
    (fm, rm), (fb, rb) = runs["mean"], runs["best_cluster"]
    for k, (X, w) in enumerate(fb.snapshots):
        np.testing.assert_array_equal(X, fm.snapshots[k][0])
        np.testing.assert_allclose(rb[k].mean, best_cluster_estimate(X, w, fb.params.kld_bin)[0], atol=1e-12)
        np.testing.assert_allclose(rm[k].mean, pose_estimate(X, w)[0], atol=1e-12)
    assert len(set(cluster_labels(*fb.snapshots[0][:1], fb.params.kld_bin).tolist())) > 1
