"""Ch. 9 on real frames (003 §4.2, §5.2): the monocular pipeline and the epipolar search on KITTI odometry data.

Data by path: any KITTI odometry folder with ``calib.txt`` (P0), ``poses.txt`` and ``image_0/``;
the default is the shared 20-frame KITTI 06 snippet.
"""

from __future__ import annotations

import numpy as np

from ..._params import refuse_set_fields
from ..._validate import as_path, check_int
from ...geometry.se3 import se3_inverse
from ...mono.evaluate import TRACK_TOL_FRAC
from ...mono.params import MonoParams
from .experiments import MonoRunResult, run_mono

__all__ = ["KITTI_ABLATIONS", "epipolar_demo", "load_kitti", "run_kitti_ablation", "run_kitti_mono"]


def load_kitti(folder=None, n_frames: int | None = None):
    """``(images, truth (N, 4, 4), K, name)`` of a KITTI odometry folder's left camera (default: the 20-frame 06 set).

    Parameters
    ----------
    folder : str or Path, optional
        KITTI odometry folder (``calib.txt``, ``poses.txt``, ``image_0/``); ``None`` = the bundled 06 set.
    n_frames : int, optional
        Read only the first ``n_frames`` (at least 2); ``None`` = all.

    Returns
    -------
    images : list of ndarray
        Grey uint8 left images.
    truth : ndarray, shape (N, 4, 4)
        Ground-truth poses (camera to world) [m].
    K : ndarray, shape (3, 3)
        Intrinsic matrix of camera 0.
    name : str
        The folder's name.
    """
    from ...data import find_data
    from ...evaluation import read_kitti
    from ...io.kitti import read_kitti_calib, read_kitti_image

    d = find_data("kitti-odometry-06-stereo") if folder is None else as_path(folder, "folder", kind="dir")
    K = read_kitti_calib(d / "calib.txt")["P0"][:, :3]
    gt = read_kitti(d / "poses.txt").poses
    n = len(gt) if n_frames is None else min(len(gt), check_int(n_frames, "n_frames", minimum=2))
    imgs = [read_kitti_image(d / "image_0" / f"{i:06d}.png") for i in range(n)]
    return imgs, gt[:n], K, d.name


def run_kitti_mono(folder=None, *, n_frames: int | None = None, params: MonoParams | None = None,
                   track_tol: float = TRACK_TOL_FRAC, **overrides) -> MonoRunResult:
    """MonoSLAM on the left camera of a KITTI odometry folder; scored against ``poses.txt`` (Sim(3)).

    Parameters
    ----------
    folder : str or Path, optional
        KITTI odometry folder; ``None`` = the bundled 06 set.
    n_frames : int, optional
        Use only the first ``n_frames``; ``None`` = all.
    params : MonoParams, optional
        Settings (default values).
    track_tol : float
        Tolerance of a correctly tracked frame as a fraction of the path length (default 0.05).
    **overrides
        Fields of :class:`MonoParams` to change.

    Returns
    -------
    MonoRunResult
        The run scored against ``poses.txt``.
    """
    imgs, gt, K, name = load_kitti(folder, n_frames)
    return run_mono(imgs, gt, K, name=name, params=params, progress=False, track_tol=track_tol, **overrides)


#: our changes to the tracker switched off one at a time (the KITTI ablation)
KITTI_ABLATIONS = {
    "defaults": {},
    "no re-initialisation after a loss": {"reinit_when_lost": False},
    "homography initialisation always": {"init_method": "homography"},
    "SVO's constant-position prior": {"motion_model": "constant_position"},
    "unwarped seed patches": {"warp_patches": False},
}


def run_kitti_ablation(folder=None, configs=None, *, n_frames: int | None = None, params: MonoParams | None = None,
                       progress=None, **overrides) -> dict:
    """The KITTI run with each of our changes undone, on the same frames.

    Parameters
    ----------
    folder : str or os.PathLike, optional
        A KITTI odometry sequence folder (default: the bundled excerpt).
    configs : mapping, optional
        Label → :class:`MonoParams` overrides (default :data:`KITTI_ABLATIONS`).
    n_frames : int, optional
        Keep the first frames only.
    params : MonoParams, optional
        The settings every configuration changes (default: the defaults); not the fields a configuration
        sets itself (``ValueError`` naming them).
    progress : bool, callable or None
        See :mod:`slamlab._progress`.
    **overrides
        :class:`MonoParams` fields under every configuration's.

    Returns
    -------
    dict
        ``{(label, folder name): MonoRunResult}``.
    """
    from ..._progress import progress_bar

    configs = KITTI_ABLATIONS if configs is None else dict(configs)
    p = MonoParams.resolve(params, **overrides)  # a bad `params` or override fails here, naming the fields
    for o in configs.values():
        p.replace(**o)  # and a bad configuration
    refuse_set_fields(p, sorted({k for o in configs.values() for k in o}),
                      "the configurations of run_kitti_ablation set it")
    imgs, gt, K, name = load_kitti(folder, n_frames)
    return {(label, name): run_mono(imgs, gt, K, name=f"{name}, {label}", params=p, progress=False, **ov)
            for label, ov in progress_bar(list(configs.items()), desc="KITTI ablation", progress=progress)}


def epipolar_demo(folder=None, *, frames=(0, 1, 2), n_seeds: int = 60, depth_mean_m: float = 10.0,
                  depth_min_m: float = 2.0, fast_threshold: int = 30):
    """Seeds of KITTI frame ``frames[0]`` searched along their epipolar segments in the next frames (003 §4.2).

    The poses are KITTI's ground truth (the search itself is what is shown). Returns a list of
    dicts, one per searched frame: ``img_ref, img_cur, uv_ref, a, b, uv_match, found, n_candidates,
    sigma`` (σ_ρ before that search).

    Parameters
    ----------
    folder : str or Path, optional
        KITTI odometry folder; ``None`` = the bundled 06 set.
    frames : tuple of int
        Reference frame then the frames searched (default ``(0, 1, 2)``).
    n_seeds : int
        Seeds drawn from the reference frame's FAST corners (default 60).
    depth_mean_m, depth_min_m : float
        Seed prior: mean and smallest depth [m] (defaults 10 and 2).
    fast_threshold : int
        FAST threshold (default 30).

    Returns
    -------
    list of dict
        One per searched frame: ``img_ref``, ``img_cur``, ``uv_ref``, ``a``, ``b``, ``uv_match``, ``found``,
        ``n_candidates``, ``sigma``.
    """
    from ...data import find_data
    from ...evaluation import read_kitti
    from ...features.opencv import fast_cv
    from ...io.kitti import read_kitti_calib, read_kitti_image
    from ...mono.depth_filter import compute_tau, init_seeds, tau_inverse, update_seeds
    from ...mono.epipolar import extract_patches, search_epipolar

    d = find_data("kitti-odometry-06-stereo") if folder is None else as_path(folder, "folder", kind="dir")
    K = read_kitti_calib(d / "calib.txt")["P0"][:, :3]
    gt = read_kitti(d / "poses.txt").poses
    imgs = {i: read_kitti_image(d / "image_0" / f"{i:06d}.png") for i in frames}
    ref = imgs[frames[0]]
    F = fast_cv(ref, threshold=fast_threshold)
    h, w = ref.shape
    keep = (F.uv[:, 0] > 20) & (F.uv[:, 0] < w - 20) & (F.uv[:, 1] > 20) & (F.uv[:, 1] < h - 20)
    uv = F.uv[keep][np.argsort(-F.response[keep], kind="stable")[:n_seeds]]
    f = np.column_stack([(uv - K[:2, 2]) / [K[0, 0], K[1, 1]], np.ones(len(uv))])
    s = init_seeds(uv, f, depth_mean_m, depth_min_m)
    patches = extract_patches(ref, uv, 9)
    out = []
    px_angle = 2 * np.arctan(1.0 / (2 * K[0, 0]))
    for fr in frames[1:]:
        T_cur_ref = se3_inverse(gt[fr]) @ gt[frames[0]]
        sigma = np.sqrt(s.sigma2)
        cur = imgs[fr]
        C = fast_cv(cur, threshold=fast_threshold).uv
        m = search_epipolar(K, T_cur_ref, s.f, s.mu, sigma, patches, cur, C, patch_px=9, tol_px=2.0)
        out.append({"img_ref": ref, "img_cur": cur, "uv_ref": uv, "a": m.a, "b": m.b, "uv_match": m.uv,
                    "found": m.found, "n_candidates": m.n_candidates, "sigma": sigma, "frame": fr})
        fi = np.flatnonzero(m.found)
        if fi.size:
            z = m.depth_m[fi]
            tau = compute_tau(se3_inverse(T_cur_ref)[:3, 3], s.f[fi], z, px_angle)
            good = np.isfinite(tau)
            fi, z, tau = fi[good], z[good], tau[good]
            s.mu[fi], s.sigma2[fi], s.a[fi], s.b[fi] = update_seeds(s.mu[fi], s.sigma2[fi], s.a[fi], s.b[fi], 1 / z,
                                                                    tau_inverse(z, tau) ** 2, s.rho_range[fi])
        s.b[np.setdiff1d(np.arange(len(s)), fi)] += 1
    return out
