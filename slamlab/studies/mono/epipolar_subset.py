"""Which corners the epipolar search looks at (003 §4.2), on rendered frames whose depth is known.

003 §4.2: searching every pixel of the band around the epipolar segment "would take very long, and the
algorithm would not run in real time", so only FAST corners are tried; and since FAST returns them
sorted by rows and columns, only those sharing rows and columns with the line need their position
checked. :func:`run_epipolar_subset` counts, for seeds on the FAST corners of one rendered frame, the
pixels of their bands, the corners in their rows, in their rows and columns (003's subset) and in their
bands, and scores the search against the truth (the renderer's depth), beside a search among every
corner of the image (ours: what the epipolar line saves).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..._table import format_table
from ..._validate import check_int, check_positive
from ...geometry.camera import project_points
from ...geometry.se3 import se3_inverse
from ...mono.depth_filter import init_seeds
from ...mono.epipolar import epipolar_candidates, epipolar_segments, extract_patches, zncc
from ...mono.params import MonoParams
from .experiments import case_seed, failure_case_frames, mono_sim

__all__ = ["EpipolarSubset", "run_epipolar_subset"]


@dataclass(frozen=True)
class EpipolarSubset:
    """Search sets of 003 §4.2 counted and scored on one rendered pair (:func:`run_epipolar_subset`).

    Attributes
    ----------
    frames : tuple of int
        Reference and searched frame.
    baseline_m : float
        Distance between the two camera centres [m].
    n_seeds : int
        Seeds: FAST corners of the reference frame whose true point is in view of the searched frame.
    n_corners : int
        FAST corners of the searched frame (inside the patch margin).
    n_in_interval : int
        Seeds whose true depth lies in the searched interval ``1/(ρ ± 2σ)``.
    rows : list of tuple
        Per search set: label, median corners in the rows, in rows and columns, in the band, median band
        pixels (or None where not counted), matches, wrong matches.
    wrong_px : float
        A match farther than this from the true point's projection is wrong [px].
    zncc_min : float
        Smallest ZNCC of a match.
    """

    frames: tuple
    baseline_m: float
    n_seeds: int
    n_corners: int
    n_in_interval: int
    rows: list = field(repr=False)
    wrong_px: float = 2.0
    zncc_min: float = 0.8

    def __str__(self) -> str:
        return (f"epipolar search sets, frame {self.frames[0]} -> {self.frames[1]}: {self.n_seeds} seeds, "
                f"{self.n_corners} corners")

    def table(self) -> str:
        """One row per search set: the corners looked at and scored, matches, wrong and right ones.

        Returns
        -------
        str
        """
        f0 = lambda x: "-" if x is None else f"{x:.0f}"
        body = [[lab, f0(r), f0(b), f0(n), f0(px), f"{m}", f"{w}", f"{m - w}"] for lab, r, b, n, px, m, w in self.rows]
        title = (f"Search sets of 003 §4.2, rendered strafe frame {self.frames[0]} -> {self.frames[1]} "
                 f"(baseline {self.baseline_m:.2f} m), true poses\n"
                 f"{self.n_seeds} seeds ({self.n_in_interval} with the true depth in the searched interval), "
                 f"{self.n_corners} FAST corners in the searched frame\n"
                 f"per seed (median): corners in the segment's rows, in its rows and columns (003's subset), in its "
                 f"band\n(scored), pixels in its band; match: best ZNCC >= {self.zncc_min}; wrong: "
                 f"> {self.wrong_px:g} px from the true point's projection")
        return format_table(["search among", "rows", "rows+cols", "band", "band pixels", "matches", "wrong",
                             "right"], body, title=title)


def run_epipolar_subset(frames=(0, 5), *, size: str = "tiny", tols_px=(1.0, 2.0, 4.0), depth_mean_m: float = 3.0,
                        depth_min_m: float = 0.5, wrong_px: float = 2.0, params: MonoParams | None = None,
                        rng=0) -> EpipolarSubset:
    """003 §4.2's search sets on a rendered pair with known depth: counted, then scored (ours).

    Seeds are the FAST corners of frame ``frames[0]`` of the chapter's rendered strafe (the frames of the
    ``"normal"`` case for ``rng``) whose true point (the renderer's depth) projects into frame
    ``frames[1]``; each starts from SVO's prior (mean depth ``depth_mean_m``, nearest ``depth_min_m``, not
    from the truth). With the true poses, each seed is searched among the corners of the band around its
    segment for each tolerance in ``tols_px`` (:func:`~slamlab.mono.epipolar.epipolar_candidates`), and among
    every corner of the image; the best ZNCC of unwarped ``patch_px`` patches at least ``zncc_min`` is a
    match, wrong when it lies over ``wrong_px`` from the true point's projection.

    Parameters
    ----------
    frames : tuple of int
        Reference frame and searched frame (default ``(0, 5)``: 0.10 m apart).
    size : str
        Render size (default ``"tiny"``).
    tols_px : sequence of float
        Half-widths of the band [px] (default 1, 2 and 4).
    depth_mean_m, depth_min_m : float
        The seeds' prior: mean and nearest depth [m] (defaults 3 and 0.5).
    wrong_px : float
        Largest distance of a right match from the true projection [px] (default 2).
    params : MonoParams, optional
        ``fast_threshold``, ``patch_px``, ``zncc_min`` and ``n_sigma`` come from here (default values).
    rng : int, SeedSequence or Generator
        The chapter's seed (the ``"normal"`` case's image noise).

    Returns
    -------
    EpipolarSubset
    """
    from ...features.opencv import fast_cv

    p = MonoParams.resolve(params)
    if len(frames) != 2:
        raise ValueError(f"`frames` must be (reference, searched); got {frames!r}")
    i0, i1 = (check_int(f, "frames", minimum=0) for f in frames)
    if i1 == i0:
        raise ValueError(f"`frames` must name two different frames; got {frames!r}")
    tols = [check_positive(t, "tols_px") for t in tols_px]
    if not tols:
        raise ValueError("`tols_px` must hold at least one tolerance; got none")
    depth_min_m = check_positive(depth_min_m, "depth_min_m")
    depth_mean_m = check_positive(depth_mean_m, "depth_mean_m")
    if depth_mean_m < depth_min_m:
        raise ValueError(f"`depth_mean_m` must be at least `depth_min_m` ({depth_min_m}); got {depth_mean_m}")
    wrong_px = check_positive(wrong_px, "wrong_px")
    stream = case_seed(rng, "normal")
    imgs, Ts, K, _ = failure_case_frames("normal", size, max(i0, i1) + 1, rng=np.random.default_rng(stream))
    ref, cur = imgs[i0], imgs[i1]
    h, w = ref.shape
    mg = (p.patch_px + 1) / 2.0 + 1

    def corners(img):
        c = fast_cv(img, threshold=p.fast_threshold).uv
        return c[(c[:, 0] >= mg) & (c[:, 0] < w - mg) & (c[:, 1] >= mg) & (c[:, 1] < h - mg)]

    uv, C = corners(ref), corners(cur)
    # the true point of each seed: the renderer's depth at its pixel (z along a ray with z = 1)
    sim = mono_sim(size)
    _, z_map, _ = sim.arena.cast(sim.rig.left, Ts[i0])
    z = z_map[uv[:, 1].astype(np.intp), uv[:, 0].astype(np.intp)].astype(np.float64)
    ray = np.column_stack([(uv - K[:2, 2]) / [K[0, 0], K[1, 1]], np.ones(len(uv))])
    T_cur_ref = se3_inverse(Ts[i1]) @ Ts[i0]
    Xc = np.einsum("ij,nj->ni", T_cur_ref[:3, :3], ray * np.where(np.isfinite(z), z, 1.0)[:, None]) + T_cur_ref[:3, 3]
    uv_true = project_points(K, np.where(Xc[:, 2:3] > 1e-6, Xc, 1.0))
    seen = (np.isfinite(z) & (Xc[:, 2] > 1e-6) & (uv_true[:, 0] >= mg) & (uv_true[:, 0] < w - mg)
            & (uv_true[:, 1] >= mg) & (uv_true[:, 1] < h - mg))
    uv, uv_true, ray, z = uv[seen], uv_true[seen], ray[seen], z[seen]
    f = ray / np.sqrt(np.einsum("ni,ni->n", ray, ray))[:, None]
    s = init_seeds(uv, f, depth_mean_m, depth_min_m)
    sigma = np.sqrt(s.sigma2)
    a, b, ok = epipolar_segments(K, T_cur_ref, s.f, s.mu, sigma, p.n_sigma)
    rho_true = 1.0 / (z * np.sqrt(np.einsum("ni,ni->n", ray, ray)))  # inverse range along the unit ray
    in_interval = int(np.sum(np.abs(rho_true - s.mu) <= p.n_sigma * sigma))
    Z = zncc(extract_patches(ref, uv, p.patch_px), extract_patches(cur, C, p.patch_px))  # (seeds, corners)

    def score(mask):
        Zm = np.where(mask, Z, -2.0)
        j = np.argmax(Zm, axis=1)
        best = Zm[np.arange(len(uv)), j]
        found = best >= p.zncc_min
        wrong = found & (np.hypot(*(C[j] - uv_true).T) > wrong_px)
        return int(found.sum()), int(wrong.sum())

    m, wr = score(np.ones(Z.shape, bool))
    rows = [("every corner (no epipolar line; ours)", None, None, float(len(C)), None, m, wr)]
    pix = np.stack(np.meshgrid(np.arange(w, dtype=np.float64), np.arange(h, dtype=np.float64)), -1).reshape(-1, 2)
    for t in tols:
        ec = epipolar_candidates(C, a, b, ok, tol_px=t)
        mask = np.zeros(Z.shape, bool)
        mask[ec.seed_idx, ec.corner_idx] = True
        n_pix = epipolar_candidates(pix, a, b, ok, tol_px=t).n_band
        m, wr = score(mask)
        rows.append((f"the {t:g} px band" + (" (the chapter's)" if t == p.epi_tol_px else ""),
                     float(np.median(ec.n_rows)), float(np.median(ec.n_box)), float(np.median(ec.n_band)),
                     float(np.median(n_pix)), m, wr))
    baseline = float(np.linalg.norm(Ts[i1][:3, 3] - Ts[i0][:3, 3]))
    return EpipolarSubset((i0, i1), baseline, len(uv), len(C), in_interval, rows, wrong_px, p.zncc_min)
