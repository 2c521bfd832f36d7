"""Ch. 2 experiments on one image (000 §1.4, §3.3): every detector's keypoint count, the SURF threshold scale,
SURF's scale on Gaussian blobs (re-exported by :mod:`slamlab.studies.features.experiments`, which holds the image-pair evaluation).
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np

from ..._table import format_table
from ..._validate import as_vector, check_int
from ...features.detect import detect
from ...features.evaluation import load_oxford_image, oxford_label
from ...features.surf import threshold_sweep

__all__ = [
    "BlobScaleResult",
    "DetectorSummaryResult",
    "SurfThresholdResult",
    "run_blob_scale",
    "run_detector_summary",
    "run_surf_threshold",
]


# --- detectors on one image -----------------------------------------------------------------------


@dataclass(frozen=True)
class DetectorSummaryResult:
    """Keypoint counts of every detector on one image; mean detection times in ``times_s``.

    Attributes
    ----------
    image_name : str
        ``<sequence>/img<index>``.
    shape : (int, int)
        Image shape (height, width) in pixels.
    names : tuple of str
        Detector labels.
    counts : tuple of int
        Keypoints found per detector.
    dims : tuple of str
        Descriptor size per detector ("—" for none).
    times_s : dict
        Best detection time in seconds per detector (machine dependent).
    """

    image_name: str
    shape: tuple[int, int]
    names: tuple[str, ...]
    counts: tuple[int, ...]
    dims: tuple[str, ...]
    times_s: dict = field(default_factory=dict, repr=False, compare=False)

    def __str__(self) -> str:
        lo, hi = int(np.argmin(self.counts)), int(np.argmax(self.counts))
        return (f"{self.image_name} {self.shape[1]}x{self.shape[0]}: {len(self.names)} detectors, from "
                f"{self.counts[lo]} keypoints ({self.names[lo]}) to {self.counts[hi]} ({self.names[hi]})")

    def table(self) -> str:
        """Keypoint count and descriptor size per detector (stable; what nbval compares).

        Returns
        -------
        str
            Fixed-precision text table.
        """
        rows = [[n, str(c), d] for n, c, d in zip(self.names, self.counts, self.dims, strict=True)]
        return format_table(["detector", "keypoints", "descriptor"], rows,
                            f"{self.image_name}, {self.shape[1]}x{self.shape[0]} pixels")

    def timing_table(self) -> str:
        """Detection (+ description) time per detector -- machine dependent, not for nbval.

        Returns
        -------
        str
            Milliseconds per detector and, when SIFT is among them, the time over SIFT's.
        """
        sift = next((self.times_s[n] for n in self.names if n.startswith("SIFT")), None)
        rows = [[n, f"{1000 * self.times_s[n]:.0f}"] + ([f"{self.times_s[n] / sift:.2f}"] if sift else [])
                for n in self.names]
        return format_table(["detector", "time [ms]"] + (["/ SIFT"] if sift else []), rows)


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
    """Every detector on one Oxford image resized to ``size`` = (width, height) (000: 768×576).

    Parameters
    ----------
    sequence : str or os.PathLike
        A shared sequence's name or an Oxford-layout folder.
    index : int
        Image number (1-based).
    size : (int, int)
        Size (width_px, height_px) the image is resized to.
    repeats : int
        Runs per detector; the fastest time is kept.

    Returns
    -------
    DetectorSummaryResult
        ``counts`` and ``dims`` per detector; ``times_s`` for :meth:`timing_table`.
    """
    import cv2

    img = load_oxford_image(sequence, index)
    w, h = (check_int(s, "size", minimum=16) for s in size)
    img = cv2.resize(img, (w, h), interpolation=cv2.INTER_AREA)
    repeats = check_int(repeats, "repeats", minimum=1)
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
    """SURF point counts against the threshold on our response scale and OpenCV's (x 255²).

    Attributes
    ----------
    image_name : str
        Image label with its size.
    thresholds : (n,) float
        Hessian thresholds on our scale (image in [0, 1]), ascending.
    counts : (n,) int
        SURF points at each threshold.
    source_threshold : float
        000's threshold (0.05).
    source_count : int
        SURF points at ``source_threshold`` on our scale.
    """

    image_name: str
    thresholds: np.ndarray
    counts: np.ndarray
    source_threshold: float
    source_count: int

    def __str__(self) -> str:
        return (f"SURF on {self.image_name}: threshold {self.source_threshold:g} (000) gives {self.source_count} "
                f"points on our scale")

    def threshold_for(self, n_points: int) -> float:
        """The largest tabulated threshold that still gives at least ``n_points``.

        Parameters
        ----------
        n_points : int
            Number of SURF points wanted.

        Returns
        -------
        float
            That threshold, NaN when no tabulated threshold gives that many.
        """
        ok = self.counts >= n_points
        return float(self.thresholds[ok].max()) if ok.any() else float("nan")

    def table(self) -> str:
        """SURF points per threshold, on our scale, OpenCV's (x 255²) and as its square root.

        Returns
        -------
        str
            Fixed-precision text table.
        """
        rows = [[f"{t:.1e}", f"{t * 255**2:.3g}", f"{np.sqrt(t):.4f}", str(c)]
                for t, c in zip(self.thresholds, self.counts, strict=True)]
        return format_table(["ours (image in [0,1])", "OpenCV hessianThreshold", "sqrt(ours)", "points"], rows,
                            f"SURF points vs threshold, {self.image_name}")


def run_surf_threshold(sequence: str = "graf", index: int = 1, *, size=(768, 576),
                       thresholds=(1e-5, 3e-5, 1e-4, 2e-4, 4e-4, 1e-3, 2.5e-3, 5e-3, 1e-2, 5e-2)):
    """How many SURF points each threshold leaves on a 768×576 image; where 000's 0.05 falls (000 §3.3).

    Parameters
    ----------
    sequence : str or os.PathLike
        A shared sequence's name or an Oxford-layout folder.
    index : int
        Image number (1-based).
    size : (int, int)
        Size (width_px, height_px) the image is resized to.
    thresholds : sequence of float
        Hessian thresholds on our scale (image in [0, 1]).

    Returns
    -------
    SurfThresholdResult
        ``counts`` per threshold and ``source_count`` at 000's 0.05.
    """
    import cv2

    img = load_oxford_image(sequence, index)
    w, h = (check_int(s, "size", minimum=16) for s in size)
    img = cv2.resize(img, (w, h), interpolation=cv2.INTER_AREA)
    th = np.sort(as_vector(thresholds, "thresholds"))
    counts = threshold_sweep(img, th)
    src = int(threshold_sweep(img, [0.05])[0])
    return SurfThresholdResult(f"{oxford_label(sequence)}/img{index} {w}x{h}", th, counts, 0.05, src)


@dataclass(frozen=True)
class BlobScaleResult:
    """Where and at what scale our SURF finds a Gaussian blob of known size.

    Attributes
    ----------
    sizes_px : (n,) float
        Blob sizes s in pixels.
    uv : (n, 2) float
        Position of the strongest keypoint per blob.
    sigma_px : (n,) float
        SURF scale of that keypoint in pixels.
    centre_px : float
        The blob centre coordinate (same in u and v).
    """

    sizes_px: np.ndarray
    uv: np.ndarray  # (n, 2) position of the strongest keypoint
    sigma_px: np.ndarray  # SURF scale of that keypoint
    centre_px: float

    def __str__(self) -> str:
        r = self.sigma_px / self.sizes_px
        return f"blob scale: SURF sigma / blob size {r.min():.2f}-{r.max():.2f} over sizes {self.sizes_px.tolist()}"

    def table(self) -> str:
        """Per blob size: where the strongest keypoint was found, its SURF scale and σ / s.

        Returns
        -------
        str
            Fixed-precision text table.
        """
        rows = [[f"{s:.0f}", f"{u:.2f}, {w:.2f}", f"{g:.2f}", f"{g / s:.2f}"]
                for s, (u, w), g in zip(self.sizes_px, self.uv, self.sigma_px, strict=True)]
        return format_table(["blob s [px]", "found at (u, v)", "SURF σ [px]", "σ / s"], rows)


def run_blob_scale(sizes_px=(3.0, 4.0, 5.0, 6.0, 8.0), *, threshold: float = 1e-4, size_px: int = 161) -> BlobScaleResult:
    """Detect a centred Gaussian blob ``exp(-r²/2s²)`` of each size with our SURF (000 §1.4; our check).

    The strongest keypoint should sit at the centre; its SURF scale should grow in
    proportion to ``s`` (a constant ``σ/s``).

    Parameters
    ----------
    sizes_px : sequence of float
        Blob sizes s in pixels.
    threshold : float
        SURF Hessian threshold (our scale).
    size_px : int
        Side of the square test image in pixels.

    Returns
    -------
    BlobScaleResult
        Position and SURF scale of the strongest keypoint per size.
    """
    from ...features.surf import surf_detect

    sizes = as_vector(sizes_px, "sizes_px")
    size_px = check_int(size_px, "size_px", minimum=16)
    c = (size_px - 1) / 2.0
    yy, xx = np.mgrid[0:size_px, 0:size_px]
    uv, sig = [], []
    for s in sizes:  # one small image per size: a handful of detections, not a hot path
        f = surf_detect(np.exp(-((xx - c) ** 2 + (yy - c) ** 2) / (2 * s**2)), threshold, descriptors=False)
        k = int(np.argmax(f.response))
        uv.append(f.uv[k])
        sig.append(f.scale_px[k])
    return BlobScaleResult(sizes, np.array(uv), np.array(sig), c)
