"""Ch. 2 experiments (000 §1.4; 003 §3.1): detectors on the Oxford affine pairs (matching: :mod:`.matching_experiments`).

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

from .. import _validate as v
from .._progress import progress_bar
from .._table import format_table
from .detect import detect
from .evaluation import (
    correct_matches,
    load_oxford_image,
    load_oxford_pair,
    oxford_folder,
    oxford_label,
    repeatability,
)
from .matching import match_descriptors
from .surf import threshold_sweep

__all__ = [
    "EVAL_DETECTORS",
    "BlobScaleResult",
    "DetectorSummaryResult",
    "PairEvaluationResult",
    "SurfThresholdResult",
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


def _detect_named(img, name, n_points):
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
    """Repeatability and matching precision/recall per (sequence, img1→img_j, detector)."""

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
        return (f"{len(self.sequences)} sequences x {len(self.steps)} pairs, {self.n_points} strongest points, "
                f"tol {self.tol_px:g} px: mean repeatability {means}")

    def _pivot(self, arr, fmt):
        rows = []
        for i, s in enumerate(self.sequences):
            for j, st in enumerate(self.steps):
                rows.append([s, f"1→{st}"] + [fmt(arr[i, j, k]) for k in range(len(self.detectors))])
        rows.append(["mean", ""] + [fmt(np.nanmean(arr[:, :, k])) for k in range(len(self.detectors))])
        return rows

    def table(self) -> str:
        """Repeatability (fraction of the common-region points found again within ``tol_px``)."""
        title = (f"Repeatability, {self.n_points} strongest points per image, tolerance {self.tol_px:g} px, "
                 f"images x{self.scale:g}")
        return format_table(["sequence", "pair", *self.detectors], self._pivot(self.rep, lambda x: f"{x:.2f}"),
                            title)

    def matching_table(self) -> str:
        """Precision / recall of the matches (rule stated in the title)."""
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
    """
    if isinstance(sequences, (str, os.PathLike)):
        sequences = (sequences,)
    folders = tuple(oxford_folder(s) for s in sequences)
    labels = tuple(oxford_label(s) for s in sequences)
    steps = tuple(v.check_int(j, "steps", minimum=2) for j in steps)
    detectors = tuple(v.check_choice(d, "detectors", tuple(EVAL_DETECTORS)) for d in detectors)
    if not sequences or not steps or not detectors:
        raise ValueError("`sequences`, `steps` and `detectors` must not be empty")
    scale = v.check_positive(scale, "scale")
    n_points = v.check_int(n_points, "n_points", minimum=10)
    tol_px = v.check_positive(tol_px, "tol_px")
    rule = v.check_choice(rule, "rule", ("000", "ratio"))
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
                    first[name], dt = _detect_named(img1, name, n_points)
                    times[name] += dt
                    n_det[name] += 1
                f1 = first[name]
                f2, dt = _detect_named(img2, name, n_points)
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


# --- detectors on one image -----------------------------------------------------------------------


@dataclass(frozen=True)
class DetectorSummaryResult:
    """Keypoint counts of every detector on one image; mean detection times in ``times_s``."""

    image_name: str
    shape: tuple[int, int]
    names: tuple[str, ...]
    counts: tuple[int, ...]
    dims: tuple[str, ...]
    times_s: dict = field(default_factory=dict, repr=False, compare=False)

    def __str__(self) -> str:
        return f"{self.image_name} {self.shape[1]}x{self.shape[0]}: " + ", ".join(
            f"{n} {c}" for n, c in zip(self.names, self.counts, strict=True))

    def table(self) -> str:
        rows = [[n, str(c), d] for n, c, d in zip(self.names, self.counts, self.dims, strict=True)]
        return format_table(["detector", "keypoints", "descriptor"], rows,
                            f"{self.image_name}, {self.shape[1]}x{self.shape[0]} pixels")

    def timing_table(self) -> str:
        """Detection (+ description) time per detector -- machine dependent, not for nbval."""
        rows = [[n, f"{1000 * self.times_s[n]:.0f}"] for n in self.names]
        return format_table(["detector", "time [ms]"], rows)


_SUMMARY = {
    "SURF (ours)": ("surf", {"threshold": 4e-4}),
    "SIFT (OpenCV)": ("sift", {}),
    "ORB (OpenCV)": ("orb", {"n_features": 2000}),
    "FAST-9 (ours)": ("fast", {"threshold": 20, "descriptors": False}),
    "FAST-9 (OpenCV)": ("fast-cv", {"threshold": 20}),
    "Moravec (ours)": ("moravec", {"threshold": 0.1}),
    "MSER (OpenCV)": ("mser", {}),
}


def run_detector_summary(sequence: str = "graf", index: int = 1, *, size=(768, 576), repeats: int = 1):
    """Every detector on one Oxford image resized to ``size`` = (width, height) (000: 768×576)."""
    import cv2

    img = load_oxford_image(sequence, index)
    w, h = (v.check_int(s, "size", minimum=16) for s in size)
    img = cv2.resize(img, (w, h), interpolation=cv2.INTER_AREA)
    repeats = v.check_int(repeats, "repeats", minimum=1)
    names, counts, dims, times = [], [], [], {}
    for name, (method, params) in _SUMMARY.items():
        params = dict(params)
        best = np.inf
        for _ in range(repeats):
            t0 = time.perf_counter()
            f = detect(img, method, **params)
            best = min(best, time.perf_counter() - t0)
        names.append(name)
        counts.append(len(f))
        dims.append("—" if f.descriptors is None else f"{f.descriptors.shape[1]}"
                    + (" bytes" if f.is_binary else "-d"))
        times[name] = best
    return DetectorSummaryResult(f"{oxford_label(sequence)}/img{index}", (h, w), tuple(names), tuple(counts), tuple(dims), times)


# --- SURF threshold scale ---------------------------------------------------------------------------


@dataclass(frozen=True)
class SurfThresholdResult:
    """SURF point counts against the threshold on our response scale and OpenCV's (x 255²)."""

    image_name: str
    thresholds: np.ndarray
    counts: np.ndarray
    source_threshold: float
    source_count: int

    def __str__(self) -> str:
        return (f"SURF on {self.image_name}: threshold {self.source_threshold:g} (000) gives {self.source_count} "
                f"points on our scale")

    def threshold_for(self, n_points: int) -> float:
        """The largest tabulated threshold that still gives at least ``n_points``."""
        ok = self.counts >= n_points
        return float(self.thresholds[ok].max()) if ok.any() else float("nan")

    def table(self) -> str:
        rows = [[f"{t:.1e}", f"{t * 255**2:.3g}", f"{np.sqrt(t):.4f}", str(c)]
                for t, c in zip(self.thresholds, self.counts, strict=True)]
        return format_table(["ours (image in [0,1])", "OpenCV hessianThreshold", "sqrt(ours)", "points"], rows,
                            f"SURF points vs threshold, {self.image_name}")


def run_surf_threshold(sequence: str = "graf", index: int = 1, *, size=(768, 576),
                       thresholds=(1e-5, 3e-5, 1e-4, 2e-4, 4e-4, 1e-3, 2.5e-3, 5e-3, 1e-2, 5e-2)):
    """How many SURF points each threshold leaves on a 768×576 image; where 000's 0.05 falls (000 §3.3)."""
    import cv2

    img = load_oxford_image(sequence, index)
    w, h = (v.check_int(s, "size", minimum=16) for s in size)
    img = cv2.resize(img, (w, h), interpolation=cv2.INTER_AREA)
    th = np.sort(v.as_vector(thresholds, "thresholds"))
    counts = threshold_sweep(img, th)
    src = int(threshold_sweep(img, [0.05])[0])
    return SurfThresholdResult(f"{oxford_label(sequence)}/img{index} {w}x{h}", th, counts, 0.05, src)


@dataclass(frozen=True)
class BlobScaleResult:
    """Where and at what scale our SURF finds a Gaussian blob of known size."""

    sizes_px: np.ndarray
    uv: np.ndarray  # (n, 2) position of the strongest keypoint
    sigma_px: np.ndarray  # SURF scale of that keypoint
    centre_px: float

    def __str__(self) -> str:
        r = self.sigma_px / self.sizes_px
        return f"blob scale: SURF sigma / blob size {r.min():.2f}-{r.max():.2f} over sizes {self.sizes_px.tolist()}"

    def table(self) -> str:
        rows = [[f"{s:.0f}", f"{u:.2f}, {w:.2f}", f"{g:.2f}", f"{g / s:.2f}"]
                for s, (u, w), g in zip(self.sizes_px, self.uv, self.sigma_px, strict=True)]
        return format_table(["blob s [px]", "found at (u, v)", "SURF σ [px]", "σ / s"], rows)


def run_blob_scale(sizes_px=(3.0, 4.0, 5.0, 6.0, 8.0), *, threshold: float = 1e-4, size_px: int = 161) -> BlobScaleResult:
    """Detect a centred Gaussian blob ``exp(-r²/2s²)`` of each size with our SURF (000 §1.4; our check).

    The strongest keypoint should sit at the centre; its SURF scale should grow in
    proportion to ``s`` (a constant ``σ/s``).
    """
    from .surf import surf_detect

    sizes = v.as_vector(sizes_px, "sizes_px")
    size_px = v.check_int(size_px, "size_px", minimum=16)
    c = (size_px - 1) / 2.0
    yy, xx = np.mgrid[0:size_px, 0:size_px]
    uv, sig = [], []
    for s in sizes:  # one small image per size: a handful of detections, not a hot path
        f = surf_detect(np.exp(-((xx - c) ** 2 + (yy - c) ** 2) / (2 * s**2)), threshold, descriptors=False)
        k = int(np.argmax(f.response))
        uv.append(f.uv[k])
        sig.append(f.scale_px[k])
    return BlobScaleResult(sizes, np.array(uv), np.array(sig), c)


def ours_vs_source(threshold: SurfThresholdResult, summary: DetectorSummaryResult,
                   pairs: PairEvaluationResult) -> str:
    """000's statements on SIFT and SURF (000 §1.4, §3.3) beside our numbers from the chapter's runs.

    ``threshold``: :func:`run_surf_threshold`; ``summary``: :func:`run_detector_summary`; ``pairs``:
    :func:`run_pair_evaluation` with SIFT and SURF among its detectors.
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
