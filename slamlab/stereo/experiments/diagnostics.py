"""Our diagnostics of the pipeline: the landmark-store calls of the closed loop (for the kd-tree chapter) and
the stereo disparity errors per ORB pyramid level (000 §3.3).
"""

from __future__ import annotations

import numpy as np

from ... import _validate as v
from ..._table import format_table
from ...geometry.se3 import se3_from_planar
from ...kdtree.stores import ExactStore
from ...kdtree.workloads import RecordingStore, Workload
from ...sim.arena import StereoArena, StereoSim
from ..params import StereoParams
from .runs import run_closed_loop


def record_stereo_stream(n_frames: int | None = None, *, detector: str = "sift", rng: int = 0,
                         progress: bool | None = None) -> Workload:
    """Record the landmark-store calls of the stereo pipeline on 000's closed loop (our addition).

    Runs the closed loop (small size: 57 frames; ``n_frames`` keeps the first frames only) with an
    :class:`~slamlab.kdtree.ExactStore` wrapped in a :class:`~slamlab.kdtree.workloads.RecordingStore`,
    and returns the recorded :class:`~slamlab.kdtree.workloads.Workload` for
    :func:`slamlab.kdtree.experiments.run_store_comparison`. ``detector="sift"`` gives 128-d float
    descriptors (OpenCV); ``"surf"`` the 64-d SURF of the features chapter. The map search is 000's
    global one for every detector (ORB's window search would leave the store almost no queries).
    ``progress``: a bar over the frames (None: on unless ``$SLAMLAB_PROGRESS=0``).

    Parameters
    ----------
    n_frames : int, optional
        Keep only the first frames.
    detector : str, default "sift"
        Detector of the run ("sift", "surf").
    rng : int, default 0
        RANSAC seed.
    progress : bool or None
        A bar over the frames.

    Returns
    -------
    Workload
    """
    p = StereoParams(detector=detector, map_search="global")
    rec = RecordingStore(ExactStore(p.base_seen_times, p.max_non_base_time))
    run_closed_loop("small", n_frames=n_frames, params=p, store=rec, progress=progress, rng=rng)
    n = len(rec.iterations)
    return rec.workload(f"stereo closed loop, {n} frames ({detector.upper()}, recorded)",
                        base_seen_times=p.base_seen_times, max_non_base_time=p.max_non_base_time)


def disparity_errors(pose=(3.0, 4.0, 1.2), *, arena: StereoArena | None = None, params: StereoParams | None = None,
                     rng=0, **overrides) -> str:
    """Stereo disparity errors against the renderer's depth, per ORB pyramid level, before and after
    :func:`~slamlab.stereo.subpixel_disparity` (our addition to 000 §3.3).

    One rendered pair at ``pose`` in ``arena`` (default the 6×8 m arena): keypoints (``params`` +
    ``overrides``, default ORB), stereo matches, and for each match the disparity minus the true one
    ``f b / z`` (``z``: the renderer's depth at the left keypoint's pixel). Returns a table of the
    median absolute error and the share above 1 px per level.

    Parameters
    ----------
    pose : array_like, shape (3,)
        Body pose ``(x_m, y_m, yaw_rad)``.
    arena : StereoArena, optional
        Scene (default the 6×8 m arena, seed 0).
    params : StereoParams, optional
        Pipeline settings (default :class:`StereoParams`).
    rng : int or numpy.random.Generator, default 0
        Seed of the simulator.
    **overrides
        :class:`StereoParams` fields to change.

    Returns
    -------
    str
    """
    from ..local_stages import _stereo_match, detect_features, subpixel_disparity

    p = StereoParams.resolve(params, **({"detector": "orb"} | overrides))
    arena = StereoArena(seed=0) if arena is None else arena
    sim = StereoSim(arena, rng=rng)
    pose = v.as_vector(pose, "pose", 3)
    left, right = sim.render_pair(pose)
    fl, fr = detect_features(left, params=p), detect_features(right, params=p)
    sm = _stereo_match(fl, fr, sim.rig.F, p.ratio, p.epi_tol_px)
    _, depth, _ = arena.cast(sim.rig.left, se3_from_planar(*pose) @ sim.T_body_left)
    fb = sim.rig.left.fx * sim.rig.baseline_m

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
