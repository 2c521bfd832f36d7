"""Labs 02 and 03 tasks: solutions written from the equations pass, typical mistakes fail at the expected case."""

from __future__ import annotations

import numpy as np
import pytest

from slamlab import lab

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

    assert "case 1 of 5 (random 5x7 image) is wrong: expected shape" in \
        lab.check("02.integral_image", no_zero_border, quiet=True).message
    assert "(a box over the top-left corner" in lab.check("02.box_sum", no_clip, quiet=True).message
    assert "case 1 of 6" in lab.check("02.hessian", no_weight, quiet=True).message
    assert not lab.check("02.fast_mask", uint8, quiet=True).passed  # failed, or error where numpy warns
    assert lab.check("02.fast_mask", no_wrap, quiet=True).status == "failed"  # random images have such arcs


def test_lab02_wrapping_arc_case_alone():
    def no_wrap_when_flat(image, t, n):  # misses wrapping arcs only on the flat test image
        return fast_mask(image, t, n, wrap=len(np.unique(image)) > 2)

    assert "wraps past the 16th" in lab.check("02.fast_mask", no_wrap_when_flat, quiet=True).message


def test_lab02_uint8_overflow_case_alone():
    """A solution that is right except for uint8 arithmetic fails at the overflow case, not before."""
    def uint8_only_when_bright(image, t, n):
        if image[4, 4] == 250:
            return fast_mask(image, np.uint8(t), n, dtype=np.uint8)
        return fast_mask(image, t, n)

    assert "I_p + t overflows uint8" in lab.check("02.fast_mask", uint8_only_when_bright, quiet=True).message


def _hint_of(task_id, value):
    res = lab.answer(task_id, value, quiet=True)
    assert res.status == "failed"
    return res.message


@pytest.mark.realdata
def test_lab02_wall_range_is_a_brute_force_count_equal_to_the_library(real_data):
    import slamlab as sl
    from slamlab.lab.features_checks import wall_repeatability_brute_force

    names, rep = wall_repeatability_brute_force()
    ev = sl.studies.features.run_pair_evaluation(("wall",), (2, 3, 4, 5, 6), scale=0.5, n_points=500, progress=False)
    assert names == ev.detectors
    np.testing.assert_allclose(rep, ev.rep[0], rtol=0, atol=1e-12)  # kd-tree count == all pairwise distances
    means = rep.mean(axis=0)
    best = float(means.max())
    assert lab.task("02.explore.wall_repeatability").accepted_range() == pytest.approx((best - 0.005, best + 0.005))
    for k in range(len(names)):  # any detector's mean to two decimals: only the best one's passes
        assert lab.answer("02.explore.wall_repeatability", round(float(means[k]), 2), quiet=True).passed == (
            means[k] == best)
    assert "percent" in _hint_of("02.explore.wall_repeatability", 100 * round(best, 2))
    assert "one pair's" in _hint_of("02.explore.wall_repeatability", round(float(rep.max()), 2))
    assert "averages the detectors" in _hint_of("02.explore.wall_repeatability", float(rep.mean()))


@pytest.mark.realdata
@pytest.mark.slow
def test_lab02_exploration_answers(real_data):
    import slamlab as sl

    img = sl.features.load_oxford_image("graf", 1, size=(768, 576))
    t = next(t for t in range(5, 105, 5) if len(sl.features.fast_detect(img, t)) <= 1000)
    assert lab.answer("02.explore.fast_threshold", t, quiet=True).passed
    assert lab.answer("02.explore.fast_threshold", t - 5, quiet=True).status == "failed"



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

    assert "(one stored point" in lab.check("03.two_nn", no_padding, quiet=True).message
    assert "(d2 exactly 2 d1" in lab.check("03.accept", strict, quiet=True).message
    assert lab.check("03.accept", divides, quiet=True).passed  # the products are safer, but d1/d2 gives the same
    assert "case 1 of 5" in lab.check("03.hamming", subtract, quiet=True).message
    assert "(200 points in 4-d, one descent only" in lab.check("03.bbf", unbounded, quiet=True).message
    assert "case 1 of 7" in lab.check("03.bbf", no_backtrack, quiet=True).message


@pytest.mark.realdata
def test_lab03_budget_range_from_exact_neighbours_over_three_query_sets(real_data):
    import slamlab as sl
    from slamlab.lab.tasks_features import EXPLORE_BUDGETS, bbf_recall_exact_truth

    curves = bbf_recall_exact_truth(EXPLORE_BUDGETS)
    lib = sl.studies.features.run_recall_vs_leaves(EXPLORE_BUDGETS, n_stored=10000, n_queries=200, progress=False)
    np.testing.assert_array_equal(curves["ranks 0-199"], lib.recall_bbf)  # SciPy's truth == the library's
    firsts = {next(b for b, r in zip(EXPLORE_BUDGETS, c, strict=True) if r >= 0.9) for c in curves.values()}
    lo, hi = lab.task("03.explore.bbf_budget").accepted_range()
    assert (lo, hi) == (min(firsts), max(firsts))
    assert lab.answer("03.explore.bbf_budget", float(lib.budgets[lib.recall_bbf >= 0.9].min()), quiet=True).passed
    k = EXPLORE_BUDGETS.index(int(lo))
    assert all(c[k - 1] < 0.9 for c in curves.values())  # the budget below fails for every query set
    assert "last budget that fails" in _hint_of("03.explore.bbf_budget", EXPLORE_BUDGETS[k - 1])
    assert "smallest budget that already" in _hint_of("03.explore.bbf_budget", EXPLORE_BUDGETS[-1])


@pytest.mark.realdata
def test_lab03_ratio_range_from_a_brute_force_matcher(real_data):
    import slamlab as sl
    from slamlab.lab.tasks_features import EXPLORE_RATIOS, ratio_precision_independent

    img1, img2, H = sl.features.load_oxford_pair("boat", 2, scale=0.5)
    f1, f2 = (sl.features.detect(i, "surf", max_points=1000, threshold=1e-4) for i in (img1, img2))
    dist, idx = two_nn(f1.descriptors, f2.descriptors)  # this file's brute-force 2-NN
    p = np.c_[f1.uv, np.ones(len(f1))] @ H.T
    ok = np.hypot(*(p[:, :2] / p[:, 2:] - f2.uv[idx[:, 0]]).T) < 2.5
    prec = np.array([ok[dist[:, 0] < r * dist[:, 1]].mean() for r in EXPLORE_RATIOS])
    np.testing.assert_allclose(prec, ratio_precision_independent(EXPLORE_RATIOS))
    lib = sl.studies.features.run_ratio_tradeoff(EXPLORE_RATIOS, detector="SURF", sequence="boat", j=2)
    np.testing.assert_allclose(prec, lib.precision)
    holds = [r for r, q in zip(EXPLORE_RATIOS, prec, strict=True) if q >= 0.9]
    lo, hi = lab.task("03.explore.precise_ratio").accepted_range()
    assert (lo, hi) == pytest.approx((max(holds) - 0.005, max(holds) + 0.005))
    assert lab.answer("03.explore.precise_ratio", 0.3 + 0.05 * EXPLORE_RATIOS.index(max(holds)), quiet=True).passed
    first_fail = next(r for r, q in zip(EXPLORE_RATIOS, prec, strict=True) if q < 0.9)
    assert first_fail < max(holds)  # precision is not monotonic: a search stopping at the first failure is wrong
    assert "stopped at the first ratio" in _hint_of("03.explore.precise_ratio", round(first_fail - 0.05, 2))
    assert "first ratio that fails" in _hint_of("03.explore.precise_ratio", round(max(holds) + 0.05, 2))
    assert "strictest" in _hint_of("03.explore.precise_ratio", min(holds))
