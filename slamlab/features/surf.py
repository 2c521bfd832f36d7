"""SURF written from the paper (Bay et al. 2006/2008; 000 §1.4.2, §3.3), vectorised numpy.

Steps (Bay et al. 2008 §3-4, with OpenSURF's conventions that 000 cites [21]):

1. integral image ``II`` of the grey image in [0, 1];
2. box-filter approximations of the second derivatives of a Gaussian, filter side
   ``L = 3·(2^(o+1)·(i+1) + 1)`` for octave ``o`` and interval ``i`` (9, 15, 21, 27;
   15, 27, 39, 51; ...), evaluated on a grid of step ``init_step·2^o``; the
   responses are divided by ``L²`` and the approximate Hessian determinant is
   ``det = Dxx·Dyy - (0.9·Dxy)²``;
3. threshold on ``det`` and 3×3×3 non-maximum suppression in (u, v, scale) within
   each octave;
4. quadratic interpolation of position and scale (offset ``-H⁻¹∇``, kept when every
   component is below 0.5 grid steps); σ = 1.2·L/9;
5. orientation: Haar responses (side 4σ) at the points of radius 6σ, weighted by a
   Gaussian of 2.5σ, summed in a sliding 60° window (step 0.15 rad); the longest
   sum gives the angle;
6. descriptor: a 20σ square aligned with the orientation, 4×4 sub-regions of 5×5
   samples, Haar responses (side 2σ) weighted by a Gaussian of 3.3σ, rotated to
   the keypoint frame, per sub-region (Σdx, Σdy, Σ|dx|, Σ|dy|) -> 64-d; the extended
   variant splits the sums by the sign of the other component -> 128-d; unit length.

000 §3.3 settings: no initial downscale, initial step 2, 4 octaves, threshold
0.05. **Response scale (our choice, stated):** ``det`` is computed on an image in
[0, 1] with area-normalised filters -- OpenSURF's scale, where its default
threshold is 0.0004. Read on that scale 000's 0.05 is about 100× OpenSURF's
default and leaves only a handful of points on a real 576×768 image; the
notebook tabulates the point count against the threshold and which scale makes
0.05 give 000's "about 2000 points" (see :func:`threshold_sweep`).

Everything is vectorised (issue 17 for the speed; the same keypoints and descriptors as the plain
versions, tested): the integral image is written into an edge-padded array (edge padding = boxes
clipped to the image); the response maps of the finest octave run on contiguous copies of its
step×step sub-grids, the coarser ones on strided views, and each octave after the first takes two
of its four layers from the octave before (same filter side, twice the step); NMS compares the
points above the threshold with their 26 neighbours; orientation and descriptors gather Haar
responses for chunks of a few dozen keypoints of one rounded scale at once (temporaries that stay
in the 1 MiB L2 cache), the orientation's sliding window from sums over angle bins. Where numba is
available (issue 45; ``SLAMLAB_NO_NUMBA=1`` takes the numpy path) the response maps, the NMS, the
orientation's Haar responses and window sums and the 64-d descriptor's sums run in compiled kernels
(``_surf_kernels``, on chunks of 512 keypoints) that repeat the numpy operations in the same order: the same
numbers bit for bit, tested.
"""

from __future__ import annotations

import numpy as np

from .._validate import check_int, check_positive
from ._padded_ii import PaddedIntegralImage
from .base import Features, to_gray_float
from .surf_descriptor import surf_describe, surf_orientation
from .surf_haar import haar_xy
from .surf_response import (
    box_sums,
    filter_sizes,
    hessian_maxima,
    hessian_response,
    integral_image,
    threshold_sweep,
)

__all__ = [
    "SURF",
    "box_sums",
    "filter_sizes",
    "haar_xy",
    "hessian_maxima",
    "hessian_response",
    "integral_image",
    "surf_describe",
    "surf_detect",
    "surf_orientation",
    "threshold_sweep",
]


def surf_detect(image, threshold: float = 0.0004, *, n_octaves: int = 4, init_step: int = 2,
                upright: bool = False, extended: bool = False, descriptors: bool = True,
                workers: int = 2) -> Features:
    """SURF keypoints and descriptors (Bay et al. 2008; 000 §1.4.2, settings of §3.3).

    Parameters
    ----------
    image : (H, W) grey image (uint8, or float in [0, 1])
    threshold : float
        Minimum Hessian determinant on our response scale (image in [0, 1], filters
        divided by L²; OpenSURF's default 0.0004). See the module notes for 000's 0.05.
    n_octaves : int
        Number of octaves (000: 4), 4 intervals each.
    init_step : int
        Sampling step of the first octave in pixels (000: 2); doubles every octave.
    upright : bool
        U-SURF: skip the orientation (all angles 0).
    extended : bool
        128-d descriptor instead of 64-d.
    descriptors : bool
        Compute descriptors (False: keypoints only).
    workers : int
        Threads for the integral image, the response maps and their maxima (ours, speed; 2 = this
        project's machines; the same result for any value). Concurrent calls share two threads.
        Orientations and descriptors run in the calling thread (two gained nothing, issue 17).

    Examples
    --------
    >>> yy, xx = np.mgrid[0:101, 0:101]
    >>> blob = np.exp(-((xx - 50.0)**2 + (yy - 50.0)**2) / (2 * 4.0**2))
    >>> f = surf_detect(blob, 1e-4)
    >>> np.round(f.uv[np.argmax(f.response)]).tolist()
    [50.0, 50.0]

    Returns
    -------
    Features
        Keypoints (``scale_px`` = 1.2·L/9, ``response`` = Hessian determinant) and float32 descriptors
        (None with ``descriptors=False``).
    """
    img = to_gray_float(image)
    threshold = check_positive(threshold, "threshold", allow_zero=True)
    n_octaves = check_int(n_octaves, "n_octaves", minimum=1, maximum=6)
    init_step = check_int(init_step, "init_step", minimum=1)
    if min(img.shape) < 16:
        raise ValueError(f"`image` must be at least 16x16 pixels for SURF; got shape {img.shape}")
    workers = check_int(workers, "workers", minimum=1)
    P = PaddedIntegralImage(image=img, workers=workers)  # the integral image written into its padded array
    II = P.II
    ext = hessian_maxima(II, threshold=threshold, n_octaves=n_octaves, init_step=init_step, workers=workers,
                         _padded=P)
    uv = np.column_stack([ext["u"], ext["v"]]) if ext["u"].size else np.zeros((0, 2))
    sigma = 1.2 * ext["L"] / 9.0
    # orientations and descriptors in one thread: their numpy calls on chunks of a few dozen keypoints
    # are too short for two threads to gain (quiet machine: 22.1 ms with one, 27.2 with two; issue 17)
    ori = (np.zeros(uv.shape[0]) if upright or uv.shape[0] == 0
           else surf_orientation(II, uv, sigma, _padded=P))
    desc = surf_describe(II, uv, sigma, ori, extended=extended, _padded=P) if descriptors else None
    name = ("U-SURF" if upright else "SURF") + ("-128" if extended else "")
    return Features(uv, sigma, ori, ext["det"], ext["octave"].astype(np.int64), desc, name)


class SURF:
    """SURF detector with its settings as state (000 §3.3 defaults): ``SURF(threshold).detect(image)``.

    Parameters
    ----------
    threshold : float
        Minimum Hessian determinant on our response scale (see :func:`surf_detect`).
    n_octaves : int
        Number of octaves, 1..6.
    init_step : int
        Sampling step of the first octave in pixels.
    upright : bool
        U-SURF (all orientations 0).
    extended : bool
        128-d descriptors instead of 64-d.
    workers : int
        Threads of the detection (same result for any value).

    Examples
    --------
    >>> SURF(threshold=0.001, upright=True).upright
    True
    """

    def __init__(self, threshold: float = 0.0004, *, n_octaves: int = 4, init_step: int = 2,
                 upright: bool = False, extended: bool = False, workers: int = 2):
        self.threshold = check_positive(threshold, "threshold", allow_zero=True)
        self.n_octaves = check_int(n_octaves, "n_octaves", minimum=1, maximum=6)
        self.init_step = check_int(init_step, "init_step", minimum=1)
        self.upright = bool(upright)
        self.extended = bool(extended)
        self.workers = check_int(workers, "workers", minimum=1)

    def __repr__(self) -> str:
        return (f"SURF(threshold={self.threshold}, n_octaves={self.n_octaves}, init_step={self.init_step}, "
                f"upright={self.upright}, extended={self.extended})")

    def detect(self, image, *, descriptors: bool = True) -> Features:
        """Keypoints (and descriptors) of ``image``.

        Parameters
        ----------
        image : (H, W) array
            Grey image (uint8, or float in [0, 1]).
        descriptors : bool
            Compute descriptors.

        Returns
        -------
        Features
            As :func:`surf_detect` with this detector's settings.
        """
        return surf_detect(image, self.threshold, n_octaves=self.n_octaves, init_step=self.init_step,
                           upright=self.upright, extended=self.extended, descriptors=descriptors,
                           workers=self.workers)
