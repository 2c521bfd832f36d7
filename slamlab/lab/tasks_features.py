"""Labs 02 and 03 (features, 000 §1.4; 003 §3.1): the tasks and the library functions they are checked against."""

from __future__ import annotations

import numpy as np

from ..features.fast import fast_corner_mask
from ..features.matching import accept_000, accept_ratio, knn2
from ..features.surf import box_sums, hessian_response, integral_image
from ..kdtree import KDTree, bbf_trace, hamming_distances
from .core import Case, ExplorationTask, Task, WrongAnswer, allclose, register
from .features_checks import (
    bbf_recall_exact_truth,
    ratio_precision_independent,
    wall_repeatability_brute_force,
)

# --- lab 02: detectors ------------------------------------------------------------------------------

#: Exploration 1 of lab 02: FAST thresholds tried and the corner budget.
EXPLORE_FAST_THRESHOLDS = tuple(range(5, 105, 5))
EXPLORE_FAST_BUDGET = 1000


def _integral_cases(rng):
    cases = [Case(f"random {h}x{w} image", {"image": rng.random((h, w))}) for h, w in ((5, 7), (12, 9))]
    cases.append(Case("a single pixel: shape (2, 2)", {"image": np.array([[0.25]])}))
    cases.append(Case("one row", {"image": rng.random((1, 6))}))
    cases.append(Case("a constant image", {"image": np.full((4, 3), 0.5)}))
    return cases


def _box_reference(II, r0, r1, c0, c1):
    pad = max(II.shape) + max(abs(r0), abs(r1), abs(c0), abs(c1)) + 1
    return float(box_sums(np.pad(II, pad, mode="edge"), pad, 1, 1, 1, r0, r1, c0, c1)[0, 0])


def _box_cases(rng):
    I = rng.random((10, 13))
    II = integral_image(I)
    cases = [Case("random box inside", {"II": II, "r0": 2, "r1": 7, "c0": 3, "c1": 11}),
             Case("random box inside, one pixel", {"II": II, "r0": 4, "r1": 5, "c0": 9, "c1": 10}),
             Case("the whole image", {"II": II, "r0": 0, "r1": 10, "c0": 0, "c1": 13}),
             Case("an empty box (r0 = r1): 0", {"II": II, "r0": 6, "r1": 6, "c0": 2, "c1": 8}),
             Case("a box over the top-left corner: only the part inside counts",
                  {"II": II, "r0": -4, "r1": 3, "c0": -2, "c1": 5}),
             Case("a box over the bottom-right corner", {"II": II, "r0": 7, "r1": 15, "c0": 10, "c1": 20}),
             Case("a box entirely outside the image: 0", {"II": II, "r0": -9, "r1": -3, "c0": 2, "c1": 6})]
    return cases


def _hessian_reference(II, row, col, L):
    det, trace = hessian_response(II, L, 1)
    return float(det[row, col]), float(trace[row, col])


def _hessian_cases(rng):
    yy, xx = np.mgrid[0:40, 0:40]
    blob = np.exp(-((xx - 20.0) ** 2 + (yy - 19.0) ** 2) / (2 * 3.0**2))
    noise = rng.random((30, 34))
    cases = [Case("random image, L = 9", {"II": integral_image(noise), "row": 14, "col": 17, "L": 9}),
             Case("random image, L = 15", {"II": integral_image(noise), "row": 12, "col": 20, "L": 15}),
             Case("a blob at its centre, L = 9: det > 0, trace < 0", {"II": integral_image(blob), "row": 19,
                                                                      "col": 20, "L": 9}),
             Case("a blob off centre, L = 21 (Dxy != 0)", {"II": integral_image(blob), "row": 15, "col": 24,
                                                           "L": 21}),
             Case("a constant image: det = 0", {"II": integral_image(np.full((20, 20), 0.7)), "row": 10, "col": 10,
                                                "L": 15}),
             Case("near the corner (2, 1): boxes clipped to the image", {"II": integral_image(noise), "row": 2,
                                                                         "col": 1, "L": 9})]
    return cases


def _fast_reference(image, t, n):
    return fast_corner_mask(image, t, n, high_speed=False)


def _fast_cases(rng):
    cases = []
    for n, t in ((9, 20), (12, 15)):
        img = rng.integers(0, 256, (14, 15)).astype(np.uint8)
        img[4:10, 5:11] = rng.integers(100, 140, (6, 6))  # a flat patch with corners
        cases.append(Case(f"random 14x15 image, n = {n}, t = {t}", {"image": img, "t": t, "n": n}))
    sq = np.full((13, 13), 60, np.uint8)
    sq[6:, 6:] = 200
    cases.append(Case("a bright square's corner, n = 9", {"image": sq, "t": 30, "n": 9}))
    hi = np.full((9, 9), 240, np.uint8)
    hi[4, 4] = 250  # I_p + t = 270 overflows uint8 (wraps to 14): every circle pixel looks "brighter"
    cases.append(Case("a bright centre 250 on 240, t = 20: I_p + t overflows uint8", {"image": hi, "t": 20, "n": 9}))
    lo = np.full((9, 9), 15, np.uint8)
    lo[4, 4] = 5  # I_p - t = -15 wraps to 241
    cases.append(Case("a dark centre 5 on 15, t = 20: I_p - t underflows uint8", {"image": lo, "t": 20, "n": 9}))
    eq = np.full((9, 9), 120, np.uint8)
    eq[4, 4] = 100  # every circle pixel exactly I_p + t: not brighter (strict >)
    cases.append(Case("circle exactly I_p + t: ties are not brighter", {"image": eq, "t": 20, "n": 9}))
    wrap = np.full((9, 9), 100, np.uint8)
    ring = np.array([(0, 3), (1, 3), (2, 2), (3, 1), (3, 0), (3, -1), (2, -2), (1, -3), (0, -3), (-1, -3),
                     (-2, -2), (-3, -1), (-3, 0), (-3, 1), (-2, 2), (-1, 3)])
    for k in (12, 13, 14, 15, 0, 1, 2, 3, 4):  # 9 contiguous across the end of the list
        wrap[4 + ring[k, 1], 4 + ring[k, 0]] = 200
    cases.append(Case("an arc of 9 that wraps past the 16th circle pixel", {"image": wrap, "t": 20, "n": 9}))
    cases.append(Case("the same arc needs n <= 9: n = 10 gives no corner", {"image": wrap, "t": 20, "n": 10}))
    cases.append(Case("an image smaller than 7x7: no corner", {"image": rng.integers(0, 256, (6, 8)).astype(np.uint8),
                                                               "t": 10, "n": 9}))
    return cases


register(Task("02.integral_image", "Task 1, the integral image", lambda image: integral_image(image),
              _integral_cases,
              "The integral image is one row and one column larger than the image: its first row "
              "and column are zero, and each entry sums everything above and to the left of it, "
              "excluding its own row and column.", compare=allclose(1e-12, 1e-12)))
register(Task("02.box_sum", "Task 2, a box sum in four look-ups", _box_reference, _box_cases,
              "A box sum needs four entries of the integral image; boxes reaching outside the "
              "image count zero there, so think about what an index below 0 or beyond the size "
              "should become (Python's negative indices wrap around).",
              compare=allclose(1e-12, 1e-12), points=2))
register(Task("02.hessian", "Task 3, the box-filter Hessian at one pixel", _hessian_reference, _hessian_cases,
              "Each second derivative is a sum of boxes scaled by the filter area; check the box "
              "sizes against 000's figure for the given L, that the boxes are half-open, and the "
              "0.81 weight on the mixed term in the determinant.",
              compare=allclose(1e-9, 1e-12), points=3))
register(Task("02.fast_mask", "Task 4, FAST's segment test on every pixel", _fast_reference, _fast_cases,
              "Three things to reason about: the image's integer type overflows when you add the "
              "threshold; 'brighter' and 'darker' are strict comparisons; the circle is closed, "
              "so a run of pixels may wrap past its start. Pixels too close to the border have no"
              " full circle.",
              compare=allclose(0.0, 0.0), points=3))


_GRID_NEXT = ("The question asks for the first value that meets the criterion: check where it changes from failing "
              "to holding.")


def _fast_threshold_for_budget() -> float:
    from ..features import fast_detect, load_oxford_image

    img = load_oxford_image("graf", 1, size=(768, 576))
    for t in EXPLORE_FAST_THRESHOLDS:
        if len(fast_detect(img, t)) <= EXPLORE_FAST_BUDGET:
            return float(t)
    return float("nan")


def fast_threshold_opencv(*, nonmax: bool = True) -> float:
    """Exploration 1 answered with OpenCV's FAST-9 (an independent detector): the smallest grid threshold within budget.

    ``nonmax=False`` counts the corners before non-maximum suppression (a typical wrong reading).

    Parameters
    ----------
    nonmax : bool
        Count corners after OpenCV's non-maximum suppression (the question's reading).

    Returns
    -------
    float
        The smallest threshold of the grid whose corner count is within the budget.
    """
    import cv2

    from ..features import load_oxford_image

    img = np.ascontiguousarray(load_oxford_image("graf", 1, size=(768, 576)), dtype=np.uint8)
    for t in EXPLORE_FAST_THRESHOLDS:
        fd = cv2.FastFeatureDetector_create(threshold=int(t), nonmaxSuppression=nonmax,
                                            type=cv2.FAST_FEATURE_DETECTOR_TYPE_9_16)
        if len(fd.detect(img)) <= EXPLORE_FAST_BUDGET:
            return float(t)
    return float("nan")


def _best_repeatability_wall() -> float:
    from ..studies.features import run_pair_evaluation

    ev = run_pair_evaluation(("wall",), (2, 3, 4, 5, 6), scale=0.5, n_points=500)
    return float(np.nanmax(np.nanmean(ev.rep, axis=(0, 1))))


def _wall_range() -> tuple[float, float]:
    best = float(wall_repeatability_brute_force()[1].mean(axis=0).max())
    return best - 0.005, best + 0.005


register(ExplorationTask(
    "02.explore.fast_threshold",
    "Exploration 1: the smallest FAST threshold t (5, 10, ..., 100) leaving at most 1000 FAST-9 corners on "
    "graf/img1 at 768x576",
    _fast_threshold_for_budget, accepted=lambda: (fast_threshold_opencv(),) * 2,
    why="exactly the grid value OpenCV's FAST-9 with non-maximum suppression gives (an independent detector; its "
        "counts equal the library's at every threshold of the grid): the count falls monotonically with t, so any "
        "search over the grid 5, 10, ..., 100 (a loop, a sweep, a bisection) finds the same t.",
    hint="the corner count falls as the threshold rises; the budget is met by every threshold from some value on, "
         "and the question asks for the smallest of them, on the image and size the question names.",
    more="Count corners after non-maximum suppression, as a tracker would use them.",
    wrong=(WrongAnswer("the last threshold over budget", lambda: fast_threshold_opencv() - 5.0,
                       hint="at that threshold there are still more than 1000 corners: it is the last one over the "
                            "budget.", more=_GRID_NEXT),
           WrongAnswer("no non-maximum suppression", lambda: fast_threshold_opencv(nonmax=False),
                       hint="that threshold fits the budget only if clusters of neighbouring corners are counted "
                            "one by one: count the corners left after non-maximum suppression."))))
register(ExplorationTask(
    "02.explore.wall_repeatability",
    "Exploration 2: the best mean repeatability of the four detectors on wall 1→2 ... 1→6",
    _best_repeatability_wall, atol=0.005, accepted=_wall_range,  # atol: the decimals a message shows
    why="a brute-force recount (not the library's kd-tree evaluation) ± 0.005, the two decimals asked for: the "
        "library's keypoints (500 strongest, half scale) mapped through the sequence's ground-truth homographies, "
        "the common region of both images, every pairwise distance against the 2.5 px tolerance, min(repeated) / "
        "min(n1, n2) per pair, averaged over the five pairs, best detector. The question fixes images, points and "
        "tolerance, so every correct method gives this number; the recount equals the library's to 1e-12.",
    hint="repeatability is a fraction between 0 and 1 per image pair; average each detector over the five pairs and "
         "give the best detector's average.",
    more="The best detector is the one with the largest mean, not the largest single pair.",
    wrong=(WrongAnswer("percent", lambda: 100.0 * float(wall_repeatability_brute_force()[1].mean(axis=0).max()),
                       rtol=0.02, hint="check the unit: repeatability is asked as a fraction, not in percent."),
           WrongAnswer("the best single pair", lambda: float(wall_repeatability_brute_force()[1].max()), atol=0.005,
                       hint="that is one pair's repeatability: the question asks for a detector's mean over the "
                            "five pairs."),
           WrongAnswer("the mean of all detectors", lambda: float(wall_repeatability_brute_force()[1].mean()),
                       atol=0.005, hint="that averages the detectors together: compare the detectors' means and "
                                        "give the best one's."))))


# --- lab 03: matching -------------------------------------------------------------------------------

#: Exploration budgets of lab 03 (BBF leaves) and the ratios tried.
EXPLORE_BUDGETS = (1, 2, 5, 10, 20, 50, 100, 200, 500, 1000)
EXPLORE_RATIOS = tuple(round(0.3 + 0.05 * i, 2) for i in range(15))


def _two_nn_cases(rng):
    cases = [Case(f"random, {m} queries, {n} stored, d = {d}", {"query": rng.normal(size=(m, d)),
                                                                 "train": rng.normal(size=(n, d))})
             for m, n, d in ((4, 10, 3), (7, 30, 8))]
    train = rng.normal(size=(6, 4))
    cases.append(Case("a query equal to a stored point: d1 = 0", {"query": train[[2, 5]] + [[0, 0, 0, 0], [0.1, 0, 0, 0]],
                                                                 "train": train}))
    dup = np.vstack([train[:3], train[1:2], train[3:]])  # rows 1 and 3 are the same point
    cases.append(Case("duplicate stored points: equal distances, the lower index first",
                      {"query": train[1:2] + 0.05, "train": dup}))
    cases.append(Case("one stored point: second neighbour inf, index -1",
                      {"query": rng.normal(size=(3, 4)), "train": rng.normal(size=(1, 4))}))
    cases.append(Case("no stored point: all inf, -1", {"query": rng.normal(size=(2, 4)), "train": np.zeros((0, 4))}))
    return cases


def _accept_reference(dist, factor, ratio, max_dist):
    keep_000 = accept_000(dist, factor=factor, max_dist=max_dist)
    keep_ratio = accept_ratio(dist, ratio) & (dist[:, 0] <= max_dist)
    return keep_000.astype(float), keep_ratio.astype(float)


def _accept_cases(rng):
    d1 = rng.uniform(0.05, 0.5, 12)
    d = np.column_stack([d1, d1 * rng.uniform(1.0, 3.0, 12)])
    cases = [Case("random distances, factor 2, ratio 0.8, no limit", {"dist": d, "factor": 2.0, "ratio": 0.8,
                                                                       "max_dist": np.inf}),
             Case("random distances, factor 1.5, ratio 0.6, d1 <= 0.3", {"dist": d, "factor": 1.5, "ratio": 0.6,
                                                                          "max_dist": 0.3}),
             Case("d2 exactly 2 d1: 000 accepts (>=), ratio 0.5 rejects (<)",
                  {"dist": np.array([[0.125, 0.25], [0.25, 0.5]]), "factor": 2.0, "ratio": 0.5, "max_dist": np.inf}),
             Case("d1 exactly max_dist: accepted (<=)", {"dist": np.array([[0.25, 1.0]]), "factor": 2.0, "ratio": 0.8,
                                                         "max_dist": 0.25}),
             Case("duplicates d1 = d2 = 0: 000 accepts (0 >= 0), ratio rejects (0 < 0 is false)",
                  {"dist": np.array([[0.0, 0.0], [0.0, 0.1]]), "factor": 2.0, "ratio": 0.8, "max_dist": 0.3}),
             Case("one stored point (d2 = inf) and none (d1 = d2 = inf)",
                  {"dist": np.array([[0.2, np.inf], [np.inf, np.inf]]), "factor": 2.0, "ratio": 0.8,
                   "max_dist": 0.3}),
             Case("no queries: empty results", {"dist": np.zeros((0, 2)), "factor": 2.0, "ratio": 0.8,
                                                "max_dist": np.inf})]
    return cases


def _hamming_cases(rng):
    cases = [Case(f"random {m} x {n} descriptors of {b} bytes",
                  {"A": rng.integers(0, 256, (m, b)).astype(np.uint8), "B": rng.integers(0, 256, (n, b)).astype(np.uint8)})
             for m, n, b in ((3, 5, 4), (6, 4, 32))]
    cases.append(Case("0 against 255: 8 bits per byte, not 255 (uint8 arithmetic wraps)",
                      {"A": np.zeros((1, 3), np.uint8), "B": np.array([[255, 255, 255], [1, 128, 0]], np.uint8)}))
    cases.append(Case("bytes that differ in several bits count every bit",
                      {"A": np.array([[0b1011, 0b11110000]], np.uint8), "B": np.array([[0b0100, 0b00001111]], np.uint8)}))
    same = rng.integers(0, 256, (2, 8)).astype(np.uint8)
    cases.append(Case("identical descriptors: 0", {"A": same, "B": same}))
    return cases


def _bbf_reference(tree, q, k, max_leaves):
    d, ids, _ = bbf_trace(tree, q, k=k, max_leaves=max_leaves)
    return d, ids.astype(float)


def _bbf_compare(expected, received):
    base = allclose(1e-9, 1e-12)
    if not isinstance(received, (tuple, list)) or len(received) != 2:
        return base(expected, received)
    diff = base(expected[0], received[0])
    if diff is not None:
        return f"item 0 of the returned tuple (distances): {diff}"
    e_ids = np.asarray(expected[1], dtype=float)
    try:
        r_ids = np.asarray(received[1], dtype=float)
    except (TypeError, ValueError):
        return f"expected integer ids; got {type(received[1]).__name__}"
    if r_ids.shape != e_ids.shape:
        return f"item 1 of the returned tuple (ids): expected shape {e_ids.shape}; got shape {r_ids.shape}"
    d = np.asarray(expected[0])
    unique = np.array([np.count_nonzero(d == x) == 1 for x in d])  # tied distances: any of the tied ids
    bad = np.flatnonzero(unique & (r_ids != e_ids))
    if bad.size:
        i = int(bad[0])
        return f"item 1 of the returned tuple (ids): at index {i} expected {int(e_ids[i])}, got {r_ids[i]:g}"
    return None


def _bbf_cases(rng):
    cases = []
    X = rng.random((30, 2)) * [2.0, 1.0]
    cases.append(Case("30 points in 2-d, exact (max_leaves None)", {"tree": KDTree(X), "q": np.array([1.1, 0.45]),
                                                                     "k": 2, "max_leaves": None}))
    Y = rng.normal(size=(200, 4))
    t4 = KDTree(Y)
    q = rng.normal(size=4)
    cases.append(Case("200 points in 4-d, one descent only (max_leaves 1)", {"tree": t4, "q": q, "k": 2,
                                                                              "max_leaves": 1}))
    cases.append(Case("200 points in 4-d, backtracking 6 leaves", {"tree": t4, "q": q, "k": 2, "max_leaves": 6}))
    cases.append(Case("200 points in 4-d, k = 3, exact", {"tree": t4, "q": rng.normal(size=4), "k": 3,
                                                           "max_leaves": None}))
    cases.append(Case("buckets of 4 points (leaf_size 4), 3 leaves", {"tree": KDTree(Y, leaf_size=4),
                                                                       "q": rng.normal(size=4), "k": 2,
                                                                       "max_leaves": 3}))
    cases.append(Case("k = 5 > 3 stored points: pad with inf and -1", {"tree": KDTree(rng.random((3, 2))),
                                                                        "q": np.array([0.5, 0.5]), "k": 5,
                                                                        "max_leaves": None}))
    D = np.repeat(rng.random((4, 2)), 3, axis=0)  # every point three times
    cases.append(Case("duplicate points: ties (any of the tied ids)", {"tree": KDTree(D), "q": D[5] + 0.01, "k": 2,
                                                                       "max_leaves": None}))
    return cases


register(Task("03.two_nn", "Task 1, exact 2-NN by brute force", lambda query, train: knn2(query, train),
              _two_nn_cases,
              "Each query needs its two nearest stored descriptors in order; when two distances "
              "are equal the lower index comes first, and when fewer than two are stored the "
              "result still has two columns (with a marker for 'none').",
              compare=allclose(1e-9, 1e-12), points=2))
register(Task("03.accept", "Task 2, 000's rule and Lowe's ratio test", _accept_reference, _accept_cases,
              "Each criterion is a comparison of the two distances; a distance can be 0 or "
              "infinite, so think about which form of the comparison stays defined then. Both "
              "criteria also need the absolute distance limit.",
              compare=allclose(0.0, 0.0), points=2))
register(Task("03.hamming", "Task 3, Hamming distances of packed binary descriptors",
              lambda A, B: hamming_distances(A, B), _hamming_cases,
              "The distance counts differing bits, not differing bytes; subtracting unsigned "
              "bytes wraps around instead of giving a difference.",
              compare=allclose(0.0, 0.0), points=2))
register(Task("03.bbf", "Task 4, Best-Bin-First: descent and backtracking", _bbf_reference, _bbf_cases,
              "Check the stopping rule (the bound against the k-th best distance so far, and the "
              "leaf budget), which child is the near one when the query lies exactly on the "
              "split, and the bound you store with the far child.",
              compare=_bbf_compare, points=3))


def _smallest_budget_90() -> float:
    from ..studies.features import run_recall_vs_leaves

    c = run_recall_vs_leaves(EXPLORE_BUDGETS, n_stored=10000, n_queries=200)
    ok = c.budgets[c.recall_bbf >= 0.9]
    return float(ok.min()) if ok.size else float("nan")


def _largest_precise_ratio() -> float:
    from ..studies.features import run_ratio_tradeoff

    tr = run_ratio_tradeoff(EXPLORE_RATIOS, detector="SURF", sequence="boat", j=2)
    ok = tr.ratios[tr.precision >= 0.9]
    return float(ok.max()) if ok.size else float("nan")


def _budget_range() -> tuple[float, float]:
    first = [min(b for b, r in zip(EXPLORE_BUDGETS, rec, strict=True) if r >= 0.9)
             for rec in bbf_recall_exact_truth(EXPLORE_BUDGETS).values()]
    return float(min(first)), float(max(first))


def _precise_ratios() -> list[float]:
    return [r for r, p in zip(EXPLORE_RATIOS, ratio_precision_independent(EXPLORE_RATIOS), strict=True) if p >= 0.9]


def _first_failing_ratio() -> float:
    return next(r for r, p in zip(EXPLORE_RATIOS, ratio_precision_independent(EXPLORE_RATIOS), strict=True) if not p >= 0.9)


register(ExplorationTask(
    "03.explore.bbf_budget",
    "Exploration 1: the smallest BBF leaf budget reaching 90 % nearest-neighbour recall with 10000 stored "
    "descriptors",
    _smallest_budget_90, accepted=_budget_range,
    why="the grid budgets at which the library's BBF first reaches 90 % recall when the true nearest neighbours come "
        "from SciPy's exact cKDTree (not the library's brute force), over three query sets of img2 (the 200 "
        "strongest, ranks 200-399, ranks 400-599): all three land on the same budget, so which 200 of img2's "
        "queries a student takes does not change it. Recall at the budget below is near 0.8 for every set.",
    hint="recall is the share of queries whose true nearest neighbour BBF finds; it grows with the leaf budget. "
         "The question asks for the smallest budget of the grid at which it reaches 90 %.",
    more="Compare BBF's result with the exact nearest neighbour, not with the ratio-test matches.",
    wrong=(WrongAnswer("the last budget below 90 %",
                       lambda: float(EXPLORE_BUDGETS[EXPLORE_BUDGETS.index(int(_budget_range()[0])) - 1]),
                       hint="at that budget the recall is still below 90 %: it is the last budget that fails.",
                       more=_GRID_NEXT),
           WrongAnswer("the largest budget tried", lambda: float(EXPLORE_BUDGETS[-1]),
                       hint="the largest budget of the grid gives the best recall, but the question asks for the "
                            "smallest budget that already reaches 90 %."))))
register(ExplorationTask(
    "03.explore.precise_ratio",
    "Exploration 2: the largest ratio (0.30, 0.35, ..., 1.00) keeping SURF's match precision >= 0.9 on boat 1→2",
    _largest_precise_ratio, atol=0.005,
    accepted=lambda: (max(_precise_ratios()) - 0.005, max(_precise_ratios()) + 0.005),
    why="the largest grid ratio with precision >= 0.9 from an independent matcher (SciPy cKDTree's two nearest "
        "neighbours of the library's SURF descriptors, Lowe's rule, correctness from the ground-truth homography), "
        "± 0.005 for a ratio computed in floating point; it equals the library's value. Precision is not monotonic "
        "here: it dips below 0.9 at a smaller ratio and recovers, so a search that stops at the first failure ends "
        "too early and is rejected.",
    hint="precision is the share of kept matches that are correct; a looser ratio keeps more matches. Precision "
         "need not fall monotonically: check every ratio of the grid, not only until the first failure.",
    more="The largest qualifying ratio can lie beyond a ratio that fails.",
    wrong=(WrongAnswer("the first ratio that fails after the answer",
                       lambda: round(max(_precise_ratios()) + 0.05, 2), atol=1e-6,
                       hint="at that ratio the precision is already below 0.9: it is the first ratio that fails, "
                            "not the last that holds."),
           WrongAnswer("stopped at the first failure", lambda: round(_first_failing_ratio() - 0.05, 2), atol=1e-6,
                       hint="precision holds there, but the search stopped at the first ratio that fails; a looser "
                            "ratio further on holds again."),
           WrongAnswer("the smallest ratio that holds", lambda: float(min(_precise_ratios())), atol=1e-6,
                       hint="that is the strictest ratio that holds: the question asks for the loosest one."))))
