"""Reading a KITTI odometry sequence folder: calibration, poses, images (real data).

Our reader for the stereo chapter; a general KITTI reader belongs in ``slamlab.io``.
"""

from __future__ import annotations

import numpy as np

from .._validate import as_path
from ..geometry.camera import PinholeCamera, StereoRig

__all__ = ["kitti_rig", "read_kitti_calib", "read_kitti_image"]


def read_kitti_calib(path) -> dict:
    """Projection matrices of a KITTI ``calib.txt``: ``{"P0": (3, 4), "P1": ..., ...}``.

    Accepts the official format (``P0: 12 numbers`` per line, also ``Tr:``) and the stripped
    one (12 numbers per line, no labels: the rows are named P0, P1, ... in order).

    Parameters
    ----------
    path : str or Path
        The ``calib.txt`` file.

    Returns
    -------
    dict
        Name (``"P0"``, ``"P1"``, ..., ``"Tr"``) → ndarray of shape (3, 4).

    Examples
    --------
    >>> import tempfile, pathlib
    >>> f = pathlib.Path(tempfile.mkdtemp()) / "calib.txt"
    >>> _ = f.write_text("P0: 7 0 6 0 0 7 1 0 0 0 1 0\\nP1: 7 0 6 -3 0 7 1 0 0 0 1 0\\n")
    >>> read_kitti_calib(f)["P1"][0].tolist()
    [7.0, 0.0, 6.0, -3.0]
    """
    path = as_path(path, "path", kind="file")
    out = {}
    for n, line in enumerate(path.read_text().splitlines(), start=1):
        if not line.strip():
            continue
        label, sep, rest = line.partition(":")
        if not sep:
            label, rest = f"P{len(out)}", line
        try:
            values = np.array(rest.split(), dtype=float)
        except ValueError as err:
            raise ValueError(f"{path}, line {n}: expected numbers after {label.strip()!r}; {err}") from None
        if values.size != 12:
            raise ValueError(f"{path}, line {n}: {label.strip()!r} must have 12 numbers (a 3x4 matrix); got {values.size}")
        out[label.strip()] = values.reshape(3, 4)
    if "P0" not in out or "P1" not in out:
        raise ValueError(f"{path} must hold the projection matrices P0 and P1; found {sorted(out)}")
    return out


def kitti_rig(calib_path, width_px: int, height_px: int) -> StereoRig:
    """The rectified grey stereo pair (cameras 0 and 1) of a KITTI ``calib.txt``, images ``width_px`` × ``height_px``.

    Parameters
    ----------
    calib_path : str or Path
        The sequence's ``calib.txt``.
    width_px, height_px : int
        Image size [px].

    Returns
    -------
    StereoRig
        Identical cameras from ``P0``, the right one offset by the baseline ``(P1[0, 3] - P0[0, 3]) / fx``.
    """
    P = read_kitti_calib(calib_path)
    P0, P1 = P["P0"], P["P1"]
    fx, fy, cx, cy = P0[0, 0], P0[1, 1], P0[0, 2], P0[1, 2]
    cam = PinholeCamera(int(width_px), int(height_px), fx, fy, cx, cy)
    # P1 = K [I | t] with t = (-b, 0, 0) relative to camera 0: P1[0, 3] - P0[0, 3] = fx t_x
    return StereoRig(cam, cam, np.eye(3), np.array([(P1[0, 3] - P0[0, 3]) / fx, 0.0, 0.0]))


def read_kitti_image(path) -> np.ndarray:
    """A grey uint8 KITTI image; ``FileNotFoundError`` naming the file when it is missing or unreadable.

    Parameters
    ----------
    path : str or Path
        The image file (PNG).

    Returns
    -------
    image : ndarray of uint8, shape (H, W)
        The grey image.
    """
    import cv2

    path = as_path(path, "image", kind="file")
    img = cv2.imread(str(path), cv2.IMREAD_GRAYSCALE)
    if img is None:
        raise FileNotFoundError(f"could not read the image {path}")
    return img
