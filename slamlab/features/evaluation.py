"""Evaluation on image pairs with a ground-truth homography (Oxford affine set; 000 §1.4).

Repeatability (our definition, position only, stated): map the keypoints of
image 1 through H; keep only points in the common visible region (img1 points
whose image lies inside img2, img2 points whose preimage lies inside img1); a
correspondence is a pair closer than ``tol_px`` in image-2 pixels. The number of
correspondences is ``min(#img1 points with an img2 point within tol,
#img2 points with an img1 point within tol)`` and the repeatability is that
number over ``min(n1, n2)`` of the common-region counts. Mikolajczyk et al.
compare region overlaps (40 % overlap error) instead; ours ignores scale and
shape.

Matching: a match i→j is correct when ``|H·p_i - p_j| < tol_px``; precision =
correct / matches; recall = correct / correspondences (the repeatable points).
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np
from scipy.spatial import cKDTree

from .._validate import as_matrix, as_path, check_int, check_positive
from ..data import find_data
from ..geometry.homography import apply_homography as project
from .base import Features
from .matching import Matches

__all__ = [
    "OXFORD_SEQUENCES",
    "PairScores",
    "common_region",
    "correct_matches",
    "load_oxford_image",
    "load_oxford_pair",
    "oxford_folder",
    "oxford_label",
    "project",
    "repeatability",
]

#: the Oxford affine sequences of the shared data folder, loadable by name (any other folder by path)
OXFORD_SEQUENCES = ("bark", "boat", "graf", "trees", "ubc", "wall")
_IMAGE_SUFFIXES = (".png", ".ppm", ".pgm", ".jpg", ".tif")


def oxford_folder(sequence) -> Path:
    """The folder of an Oxford-layout sequence: a shared sequence's name (:data:`OXFORD_SEQUENCES`,
    found by :func:`slamlab.data.find_data`) or a ``str`` / ``os.PathLike`` path to any folder with
    ``img1.<ext> ... imgN.<ext>`` and the homographies ``H1to2p ... H1toNp`` (the Oxford layout).

    Parameters
    ----------
    sequence : str or os.PathLike
        A name in :data:`OXFORD_SEQUENCES` or the path of an Oxford-layout folder.

    Returns
    -------
    pathlib.Path
        The sequence's folder.
    """
    if isinstance(sequence, str) and sequence in OXFORD_SEQUENCES:
        return Path(find_data(f"oxford-affine/{sequence}"))
    if isinstance(sequence, str) and not any(c in sequence for c in "/\\") and not Path(sequence).exists():
        raise ValueError(f"`sequence` must be one of {OXFORD_SEQUENCES} or the path of an Oxford-layout folder; "
                         f"got {sequence!r}")
    return as_path(sequence, "sequence", kind="dir")


def oxford_label(sequence) -> str:
    """The name of a sequence for tables and titles: the folder's name.

    Parameters
    ----------
    sequence : str or os.PathLike
        A shared sequence's name or an Oxford-layout folder (see :func:`oxford_folder`).

    Returns
    -------
    str
        The shared name as given, else the folder's name.
    """
    return sequence if isinstance(sequence, str) and sequence in OXFORD_SEQUENCES else oxford_folder(sequence).name


def _image_file(folder: Path, index: int) -> Path:
    for suffix in _IMAGE_SUFFIXES:
        path = folder / f"img{index}{suffix}"
        if path.is_file():
            return path
    raise FileNotFoundError(f"no image img{index} ({', '.join(_IMAGE_SUFFIXES)}) in {folder}")


def load_oxford_image(sequence, index: int, *, scale: float = 1.0, size=None) -> np.ndarray:
    """Grey uint8 image ``img<index>`` of an Oxford-layout sequence (name or folder path, see
    :func:`oxford_folder`), resized by ``scale`` or to ``size = (width_px, height_px)``
    (INTER_AREA; e.g. 000's camera, (768, 576)). Colour files are read as OpenCV's grey.

    Parameters
    ----------
    sequence : str or os.PathLike
        A shared sequence's name or an Oxford-layout folder.
    index : int
        Image number, 1-based (``img1`` is the reference image).
    scale : float
        Resize factor (> 0); 1 keeps the file's size. Not together with ``size``.
    size : (int, int), optional
        Output size (width_px, height_px).

    Returns
    -------
    image : (H, W) uint8
        The grey image.
    """
    import cv2

    folder = oxford_folder(sequence)
    index = check_int(index, "index", minimum=1)
    scale = check_positive(scale, "scale")
    if size is not None:
        if scale != 1.0:
            raise ValueError(f"give `scale` or `size`, not both; got scale={scale}, size={size}")
        if len(size) != 2:
            raise ValueError(f"`size` must be (width_px, height_px); got {size}")
        size = (check_int(size[0], "size[0]", minimum=1), check_int(size[1], "size[1]", minimum=1))
    path = _image_file(folder, index)
    img = cv2.imread(str(path), cv2.IMREAD_GRAYSCALE)
    if img is None:
        raise FileNotFoundError(f"could not read {path}")
    if size is not None:
        img = cv2.resize(img, size, interpolation=cv2.INTER_AREA)
    elif scale != 1.0:
        h, w = img.shape
        img = cv2.resize(img, (max(1, round(w * scale)), max(1, round(h * scale))), interpolation=cv2.INTER_AREA)
    return img


def load_oxford_pair(sequence, j: int, *, scale: float = 1.0):
    """``(img1, img_j, H)``: grey images and the homography img1 → img_j (pixel centres, after ``scale``).

    ``sequence``: a shared sequence's name or the path of any Oxford-layout folder
    (:func:`oxford_folder`). Resizing by ``s`` maps a pixel centre x to ``s·(x + 0.5) - 0.5``, so
    ``H_s = S·H·S⁻¹`` with ``S = [[s, 0, s/2 - 1/2], [0, s, s/2 - 1/2], [0, 0, 1]]``.

    Parameters
    ----------
    sequence : str or os.PathLike
        A shared sequence's name or an Oxford-layout folder.
    j : int
        Number of the second image (>= 2); its homography file is ``H1to<j>p``.
    scale : float
        Resize factor (> 0) applied to both images; H is adapted to it.

    Returns
    -------
    img1, img_j : (H, W) uint8
        The grey reference image and image ``j``.
    H : (3, 3) float
        Homography from img1 pixels to img_j pixels, normalised so that ``H[2, 2] = 1``.
    """
    folder = oxford_folder(sequence)
    j = check_int(j, "j", minimum=2)
    img1 = load_oxford_image(folder, 1, scale=scale)
    img2 = load_oxford_image(folder, j, scale=scale)
    h_path = folder / f"H1to{j}p"
    if not h_path.is_file():
        raise FileNotFoundError(f"no homography file {h_path}")
    H = np.loadtxt(h_path)
    if H.shape != (3, 3):
        raise ValueError(f"{h_path} must hold a 3x3 homography; got shape {H.shape}")
    s = float(scale)
    S = np.array([[s, 0, s / 2 - 0.5], [0, s, s / 2 - 0.5], [0, 0, 1.0]])
    H = S @ H @ np.linalg.inv(S)
    return img1, img2, H / H[2, 2]


def _inside(uv, shape, margin):
    h, w = shape[:2]
    return (uv[:, 0] >= margin) & (uv[:, 0] <= w - 1 - margin) & (uv[:, 1] >= margin) & (uv[:, 1] <= h - 1 - margin)


def common_region(f1: Features, f2: Features, H, shape1, shape2, *, margin_px: float = 0.0):
    """Masks of the keypoints of each image that lie in the part of the scene both images see.

    Parameters
    ----------
    f1, f2 : Features
        Keypoints of image 1 and image 2.
    H : (3, 3) array
        Homography from image-1 to image-2 pixels.
    shape1, shape2 : tuple
        Shapes ``(H, W, ...)`` of image 1 and image 2.
    margin_px : float
        A mapped point must lie at least this many pixels inside the other image's border.

    Returns
    -------
    in1 : (len(f1),) bool
        Image-1 keypoints whose image under H lies inside image 2.
    in2 : (len(f2),) bool
        Image-2 keypoints whose preimage lies inside image 1.
    """
    H = as_matrix(H, "H", (3, 3))
    in1 = _inside(project(H, f1.uv), shape2, margin_px) if len(f1) else np.zeros(0, dtype=bool)
    in2 = _inside(project(np.linalg.inv(H), f2.uv), shape1, margin_px) if len(f2) else np.zeros(0, dtype=bool)
    return in1, in2


def _check_features(f, name):
    if not isinstance(f, Features):
        raise TypeError(f"`{name}` must be slamlab.features.Features; got {type(f).__name__}")
    return f


@dataclass(frozen=True)
class PairScores:
    """Repeatability and (optionally) matching scores of one detector on one image pair.

    Attributes
    ----------
    n1, n2 : int
        Keypoints of img1 and of img2 in the common region.
    correspondences : int
        Repeated points (see the module notes).
    repeatability : float
        ``correspondences / min(n1, n2)``.
    matches : int
        Accepted descriptor matches (0 when matching was not scored).
    correct : int
        Matches that the homography confirms; ``precision`` and ``recall`` derive from these.
    """

    n1: int  # keypoints of img1 in the common region
    n2: int
    correspondences: int
    repeatability: float
    matches: int = 0
    correct: int = 0

    @property
    def precision(self) -> float:
        return self.correct / self.matches if self.matches else float("nan")

    @property
    def recall(self) -> float:
        return self.correct / self.correspondences if self.correspondences else float("nan")


def repeatability(f1: Features, f2: Features, H, shape1, shape2, *, tol_px: float = 2.5) -> PairScores:
    """Repeatability of keypoints under a known homography (position only; see the module notes).

    Parameters
    ----------
    f1, f2 : Features
        Keypoints of image 1 and image 2.
    H : (3, 3) array
        Homography from image-1 to image-2 pixels.
    shape1, shape2 : tuple
        Shapes of image 1 and image 2 (they bound the common region).
    tol_px : float
        A correspondence is a pair closer than this, in image-2 pixels.

    Returns
    -------
    PairScores
        ``n1``, ``n2``, ``correspondences`` and ``repeatability`` (matching fields 0).

    Examples
    --------
    >>> from slamlab.features.base import Features
    >>> z = np.zeros(3)
    >>> f = Features(np.array([[10.0, 10], [20, 20], [30, 5]]), z, z, z, z.astype(int))
    >>> g = Features(np.array([[11.0, 10], [50, 50]]), np.zeros(2), np.zeros(2), np.zeros(2), np.zeros(2, int))
    >>> r = repeatability(f, g, np.eye(3), (40, 40), (60, 60))
    >>> (r.n1, r.n2, r.correspondences, r.repeatability)
    (3, 1, 1, 1.0)
    """
    f1, f2 = _check_features(f1, "f1"), _check_features(f2, "f2")
    tol_px = check_positive(tol_px, "tol_px")
    in1, in2 = common_region(f1, f2, H, shape1, shape2)
    p1 = project(H, f1.uv[in1]) if in1.any() else np.zeros((0, 2))
    p2 = f2.uv[in2]
    n1, n2 = len(p1), len(p2)
    if n1 == 0 or n2 == 0:
        return PairScores(n1, n2, 0, 0.0)
    d12, _ = cKDTree(p2).query(p1)
    d21, _ = cKDTree(p1).query(p2)
    corr = int(min(np.count_nonzero(d12 < tol_px), np.count_nonzero(d21 < tol_px)))
    return PairScores(n1, n2, corr, corr / min(n1, n2))


def correct_matches(f1: Features, f2: Features, matches: Matches, H, *, tol_px: float = 2.5) -> np.ndarray:
    """True for the matches (f1 as query, f2 as train) that H maps within ``tol_px``.

    Parameters
    ----------
    f1, f2 : Features
        Keypoints of image 1 (query side) and image 2 (train side).
    matches : Matches
        Matches between them (:func:`slamlab.features.matching.match_descriptors`).
    H : (3, 3) array
        Homography from image-1 to image-2 pixels.
    tol_px : float
        Largest distance in image-2 pixels between ``H·p_i`` and ``p_j`` of a correct match.

    Returns
    -------
    (len(matches),) bool
        True for the correct matches.
    """
    f1, f2 = _check_features(f1, "f1"), _check_features(f2, "f2")
    tol_px = check_positive(tol_px, "tol_px")
    if len(matches) == 0:
        return np.zeros(0, dtype=bool)
    p = project(H, f1.uv[matches.query_idx])
    return np.linalg.norm(p - f2.uv[matches.train_idx], axis=1) < tol_px
