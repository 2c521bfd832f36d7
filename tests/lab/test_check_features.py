"""Labs 02 and 03 tasks: solutions written from the equations pass, typical mistakes fail at the expected case."""

from __future__ import annotations

import numpy as np
import pytest

import slamlab_grading as lab
from slamlab_grading import core


def _fails_on_both(task_id, fn, fragment):
    """``fn`` fails on the student's feedback cases (seed 0) and on the grading cases, with ``fragment``."""
    for rng in (0, core.GRADING_RNG):
        res = lab.check(task_id, fn, quiet=True, rng=rng)
        assert not res.passed, (task_id, rng)
        assert fragment in res.message, (task_id, rng, res.message)

# --- lab 02: independent solutions (what a student should write) ------------------------------------

CIRCLE = [(0, 3), (1, 3), (2, 2), (3, 1), (3, 0), (3, -1), (2, -2), (1, -3), (0, -3), (-1, -3), (-2, -2),
          (-3, -1), (-3, 0), (-3, 1), (-2, 2), (-1, 3)]  # (du, dv)


def integral_image(image):
    H, W = image.shape
    II = np.zeros((H + 1, W + 1))
    for r in range(H):
        for c in range(W):
            II[r + 1, c + 1] = image[r, c] + II[r, c + 1] + II[r + 1, c] - II[r, c]
    return II


def box_sum(II, r0, r1, c0, c1, *, clip=True):
    H, W = II.shape[0] - 1, II.shape[1] - 1
    if clip:
        r0, r1 = min(max(r0, 0), H), min(max(r1, 0), H)
        c0, c1 = min(max(c0, 0), W), min(max(c1, 0), W)
    return II[r1, c1] - II[r0, c1] - II[r1, c0] + II[r0, c0]


def hessian(II, row, col, L, *, weight=0.81):
    l, b = L // 3, (L - 1) // 2
    h = l // 2

    def box(a0, a1, b0, b1):
        return box_sum(II, row + a0, row + a1, col + b0, col + b1)

    Dxx = box(-l + 1, l, -b, b + 1) - 3 * box(-l + 1, l, -h, -h + l)
    Dyy = box(-b, b + 1, -l + 1, l) - 3 * box(-h, -h + l, -l + 1, l)
    Dxy = box(-l, 0, 1, l + 1) + box(1, l + 1, -l, 0) - box(-l, 0, -l, 0) - box(1, l + 1, 1, l + 1)
    Dxx, Dyy, Dxy = Dxx / L**2, Dyy / L**2, Dxy / L**2
    return Dxx * Dyy - weight * Dxy**2, Dxx + Dyy


def fast_mask(image, t, n, *, dtype=int, wrap=True):
    img = image.astype(dtype)
    H, W = img.shape
    out = np.zeros((H, W), dtype=bool)
    for r in range(3, H - 3):
        for c in range(3, W - 3):
            p = img[r, c]
            ring = np.array([img[r + dv, c + du] for du, dv in CIRCLE])
            for flags in (ring > p + t, ring < p - t):
                seq = np.concatenate([flags, flags]) if wrap else flags
                run = best = 0
                for f in seq:
                    run = run + 1 if f else 0
                    best = max(best, run)
                out[r, c] |= best >= n
    return out


@pytest.mark.parametrize(("task_id", "fn"), [("02.integral_image", integral_image), ("02.box_sum", box_sum),
                                             ("02.hessian", hessian), ("02.fast_mask", fast_mask)])
def test_lab02_correct_solutions_pass(task_id, fn):
    res = lab.check(task_id, fn, quiet=True)
    assert res.passed, res.message


def test_lab02_mistakes():
    def no_zero_border(image):  # II[r, c] = sum of I[:r+1, :c+1], shape (H, W)
        return np.cumsum(np.cumsum(image, axis=0), axis=1)

    def no_clip(II, r0, r1, c0, c1):  # negative indices wrap around
        return box_sum(II, r0, r1, c0, c1, clip=False)

    def no_weight(II, row, col, L):  # det without 0.9²
        return hessian(II, row, col, L, weight=1.0)

    def uint8(image, t, n):  # I_p + t computed in uint8
        return fast_mask(image, np.uint8(t), n, dtype=np.uint8)

    def no_wrap(image, t, n):  # runs that cross the end of the circle list are missed
        return fast_mask(image, t, n, wrap=False)

    _fails_on_both("02.integral_image", no_zero_border, "case 1 of 5 (random 5x7 image) is wrong: expected shape")
    _fails_on_both("02.box_sum", no_clip, "(a box over the top-left corner")
    _fails_on_both("02.hessian", no_weight, "case 1 of 6")
    _fails_on_both("02.fast_mask", uint8, "")  # failed, or error where numpy warns
    _fails_on_both("02.fast_mask", no_wrap, "")  # random images have such arcs, and so has an edge case


def test_lab02_wrapping_arc_case_alone():
    def no_wrap_when_flat(image, t, n):  # misses wrapping arcs only on the flat test image
        return fast_mask(image, t, n, wrap=len(np.unique(image)) > 2)

    _fails_on_both("02.fast_mask", no_wrap_when_flat, "wraps past the 16th")


def test_lab02_uint8_overflow_case_alone():
    """A solution that is right except for uint8 arithmetic fails at the overflow case, not before."""
    def uint8_only_when_bright(image, t, n):
        if image[4, 4] == 250:
            return fast_mask(image, np.uint8(t), n, dtype=np.uint8)
        return fast_mask(image, t, n)

    _fails_on_both("02.fast_mask", uint8_only_when_bright, "I_p + t overflows uint8")


def _hint_of(task_id, value):
    res = lab.answer(task_id, value, quiet=True)
    assert res.status == "failed"
    return res.message


def _wall_count_by_kdtree(region_margin):
    """Lab 02's Exploration 2 counted here with SciPy's cKDTree (a second method), on the library's keypoints.

    ``region_margin``: a mapped point is inside an image of width W when -m <= u <= W - 1 + m (0 or 0.5-ish)."""
    from scipy.spatial import cKDTree

    from slamlab_grading.features_checks import _wall_keypoints

    _, pairs = _wall_keypoints()
    rep = np.zeros((5, 4))
    for i, (s1, s2, H, uv) in enumerate(pairs):
        for k, (u1, u2) in enumerate(uv):
            q1 = np.c_[u1, np.ones(len(u1))] @ H.T
            q1 = q1[:, :2] / q1[:, 2:]
            q2 = np.c_[u2, np.ones(len(u2))] @ np.linalg.inv(H).T
            q2 = q2[:, :2] / q2[:, 2:]

            def inside(p, shape):
                return np.all((p >= -region_margin) & (p <= np.array(shape[::-1]) - 1 + region_margin), axis=1)

            a, b = q1[inside(q1, s2)], u2[inside(q2, s1)]
            r1 = np.count_nonzero(cKDTree(b).query(a)[0] < 2.5)
            r2 = np.count_nonzero(cKDTree(a).query(b)[0] < 2.5)
            rep[i, k] = min(r1, r2) / min(len(a), len(b))
    return rep


@pytest.mark.realdata
def test_lab02_wall_range_is_a_brute_force_count_equal_to_the_library(real_data):
    import slamlab as sl
    from slamlab_grading.features_checks import wall_repeatability_brute_force, wall_repeatability_variants
    from slamlab_grading.tasks_features import WALL_REGIONS

    names, rep = wall_repeatability_brute_force()
    ev = sl.studies.features.run_pair_evaluation(("wall",), (2, 3, 4, 5, 6), scale=0.5, n_points=500, progress=False)
    assert names == ev.detectors
    np.testing.assert_allclose(rep, ev.rep[0], rtol=0, atol=1e-12)  # kd-tree count == all pairwise distances
    variants = wall_repeatability_variants((2.5,))
    np.testing.assert_allclose(variants[WALL_REGIONS[0]][0], rep, rtol=0, atol=1e-12)
    best = [float(variants[v][0].mean(axis=0).max()) for v in WALL_REGIONS]
    lo, hi = lab.task("02.explore.wall_repeatability").accepted_range()
    assert (lo, hi) == pytest.approx((min(best) - 0.005, max(best) + 0.005))
    assert hi - lo < 0.02
    # two correct methods: the library's evaluation and a cKDTree count written here, with two region readings,
    # to full precision and to the two decimals asked
    here = [_wall_count_by_kdtree(m).mean(axis=0).max() for m in (0.0, 0.5)]
    np.testing.assert_allclose(here[0], rep.mean(axis=0).max(), atol=1e-12)
    for v in (*here, float(np.nanmean(ev.rep, axis=(0, 1)).max())):
        assert lab.answer("02.explore.wall_repeatability", float(v), quiet=True).passed, v
        assert lab.answer("02.explore.wall_repeatability", round(float(v), 2), quiet=True).passed, v
    means = rep.mean(axis=0)
    for k in range(len(names)):  # any detector's mean to two decimals: only the best one's passes
        assert lab.answer("02.explore.wall_repeatability", round(float(means[k]), 2), quiet=True).passed == (
            means[k] == means.max())
    v = wall_repeatability_variants((2.5,))
    assert "percent" in _hint_of("02.explore.wall_repeatability", 100 * round(float(means.max()), 2))
    assert "one pair's" in _hint_of("02.explore.wall_repeatability", round(float(rep.max()), 2))
    assert "averages the detectors" in _hint_of("02.explore.wall_repeatability", float(rep.mean()))
    # one-to-one (0.469) and the mean of all detectors (0.474) round alike: the hints tell them apart to 3 decimals
    assert "at most one point" in _hint_of("02.explore.wall_repeatability",
                                           round(float(v["one-to-one"][0].mean(axis=0).max()), 3))
    assert "cannot see" in _hint_of("02.explore.wall_repeatability",
                                    round(float(v["no common region"][0].mean(axis=0).max()), 2))


@pytest.mark.realdata
def test_lab02_wall_misconceptions_are_rejected_at_30_tolerances(real_data):
    """Each named mistake, recounted at 30 tolerances (1.5 ... 4.4 px), lies outside that tolerance's range
    (the question's count under every region reading, ± 0.005): no mistake is one by luck at 2.5 px."""
    from slamlab_grading.features_checks import wall_repeatability_variants
    from slamlab_grading.tasks_features import WALL_REGIONS

    tols = tuple(round(1.5 + 0.1 * i, 2) for i in range(30))
    v = wall_repeatability_variants(tols)
    best = np.array([v[r].mean(axis=1).max(axis=1) for r in WALL_REGIONS])  # (3 readings, 30 tolerances)
    lo, hi = best.min(axis=0) - 0.005, best.max(axis=0) + 0.005
    wrong = {"percent": 100 * best[0], "best single pair": v[WALL_REGIONS[0]].max(axis=(1, 2)),
             "mean of all detectors": v[WALL_REGIONS[0]].mean(axis=(1, 2)),
             "one-to-one": v["one-to-one"].mean(axis=1).max(axis=1),
             "no common region": v["no common region"].mean(axis=1).max(axis=1)}
    for name, w in wrong.items():
        inside = [t for t, x, a, b in zip(tols, w, lo, hi, strict=True) if a <= x <= b]
        assert not inside, f"{name} is accepted at {inside} px"


@pytest.mark.realdata
def test_lab02_fast_threshold_two_methods_and_no_nms_rejected_for_30_budgets(real_data):
    import slamlab as sl
    from slamlab_grading.tasks_features import (
        EXPLORE_FAST_THRESHOLDS,
        fast_counts_opencv,
        fast_threshold_opencv,
    )

    lo, hi = lab.task("02.explore.fast_threshold").accepted_range()
    # method 1: the library's detector, from the top of the grid down until the budget is exceeded
    img = sl.features.load_oxford_image("graf", 1, size=(768, 576))
    t_down = None
    for t in EXPLORE_FAST_THRESHOLDS[::-1]:
        if len(sl.features.fast_detect(img, t)) > 1000:
            break
        t_down = t
    # method 2: OpenCV's counts, bisection over the grid (the count falls with t)
    counts = fast_counts_opencv()
    a, b = 0, len(counts) - 1
    while a < b:
        m = (a + b) // 2
        a, b = (a, m) if counts[m] <= 1000 else (m + 1, b)
    for t in (t_down, EXPLORE_FAST_THRESHOLDS[a]):
        assert lo <= t <= hi
        assert lab.answer("02.explore.fast_threshold", t, quiet=True).passed
    assert "non-maximum suppression" in _hint_of("02.explore.fast_threshold", fast_threshold_opencv(nonmax=False))
    for budget in range(600, 3600, 100):  # 30 budgets: counting before suppression never gives the right t
        right, wrong = fast_threshold_opencv(budget=budget), fast_threshold_opencv(nonmax=False, budget=budget)
        assert np.isfinite(right)
        assert wrong != right, budget


# --- lab 03: independent solutions ------------------------------------------------------------------


def two_nn(query, train, *, stable=True):
    M = query.shape[0]
    dist, idx = np.full((M, 2), np.inf), np.full((M, 2), -1)
    if train.shape[0] == 0:
        return dist, idx
    D = np.sqrt(((query[:, None, :] - train[None, :, :]) ** 2).sum(axis=2))
    o = np.argsort(D, axis=1, kind="stable" if stable else "quicksort")[:, :2]
    k = o.shape[1]
    dist[:, :k], idx[:, :k] = np.take_along_axis(D, o, axis=1), o
    return dist, idx


def accept(dist, factor, ratio, max_dist, *, strict_000=False):
    d1, d2 = dist[:, 0], dist[:, 1]
    keep_000 = (d2 > factor * d1) if strict_000 else (d2 >= factor * d1)
    return keep_000 & (d1 <= max_dist), (d1 < ratio * d2) & (d1 <= max_dist)


def hamming(A, B):
    x = A[:, None, :] ^ B[None, :, :]
    return np.unpackbits(x, axis=2).sum(axis=2)


def bbf(tree, q, k, max_leaves, *, plane_bound_only=False):
    import heapq

    t = tree.nodes
    heap, best, leaves = [(0.0, 0)], [], 0
    while heap:
        bound, node = heapq.heappop(heap)
        if len(best) >= k and bound >= best[k - 1][0]:
            break
        while t["left"][node] >= 0:
            diff = q[t["split_dim"][node]] - t["split_val"][node]
            near, far = (t["left"][node], t["right"][node]) if diff <= 0 else (t["right"][node], t["left"][node])
            heapq.heappush(heap, (diff**2 if plane_bound_only else max(bound, diff**2), int(far)))
            node = near
        rows = t["perm"][t["start"][node]:t["stop"][node]]
        d2 = ((t["points"][rows] - q) ** 2).sum(axis=1)
        best = sorted(best + list(zip(d2.tolist(), t["ids"][rows].tolist(), strict=True)))[:k]
        leaves += 1
        if max_leaves is not None and leaves >= max_leaves:
            break
    best += [(np.inf, -1)] * (k - len(best))
    return np.sqrt([b[0] for b in best]), np.array([b[1] for b in best])


@pytest.mark.parametrize(("task_id", "fn"), [("03.two_nn", two_nn), ("03.accept", accept), ("03.hamming", hamming),
                                             ("03.bbf", bbf)])
def test_lab03_correct_solutions_pass(task_id, fn):
    res = lab.check(task_id, fn, quiet=True)
    assert res.passed, res.message


def test_lab03_mistakes():
    def no_padding(query, train):  # breaks with fewer than 2 stored points
        D = np.linalg.norm(query[:, None, :] - train[None, :, :], axis=2)
        o = np.argsort(D, axis=1, kind="stable")[:, :2]
        return np.take_along_axis(D, o, axis=1), o

    def strict(dist, factor, ratio, max_dist):  # 000's ">=" read as ">"
        return accept(dist, factor, ratio, max_dist, strict_000=True)

    def divides(dist, factor, ratio, max_dist):  # d1 / d2 < ratio: 0 / 0 is nan
        d1, d2 = dist[:, 0], dist[:, 1]
        with np.errstate(invalid="ignore", divide="ignore"):
            r = d1 / d2
        return (d2 >= factor * d1) & (d1 <= max_dist), (r < ratio) & (d1 <= max_dist)

    def subtract(A, B):  # |a - b| in uint8 instead of differing bits
        return np.abs(A[:, None, :].astype(int) - B[None, :, :]).sum(axis=2)

    def unbounded(tree, q, k, max_leaves):  # every leaf, whatever max_leaves
        return bbf(tree, q, k, None)

    def no_backtrack(tree, q, k, max_leaves):  # one descent only
        return bbf(tree, q, k, 1)

    _fails_on_both("03.two_nn", no_padding, "(one stored point")
    _fails_on_both("03.accept", strict, "(d2 exactly 2 d1")
    for rng in (0, core.GRADING_RNG):  # the products are safer, but d1/d2 gives the same on every case
        assert lab.check("03.accept", divides, quiet=True, rng=rng).passed
    _fails_on_both("03.hamming", subtract, "case 1 of 5")
    _fails_on_both("03.bbf", unbounded, "(200 points in 4-d, one descent only")
    _fails_on_both("03.bbf", no_backtrack, "case 1 of 7")


@pytest.mark.realdata
@pytest.mark.slow
def test_lab03_budget_range_from_exact_neighbours_over_three_query_sets(real_data):
    import slamlab as sl
    from slamlab_grading.features_checks import bbf_recall_without_distractors
    from slamlab_grading.tasks_features import EXPLORE_BUDGETS, bbf_recall_exact_truth

    curves = bbf_recall_exact_truth(EXPLORE_BUDGETS)
    lib = sl.studies.features.run_recall_vs_leaves(EXPLORE_BUDGETS, n_stored=10000, n_queries=200, progress=False)
    np.testing.assert_array_equal(curves["ranks 0-199"], lib.recall_bbf)  # SciPy's truth == the library's
    firsts = {next(b for b, r in zip(EXPLORE_BUDGETS, c, strict=True) if r >= 0.9) for c in curves.values()}
    lo, hi = lab.task("03.explore.bbf_budget").accepted_range()
    assert (lo, hi) == (min(firsts), max(firsts))
    # a second method: the truth from this file's brute-force 2-NN, the store and queries rebuilt from the question
    from slamlab.studies.features.matching_workload import matching_workload

    _, q, train, _ = matching_workload(10000, 200, "graf", 2, 0.5, 5e-5)
    _, truth = two_nn(q.descriptors.astype(float), train.astype(float))
    tree = sl.kdtree.KDTree(train)
    recall = [np.mean(tree.query(q.descriptors, k=2, max_leaves=b)[1][:, 0] == truth[:, 0]) for b in EXPLORE_BUDGETS]
    mine = next(b for b, r in zip(EXPLORE_BUDGETS, recall, strict=True) if r >= 0.9)
    for answer in (mine, float(lib.budgets[lib.recall_bbf >= 0.9].min())):
        assert lab.answer("03.explore.bbf_budget", answer, quiet=True).passed
    k = EXPLORE_BUDGETS.index(int(lo))
    assert all(c[k - 1] < 0.85 and c[k] >= 0.9 for c in curves.values())  # no knife-edge at the question's budget
    assert "smallest budget that already" in _hint_of("03.explore.bbf_budget", EXPLORE_BUDGETS[-1])
    no_distractors = next(b for b, r in zip(EXPLORE_BUDGETS, bbf_recall_without_distractors(EXPLORE_BUDGETS),
                                            strict=True) if r >= 0.9)
    assert "img1's descriptors alone" in _hint_of("03.explore.bbf_budget", no_distractors)


@pytest.mark.realdata
@pytest.mark.slow
def test_lab03_no_distractors_is_rejected_for_30_query_sets(real_data):
    """The store without distractors gives another budget than the question's store for 30 random sets of 200
    queries (seeds 0-29), not only for the 200 strongest: the mistake is no accident of the query set."""
    from slamlab_grading.features_checks import bbf_found_all_queries
    from slamlab_grading.tasks_features import EXPLORE_BUDGETS

    full, nn_full, _ = bbf_found_all_queries(EXPLORE_BUDGETS)
    alone, nn_alone, _ = bbf_found_all_queries(EXPLORE_BUDGETS, distractors=False)
    for seed in range(30):
        q = np.random.default_rng(seed).choice(full.shape[1], 200, replace=False)
        right = next(b for b, r in zip(EXPLORE_BUDGETS, (full[:, q] == nn_full[q]).mean(axis=1), strict=True)
                     if r >= 0.9)
        wrong = next(b for b, r in zip(EXPLORE_BUDGETS, (alone[:, q] == nn_alone[q]).mean(axis=1), strict=True)
                     if r >= 0.9)
        assert wrong < right, seed


@pytest.mark.realdata
def test_lab03_ratio_range_from_a_brute_force_matcher(real_data):
    import slamlab as sl
    from slamlab_grading.tasks_features import (
        EXPLORE_PRECISION,
        EXPLORE_RATIOS,
        largest_ratio,
        ratio_precision_independent,
    )

    assert EXPLORE_PRECISION == 0.8
    img1, img2, H = sl.features.load_oxford_pair("boat", 2, scale=0.5)
    f1, f2 = (sl.features.detect(i, "surf", max_points=1000, threshold=1e-4) for i in (img1, img2))
    assert len(f1) < 1000  # "at most 1000": every SURF point of the images
    assert len(f2) < 1000
    dist, idx = two_nn(f1.descriptors.astype(float), f2.descriptors.astype(float))  # this file's brute-force 2-NN
    p = np.c_[f1.uv, np.ones(len(f1))] @ H.T
    ok = np.hypot(*(p[:, :2] / p[:, 2:] - f2.uv[idx[:, 0]]).T) < 2.5
    prec = np.array([ok[dist[:, 0] < r * dist[:, 1]].mean() for r in EXPLORE_RATIOS])
    np.testing.assert_allclose(prec, ratio_precision_independent(EXPLORE_RATIOS), atol=1e-12)
    lib = sl.studies.features.run_ratio_tradeoff(EXPLORE_RATIOS, detector="SURF", sequence="boat", j=2)
    np.testing.assert_allclose(prec, lib.precision)
    best = largest_ratio(prec)
    lo, hi = lab.task("03.explore.precise_ratio").accepted_range()
    assert (lo, hi) == pytest.approx((best - 0.005, best + 0.005))
    k = EXPLORE_RATIOS.index(best)
    assert prec[k] >= 0.8 + 0.02  # no knife-edge: several matches either side
    assert prec[k + 1] <= 0.8 - 0.01
    # two methods (brute force here, the library's trade-off), and a grid built by np.arange, all pass
    for answer in (best, float(lib.ratios[lib.precision >= 0.8].max()), 0.3 + 0.05 * k):
        assert lab.answer("03.explore.precise_ratio", answer, quiet=True).passed
    assert "squared distances" in _hint_of("03.explore.precise_ratio",
                                           largest_ratio(ratio_precision_independent(EXPLORE_RATIOS, squared=True)))
    assert "strictest" in _hint_of("03.explore.precise_ratio", min(r for r, q in zip(EXPLORE_RATIOS, prec,
                                                                                       strict=True) if q >= 0.8))


@pytest.mark.realdata
def test_lab03_ratio_misconceptions_are_rejected_at_30_tolerances(real_data):
    """Squared distances and the strictest holding ratio differ from the right answer at every tolerance from
    1.5 to 4.4 px (30 settings), not only at the question's 2.5 px."""
    from slamlab_grading.tasks_features import EXPLORE_RATIOS, largest_ratio, ratio_precision_independent

    for tol in (round(1.5 + 0.1 * i, 2) for i in range(30)):
        prec = ratio_precision_independent(EXPLORE_RATIOS, tol)
        right = largest_ratio(prec)
        squared = largest_ratio(ratio_precision_independent(EXPLORE_RATIOS, tol, squared=True))
        strictest = min(r for r, q in zip(EXPLORE_RATIOS, prec, strict=True) if q >= 0.8)
        assert abs(squared - right) > 0.01, tol
        assert abs(strictest - right) > 0.01, tol


@pytest.mark.parametrize(("task_id", "library"), [
    ("02.integral_image", "slamlab.features.surf_response.integral_image"),
    ("02.box_sum", "slamlab.features.surf_response.box_sums"),
    ("02.hessian", "slamlab.features.surf_response.hessian_response"),
    ("02.fast_mask", "slamlab.features.fast.fast_corner_mask"),
    ("03.two_nn", "slamlab.features.matching.knn2"),
    ("03.accept", "slamlab.features.matching.accept_"),
    ("03.hamming", "slamlab.kdtree."),
    ("03.bbf", "slamlab.kdtree.trace.bbf_trace"),
])
def test_the_library_itself_does_not_pass(task_id, library):
    """The reference (the library's functions wrapped to the task's signature) is caught calling the library."""
    ref = lab.task(task_id).reference
    for rng in (0, core.GRADING_RNG):
        res = lab.check(task_id, ref, quiet=True, rng=rng)
        assert not res.passed
        assert f"called the library's {library}" in res.message, res.message


def test_bbf_may_read_the_trees_arrays_but_not_search_it():
    from slamlab_grading.tasks_features import BBF_TREE_ACCESSORS

    def by_query(tree, q, k, max_leaves):  # the tree's own search
        return tree.query(q, k=k, max_leaves=max_leaves)

    def by_leaf_arrays(tree, q, k, max_leaves):  # the accessors in leaf order: allowed
        assert tree.n == len(tree)
        assert tree.dim == q.size
        assert tree.leaf_points.shape[0] == tree.leaf_ids.size
        return bbf(tree, q, k, max_leaves)

    assert "slamlab.kdtree.tree.KDTree.query" not in BBF_TREE_ACCESSORS
    res = lab.check("03.bbf", by_query, quiet=True)
    assert "called the library's slamlab.kdtree.tree.KDTree.query" in res.message
    assert lab.check("03.bbf", by_leaf_arrays, quiet=True).passed
