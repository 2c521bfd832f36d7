"""SURF's detector: box-filter Hessian responses, scale-space maxima and the threshold sweep (Bay 2008 §3; 000 §3.3).

Part of :mod:`slamlab.features.surf` (which re-exports the public names; its docstring describes the steps).
"""

from __future__ import annotations

import numpy as np

from .._compiled import numba_enabled
from .._threads import run_tasks
from .._validate import as_finite_array, as_vector, check_int, check_positive
from ._padded_ii import PaddedIntegralImage
from .base import to_gray_float

__all__ = ["box_sums", "filter_sizes", "hessian_maxima", "hessian_response", "integral_image", "threshold_sweep"]


def integral_image(image) -> np.ndarray:
    """Integral image with a zero first row and column: ``II[r, c] = Σ I[:r, :c]`` (Bay 2008 §3.1).

    Parameters
    ----------
    image : (H, W) array
        Grey image (uint8 scaled to [0, 1], float as given).

    Returns
    -------
    II : (H+1, W+1) float64

    Examples
    --------
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

    Parameters
    ----------
    n_octaves : int
        Number of octaves (rows).
    n_intervals : int
        Filters per octave (columns).

    Returns
    -------
    L : (n_octaves, n_intervals) int
        Filter sides in pixels.

    Examples
    --------
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

    Parameters
    ----------
    II : (H+1, W+1) float
        Integral image.
    L : int
        Filter side in pixels (9, 15, ...).
    step : int
        Grid step in pixels.
    IIp : array, optional
        ``II`` edge-padded by ``pad`` on every side (built here when None).
    pad : int, optional
        The padding of ``IIp`` (at least ``L + step``; ignored when ``IIp`` is None).

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
    are strided copies of the padded image ``E`` (``PaddedIntegralImage``) where it is large enough,
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
    of the 16 maps are computed, split over ``workers``. With compiled kernels (issue 45) each map is one
    pass over the padded image (``_surf_kernels.hessian_det``: the operations of :func:`hessian_response`
    per grid point). Without, the first ``phase_octaves`` octaves run on contiguous phases (:class:`_Phases`);
    the coarser ones, whose phases would outweigh their maps (16 phases for 2 maps at step 4), on strided
    views of the padded image. Same values bit for bit.
    """
    H, W = II.shape[0] - 1, II.shape[1] - 1
    L = filter_sizes(n_octaves)
    E = PaddedIntegralImage(II) if padded is None else padded
    out, jobs = [], []
    compiled = numba_enabled()
    if compiled:
        _load_kernels(E)
    for o in range(n_octaves):
        step = init_step * 2**o
        nr, nc = -(-H // step), -(-W // step)
        D = np.empty((4, nr, nc))
        new = range(4) if o == 0 else (2, 3)
        reach = (int(L[o][-1]) - 1) // 2 + 1
        if compiled and reach + step <= E.pad:  # the same values, one pass per map (_surf_kernels; issue 45)
            from ._surf_kernels import hessian_det

            jobs += [lambda Li=int(L[o][i]), d=D[i], step=step, nr=nr, nc=nc: hessian_det(
                     E.flat, E.Wp, int(E.index(0, 0)), step, nr, nc, Li, d) for i in new]
        elif o < phase_octaves:
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


def _load_kernels(E):
    """Compile (or load from numba's cache) the response and NMS kernels here, before worker threads call them.

    Two threads making the first call of a kernel at once would each compile or load it (the same code,
    twice the time); a call on a 1×1 grid and a 3×3×3 stack costs microseconds.
    """
    from ._surf_kernels import hessian_det, interior_maxima

    hessian_det(E.flat, E.Wp, int(E.index(0, 0)), 1, 1, 1, 9, np.empty((1, 1)))
    interior_maxima(np.zeros((3, 3, 3)), 0.0, np.empty(27, dtype=np.int64))


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
    if numba_enabled():  # the same points in the same order, one pass (_surf_kernels; issue 45)
        from ._surf_kernels import interior_maxima

        f = np.empty(D.size, dtype=np.int64)
        f = f[:interior_maxima(D, float(threshold), f)]
        i, rc = np.divmod(f, nr * nc)
        r, c = np.divmod(rc, nc)
        return i, r, c
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


def hessian_maxima(II, *, threshold: float, n_octaves: int = 4, init_step: int = 2, workers: int = 1,
                   _padded=None) -> dict:
    """SURF's keypoints: thresholded 3×3×3 maxima of the Hessian determinant, interpolated (Bay 2008 §3.4).

    The position and scale are refined as Brown & Lowe 2002 do, before any orientation. The response maps of every octave (:func:`hessian_response` on the grid of step ``init_step·2^o``), the
    points above ``threshold`` that are the largest of their 3×3×3 (interval, row, column) box, and a
    quadratic fit of position and scale (kept when every offset is below half a grid step). Octaves run in
    parallel on ``workers`` threads (the same result for any number).

    Parameters
    ----------
    II : (H+1, W+1) float
        Integral image (:func:`integral_image`).
    threshold : float
        Minimum Hessian determinant (our response scale: image in [0, 1], filters divided by L²).
    n_octaves : int
        Number of octaves, 1..6 (000: 4), 4 intervals each.
    init_step : int
        Sampling step of the first octave in pixels (000: 2).
    workers : int
        Threads.
    _padded : PaddedIntegralImage, optional
        Private: the padded integral image already built by :func:`~slamlab.features.surf.surf_detect`.

    Returns
    -------
    dict of (K,) arrays
        ``u``, ``v`` (pixels), ``L`` (interpolated filter side in pixels; σ = 1.2·L/9), ``det`` (the response
        at the maximum) and ``octave``.

    Examples
    --------
    >>> yy, xx = np.mgrid[0:101, 0:101]
    >>> blob = np.exp(-((xx - 50.0)**2 + (yy - 50.0)**2) / (2 * 4.0**2))
    >>> m = hessian_maxima(integral_image(blob), threshold=1e-4)
    >>> i = np.argmax(m["det"]); round(float(m["u"][i])), round(float(m["v"][i]))
    (50, 50)
    """
    II = as_finite_array(II, "II", ndim=2)
    threshold = check_positive(threshold, "threshold", allow_zero=True)
    n_octaves = check_int(n_octaves, "n_octaves", minimum=1, maximum=6)
    init_step = check_int(init_step, "init_step", minimum=1)
    workers = check_int(workers, "workers", minimum=1)
    H, W = II.shape[0] - 1, II.shape[1] - 1
    L = filter_sizes(n_octaves)
    stacks = _response_stacks(II, n_octaves, init_step, workers, _padded)
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


def threshold_sweep(image, thresholds, *, n_octaves: int = 4, init_step: int = 2) -> np.ndarray:
    """Number of SURF keypoints for each threshold (one response computation).

    Parameters
    ----------
    image : (H, W) array
        Grey image (uint8, or float in [0, 1]).
    thresholds : sequence of float
        Hessian thresholds on our scale.
    n_octaves : int
        Number of octaves.
    init_step : int
        Sampling step of the first octave in pixels.

    Returns
    -------
    (n,) int
        Keypoints with response above each threshold.
    """
    img = to_gray_float(image)
    th = as_vector(thresholds, "thresholds")
    II = integral_image(img)
    ext = hessian_maxima(II, threshold=float(th.min()) if th.min() > 0 else 0.0, n_octaves=n_octaves,
                         init_step=init_step)
    return np.array([int(np.count_nonzero(ext["det"] > t)) for t in th])
