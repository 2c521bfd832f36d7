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
in the 1 MiB L2 cache), the orientation's sliding window from sums over angle bins.
"""

from __future__ import annotations

import numpy as np

from .. import _validate as v
from .._threads import run_tasks
from .base import Features, to_gray_float


def _by_chunks(fn, fast, s, chunk, workers, out):
    """``out[idx] = fn(idx, is_fast, s)`` for chunks of at most ``chunk`` keypoints (issue 17, speed).

    A chunk holds keypoints of one rounded scale ``s`` (so the Haar corners are at fixed offsets
    from each sample, :meth:`_PaddedII.corners`) that are all ``fast`` (boxes inside the padding
    of :class:`_PaddedII`) or all not. The chunks are split into ``workers`` contiguous parts of
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


__all__ = [
    "SURF",
    "box_sums",
    "filter_sizes",
    "haar_xy",
    "hessian_response",
    "integral_image",
    "surf_describe",
    "surf_detect",
    "surf_orientation",
    "threshold_sweep",
]


def integral_image(image) -> np.ndarray:
    """Integral image with a zero first row and column: ``II[r, c] = Σ I[:r, :c]`` (Bay 2008 §3.1).

    >>> integral_image(np.ones((2, 3)))[-1].tolist()
    [0.0, 2.0, 4.0, 6.0]
    """
    img = to_gray_float(image)
    H, W = img.shape
    II = np.zeros((H + 1, W + 1))
    np.cumsum(np.cumsum(img, axis=0), axis=1, out=II[1:, 1:])
    return II


def filter_sizes(n_octaves: int = 4, n_intervals: int = 4) -> np.ndarray:
    """Box-filter sides ``L[o, i] = 3·(2^(o+1)·(i+1) + 1)`` (Bay 2008 §3.3).

    >>> filter_sizes(2).tolist()
    [[9, 15, 21, 27], [15, 27, 39, 51]]
    """
    o = np.arange(n_octaves)[:, None]
    i = np.arange(n_intervals)[None, :]
    return 3 * ((2 ** (o + 1)) * (i + 1) + 1)


def box_sums(IIp, pad, step, nr, nc, r0, r1, c0, c1):
    """Box sums over rows ``[r + r0, r + r1)`` × cols ``[c + c0, c + c1)`` at every grid point ``(r, c) = step·(i, j)``.

    Four corner reads of the integral image per box (Bay 2008 §2; 001 §2.1), for the whole grid at once.

    Parameters
    ----------
    IIp : ndarray, shape (H + 1 + 2 pad, W + 1 + 2 pad)
        The integral image (see :func:`integral_image`) edge-padded by ``pad``: edge padding of the integral image
        is the same as clipping the box to the image (zero outside).
    pad : int
        The padding of ``IIp``; at least the largest box offset.
    step : int
        Grid spacing in pixels.
    nr, nc : int
        Grid rows and columns.
    r0, r1, c0, c1 : int
        The box's row and column offsets from each grid point (half-open).

    Returns
    -------
    ndarray, shape (nr, nc)
        The sum of the image over the box at each grid point.
    """
    def corner(dr, dc):
        return IIp[pad + dr:pad + dr + step * nr:step, pad + dc:pad + dc + step * nc:step][:nr, :nc]

    return corner(r1, c1) - corner(r0, c1) - corner(r1, c0) + corner(r0, c0)


def hessian_response(II, L: int, step: int, *, IIp=None, pad: int | None = None):
    """Approximate Hessian determinant and Laplacian sign on the grid of ``step`` (Bay 2008 §3.2).

    Box layout of OpenSURF: lobe ``l = L/3``; Dxx = whole (2l-1)×L box minus 3× the
    middle lobe; Dxy = four l×l boxes with signs (+ - / - +) around the centre. Each
    D is divided by L² and ``det = Dxx·Dyy - 0.81·Dxy²``.

    Returns
    -------
    det, trace : (ceil(H/step), ceil(W/step)) arrays
    """
    H, W = II.shape[0] - 1, II.shape[1] - 1
    if IIp is None:
        pad = L + step
        IIp = np.pad(II, pad, mode="edge")
    nr, nc = -(-H // step), -(-W // step)
    l = L // 3
    b = (L - 1) // 2
    h = l // 2
    Dxx = (box_sums(IIp, pad, step, nr, nc, -l + 1, l, -b, b + 1)
           - 3.0 * box_sums(IIp, pad, step, nr, nc, -l + 1, l, -h, -h + l))
    Dyy = (box_sums(IIp, pad, step, nr, nc, -b, b + 1, -l + 1, l)
           - 3.0 * box_sums(IIp, pad, step, nr, nc, -h, -h + l, -l + 1, l))
    Dxy = (box_sums(IIp, pad, step, nr, nc, -l, 0, 1, l + 1) + box_sums(IIp, pad, step, nr, nc, 1, l + 1, -l, 0)
           - box_sums(IIp, pad, step, nr, nc, -l, 0, -l, 0) - box_sums(IIp, pad, step, nr, nc, 1, l + 1, 1, l + 1))
    inv = 1.0 / (L * L)
    Dxx *= inv
    Dyy *= inv
    Dxy *= inv
    return Dxx * Dyy - 0.81 * Dxy * Dxy, Dxx + Dyy


class _Phases:
    """The integral image on the grid ``(r, c) = step·(i, j)``, split into its step×step phases (issue 17).

    Phase ``(p, q)`` holds ``II[p + step·a - P, q + step·b - P]`` (indices clipped to the image: the
    same as edge padding, i.e. boxes clipped to the image), contiguous and flat with row length
    ``Cq``. The corner ``II[r + dr, c + dc]`` over the whole grid is then one contiguous slice of one
    phase, laid out as ``i·Cq + j`` (columns ``j >= nc`` are padding), so every pass of the box
    filters runs on contiguous memory -- 2-3x faster than the strided views of :func:`box_sums`. Phases
    are strided copies of the padded image ``E`` (:class:`_PaddedII`) where it is large enough,
    gathered from ``II`` otherwise (the coarse octaves of ``n_octaves > 4``).
    """

    def __init__(self, E, step, reach, nr, nc):
        self.E, self.step, self.nr, self.nc = E, step, nr, nc
        m = -(-reach // step)  # margin in grid steps: every |dr|, |dc| <= reach
        self.P = m * step
        self.Cq = nc + 2 * m + 1
        self.Rq = nr + 2 * m + 1  # the last slice ends in row nr + 2m
        self._phase = {}

    def _build(self, p, q):
        st, P, E = self.step, self.P, self.E
        r0, c0 = E.pad - P + p, E.pad - P + q
        if r0 >= 0 and c0 >= 0:
            view = E.E[r0::st, c0::st]
            if view.shape[0] >= self.Rq and view.shape[1] >= self.Cq:
                return np.ascontiguousarray(view[:self.Rq, :self.Cq]).ravel()
        ri = np.clip(p - P + st * np.arange(self.Rq), 0, E.H)
        ci = np.clip(q - P + st * np.arange(self.Cq), 0, E.W)
        return np.take(E.flat, E.index(ri[:, None], ci)).ravel()

    def corner(self, dr, dc):
        """``II[r + dr, c + dc]`` for every grid point, flat ``(nr·Cq,)``."""
        st, P = self.step, self.P
        key = ((P + dr) % st, (P + dc) % st)
        ph = self._phase.get(key)
        if ph is None:  # two threads may build the same phase: same array, either one is kept
            ph = self._phase[key] = self._build(*key)
        off = (P + dr) // st * self.Cq + (P + dc) // st
        return ph[off:off + self.nr * self.Cq]


def _hessian_phases(ph, L, det_out):
    """The determinant of :func:`hessian_response` of side ``L`` on :class:`_Phases` ``ph``, into ``det_out``.

    The same operations in the same order as :func:`hessian_response` (so the same values to the
    last bit), done in place on contiguous buffers.
    """
    l, b = L // 3, (L - 1) // 2
    h = l // 2
    n = ph.nr * ph.Cq
    c = ph.corner

    def box(out, r0, r1, c0, c1):
        np.subtract(c(r1, c1), c(r0, c1), out=out)
        out -= c(r1, c0)
        out += c(r0, c0)
        return out

    Dxx, Dyy, Dxy, t = np.empty(n), np.empty(n), np.empty(n), np.empty(n)
    box(Dxx, -l + 1, l, -b, b + 1)
    Dxx -= np.multiply(box(t, -l + 1, l, -h, -h + l), 3.0, out=t)
    box(Dyy, -b, b + 1, -l + 1, l)
    Dyy -= np.multiply(box(t, -h, -h + l, -l + 1, l), 3.0, out=t)
    box(Dxy, -l, 0, 1, l + 1)
    Dxy += box(t, 1, l + 1, -l, 0)
    Dxy -= box(t, -l, 0, -l, 0)
    Dxy -= box(t, 1, l + 1, 1, l + 1)
    inv = 1.0 / (L * L)
    Dxx *= inv
    Dyy *= inv
    Dxy *= inv
    np.multiply(Dxy, 0.81, out=t)
    t *= Dxy
    Dxx *= Dyy
    shape = (ph.nr, ph.Cq)
    np.subtract(Dxx.reshape(shape)[:, :ph.nc], t.reshape(shape)[:, :ph.nc], out=det_out)


def _response_stacks(II, n_octaves, init_step, workers=1, padded=None, phase_octaves=1):
    """Per octave ``(det, step)``, ``det`` the ``(4, nr, nc)`` stack of :func:`hessian_response` (Bay 2008 §3.3).

    Speed (issue 17): octave ``o > 0`` shares two filter sides with octave ``o - 1`` (15 and 27 with
    9, 15, 21, 27; ...) on a grid twice as coarse, so its intervals 0 and 1 are the previous octave's
    intervals 1 and 3 taken every second row and column (OpenSURF shares these layers too); only 10
    of the 16 maps are computed, split over ``workers``. The first ``phase_octaves`` octaves run on
    contiguous phases (:class:`_Phases`); the coarser ones, whose phases would outweigh their maps
    (16 phases for 2 maps at step 4), on strided views of the padded image. Same values bit for bit.
    """
    H, W = II.shape[0] - 1, II.shape[1] - 1
    L = filter_sizes(n_octaves)
    E = _PaddedII(II) if padded is None else padded
    out, jobs = [], []
    for o in range(n_octaves):
        step = init_step * 2**o
        nr, nc = -(-H // step), -(-W // step)
        D = np.empty((4, nr, nc))
        new = range(4) if o == 0 else (2, 3)
        reach = (int(L[o][-1]) - 1) // 2 + 1
        if o < phase_octaves:
            ph = _Phases(E, step, reach, nr, nc)
            jobs += [lambda ph=ph, Li=int(L[o][i]), d=D[i]: _hessian_phases(ph, Li, d) for i in new]
        else:
            pad_ok = reach + step <= E.pad
            kw = {"IIp": E.E, "pad": E.pad} if pad_ok else {}
            jobs += [lambda Li=int(L[o][i]), d=D[i], step=step, kw=kw: d.__setitem__(
                     Ellipsis, hessian_response(II, Li, step, **kw)[0]) for i in new]
        out.append((D, step))
    run_tasks(jobs, workers)
    for o in range(1, n_octaves):  # L[o][0] = L[o-1][1], L[o][1] = L[o-1][3] at twice the step
        (D0, _), (D, _) = out[o - 1], out[o]
        D[0], D[1] = D0[1, ::2, ::2], D0[3, ::2, ::2]
    return out


# the 26 neighbours of the 3×3×3 box: the 6 faces first (column ones first), then edges, corners
_NMS_NB = [(0, 0, -1), (0, 0, 1), *sorted(
    ((di, dr, dc) for di in (-1, 0, 1) for dr in (-1, 0, 1) for dc in (-1, 0, 1) if (di, dr) != (0, 0)),
    key=lambda d: (abs(d[0]) + abs(d[1]) + abs(d[2]), d))]


def _interior_maxima(D, threshold):
    """Indices of the interior points of ``D`` above ``threshold`` that equal the max of their 3×3×3 box.

    Border points of the (interval, row, column) stack are never maxima (Bay 2008 §3.4). Speed
    (issue 17): the points above ``threshold`` (~15 % on graf) are compared with their 26
    neighbours one offset at a time, each comparison keeping only the survivors; same set and
    order as ``scipy.ndimage.maximum_filter`` (a point equal to the max is kept).
    """
    _, nr, nc = D.shape
    inner = D[1:-1, 1:-1, 1:-1]
    cand = threshold < inner
    cand &= inner >= D[1:-1, 1:-1, :-2]  # the two column neighbours on whole arrays, the rest by gathers
    cand &= inner >= D[1:-1, 1:-1, 2:]
    i, r, c = np.nonzero(cand)
    f = ((i + 1) * nr + (r + 1)) * nc + (c + 1)
    flat = D.ravel()
    val = flat[f]
    for di, dr, dc in _NMS_NB[2:]:
        keep = val >= flat[f + ((di * nr + dr) * nc + dc)]
        f, val = f[keep], val[keep]
    i, rc = np.divmod(f, nr * nc)
    r, c = np.divmod(rc, nc)
    return i, r, c


def _extrema(II, *, threshold, n_octaves, init_step, workers=1, padded=None):
    """Thresholded 3×3×3 maxima, interpolated (Bay 2008 §3.4; Brown & Lowe 2002); octaves in parallel."""
    H, W = II.shape[0] - 1, II.shape[1] - 1
    L = filter_sizes(n_octaves)
    stacks = _response_stacks(II, n_octaves, init_step, workers, padded)
    found = run_tasks([lambda o=o, D=D, step=step: _octave_extrema(D, step, L[o], o, threshold, H, W)
                       for o, (D, step) in enumerate(stacks)], workers)
    found = [f for f in found if f is not None]
    if not found:
        return {k: np.zeros(0) for k in ("u", "v", "L", "det", "octave")}
    return {k: np.concatenate([f[k] for f in found]) for k in found[0]}


def _octave_extrema(D, step, Lo, o, threshold, H, W):
    """The interpolated maxima of one octave's stack ``D`` (filter sides ``Lo``), or None if none."""
    nI, nr, nc = D.shape
    if nr < 3 or nc < 3 or nI < 3:
        return None
    i, r, c = _interior_maxima(D, threshold)
    # the largest filter of the 3x3x3 neighbourhood must lie inside the image
    b_top = (Lo[np.minimum(i + 1, nI - 1)] - 1) // 2 + 1
    rr, cc = r * step, c * step
    ok = (rr - b_top >= 0) & (rr + b_top < H) & (cc - b_top >= 0) & (cc + b_top < W)
    i, r, c = i[ok], r[ok], c[ok]
    if i.size == 0:
        return None
    v0 = D[i, r, c]
    dx = (D[i, r, c + 1] - D[i, r, c - 1]) / 2
    dy = (D[i, r + 1, c] - D[i, r - 1, c]) / 2
    ds = (D[i + 1, r, c] - D[i - 1, r, c]) / 2
    dxx = D[i, r, c + 1] + D[i, r, c - 1] - 2 * v0
    dyy = D[i, r + 1, c] + D[i, r - 1, c] - 2 * v0
    dss = D[i + 1, r, c] + D[i - 1, r, c] - 2 * v0
    dxy = (D[i, r + 1, c + 1] - D[i, r + 1, c - 1] - D[i, r - 1, c + 1] + D[i, r - 1, c - 1]) / 4
    dxs = (D[i + 1, r, c + 1] - D[i + 1, r, c - 1] - D[i - 1, r, c + 1] + D[i - 1, r, c - 1]) / 4
    dys = (D[i + 1, r + 1, c] - D[i + 1, r - 1, c] - D[i - 1, r + 1, c] + D[i - 1, r - 1, c]) / 4
    Hm = np.stack([np.stack([dxx, dxy, dxs], -1), np.stack([dxy, dyy, dys], -1),
                   np.stack([dxs, dys, dss], -1)], -2)
    g = np.stack([dx, dy, ds], -1)
    det = np.linalg.det(Hm)
    good = np.abs(det) > 1e-300
    off = np.zeros_like(g)
    off[good] = -np.linalg.solve(Hm[good], g[good][..., None])[..., 0]
    good &= np.all(np.abs(off) < 0.5, axis=1)
    i, r, c, off, v0 = i[good], r[good], c[good], off[good], v0[good]
    return {"u": (c + off[:, 0]) * step, "v": (r + off[:, 1]) * step, "L": Lo[i] + off[:, 2] * (Lo[1] - Lo[0]),
            "det": v0, "octave": np.full(i.size, o)}


def haar_xy(II, rows, cols, half):
    """Haar wavelet responses of side ``2·half`` centred on integer pixels (Bay 2008 §4.1).

    dx = right half minus left half, dy = lower half minus upper half (v down),
    boxes clipped to the image. ``rows``, ``cols``, ``half`` broadcast together.
    """
    H, W = II.shape[0] - 1, II.shape[1] - 1
    Wp = W + 1
    flat = II.ravel()
    r0 = np.clip(rows - half, 0, H) * Wp
    rm = np.clip(rows, 0, H) * Wp
    r1 = np.clip(rows + half, 0, H) * Wp
    c0 = np.clip(cols - half, 0, W)
    cm = np.clip(cols, 0, W)
    c1 = np.clip(cols + half, 0, W)
    return _haar_from_corners(flat[r0 + c0], flat[r0 + cm], flat[r0 + c1], flat[rm + c0], flat[rm + c1],
                              flat[r1 + c0], flat[r1 + cm], flat[r1 + c1])


def _haar_from_corners(A00, A01, A02, A10, A12, A20, A21, A22):
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


class _PaddedII:
    """The integral image edge-padded, flat: Haar responses without clipping, phases by slicing (issue 17).

    ``pad`` rows/columns before the image, ``pad + extra`` after it; ``II`` is a view of its inside.
    Edge padding of the integral image is the same as clipping the boxes to the image, so
    :meth:`haar` gives the values of :func:`haar_xy` bit for bit (same corners, same operations) for
    every keypoint whose boxes reach at most ``pad`` pixels outside the image (:meth:`fits`), with one
    flat index per sample and fixed corner offsets instead of six clips and three row products.
    ``extra`` lets the coarse octaves read it directly too (phases or strided views,
    :func:`_response_stacks`): octave 3 of the default settings reaches 112 + 16 pixels before and
    112 + 2·16 after the image.
    ``_PaddedII(image=img)`` writes :func:`integral_image` of ``img`` straight into the padded array
    (same values: the same two cumulative sums).
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
            body = inner[1:, 1:]  # columns, then rows, in two halves (independent: same sums)
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
        """:func:`haar_xy` (same operations, same values) at flat indices ``idx``, one ``half`` for all."""
        (A00, A01, A02), (A10, _, A12), (A20, A21, A22) = self.corners(idx, half)
        return _haar_from_corners(A00, A01, A02, A10, A12, A20, A21, A22)

    def haar_clipped(self, rows, cols, half):
        """:func:`haar_xy` (boxes clipped to the image; same values) for keypoints past the padding."""
        H, W, f = self.H, self.W, self.flat
        r = [np.clip(rows + d, 0, H) for d in (-half, 0, half)]
        c = [np.clip(cols + d, 0, W) for d in (-half, 0, half)]
        return _haar_from_corners(*(f[self.index(r[i], c[j])] for i, j in
                                    ((0, 0), (0, 1), (0, 2), (1, 0), (1, 2), (2, 0), (2, 1), (2, 2))))


_ORI_I, _ORI_J = np.meshgrid(np.arange(-6, 7), np.arange(-6, 7), indexing="ij")
_ORI_MASK = _ORI_I**2 + _ORI_J**2 < 36
_ORI_I, _ORI_J = _ORI_I[_ORI_MASK], _ORI_J[_ORI_MASK]  # 109 samples
_ORI_G = np.exp(-(_ORI_I**2 + _ORI_J**2) / (2 * 2.5**2))


def _window_edges(window_rad, step_rad):
    """Indices into the per-keypoint cumulative sums of :func:`_orientation_chunk` for every window.

    Windows start at ``s_j = j·step`` (``j < nW``) and hold the angles in ``[s_j, s_j + w)`` and, for the
    wrap, those below ``s_j + w - 2π``. Every edge lies at ``(j + t)·step`` with ``t`` in ``{0, f1, f2}``,
    the fractional parts of ``w/step`` and ``(w - 2π)/step``; a sample of bin ``b = ⌊a/step⌋`` and
    fraction ``f`` has the fine index ``3b + [f >= t0] + [f >= t1]`` (``t0 <= t1`` the sorted ``f1, f2``),
    so the sum over ``a < (j + t)·step`` is the cumulative sum up to fine index ``3j + k(t)``.
    """
    nW = np.arange(0.0, 2 * np.pi, step_rad).size
    x1, x2 = window_rad / step_rad, (window_rad - 2 * np.pi) / step_rad
    J1, J2 = np.floor(x1), np.floor(x2)
    f1, f2 = x1 - J1, x2 - J2
    t = (min(f1, f2), max(f1, f2))
    j = np.arange(nW)

    def edge(jb, k):
        return np.clip(3 * jb + k, 0, 3 * nW).astype(np.intp)

    e0 = edge(j, 0)
    e1 = edge(j + int(J1), 1 if f1 == t[0] else 2)
    e2 = edge(j + int(J2), 1 if f2 == t[0] else 2)
    return nW, t, e0, e1, e2


def _orientation_chunk(P, uv, s, step_rad, edges, fast):
    """Orientations of the keypoints ``uv`` of rounded scale ``s``, see :func:`surf_orientation`."""
    nW, (t0, t1), e0, e1, e2 = edges
    k = uv.shape[0]
    r0, c0 = np.rint(uv[:, 1]).astype(np.int64)[:, None], np.rint(uv[:, 0]).astype(np.int64)[:, None]
    if fast:
        dx, dy = P.haar(P.index(r0, c0) + P.index(_ORI_J * s, _ORI_I * s) - P.index(0, 0), 2 * s)
    else:
        dx, dy = P.haar_clipped(r0 + _ORI_J * s, c0 + _ORI_I * s, 2 * s)
    dx *= _ORI_G
    dy *= _ORI_G
    ang = np.arctan2(dy, dx)
    np.add(ang, 2 * np.pi, out=ang, where=ang < 0)  # = ang % 2π for ang in [-π, π]
    u = np.divide(ang, step_rad, out=ang)
    bins = np.minimum(np.floor(u), nW - 1)
    u -= bins  # fraction within the bin
    fine = bins * 3
    fine += u >= t0
    fine += u >= t1
    idx = fine.astype(np.intp)
    idx += (3 * nW) * np.arange(k)[:, None]
    # window sums: cumulative sums of the samples over (keypoint, fine index), differences at the edges
    C = np.zeros((2, k, 3 * nW + 1))
    C[0, :, 1:] = np.bincount(idx.ravel(), dx.ravel(), minlength=3 * nW * k).reshape(k, -1)
    C[1, :, 1:] = np.bincount(idx.ravel(), dy.ravel(), minlength=3 * nW * k).reshape(k, -1)
    np.cumsum(C, axis=2, out=C)
    S = C[:, :, e1] - C[:, :, e0] + C[:, :, e2]  # (2, k, nW): Σdx, Σdy per window
    # the longest sum; among windows within 1e-12 of it (ties, e.g. windows that differ only by
    # zero responses of a flat patch) the first, whatever the rounding of the sums (ours)
    n2 = S[0] * S[0] + S[1] * S[1]
    best = np.argmax(n2 >= (1 - 1e-12) * n2.max(axis=1, keepdims=True), axis=1)
    kk = np.arange(k)
    return np.arctan2(S[1, kk, best], S[0, kk, best]) % (2 * np.pi)


def surf_orientation(II, uv, scale_px, *, window_rad: float = np.pi / 3, step_rad: float = 0.15,
                     chunk: int = 128, workers: int = 1, _padded=None) -> np.ndarray:
    """Dominant orientation from Haar responses in a sliding 60° window (Bay 2008 §4.1).

    Returns angles in [0, 2π), image axes (u right, v down). The window sums are differences of
    cumulative sums over the samples binned by angle (speed, issue 17: no per-keypoint sort; same
    sets of samples per window as the sorted sweep). Windows whose sums are within 1e-12 of the
    longest count as tied and the first wins (ours: the choice does not depend on rounding).
    ``chunk`` keypoints at a time, split over ``workers`` threads (ours, speed; the result does not
    depend on either).
    """
    uv = np.asarray(uv, dtype=np.float64).reshape(-1, 2)
    s = np.maximum(np.rint(np.asarray(scale_px, dtype=np.float64)), 1).astype(np.int64)
    chunk = v.check_int(chunk, "chunk", minimum=1)
    workers = v.check_int(workers, "workers", minimum=1)
    P = _PaddedII(II) if _padded is None else _padded
    edges = _window_edges(float(window_rad), float(step_rad))
    fast = P.fits(uv, 7 * s + 1)  # samples at up to 5s, boxes of half-side 2s

    def one(idx, f, si):
        return _orientation_chunk(P, uv[idx], si, step_rad, edges, f)

    return _by_chunks(one, fast, s, chunk, workers, np.zeros(uv.shape[0]))


_D_OFF = (np.arange(20) - 9.5)  # sample centres in units of σ along each axis
_D_X, _D_Y = np.meshgrid(_D_OFF, _D_OFF, indexing="xy")  # (20, 20): rows = y, cols = x
_D_X, _D_Y = _D_X.ravel(), _D_Y.ravel()
_D_G = np.exp(-(_D_X**2 + _D_Y**2) / (2 * 3.3**2))


def _subregion_sums(R):
    """Gaussian-weighted sums ``(..., 16)`` over the 4×4 sub-regions of 5×5 samples of ``R (..., 400)``.

    Row-major sub-regions (4·row + column). Sums of strided slices, not a product with a
    0/1 matrix: a product of this size can start OpenBLAS's threads, which cost ~10x on a
    busy 2-core machine (issue 17). ``R`` is overwritten.
    """
    R *= _D_G
    V = R.reshape(*R.shape[:-1], 20, 4, 5)  # sample row, sub-region column, column within it
    t = V[..., 0] + V[..., 1]
    for j in range(2, 5):
        t += V[..., j]
    T = t.reshape(*R.shape[:-1], 4, 5, 4)  # sub-region row, row within it, sub-region column
    S = T[..., 0, :] + T[..., 1, :]
    for j in range(2, 5):
        S += T[..., j, :]
    return S.reshape(*R.shape[:-1], 16)


def _describe_chunk(P, uv, sigma, s, th, extended, fast):
    """Descriptors of the keypoints ``uv`` of rounded scale ``s``, see :func:`surf_describe`."""
    k = uv.shape[0]
    cs, sn = np.cos(th)[:, None], np.sin(th)[:, None]
    sg = sigma[:, None]
    # sample positions: the 20×20 grid rotated by θ (u right, v down), rounded to pixels;
    # x = (X·c - Y·s)·σ + u with the products taken on the 20 grid values (the same numbers)
    x = np.subtract((_D_OFF * cs)[:, None, :], (_D_OFF * sn)[:, :, None]).reshape(k, -1)
    x *= sg
    x += uv[:, 0:1]
    y = np.add((_D_OFF * sn)[:, None, :], (_D_OFF * cs)[:, :, None]).reshape(k, -1)
    y *= sg
    y += uv[:, 1:2]
    np.rint(x, out=x)
    np.rint(y, out=y)
    R = np.empty((4, k, _D_X.size))  # dx, dy, |rx|, |ry| per sample, summed per sub-region together
    dx, dy, t = R[0], R[1], R[2]
    if fast:
        y *= P.Wp
        y += x
        A = P.corners(y.astype(np.intp) + P.index(0, 0), s)
        # dx = right - left = (A22 - A00) + (A20 - A02) - 2(A21 - A01); dy likewise with A12, A10
        d1, d2 = A[2][2] - A[0][0], A[2][0] - A[0][2]
        np.add(d1, d2, out=dx)
        np.subtract(A[2][1], A[0][1], out=t)
        t += t
        dx -= t
        np.subtract(d1, d2, out=dy)
        np.subtract(A[1][2], A[1][0], out=t)
        t += t
        dy -= t
    else:
        dx[...], dy[...] = P.haar_clipped(y.astype(np.int64), x.astype(np.int64), s)
    # responses in the keypoint frame (the Gaussian weight is applied in _subregion_sums)
    rx, ry = R[2], R[3]
    np.multiply(dx, cs, out=rx)
    rx += sn * dy
    np.multiply(dy, cs, out=ry)
    ry -= sn * dx
    if not extended:
        # Σ(c·dx + s·dy)·g = c·Σdx·g + s·Σdy·g: the signed sums are rotated after summing
        np.abs(rx, out=rx)
        np.abs(ry, out=ry)
        S = _subregion_sums(R)
        feats = (cs * S[0] + sn * S[1], cs * S[1] - sn * S[0], S[2], S[3])
    else:
        neg_y, neg_x = ry < 0, rx < 0
        arx, ary = np.abs(rx), np.abs(ry)
        feats = _subregion_sums(np.stack([np.where(neg_y, rx, 0), np.where(neg_y, arx, 0),
                                          np.where(neg_y, 0, rx), np.where(neg_y, 0, arx),
                                          np.where(neg_x, ry, 0), np.where(neg_x, ary, 0),
                                          np.where(neg_x, 0, ry), np.where(neg_x, 0, ary)]))
    desc = np.stack(feats, axis=-1).reshape(k, -1)  # (k, 16, nf): per sub-region
    norm = np.linalg.norm(desc, axis=1, keepdims=True)
    return desc / np.where(norm > 0, norm, 1.0)


def surf_describe(II, uv, scale_px, orientation_rad, *, extended: bool = False, chunk: int = 32,
                  workers: int = 1, _padded=None):
    """64-d (or extended 128-d) SURF descriptors, unit length (Bay 2008 §4.2).

    Returns float32 ``(K, 64)`` or ``(K, 128)``. The Gaussian-weighted sums over the 16
    sub-regions are taken for all features of a chunk together (:func:`_subregion_sums`); the
    signed sums of the rotated responses are the rotated sums (Σ(c·dx + s·dy)·g = c·Σdx·g +
    s·Σdy·g), so only the absolute values need the rotated responses per sample (speed, issue 17;
    same values to rounding). ``chunk`` keypoints at a time, split over ``workers`` threads (the
    result does not depend on either).
    """
    uv = np.asarray(uv, dtype=np.float64).reshape(-1, 2)
    sigma = np.asarray(scale_px, dtype=np.float64)
    s_int = np.maximum(np.rint(sigma), 1).astype(np.int64)
    th = np.asarray(orientation_rad, dtype=np.float64)
    K = uv.shape[0]
    dim = 128 if extended else 64
    out = np.zeros((K, dim), dtype=np.float32)
    chunk = v.check_int(chunk, "chunk", minimum=1)
    workers = v.check_int(workers, "workers", minimum=1)
    P = _PaddedII(II) if _padded is None else _padded
    fast = P.fits(uv, np.ceil(13.44 * sigma) + s_int + 1)  # samples within 9.5·√2·σ, boxes of half-side s

    def one(idx, f, si):
        return _describe_chunk(P, uv[idx], sigma[idx], si, th[idx], extended, f)

    return _by_chunks(one, fast, s_int, chunk, workers, out)


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
    """
    img = to_gray_float(image)
    threshold = v.check_positive(threshold, "threshold", allow_zero=True)
    n_octaves = v.check_int(n_octaves, "n_octaves", minimum=1, maximum=6)
    init_step = v.check_int(init_step, "init_step", minimum=1)
    if min(img.shape) < 16:
        raise ValueError(f"`image` must be at least 16x16 pixels for SURF; got shape {img.shape}")
    workers = v.check_int(workers, "workers", minimum=1)
    P = _PaddedII(image=img, workers=workers)  # the integral image written into its padded array
    II = P.II
    ext = _extrema(II, threshold=threshold, n_octaves=n_octaves, init_step=init_step, workers=workers, padded=P)
    uv = np.column_stack([ext["u"], ext["v"]]) if ext["u"].size else np.zeros((0, 2))
    sigma = 1.2 * ext["L"] / 9.0
    # orientations and descriptors in one thread: their numpy calls on chunks of a few dozen keypoints
    # are too short for two threads to gain (quiet machine: 22.1 ms with one, 27.2 with two; issue 17)
    ori = (np.zeros(uv.shape[0]) if upright or uv.shape[0] == 0
           else surf_orientation(II, uv, sigma, _padded=P))
    desc = surf_describe(II, uv, sigma, ori, extended=extended, _padded=P) if descriptors else None
    name = ("U-SURF" if upright else "SURF") + ("-128" if extended else "")
    return Features(uv, sigma, ori, ext["det"], ext["octave"].astype(np.int64), desc, name)


def threshold_sweep(image, thresholds, *, n_octaves: int = 4, init_step: int = 2) -> np.ndarray:
    """Number of SURF keypoints for each threshold (one response computation)."""
    img = to_gray_float(image)
    th = v.as_vector(thresholds, "thresholds")
    II = integral_image(img)
    ext = _extrema(II, threshold=float(th.min()) if th.min() > 0 else 0.0, n_octaves=n_octaves,
                   init_step=init_step)
    return np.array([int(np.count_nonzero(ext["det"] > t)) for t in th])


class SURF:
    """SURF detector with its settings as state (000 §3.3 defaults): ``SURF(threshold).detect(image)``.

    >>> SURF(threshold=0.001, upright=True).upright
    True
    """

    def __init__(self, threshold: float = 0.0004, *, n_octaves: int = 4, init_step: int = 2,
                 upright: bool = False, extended: bool = False, workers: int = 2):
        self.threshold = v.check_positive(threshold, "threshold", allow_zero=True)
        self.n_octaves = v.check_int(n_octaves, "n_octaves", minimum=1, maximum=6)
        self.init_step = v.check_int(init_step, "init_step", minimum=1)
        self.upright = bool(upright)
        self.extended = bool(extended)
        self.workers = v.check_int(workers, "workers", minimum=1)

    def __repr__(self) -> str:
        return (f"SURF(threshold={self.threshold}, n_octaves={self.n_octaves}, init_step={self.init_step}, "
                f"upright={self.upright}, extended={self.extended})")

    def detect(self, image, *, descriptors: bool = True) -> Features:
        """Keypoints (and descriptors) of ``image``."""
        return surf_detect(image, self.threshold, n_octaves=self.n_octaves, init_step=self.init_step,
                           upright=self.upright, extended=self.extended, descriptors=descriptors,
                           workers=self.workers)
