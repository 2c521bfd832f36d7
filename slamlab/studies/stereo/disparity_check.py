"""The stereo disparity errors of one rendered pair against the true depth, per ORB pyramid level (our addition to
000 §3.3); the pair and its depth come from :func:`slamlab.studies.stereo.experiments.disparity_errors` (no simulator here)."""

from __future__ import annotations

import numpy as np

from ..._table import format_table
from ...geometry.camera import StereoRig
from ...stereo.local_stages import detect_pair, stereo_match, subpixel_disparity
from ...stereo.params import StereoParams

__all__ = ["disparity_error_table"]


def disparity_error_table(left, right, depth, rig: StereoRig, *, params: StereoParams) -> str:
    """Stereo disparity errors against the true depth, per pyramid level, before and after
    :func:`~slamlab.stereo.subpixel_disparity` (our addition to 000 §3.3).

    Keypoints of both images (``params``), their stereo matches, and for each match the disparity minus
    the true one ``f b / z`` (``z``: ``depth`` at the left keypoint's pixel). Returns a table of the
    median absolute error and the share above 1 px per level.

    Parameters
    ----------
    left, right : numpy.ndarray, shape (H, W)
        The stereo pair.
    depth : numpy.ndarray, shape (H, W)
        True depth of each left-image pixel [m].
    rig : StereoRig
        The calibrated pair (epipolar lines, focal length and baseline).
    params : StereoParams
        Pipeline settings (detector, ratio, epipolar tolerance, sub-pixel window).

    Returns
    -------
    str
    """
    p = params
    fl, fr = detect_pair(left, right, params=p)
    sm = stereo_match(fl, fr, rig, params=p)
    fb = rig.left.fx * rig.baseline_m

    def errors(uvl, uvr):
        c, r = np.rint(uvl).astype(int).T
        return (uvl[:, 0] - uvr[:, 0]) - fb / depth[r, c]

    uvl, uvr = fl.uv[sm.left], fr.uv[sm.right]
    raw = errors(uvl, uvr)
    ref_l, ref_r, ok = subpixel_disparity(left, right, uvl, uvr, half_px=p.subpixel_half_px, search_px=p.subpixel_search_px)
    ref = np.full(len(raw), np.nan)
    ref[ok] = errors(ref_l[ok], ref_r[ok])
    level = fl.octave[sm.left]
    rows = []
    for lv in np.unique(level):
        m = (level == lv) & np.isfinite(raw)
        mr = m & ok
        rows.append([f"{lv}", f"{m.sum()}", f"{np.median(np.abs(raw[m])):.2f}", f"{100 * np.mean(np.abs(raw[m]) > 1):.0f}",
                     f"{np.median(np.abs(ref[mr])):.2f}", f"{100 * np.mean(np.abs(ref[mr]) > 1):.0f}", f"{100 * mr.sum() / max(m.sum(), 1):.0f}"])
    head = ["level", "matches", "keypoints: median |err|, px", "> 1 px, %", "refined: median |err|, px", "> 1 px, %",
            "refined, %"]
    return format_table(head, rows, title=f"disparity error against the renderer ({p.detector.upper()}, one frame)")
