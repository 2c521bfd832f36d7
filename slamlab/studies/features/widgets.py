"""Widgets for Ch. 2: detector, threshold, image pair and viewpoint step; ratio, max_leaves and detector."""

from __future__ import annotations

import ipywidgets as widgets
import numpy as np

from ...features.detect import detect
from ...features.evaluation import OXFORD_SEQUENCES, correct_matches, load_oxford_pair, repeatability
from ...features.matching import Matches, accept_ratio, knn2
from ...features.plot import plot_keypoint_pair, plot_matches
from ...widgets import STYLE as _STYLE
from ...widgets import interactive, show_run

__all__ = ["explore_detectors", "explore_matching"]

_ERRORS = (ValueError, TypeError, FileNotFoundError)  # FileNotFoundError: the Oxford images are data files


# detector -> (method, threshold parameter name, default, min, max, step, log scale)
_DETECTOR_KNOBS = {
    "SURF (ours)": ("surf", "threshold", -3.4, -5.0, -1.0, 0.2, True),
    "SIFT (OpenCV)": ("sift", "contrast_threshold", 0.04, 0.005, 0.2, 0.005, False),
    "ORB (OpenCV)": ("orb", "fast_threshold", 20, 1, 100, 1, False),
    "FAST-9 (ours)": ("fast", "threshold", 20, 1, 120, 1, False),
    "Moravec (ours)": ("moravec", "threshold", 0.1, 0.01, 2.0, 0.01, False),
    "MSER (OpenCV)": ("mser", "delta", 5, 1, 30, 1, False),
}


def _params(name, value):
    method, pname, _, _, _, _, log = _DETECTOR_KNOBS[name]
    val = 10.0 ** value if log else value
    if pname in ("fast_threshold", "threshold", "delta") and method in ("orb", "fast", "mser"):
        val = round(val)
    return method, {pname: val}


def explore_detectors(**defaults):
    """Detector, its threshold, the Oxford sequence and the viewpoint step -> keypoints on both images.

    The threshold slider is read as the chosen detector's own knob (SURF: log10 of
    the Hessian threshold). Prints counts and the repeatability (tolerance 2.5 px).

    Parameters
    ----------
    **defaults
        Initial values: ``detector`` (label), ``threshold`` (slider fraction 0..1), ``sequence``,
        ``step`` (2..6), ``scale`` (image resize factor), ``draw`` (bool).

    Returns
    -------
    ipywidgets.interactive
    """
    d = {"detector": "SURF (ours)", "threshold": 0.5, "sequence": "graf", "step": 2, "scale": 0.5, "draw": True}
    d.update(defaults)

    def show(detector, threshold_fraction, sequence, step, draw):
        _, _, _, lo, hi, _, _ = _DETECTOR_KNOBS[detector]
        value = lo + threshold_fraction * (hi - lo)
        method, params = _params(detector, value)

        def run():
            img1, img2, H = load_oxford_pair(sequence, step, scale=d["scale"])
            f1 = detect(img1, method, descriptors=False, **params)
            f2 = detect(img2, method, descriptors=False, **params)
            return img1, img2, H, f1, f2

        def table(out):
            img1, img2, H, f1, f2 = out
            r = repeatability(f1, f2, H, img1.shape, img2.shape)
            shown = f"{10 ** value:.2g}" if _DETECTOR_KNOBS[detector][6] else f"{params[next(iter(params))]}"
            return (f"{detector}, {next(iter(params))} = {shown}: img1 {len(f1)} points, img{step} {len(f2)} points, "
                    f"repeatability {r.repeatability:.2f} ({r.correspondences} of min({r.n1}, {r.n2}))")

        def plot(out):
            img1, img2, _, f1, f2 = out
            plot_keypoint_pair(img1, f1, img2, f2, (f"{sequence} img1", f"{sequence} img{step}"))

        show_run(run, plot if draw else None, table=table, errors=_ERRORS)

    return interactive(
        show,
        detector=widgets.Dropdown(options=list(_DETECTOR_KNOBS), value=d["detector"], description="detector"),
        threshold_fraction=widgets.FloatSlider(value=d["threshold"], min=0.0, max=1.0, step=0.05,
                                               description="threshold (low → high)", continuous_update=False,
                                               style=_STYLE),
        sequence=widgets.Dropdown(options=list(OXFORD_SEQUENCES), value=d["sequence"], description="sequence"),
        step=widgets.IntSlider(value=d["step"], min=2, max=6, description="img1 → img", continuous_update=False,
                               style=_STYLE),
        draw=widgets.Checkbox(value=d["draw"], description="draw the keypoints"),
    )


_MATCH_DETECTORS = {"SURF (ours)": ("surf", {"threshold": 1e-4}), "SIFT (OpenCV)": ("sift", {}),
                    "ORB (OpenCV)": ("orb", {"n_features": 2000}), "FAST-9 + U-SURF (ours)": ("fast", {})}


def explore_matching(**defaults):
    """Ratio threshold, BBF max_leaves (0 = exact brute force) and detector -> matches drawn and scored.

    Parameters
    ----------
    **defaults
        Initial values: ``ratio``, ``max_leaves``, ``detector`` (label), ``sequence``, ``step``,
        ``scale`` (image resize factor), ``n_points`` (strongest keypoints per image), ``draw``.

    Returns
    -------
    ipywidgets.interactive
    """
    d = {"ratio": 0.8, "max_leaves": 200, "detector": "SURF (ours)", "sequence": "graf", "step": 2,
         "scale": 0.5, "n_points": 800, "draw": True}
    d.update(defaults)
    cache = {}

    def features(detector, sequence, step):
        key = (detector, sequence, step)
        if key not in cache:
            img1, img2, H = load_oxford_pair(sequence, step, scale=d["scale"])
            method, params = _MATCH_DETECTORS[detector]
            f1 = detect(img1, method, max_points=d["n_points"], **params)
            f2 = detect(img2, method, max_points=d["n_points"], **params)
            cache[key] = (img1, img2, H, f1, f2)
        return cache[key]

    def show(ratio, max_leaves, detector, sequence, step, draw):
        def run():
            img1, img2, H, f1, f2 = features(detector, sequence, step)
            method = "brute" if (max_leaves == 0 or f1.is_binary) else "bbf"
            dist, idx = knn2(f1.descriptors, f2.descriptors, method=method, max_leaves=max(int(max_leaves), 1))
            keep = np.flatnonzero(accept_ratio(dist, ratio) & (idx[:, 0] >= 0))
            m = Matches(keep, idx[keep, 0], dist[keep, 0], dist[keep, 1])
            return method, H, (img1, img2, f1, f2, m, correct_matches(f1, f2, m, H))  # the last: plot_matches's

        def table(out):
            method, H, (img1, img2, f1, f2, m, c) = out
            r = repeatability(f1, f2, H, img1.shape, img2.shape)
            note = " (binary: brute-force Hamming)" if f1.is_binary and max_leaves else ""
            return (f"{detector}, ratio {ratio:.2f}, {'exact' if method == 'brute' else f'BBF {max_leaves} leaves'}"
                    f"{note}: {len(m)} matches, precision {c.mean() if len(m) else float('nan'):.2f}, "
                    f"recall {c.sum() / max(r.correspondences, 1):.2f}")

        show_run(run, (lambda out: plot_matches(*out[2])) if draw else None, table=table, errors=_ERRORS)

    return interactive(
        show,
        ratio=widgets.FloatSlider(value=d["ratio"], min=0.3, max=1.0, step=0.05, description="ratio d1/d2 <",
                                  continuous_update=False, style=_STYLE),
        max_leaves=widgets.IntSlider(value=d["max_leaves"], min=0, max=1000, step=10,
                                     description="BBF max_leaves (0 = exact)", continuous_update=False, style=_STYLE),
        detector=widgets.Dropdown(options=list(_MATCH_DETECTORS), value=d["detector"], description="detector"),
        sequence=widgets.Dropdown(options=list(OXFORD_SEQUENCES), value=d["sequence"], description="sequence"),
        step=widgets.IntSlider(value=d["step"], min=2, max=6, description="img1 → img", continuous_update=False,
                               style=_STYLE),
        draw=widgets.Checkbox(value=d["draw"], description="draw the matches"),
    )

