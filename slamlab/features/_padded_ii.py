"""The edge-padded integral image SURF reads its boxes from, and the keypoint chunks it works in (package-private;
Bay 2008 §3-4; issue 17, speed).

:class:`PaddedIntegralImage` (the integral image edge-padded, flat: Haar responses and box corners without
clipping), :func:`haar_from_corners` (one Haar response from its eight box corners) and :func:`by_chunks`
(keypoints of one rounded scale at a time, in the shared worker threads); used by the SURF modules
(:mod:`slamlab.features.surf`, ``surf_response``, ``surf_descriptor``, ``surf_haar``).
"""

from __future__ import annotations

import numpy as np

from .._compiled import numba_enabled
from .._threads import run_tasks

__all__ = ["PaddedIntegralImage", "by_chunks", "haar_from_corners"]


def by_chunks(fn, fast, s, chunk, workers, out):
    """``out[idx] = fn(idx, is_fast, s)`` for chunks of at most ``chunk`` keypoints (issue 17, speed).

    A chunk holds keypoints of one rounded scale ``s`` (so the Haar corners are at fixed offsets
    from each sample, :meth:`PaddedIntegralImage.corners`) that are all ``fast`` (boxes inside the padding
    of :class:`PaddedIntegralImage`) or all not. The chunks are split into ``workers`` contiguous parts of
    about equal keypoint counts, run in parallel. Every keypoint is computed on its own: the result
    depends on neither ``chunk`` nor ``workers``.
    """
    key = np.where(fast, s, -s)
    order = np.argsort(key, kind="stable")
    bounds = np.flatnonzero(np.diff(key[order])) + 1
    chunks = []
    for g in np.split(order, bounds):
        if g.size:
            chunks += [(g[a:a + chunk], bool(fast[g[0]]), int(s[g[0]])) for a in range(0, g.size, chunk)]
    sizes = np.cumsum([c[0].size for c in chunks])
    n_parts = max(1, min(workers, len(chunks)))
    cut = np.searchsorted(sizes, sizes[-1] * np.arange(1, n_parts) / n_parts) + 1 if chunks else []
    parts = np.split(np.arange(len(chunks)), cut)

    def part(ids):
        for i in ids:
            idx, f, si = chunks[i]
            out[idx] = fn(idx, f, si)

    run_tasks([lambda ids=ids: part(ids) for ids in parts if ids.size], workers)
    return out


def haar_from_corners(A00, A01, A02, A10, A12, A20, A21, A22):
    """(dx, dy) from the eight corners ``A[i][j] = II[r + (i-1)·half, c + (j-1)·half]``."""
    right = A22 - A02
    right -= A21
    right += A01
    left = A21 - A01
    left -= A20
    left += A00
    lower = A22 - A12
    lower -= A20
    lower += A10
    upper = A12 - A02
    upper -= A10
    upper += A00
    right -= left
    lower -= upper
    return right, lower


class PaddedIntegralImage:
    """The integral image edge-padded, flat: Haar responses without clipping, phases by slicing (issue 17).

    ``pad`` rows/columns before the image, ``pad + extra`` after it; ``II`` is a view of its inside.
    Edge padding of the integral image is the same as clipping the boxes to the image, so :meth:`haar` gives
    the values of :func:`~slamlab.features.surf_haar.haar_xy` bit for bit (same corners, same operations) for
    every keypoint whose boxes reach at most ``pad`` pixels outside the image (:meth:`fits`), with one
    flat index per sample and fixed corner offsets instead of six clips and three row products.
    ``extra`` lets the coarse octaves read it directly too (phases or strided views,
    ``surf_response._response_stacks``): octave 3 of the default settings reaches 112 + 16 pixels before and
    112 + 2·16 after the image.
    ``PaddedIntegralImage(image=img)`` writes :func:`~slamlab.features.surf.integral_image` of ``img`` straight
    into the padded array (same values: the same two cumulative sums).
    """

    def __init__(self, II=None, pad: int = 128, extra: int = 32, *, image=None, workers: int = 1):
        self.pad = pad
        if image is None:
            self.H, self.W = II.shape[0] - 1, II.shape[1] - 1
            self.E = np.pad(II, ((pad, pad + extra), (pad, pad + extra)), mode="edge")
        else:
            self.H, self.W = image.shape
            H, W, e = self.H, self.W, pad + extra
            self.E = E = np.empty((H + 1 + pad + e, W + 1 + pad + e))
            inner = E[pad:pad + H + 1, pad:pad + W + 1]
            inner[0] = 0.0
            inner[:, 0] = 0.0
            body = inner[1:, 1:]
            if image.dtype == np.float64 and numba_enabled():  # the same sums, row by row (issue 45)
                from ._surf_kernels import integral_body

                integral_body(image, body)
            else:  # columns, then rows, in two halves (independent: same sums)
                halves = (slice(None, W // 2), slice(W // 2, None)), (slice(None, H // 2), slice(H // 2, None))
                run_tasks([lambda c=c: np.cumsum(image[:, c], axis=0, out=body[:, c]) for c in halves[0]], workers)
                run_tasks([lambda r=r: np.cumsum(body[r], axis=1, out=body[r]) for r in halves[1]], workers)
            E[pad:pad + H + 1, :pad] = inner[:, :1]  # edge padding, as np.pad(mode="edge")
            E[pad:pad + H + 1, pad + W + 1:] = inner[:, -1:]
            E[:pad] = E[pad]
            E[pad + H + 1:] = E[pad + H]
        self.II = self.E[pad:pad + self.H + 1, pad:pad + self.W + 1]
        self.Wp = self.E.shape[1]
        self.flat = self.E.ravel()

    def fits(self, uv, reach):
        """Keypoints whose samples, ``reach`` pixels around ``uv``, stay inside the padding."""
        p = self.pad
        return ((uv[:, 0] - reach >= -p) & (uv[:, 0] + reach <= self.W + p)
                & (uv[:, 1] - reach >= -p) & (uv[:, 1] + reach <= self.H + p))

    def index(self, rows, cols):
        """Flat index into the padded image of pixel ``(rows, cols)`` (int or integral float arrays)."""
        return rows * self.Wp + cols + self.pad * (self.Wp + 1)

    def corners(self, idx, half):
        """The 3×3 corners ``A[i][j] = II[r + (i-1)·half, c + (j-1)·half]`` (``A[1][1]`` is None) of the
        boxes of side ``2·half`` around the pixels of flat indices ``idx``: one gather per corner from a
        shifted view, no index arithmetic (one ``half`` for all)."""
        Wp, f = self.Wp, self.flat
        top_left = np.subtract(idx, half * (Wp + 1))
        return [[None if i == j == 1 else np.take(f[(i * Wp + j) * half:], top_left) for j in range(3)]
                for i in range(3)]

    def haar(self, idx, half):
        """:func:`~slamlab.features.surf_haar.haar_xy` (same operations, same values) at flat indices ``idx``, one ``half`` for all."""
        (A00, A01, A02), (A10, _, A12), (A20, A21, A22) = self.corners(idx, half)
        return haar_from_corners(A00, A01, A02, A10, A12, A20, A21, A22)

    def haar_clipped(self, rows, cols, half):
        """:func:`~slamlab.features.surf_haar.haar_xy` (boxes clipped to the image; same values) for keypoints past the padding."""
        H, W, f = self.H, self.W, self.flat
        r = [np.clip(rows + d, 0, H) for d in (-half, 0, half)]
        c = [np.clip(cols + d, 0, W) for d in (-half, 0, half)]
        return haar_from_corners(*(f[self.index(r[i], c[j])] for i, j in
                                    ((0, 0), (0, 1), (0, 2), (1, 0), (1, 2), (2, 0), (2, 1), (2, 2))))
