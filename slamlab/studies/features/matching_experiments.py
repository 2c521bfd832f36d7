"""Ch. 3 experiments (000 §1.4.3, §3.3): descriptor matching on the Oxford affine pairs -- exact vs BBF vs FLANN vs
brute-force k-NN, recall against the leaf budget, the ratio test's trade-off.

Each ``run_*`` returns a frozen dataclass: ``str(result)`` is a one-line summary, ``result.table()`` a
fixed-precision text table (what the notebook prints and nbval compares); timings live in a separate ``times_s``
field, never in a table. ``scale`` downsizes the images to keep notebook runs short.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np

from ..._progress import progress_bar
from ..._table import format_table
from ..._validate import as_vector, check_choice, check_int
from ...features.evaluation import (
    correct_matches,
    load_oxford_pair,
    oxford_label,
    repeatability,
)
from ...features.matching import accept_000, accept_ratio, knn2
from ...kdtree.knn import flann_index
from .experiments import EVAL_DETECTORS, detect_for_evaluation
from .matching_workload import descriptor_pool, matching_workload, surf_features

__all__ = [
    "KnnComparisonResult",
    "LeavesCurveResult",
    "RatioTradeoffResult",
    "descriptor_pool",
    "matching_vs_source",
    "run_knn_comparison",
    "run_ratio_tradeoff",
    "run_recall_vs_leaves",
    "surf_features",
]


# --- descriptor matching: exact vs BBF vs FLANN vs brute ---------------------------------------------


@dataclass(frozen=True)
class KnnComparisonResult:
    """Per store size and method: recall of the true nearest neighbour, precision after the ratio rule.

    Attributes
    ----------
    sizes : tuple of int
        Stored descriptors per run.
    methods : tuple of str
        Search labels (:data:`KNN_LABELS`).
    n_queries : int
        Query descriptors per run.
    recall : (n_sizes, n_methods) float
        Fraction of queries whose nearest neighbour equals brute force's (NaN = not run).
    precision : (n_sizes, n_methods) float
        Correct fraction of the matches accepted by ratio 0.8.
    n_matches : (n_sizes, n_methods) float
        Matches accepted by ratio 0.8.
    evals : (n_sizes, n_methods) float
        Mean distance evaluations per query (our trees; NaN otherwise).
    times_s : (n_sizes, n_methods) float
        Search time in seconds for all queries (machine dependent).
    """

    sizes: tuple[int, ...]
    methods: tuple[str, ...]
    n_queries: int
    recall: np.ndarray = field(repr=False)  # (n_sizes, n_methods); NaN = not run
    precision: np.ndarray = field(repr=False)
    n_matches: np.ndarray = field(repr=False)
    evals: np.ndarray = field(repr=False)  # mean distance evaluations per query (ours); NaN otherwise
    times_s: np.ndarray = field(default=None, repr=False, compare=False)

    def __str__(self) -> str:
        return f"{self.n_queries} SURF queries against {', '.join(map(str, self.sizes))} stored descriptors"

    def table(self) -> str:
        """NN recall, matches, precision and distance evaluations per store size and method (stable).

        Returns
        -------
        str
            Fixed-precision text table.
        """
        rows = []
        for i, n in enumerate(self.sizes):
            for k, m in enumerate(self.methods):
                if not np.isfinite(self.recall[i, k]):
                    rows.append([str(n), m, "—", "—", "—", "—"])
                    continue
                ev = "—" if not np.isfinite(self.evals[i, k]) else f"{self.evals[i, k]:.0f}"
                rows.append([str(n), m, f"{self.recall[i, k]:.3f}", str(int(self.n_matches[i, k])),
                             f"{self.precision[i, k]:.3f}", ev])
        return format_table(["stored", "method", "NN recall", "matches", "precision", "dist. evals/query"], rows,
                            f"{self.n_queries} queries, 2-NN + ratio 0.8; NN recall = same nearest as brute force")

    def timing_table(self) -> str:
        """Search time per store size and method, and its ratio to brute force (machine dependent).

        Returns
        -------
        str
            Milliseconds per batch of queries.
        """
        rows = []
        for i, n in enumerate(self.sizes):
            brute = self.times_s[i, self.methods.index("brute")] if "brute" in self.methods else np.nan
            for k, m in enumerate(self.methods):
                t = self.times_s[i, k]
                if np.isfinite(t):
                    rows.append([str(n), m, f"{1000 * t:.1f}", f"{t / brute:.2f}" if np.isfinite(brute) else "—"])
        return format_table(["stored", "method", f"time per {self.n_queries} queries [ms]", "/ brute"], rows)


KNN_LABELS = ("brute", "kd-tree exact (ours)", "cKDTree exact (scipy)", "BBF 200 leaves (ours)",
              "FLANN kd checks=200")


def run_knn_comparison(sizes=(2000, 13000), *, n_queries: int = 500, max_leaves: int = 200, checks: int = 200,
                       max_exact_ours: int = 2000, sequence: str = "graf", j: int = 2, scale: float = 0.5,
                       threshold: float = 5e-5, tol_px: float = 2.5, progress: bool | None = None) -> KnnComparisonResult:
    """Exact kd-tree vs BBF vs FLANN vs brute force on real SURF descriptors (000 §1.4.3).

    The store holds img1's descriptors of ``sequence`` plus distractors from the
    other sequences up to each size; the queries are img_j's strongest
    ``n_queries``. Our exact tree runs only up to ``max_exact_ours`` points (in 64-d
    it visits nearly every leaf and the lock-step numpy search is then slow). ``progress``: a bar
    over the sizes (None: on unless ``$SLAMLAB_PROGRESS=0``).

    Parameters
    ----------
    sizes : sequence of int
        Store sizes (>= 10 descriptors each).
    n_queries : int
        Strongest img_j keypoints used as queries.
    max_leaves : int
        BBF leaf budget.
    checks : int
        FLANN checks.
    max_exact_ours : int
        Largest store our exact kd-tree is run on.
    sequence : str
        Shared Oxford sequence.
    j : int
        Query image number (img1 → img_j).
    scale : float
        Image resize factor.
    threshold : float
        SURF Hessian threshold on our scale.
    tol_px : float
        Correct-match tolerance in image-j pixels.
    progress : bool, callable or None
        Progress bar over the sizes.

    Returns
    -------
    KnnComparisonResult
        ``recall``, ``precision``, ``evals`` and ``times_s`` per (size, method).
    """
    from scipy.spatial import cKDTree

    from ...kdtree import KDTree

    sizes = tuple(check_int(n, "sizes", minimum=10) for n in sizes)
    n_queries = check_int(n_queries, "n_queries", minimum=1)
    shape = (len(sizes), len(KNN_LABELS))
    rec, prec, nm, ev, tm = (np.full(shape, np.nan) for _ in range(5))
    for i, n in enumerate(progress_bar(sizes, desc="kNN comparison", progress=progress)):
        f1, q, train, H = matching_workload(n, n_queries, sequence, j, scale, threshold)
        Q = q.descriptors
        t0 = time.perf_counter()
        d_ref, i_ref = knn2(Q, train, method="brute")
        tm[i, 0] = time.perf_counter() - t0
        results = {0: (d_ref, i_ref, np.nan)}
        if n <= max_exact_ours:
            tree = KDTree(train)
            t0 = time.perf_counter()
            d, idx = tree.query(Q, k=2)
            tm[i, 1] = time.perf_counter() - t0
            results[1] = (d, idx, tree.last_stats.mean_distance_evals)
        ck = cKDTree(train.astype(np.float64))
        t0 = time.perf_counter()
        d, idx = ck.query(Q.astype(np.float64), k=2)
        tm[i, 2] = time.perf_counter() - t0
        results[2] = (d, idx, np.nan)
        tree = KDTree(train)
        t0 = time.perf_counter()
        d, idx = tree.query(Q, k=2, max_leaves=max_leaves)
        tm[i, 3] = time.perf_counter() - t0
        results[3] = (d, idx, tree.last_stats.mean_distance_evals)
        fl = flann_index(train, trees=1)
        t0 = time.perf_counter()
        d, idx = knn2(Q, train, method="flann", checks=checks, tree=fl)
        tm[i, 4] = time.perf_counter() - t0
        results[4] = (d, idx, np.nan)
        for k, (d, idx, e) in results.items():
            rec[i, k] = np.mean(idx[:, 0] == i_ref[:, 0])
            keep = accept_ratio(d, 0.8)
            qi = np.flatnonzero(keep)
            ti = idx[qi, 0]
            true = ti < len(f1)
            from ...features.evaluation import project

            ok = np.zeros(qi.size, dtype=bool)
            if true.any():
                p = project(H, f1.uv[ti[true]])
                ok[true] = np.linalg.norm(p - q.uv[qi[true]], axis=1) < tol_px
            nm[i, k] = qi.size
            prec[i, k] = ok.mean() if qi.size else np.nan
            ev[i, k] = e
    return KnnComparisonResult(sizes, KNN_LABELS, n_queries, rec, prec, nm, ev, tm)


@dataclass(frozen=True)
class LeavesCurveResult:
    """Recall of the true nearest neighbour against the search budget: our BBF (leaves) and FLANN (checks).

    Attributes
    ----------
    n_stored : int
        Stored descriptors.
    n_queries : int
        Query descriptors.
    budgets : (n,) int
        Leaf budgets (BBF ``max_leaves``, FLANN ``checks``).
    recall_bbf, recall_flann : (n,) float
        Fraction of queries whose nearest neighbour equals brute force's.
    evals_bbf : (n,) float
        Mean distance evaluations per query of BBF.
    exact_evals : float
        Mean distance evaluations per query of the exact search (50 queries).
    times_s : (n,) float
        BBF search time in seconds per budget (machine dependent).
    """

    n_stored: int
    n_queries: int
    budgets: np.ndarray
    recall_bbf: np.ndarray
    recall_flann: np.ndarray
    evals_bbf: np.ndarray
    exact_evals: float
    times_s: np.ndarray = field(default=None, repr=False, compare=False)

    def __str__(self) -> str:
        return (f"BBF on {self.n_stored} SURF descriptors: recall {self.recall_bbf[-1]:.3f} at "
                f"{int(self.budgets[-1])} leaves; exact search evaluates {self.exact_evals:.0f} points per query")

    def table(self) -> str:
        """BBF and FLANN recall and BBF distance evaluations per budget (stable).

        Returns
        -------
        str
            Fixed-precision text table.
        """
        rows = [[str(int(b)), f"{rb:.3f}", f"{rf:.3f}", f"{e:.0f}"]
                for b, rb, rf, e in zip(self.budgets, self.recall_bbf, self.recall_flann, self.evals_bbf,
                                        strict=True)]
        return format_table(["max_leaves / checks", "BBF recall", "FLANN recall", "BBF dist. evals"], rows,
                            f"{self.n_queries} queries, {self.n_stored} stored 64-d SURF descriptors")


def run_recall_vs_leaves(budgets=(1, 2, 5, 10, 20, 50, 100, 200, 500, 1000), *, n_stored: int = 5000,
                         n_queries: int = 300, sequence: str = "graf", j: int = 2, scale: float = 0.5,
                         threshold: float = 5e-5, progress: bool | None = None) -> LeavesCurveResult:
    """Recall of BBF and FLANN against the number of leaves / checks (000 §1.4.3: "about 200").

    ``progress``: a bar over the budgets (None: on unless ``$SLAMLAB_PROGRESS=0``).

    Parameters
    ----------
    budgets : sequence of int
        Leaf budgets (>= 1).
    n_stored : int
        Store size (img1 descriptors plus distractors).
    n_queries : int
        Strongest img_j keypoints used as queries.
    sequence : str
        Shared Oxford sequence.
    j : int
        Query image number.
    scale : float
        Image resize factor.
    threshold : float
        SURF Hessian threshold on our scale.
    progress : bool, callable or None
        Progress bar over the budgets.

    Returns
    -------
    LeavesCurveResult
        ``recall_bbf`` and ``recall_flann`` per budget.
    """

    from ...kdtree import KDTree

    budgets = np.array([check_int(b, "budgets", minimum=1) for b in budgets])
    _, q, train, _ = matching_workload(n_stored, n_queries, sequence, j, scale, threshold)
    Q = q.descriptors
    _, i_ref = knn2(Q, train, method="brute")
    tree = KDTree(train)
    fl = flann_index(train, trees=1)
    rb, rf, eb, tm = [], [], [], []
    for b in progress_bar(budgets, desc="recall vs leaves", progress=progress):
        t0 = time.perf_counter()
        _, idx = tree.query(Q, k=2, max_leaves=int(b))
        tm.append(time.perf_counter() - t0)
        rb.append(np.mean(idx[:, 0] == i_ref[:, 0]))
        eb.append(tree.last_stats.mean_distance_evals)
        _, idf = knn2(Q, train, method="flann", checks=int(b), tree=fl)
        rf.append(np.mean(idf[:, 0] == i_ref[:, 0]))
    # exact search work on a subset of the queries (it is slow in 64-d)
    tree.query(Q[:50], k=2)
    exact = tree.last_stats.mean_distance_evals
    return LeavesCurveResult(len(train), len(Q), budgets, np.array(rb), np.array(rf), np.array(eb), exact,
                             np.array(tm))


@dataclass(frozen=True)
class RatioTradeoffResult:
    """Precision and recall of the matches against the ratio (000's 2× rule = ratio 0.5).

    Attributes
    ----------
    detector : str
        Detector name.
    pair : str
        Pair label (sequence, 1→j, scale).
    ratios : (n,) float
        Ratios, ascending.
    precision, recall : (n,) float
        Match precision and recall per ratio.
    n_matches : (n,) int
        Accepted matches per ratio.
    correspondences : int
        Repeatable points of the pair (recall's denominator).
    source_row : tuple
        (matches, precision, recall, max_dist) of 000's rule with ``max_dist``.
    """

    detector: str
    pair: str
    ratios: np.ndarray
    precision: np.ndarray
    recall: np.ndarray
    n_matches: np.ndarray
    correspondences: int
    source_row: tuple  # (matches, precision, recall) of 000's rule with max_dist

    def __str__(self) -> str:
        return f"{self.detector} on {self.pair}: {self.correspondences} repeatable points"

    def table(self) -> str:
        """Matches, precision and recall per ratio, and 000's rule as the last row.

        Returns
        -------
        str
            Fixed-precision text table.
        """
        rows = [[f"{r:.2f}", str(int(n)), f"{p:.3f}", f"{rc:.3f}"]
                for r, n, p, rc in zip(self.ratios, self.n_matches, self.precision, self.recall, strict=True)]
        m, p, rc, md = self.source_row
        rows.append([f"000: d2>=2d1, d1<={md:g}", str(m), f"{p:.3f}", f"{rc:.3f}"])
        return format_table(["ratio d1/d2 <", "matches", "precision", "recall"], rows,
                            f"{self.detector}, {self.pair}: ratio rule trade-off")


def run_ratio_tradeoff(ratios=(0.3, 0.4, 0.5, 0.6, 0.7, 0.8, 0.9, 1.0), *, detector: str = "SURF",
                       sequence: str = "graf", j: int = 2, scale: float = 0.5, n_points: int = 1000,
                       tol_px: float = 2.5, max_dist: float = 0.3) -> RatioTradeoffResult:
    """Precision/recall of the ratio rule and of 000's rule with an absolute limit (000 §1.4.3).

    Parameters
    ----------
    ratios : sequence of float
        Lowe ratios to score.
    detector : str
        Key of :data:`EVAL_DETECTORS`.
    sequence : str or os.PathLike
        Oxford sequence.
    j : int
        Second image number.
    scale : float
        Image resize factor.
    n_points : int
        Strongest keypoints kept per image.
    tol_px : float
        Correct-match tolerance in image-j pixels.
    max_dist : float
        000's absolute limit on d1 (times 256 for ORB's Hamming distances).

    Returns
    -------
    RatioTradeoffResult
        Precision, recall and matches per ratio plus 000's rule in ``source_row``.
    """
    detector = check_choice(detector, "detector", tuple(EVAL_DETECTORS))
    ratios = np.sort(as_vector(ratios, "ratios"))
    img1, img2, H = load_oxford_pair(sequence, j, scale=scale)
    f1, _ = detect_for_evaluation(img1, detector, n_points)
    f2, _ = detect_for_evaluation(img2, detector, n_points)
    r = repeatability(f1, f2, H, img1.shape, img2.shape, tol_px=tol_px)
    d, idx = knn2(f1.descriptors, f2.descriptors)
    from ...features.matching import Matches

    def score(keep):
        q = np.flatnonzero(keep & (idx[:, 0] >= 0))
        m = Matches(q, idx[q, 0], d[q, 0], d[q, 1])
        c = correct_matches(f1, f2, m, H, tol_px=tol_px)
        return len(q), (c.mean() if len(q) else np.nan), (c.sum() / r.correspondences if r.correspondences else
                                                          np.nan)

    res = [score(accept_ratio(d, float(x))) for x in ratios]
    n, p, rc = (np.array(col) for col in zip(*res, strict=True))
    md = float(max_dist) if detector != "ORB" else float(max_dist) * 256
    src = score(accept_000(d, max_dist=md))
    return RatioTradeoffResult(detector, f"{oxford_label(sequence)} 1→{j} x{scale:g}", ratios, p, rc, n, r.correspondences,
                               (src[0], src[1], src[2], md))


def matching_vs_source(curve: LeavesCurveResult, trade: RatioTradeoffResult, knn: KnnComparisonResult) -> str:
    """000 §1.4.3's statements on kd-tree search and the 2× rule beside our numbers from the chapter's runs.

    Parameters
    ----------
    curve : LeavesCurveResult
        From :func:`run_recall_vs_leaves`.
    trade : RatioTradeoffResult
        From :func:`run_ratio_tradeoff`.
    knn : KnnComparisonResult
        From :func:`run_knn_comparison`.

    Returns
    -------
    str
        A table (quantity, 000's statement, our figure) and notes on its rows under it.
    """
    rows, notes = [], []
    at200 = np.flatnonzero(curve.budgets == 200)
    if at200.size:
        rows.append([f"BBF 200 leaves: NN recall, {curve.n_stored} stored", "'in most cases the nearest'",
                     f"{curve.recall_bbf[at200[0]]:.3f}"])
    m_bbf = [i for i, m in enumerate(knn.methods) if m.startswith("BBF")]
    m_brute = [i for i, m in enumerate(knn.methods) if m == "brute"]
    if m_bbf and m_brute:
        for s, size in enumerate(knn.sizes):
            b, e = m_bbf[0], m_brute[0]
            rows.append([f"BBF at {size} stored: recall / precision", "a close point if not",
                         f"{knn.recall[s, b]:.3f} / {knn.precision[s, b]:.3f} (exact {knn.precision[s, e]:.3f})"])
        notes.append(f"BBF: {knn.methods[m_bbf[0]]}; precision of the matches after the ratio rule 0.8; "
                     "exact: brute force")
    rows.append(["exact 64-d search: points per query", "kd-trees lose out in high dimension",
                 f"{curve.exact_evals:.0f} of {curve.n_stored}"])
    m, p, r, md = trade.source_row
    rows.append([f"000's rule, {trade.pair}: matches, P, R", "accepted as correct", f"{m}, {p:.3f}, {r:.3f}"])
    notes.append(f"000's rule: d2 >= 2 d1 and d1 <= {md:g}; P, R: precision, recall")
    i8 = np.flatnonzero(np.isclose(trade.ratios, 0.8))
    if i8.size:
        k = i8[0]
        rows.append(["ratio 0.8 (Lowe's usual): matches, P, R", "—",
                     f"{trade.n_matches[k]}, {trade.precision[k]:.3f}, {trade.recall[k]:.3f}"])
    table = format_table(["quantity", "000", "ours"], rows, title="Matching: 000 beside ours (times: timing tables)")
    return "\n".join([table, *notes])
