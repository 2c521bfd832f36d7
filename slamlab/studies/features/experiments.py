"""Ch. 2 experiments (000 §1.4; 003 §3.1): detectors on the Oxford affine pairs (one image: :mod:`.detector_experiments`; matching: :mod:`.matching_experiments`).

Each ``run_*`` returns a frozen dataclass: ``str(result)`` is a one-line summary,
``result.table()`` a fixed-precision text table (what the notebook prints and
nbval compares); timings live in a separate ``times_s`` field, never in a table.
``scale`` downsizes the images (INTER_AREA) to keep notebook runs short; the
benchmark uses ``scale=1``.
"""

from __future__ import annotations

import os
import time
from dataclasses import dataclass, field

import numpy as np

from ..._progress import progress_bar
from ..._table import format_table
from ..._validate import check_choice, check_int, check_positive
from ...features.detect import detect
from ...features.evaluation import (
    correct_matches,
    load_oxford_pair,
    oxford_folder,
    oxford_label,
    repeatability,
)
from ...features.matching import match_descriptors
from .detector_experiments import (
    BlobScaleResult,
    DetectorSummaryResult,
    SurfThresholdResult,
    run_blob_scale,
    run_detector_summary,
    run_surf_threshold,
)

__all__ = [
    "EVAL_DETECTORS",
    "BlobScaleResult",
    "DetectorSummaryResult",
    "PairEvaluationResult",
    "SurfThresholdResult",
    "detect_for_evaluation",
    "ours_vs_source",
    "run_blob_scale",
    "run_detector_summary",
    "run_pair_evaluation",
    "run_surf_threshold",
]

#: Detectors of the evaluation and the parameters we use (stated in the notebook).
EVAL_DETECTORS = {
    "SIFT": ("sift", {}),
    "SURF": ("surf", {"threshold": 1e-4}),
    "ORB": ("orb", {"n_features": 3000}),
    "FAST": ("fast", {"threshold": 20}),
}


def detect_for_evaluation(img, name: str, n_points: int):
    """The strongest ``n_points`` keypoints by one of :data:`EVAL_DETECTORS` with its settings, timed (003 §3.1).

    Ours: ORB is asked for at least ``2·n_points`` features, so that ``n_points`` survive.

    Parameters
    ----------
    img : (H, W) array
        Grey image (uint8, or float in [0, 1]).
    name : {'SIFT', 'SURF', 'ORB', 'FAST'}
        A key of :data:`EVAL_DETECTORS`.
    n_points : int
        Keypoints kept (the strongest), >= 1.

    Returns
    -------
    features : Features
        At most ``n_points`` keypoints with descriptors.
    seconds : float
        Wall time of the detection (machine dependent).
    """
    check_choice(name, "name", EVAL_DETECTORS)
    n_points = check_int(n_points, "n_points", minimum=1)
    method, params = EVAL_DETECTORS[name]
    params = dict(params)
    if name == "ORB":
        params["n_features"] = max(params["n_features"], 2 * n_points)
    t0 = time.perf_counter()
    f = detect(img, method, max_points=n_points, **params)
    return f, time.perf_counter() - t0


# --- repeatability and matching on image pairs ------------------------------------------------------


@dataclass(frozen=True)
class PairEvaluationResult:
    """Repeatability and matching precision/recall per (sequence, img1→img_j, detector).

    Attributes
    ----------
    sequences : tuple of str
        Sequence labels (folder names).
    steps : tuple of int
        The ``j`` of each pair img1 → img_j.
    detectors : tuple of str
        Detector names (keys of :data:`EVAL_DETECTORS`).
    scale : float
        Image resize factor used.
    n_points : int
        Strongest keypoints kept per image.
    tol_px : float
        Correspondence / correct-match tolerance in image-2 pixels.
    rule : str
        The matching rule, as text for table titles.
    rep, precision, recall : (n_seq, n_steps, n_det) float
        Repeatability, match precision and match recall (NaN where undefined).
    n_matches, n_correct : (n_seq, n_steps, n_det) int
        Accepted and correct matches.
    times_s : dict
        Mean detection time per image in seconds, per detector (machine dependent).
    """

    sequences: tuple[str, ...]
    steps: tuple[int, ...]
    detectors: tuple[str, ...]
    scale: float
    n_points: int
    tol_px: float
    rule: str
    rep: np.ndarray = field(repr=False)  # (n_seq, n_steps, n_det)
    precision: np.ndarray = field(repr=False)
    recall: np.ndarray = field(repr=False)
    n_matches: np.ndarray = field(repr=False)
    n_correct: np.ndarray = field(repr=False)
    times_s: dict = field(default_factory=dict, repr=False, compare=False)

    def __str__(self) -> str:
        means = ", ".join(f"{d} {np.nanmean(self.rep[:, :, k]):.2f}" for k, d in enumerate(self.detectors))
        return (f"{len(self.sequences)} sequences x {len(self.steps)} pairs, {self.n_points} points, "
                f"{self.tol_px:g} px: mean repeatability {means}")

    def _pivot(self, arr, fmt):
        rows = []
        for i, s in enumerate(self.sequences):
            for j, st in enumerate(self.steps):
                rows.append([s, f"1→{st}"] + [fmt(arr[i, j, k]) for k in range(len(self.detectors))])
        rows.append(["mean", ""] + [fmt(np.nanmean(arr[:, :, k])) for k in range(len(self.detectors))])
        return rows

    def table(self) -> str:
        """Repeatability (fraction of the common-region points found again within ``tol_px``).

        Returns
        -------
        str
            One row per (sequence, pair) and a mean row; one column per detector.
        """
        title = (f"Repeatability, {self.n_points} strongest points per image, tolerance {self.tol_px:g} px, "
                 f"images x{self.scale:g}")
        return format_table(["sequence", "pair", *self.detectors], self._pivot(self.rep, lambda x: f"{x:.2f}"),
                            title)

    def matching_table(self) -> str:
        """Precision / recall of the matches (rule stated in the title).

        Returns
        -------
        str
            ``precision/recall`` per (sequence, pair) and detector.
        """
        def fmt(pr):
            return "—" if not np.isfinite(pr[0]) else f"{pr[0]:.2f}/{pr[1]:.2f}"

        both = np.stack([self.precision, self.recall], axis=-1)
        rows = []
        for i, s in enumerate(self.sequences):
            for j, st in enumerate(self.steps):
                rows.append([s, f"1→{st}"] + [fmt(both[i, j, k]) for k in range(len(self.detectors))])
        rows.append(["mean", ""] + [fmt(np.nanmean(both[:, :, k], axis=(0, 1))) for k in range(len(self.detectors))])
        return format_table(["sequence", "pair", *self.detectors], rows,
                            f"Matching precision/recall, rule {self.rule}, correct within {self.tol_px:g} px")


def run_pair_evaluation(sequences=("graf", "boat"), steps=(2, 3, 4, 5, 6), *,
                        detectors=("SIFT", "SURF", "ORB", "FAST"), scale: float = 0.5, n_points: int = 500,
                        tol_px: float = 2.5, rule: str = "ratio", ratio: float = 0.8,
                        progress: bool | None = None) -> PairEvaluationResult:
    """Repeatability and matching precision/recall on img1 → img_j of Oxford sequences (000 §1.4).

    ``sequences``: names of the shared sequences (:data:`OXFORD_SEQUENCES`) or ``str`` /
    ``os.PathLike`` paths of any Oxford-layout folders (``img1..imgN`` + ``H1to2p..``); tables
    name them by folder name.

    Every detector keeps its ``n_points`` strongest keypoints per image (equal
    budgets: with a fixed pixel tolerance a denser detector would look more
    repeatable by chance). FAST corners carry upright SURF descriptors (σ = 2 px). ``progress``:
    a bar over the image pairs (None: on unless ``$SLAMLAB_PROGRESS=0``).

    Parameters
    ----------
    sequences : str, os.PathLike or sequence of them
        Shared sequence names or Oxford-layout folders.
    steps : sequence of int
        Second images ``j`` (>= 2) of the pairs img1 → img_j.
    detectors : sequence of str
        Keys of :data:`EVAL_DETECTORS`.
    scale : float
        Image resize factor (> 0).
    n_points : int
        Strongest keypoints kept per image (>= 10).
    tol_px : float
        Repeatability and correct-match tolerance in image-2 pixels.
    rule : {'ratio', '000'}
        Match acceptance rule (:func:`slamlab.features.matching.match_descriptors`).
    ratio : float
        Lowe's ratio for ``rule='ratio'``.
    progress : bool, callable or None
        Progress bar over the pairs (see :mod:`slamlab._progress`).

    Returns
    -------
    PairEvaluationResult
        ``rep``, ``precision``, ``recall`` per (sequence, pair, detector); ``table()`` and
        ``matching_table()`` print them.
    """
    if isinstance(sequences, (str, os.PathLike)):
        sequences = (sequences,)
    folders = tuple(oxford_folder(s) for s in sequences)
    labels = tuple(oxford_label(s) for s in sequences)
    steps = tuple(check_int(j, "steps", minimum=2) for j in steps)
    detectors = tuple(check_choice(d, "detectors", tuple(EVAL_DETECTORS)) for d in detectors)
    if not sequences or not steps or not detectors:
        raise ValueError("`sequences`, `steps` and `detectors` must not be empty")
    scale = check_positive(scale, "scale")
    n_points = check_int(n_points, "n_points", minimum=10)
    tol_px = check_positive(tol_px, "tol_px")
    rule = check_choice(rule, "rule", ("000", "ratio"))
    shape = (len(sequences), len(steps), len(detectors))
    rep, prec, rec = np.full(shape, np.nan), np.full(shape, np.nan), np.full(shape, np.nan)
    n_m, n_c = np.zeros(shape, dtype=int), np.zeros(shape, dtype=int)
    times = {d: 0.0 for d in detectors}
    n_det = {d: 0 for d in detectors}
    bar = progress_bar(total=len(folders) * len(steps), desc="pair evaluation", progress=progress)
    for i, seq in enumerate(folders):
        first = {}
        for j, st in enumerate(steps):
            img1, img2, H = load_oxford_pair(seq, st, scale=scale)
            for k, name in enumerate(detectors):
                if name not in first:
                    first[name], dt = detect_for_evaluation(img1, name, n_points)
                    times[name] += dt
                    n_det[name] += 1
                f1 = first[name]
                f2, dt = detect_for_evaluation(img2, name, n_points)
                times[name] += dt
                n_det[name] += 1
                r = repeatability(f1, f2, H, img1.shape, img2.shape, tol_px=tol_px)
                rep[i, j, k] = r.repeatability
                m = match_descriptors(f1.descriptors, f2.descriptors, rule=rule, ratio=ratio)
                c = correct_matches(f1, f2, m, H, tol_px=tol_px)
                n_m[i, j, k], n_c[i, j, k] = len(m), int(c.sum())
                prec[i, j, k] = c.mean() if len(m) else np.nan
                rec[i, j, k] = c.sum() / r.correspondences if r.correspondences else np.nan
            bar.update()
    bar.close()
    rule_txt = f"ratio {ratio:g}" if rule == "ratio" else "000 (d2 >= 2 d1)"
    return PairEvaluationResult(labels, steps, detectors, scale, n_points, tol_px, rule_txt, rep, prec, rec,
                                n_m, n_c, {d: times[d] / max(n_det[d], 1) for d in detectors})


def ours_vs_source(threshold: SurfThresholdResult, summary: DetectorSummaryResult,
                   pairs: PairEvaluationResult) -> str:
    """000's statements on SIFT and SURF (000 §1.4, §3.3) beside our numbers from the chapter's runs.

    Parameters
    ----------
    threshold : SurfThresholdResult
        From :func:`run_surf_threshold`.
    summary : DetectorSummaryResult
        From :func:`run_detector_summary`.
    pairs : PairEvaluationResult
        From :func:`run_pair_evaluation` with SIFT and SURF among its detectors.

    Returns
    -------
    str
        A table: quantity, 000's statement, our figure.
    """
    counts = dict(zip(summary.names, summary.counts, strict=True))
    surf = next(c for n, c in counts.items() if n.startswith("SURF"))
    sift = next(c for n, c in counts.items() if n.startswith("SIFT"))
    rows = [
        [f"SURF points at threshold {threshold.source_threshold:g}", "~2000 (576x768, §3.3)",
         f"{threshold.source_count} ({threshold.image_name})"],
        ["SURF threshold for >= 2000 points", "0.05 (scale not stated)", f"{threshold.threshold_for(2000):.1e}"],
        ["SIFT points", "~2000 on ~500x500 (§1.4.1)", f"{sift} ({summary.image_name})"],
        ["SURF vs SIFT points", "SURF finds fewer (§1.4.2)", f"{surf} vs {sift}"],
    ]
    det = list(pairs.detectors)
    if "SIFT" in det and "SURF" in det:
        k_sift, k_surf = det.index("SIFT"), det.index("SURF")
        for i, seq in enumerate(pairs.sequences):
            for j, st in enumerate(pairs.steps[:2]):
                rows.append([f"repeatability {seq} 1→{st}: SURF vs SIFT", "SURF more stable (§1.4.2)",
                             f"{pairs.rep[i, j, k_surf]:.2f} vs {pairs.rep[i, j, k_sift]:.2f}"])
    return format_table(["quantity", "000", "ours"], rows, title="Detectors: 000 beside ours (times: timing tables)")
