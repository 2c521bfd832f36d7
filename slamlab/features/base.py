"""One result type for every detector: keypoints and descriptors as numpy arrays (000 §1.4)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .._validate import as_image, check_choice, check_int

__all__ = ["CHANNEL_ORDERS", "Features", "to_gray_float", "to_gray_uint8"]


@dataclass(frozen=True)
class Features:
    """Keypoints and descriptors of one image (000 §1.4).

    Attributes
    ----------
    uv : (N, 2) float
        Pixel position (u, v) = (column, row), origin at the top-left pixel centre.
    scale_px : (N,) float
        Characteristic scale σ in pixels (SURF: 1.2·L/9 for filter size L; OpenCV
        detectors: ``KeyPoint.size / 2``; FAST/Moravec: the radius of their support).
    orientation_rad : (N,) float
        Orientation in [0, 2π), image axes (u right, v down); 0 for upright/unoriented.
    response : (N,) float
        Detector strength (SURF: Hessian determinant; FAST: OpenCV score; Moravec: min SSD).
    octave : (N,) int
        Octave the point was found in (0 for single-scale detectors).
    descriptors : (N, d) array or None
        float32 (SIFT 128, SURF 64/128) or uint8 bytes of a binary descriptor (ORB 32).
    method : str
        Name of the detector.
    """

    uv: np.ndarray
    scale_px: np.ndarray
    orientation_rad: np.ndarray
    response: np.ndarray
    octave: np.ndarray
    descriptors: np.ndarray | None = None
    method: str = ""

    def __post_init__(self):
        n = len(self.uv)
        for name in ("scale_px", "orientation_rad", "response", "octave"):
            if len(getattr(self, name)) != n:
                raise ValueError(f"`{name}` must have {n} entries to match `uv`; got {len(getattr(self, name))}")
        if self.descriptors is not None and len(self.descriptors) != n:
            raise ValueError(f"`descriptors` must have {n} rows to match `uv`; got {len(self.descriptors)}")

    def __len__(self) -> int:
        return len(self.uv)

    @property
    def is_binary(self) -> bool:
        """True for binary descriptors (compared with the Hamming distance)."""
        return self.descriptors is not None and self.descriptors.dtype == np.uint8

    def __str__(self) -> str:
        d = "no descriptors" if self.descriptors is None else f"{self.descriptors.shape[1]}-d descriptors"
        return f"{self.method}: {len(self)} keypoints, {d}"

    def subset(self, index) -> Features:
        """The keypoints selected by a boolean mask or an index array.

        Parameters
        ----------
        index : (N,) bool or (K,) int array
            Boolean mask over the keypoints or indices of the keypoints to keep, in that order.

        Returns
        -------
        Features
            The selected keypoints (and descriptors), same ``method``.
        """
        index = np.asarray(index)
        return Features(self.uv[index], self.scale_px[index], self.orientation_rad[index], self.response[index],
                        self.octave[index], None if self.descriptors is None else self.descriptors[index],
                        self.method)

    def strongest(self, n: int) -> Features:
        """The ``n`` keypoints of largest response (stable order for ties).

        Parameters
        ----------
        n : int
            Number of keypoints to keep (>= 0); all of them when ``n`` exceeds their number.

        Returns
        -------
        Features
            The ``n`` strongest keypoints, in their original order.
        """
        n = check_int(n, "n", minimum=0)
        order = np.argsort(-self.response, kind="stable")[:n]
        return self.subset(np.sort(order))

    @classmethod
    def empty(cls, method: str = "", dim: int | None = None, dtype=np.float32) -> Features:
        """No keypoints (what a detector returns when it finds none).

        Parameters
        ----------
        method : str
            Name of the detector.
        dim : int, optional
            Descriptor length: a ``(0, dim)`` descriptor array; None for no descriptors.
        dtype : numpy dtype
            Descriptor type (float32, or uint8 for binary descriptors).

        Returns
        -------
        Features
        """
        z = np.zeros(0)
        desc = None if dim is None else np.zeros((0, dim), dtype=dtype)
        return cls(np.zeros((0, 2)), z, z, z, np.zeros(0, dtype=np.int64), desc, method)


#: channel orders of colour images: "rgb" (numpy / matplotlib / imageio) or "bgr" (``cv2.imread``)
CHANNEL_ORDERS = ("rgb", "bgr")
_BT601 = np.array([0.299, 0.587, 0.114])


def to_gray_float(image, name: str = "image", *, channel_order: str = "rgb") -> np.ndarray:
    """Grey image as float64 in [0, 1] (uint8 / 255; float taken as given; colour weighted as BT.601).

    ``channel_order`` says how a colour image's channels are ordered: ``"rgb"`` (default:
    numpy, matplotlib, imageio) or ``"bgr"`` (what ``cv2.imread`` returns).

    Parameters
    ----------
    image : (H, W) or (H, W, 3|4) array
        Grey or colour image: uint8 (divided by 255), bool, or float (taken as given).
    name : str
        Argument name used in error messages.
    channel_order : {'rgb', 'bgr'}
        Channel order of a colour image.

    Returns
    -------
    gray : (H, W) float64
        Grey image, in [0, 1] for uint8 input.

    Examples
    --------
    >>> to_gray_float(np.array([[0, 255]], dtype=np.uint8)).tolist()
    [[0.0, 1.0]]
    >>> bgr = np.array([[[255, 0, 0]]], np.uint8)  # pure blue in OpenCV's order
    >>> round(float(to_gray_float(bgr, channel_order="bgr")[0, 0]), 3)
    0.114
    """
    img = as_image(image, name, allow_color=True)
    if img.ndim == 3:
        w = _BT601 if check_choice(channel_order, "channel_order", CHANNEL_ORDERS) == "rgb" else _BT601[::-1]
        g = img[..., :3].astype(np.float64) @ w
        scale = 255.0 if np.asarray(image).dtype == np.uint8 else 1.0
        return g / scale
    if img.dtype == np.uint8:
        return img.astype(np.float64) / 255.0
    if img.dtype == np.bool_:
        return img.astype(np.float64)
    return img.astype(np.float64, copy=False)


def to_gray_uint8(image, name: str = "image", *, channel_order: str = "rgb") -> np.ndarray:
    """Grey uint8 image (float images are taken to be in [0, 1]); what OpenCV's detectors need.

    A uint8 colour image is converted by OpenCV (``cv2.COLOR_RGB2GRAY`` or, with
    ``channel_order="bgr"``, ``cv2.COLOR_BGR2GRAY``: the same values as ``cv2.imread(...,
    cv2.IMREAD_GRAYSCALE)`` of a colour file read in colour).

    Parameters
    ----------
    image : (H, W) or (H, W, 3|4) array
        Grey or colour image, uint8 or float in [0, 1] (rounded and clipped to 0..255).
    name : str
        Argument name used in error messages.
    channel_order : {'rgb', 'bgr'}
        Channel order of a colour image.

    Returns
    -------
    gray : (H, W) uint8
        Grey image (a uint8 grey input is returned as is).
    """
    img = as_image(image, name, allow_color=True)
    if img.dtype == np.uint8 and img.ndim == 2:
        return img
    if img.dtype == np.uint8:
        import cv2

        code = {"rgb": cv2.COLOR_RGB2GRAY, "bgr": cv2.COLOR_BGR2GRAY}[
            check_choice(channel_order, "channel_order", CHANNEL_ORDERS)]
        return cv2.cvtColor(np.ascontiguousarray(img[..., :3]), code)
    g = to_gray_float(img, name, channel_order=channel_order)
    return np.clip(np.rint(g * 255.0), 0, 255).astype(np.uint8)
