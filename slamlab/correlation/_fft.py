"""Package-private: the batched FFT search of correlation localisation (004 §7), shared by
:mod:`slamlab.correlation.algorithm` (the search) and :mod:`slamlab.correlation.scoring` (the score maps).

The stamps ``T_n`` of a list of headings are rasterised once per heading modulo 90° (``Stamps``) and correlated
with the map by batched real FFTs against its spectrum, computed once per quarter turn (``MapSpectrum``,
``map_spectra``), pruned to the valid shifts; ``peak_search`` streams the maps ``D_n`` for their maximum,
``rival_search`` finds the best pose away from it, ``ExploredNorm`` divides the scores by the marks on explored
cells (ours, issue 25). The index mapping is derived in :mod:`slamlab.correlation.algorithm`.
"""

from __future__ import annotations

import numpy as np
import scipy.fft as sfft

from ..geometry import wrap_angle


class Stamps:
    """T_n for a list of headings, rasterising each heading modulo 90° once (quarter turns are exact on the grid).

    A point ``(x, y) → (-y, x)`` under a quarter turn: ``T'[o + x, o - y] = T[o + y, o + x]``, i.e.
    ``T'[i, j] = T[(2o - j) mod S, i]`` (the wrapped row/column is the outer ring, always a_n).
    """

    def __init__(self, free, obs, headings, a_c, a_p, a_n, o, dtype):
        S = 2 * o
        self.S, self.dtype = S, dtype
        self.quarter = np.floor(np.mod(headings, 2 * np.pi) / (np.pi / 2) + 1e-9).astype(int) % 4
        base = np.mod(headings, np.pi / 2)
        base[base > np.pi / 2 - 1e-9] = 0.0
        ub, self.inv = np.unique(np.round(base, 12), return_inverse=True)
        self.Tb = np.full((ub.size, S, S), a_n, dtype=dtype)
        write_marks(self.Tb, ub, free, obs, a_c, a_p, o)
        self.Tb = self.Tb.reshape(ub.size, S * S)
        i, j = np.divmod(np.arange(S * S), S)
        p1 = ((2 * o - j) % S) * S + i
        self.perm = [None, p1, p1[p1], p1[p1][p1]]

    def take(self, sel: np.ndarray) -> np.ndarray:
        """The stack ``T[sel]`` of shape ``(len(sel), S, S)``."""
        out = np.empty((sel.size, self.S * self.S), dtype=self.dtype)
        q = self.quarter[sel]
        for k in range(4):
            m = np.nonzero(q == k)[0]
            if m.size:
                block = self.Tb[self.inv[sel[m]]]
                out[m] = block if k == 0 else np.take(block, self.perm[k], axis=1)
        return out.reshape(sel.size, self.S, self.S)


def write_marks(T: np.ndarray, headings: np.ndarray, free: np.ndarray, obs: np.ndarray, a_c: float, a_p: float,
           o: int) -> None:
    """Write a_c at the free samples and then a_p at the obstacle samples of each heading (in place)."""
    n, S, _ = T.shape
    flat = T.reshape(-1)
    big = n * S * S >= 2**24  # float32 holds integers exactly below 2**24
    ft = np.float64 if big else np.float32
    c = np.cos(headings).astype(ft)[:, None]
    s = np.sin(headings).astype(ft)[:, None]
    base = (np.arange(n, dtype=ft) * (S * S) + o * S + o + 0.5 * (S + 1))[:, None]
    chunk = max(1, int(4e6 // max(free.shape[0], 1)))
    for pts, val in ((free, a_c), (obs, a_p)):  # obstacle marks overwrite free ones
        if pts.shape[0] == 0:
            continue
        px, py = pts[:, 0].astype(ft), pts[:, 1].astype(ft)
        for k0 in range(0, n, chunk):
            cc, ss = c[k0:k0 + chunk], s[k0:k0 + chunk]
            x = cc * px
            x -= ss * py
            y = ss * px
            y += cc * py
            # floor(v + 0.5) for row and column, folded: idx = (floor(y+.5)+o)·S + floor(x+.5)+o + n·S²
            np.floor(x + 0.5, out=x)
            np.floor(y + 0.5, out=y)
            y *= S
            y += x
            y += base[k0:k0 + chunk] - 0.5 * (S + 1)
            # val: a scalar, or one value per point (obstacle weights, ours): the same for every heading
            flat[y.astype(np.int64).ravel()] = val if np.ndim(val) == 0 else np.broadcast_to(val, y.shape).ravel()


def fast_len(n: int) -> int:
    return sfft.next_fast_len(n, real=True)


class MapSpectrum:
    """rfft2 of the map zero-padded for the robot-inside-map shifts of an S×S stamp (computed once)."""

    def __init__(self, Mv: np.ndarray, S: int, o: int, dtype, workers: int | None, L: tuple[int, int] | None = None):
        H, W = Mv.shape
        # circular correlation c[k] = Σ_i T[i]·Mp[(i + k) mod L] equals the linear one for the shifts
        # k = row - o, row ∈ [0, H), when L ≥ H + o and L ≥ H + S - 1 - o (derived in
        # slamlab.correlation.algorithm's docstring)
        need = (max(H + o, H + S - 1 - o), max(W + o, W + S - 1 - o))
        self.L = (fast_len(need[0]), fast_len(need[1])) if L is None else L
        if self.L[0] < need[0] or self.L[1] < need[1]:
            raise ValueError(f"FFT size {self.L} too small for map {Mv.shape} and stamp {S}")
        self.shape = (H, W)
        self.S, self.o, self.dtype, self.workers = S, o, dtype, workers
        self.FM = sfft.rfft2(Mv.astype(dtype, copy=False), s=self.L, workers=workers)
        self.rows = (np.arange(H) - o) % self.L[0]
        self.cols = (np.arange(W) - o) % self.L[1]

    def forward(self, T: np.ndarray) -> np.ndarray:
        """conj(rfft2(T)) at this spectrum's size (pruned: rfft on the S rows only, then fft along rows)."""
        FT = sfft.rfft(T.astype(self.dtype, copy=False), n=self.L[1], axis=-1, workers=self.workers)
        FT = sfft.fft(FT, n=self.L[0], axis=-2, workers=self.workers, overwrite_x=True)
        return np.conjugate(FT, out=FT)

    def inverse(self, FTc: np.ndarray) -> np.ndarray:
        """Scores ``(n, H, W)`` from ``forward(T)``: product with the map spectrum, pruned irfft2."""
        P = FTc * self.FM
        c = sfft.ifft(P, axis=-2, workers=self.workers, overwrite_x=True)[:, self.rows]
        c = sfft.irfft(c, n=self.L[1], axis=-1, workers=self.workers, overwrite_x=True)
        return c[:, :, self.cols]

    def scores(self, T: np.ndarray) -> np.ndarray:
        return self.inverse(self.forward(T))


def map_spectra(Mv, stamps, S, o, *, dtype, workers):
    """Spectra of the map turned by every quarter turn the stamps use (one FFT size for all)."""
    H, W = Mv.shape
    side = max(H, W)
    L = fast_len(max(side + o, side + S - 1 - o))
    return {q: MapSpectrum(np.ascontiguousarray(np.rot90(Mv, q)), S, o, dtype, workers, L=(L, L))
            for q in sorted(set(stamps.quarter.tolist()))}


class ExploredNorm:
    """What ``iter_scores`` needs to divide each pose's score by its marks on explored cells (ours, issue 25).

    ``count[n, row, col] = Σ_{i,j} [T_n[i, j] marked]·E[row + i - o, col + j - o]`` with ``E`` = 1 on the
    explored cells of the map (value ≠ ``a_n``) and 0 elsewhere and outside: one more correlation, of the
    indicator stamps (the same samples rasterised with value 1) with ``E``, by the same batched FFTs. A pose
    scores ``D / count`` when ``count ≥ min_fraction · marks_n`` (``marks_n``: the stamp's marked cells), else
    ``floor``.
    """

    def __init__(self, Mv, free, obs, headings, o, a_n, min_fraction, floor, *, dtype, workers):
        S = 2 * o
        self.stamps = Stamps(free, obs, headings, 1.0, 1.0, 0.0, o, dtype)
        self.marks = np.count_nonzero(self.stamps.Tb, axis=1)  # per base stamp (a quarter turn keeps the count)
        self.specs = map_spectra((Mv != a_n).astype(np.float64), self.stamps, S, o, dtype=dtype, workers=workers)
        self.min_fraction, self.floor = float(min_fraction), float(floor)

    def apply(self, D, FTc_ind, q, heads):
        """``D`` normalised for the headings ``heads`` of quarter turn ``q``."""
        cnt = self.specs[q].inverse(FTc_ind)
        if q:
            cnt = np.rot90(cnt, -q, axes=(1, 2))
        cnt = np.rint(cnt)
        need = self.min_fraction * self.marks[self.stamps.inv[heads]][:, None, None] - 1e-9
        return np.where(cnt >= need, D / np.maximum(cnt, 1.0), self.floor)


def iter_scores(specs, stamps, sel, S, chunk, norm: ExploredNorm | None = None):
    """Yield ``(heads, D)``: score maps ``D[k] = D_{heads[k]}`` for the headings ``sel``, in chunks of base stamps.

    Quarter turns: with ``R`` the quarter turn of the stamps, ``D_{T∘R⁻¹}(M) = rot90(D_T(rot90(M)), -1)``
    (derivation in the notebook), so the spectrum of each base stamp (heading mod 90°) is computed once
    and correlated with the four rotated maps' spectra. With ``norm`` (``ExploredNorm``) the maps are
    divided by the marks on explored cells.
    """
    quarters = sorted(specs)
    bases = np.unique(stamps.inv[sel])
    for b0 in range(0, bases.size, chunk):
        bs = bases[b0:b0 + chunk]
        FTc = specs[quarters[0]].forward(stamps.Tb[bs].reshape(bs.size, S, S))
        if norm is not None:
            FTi = norm.specs[quarters[0]].forward(norm.stamps.Tb[bs].reshape(bs.size, S, S))
        in_chunk = sel[np.isin(stamps.inv[sel], bs)]
        for q in quarters:
            heads = in_chunk[stamps.quarter[in_chunk] == q]
            if heads.size == 0:
                continue
            pick = np.searchsorted(bs, stamps.inv[heads])
            D = specs[q].inverse(FTc[pick])
            if q:
                D = np.rot90(D, -q, axes=(1, 2))
            if norm is not None:
                D = norm.apply(D, FTi[pick], q, heads)
            yield heads, D


def peak_search(Mv, stamps, headings, S, o, *, dtype, workers, chunk, tol, specs=None, n_peaks: int = 0,
                 norm: ExploredNorm | None = None):
    """Maximum of the 3-D stack D[n, row, col] over all headings (streamed; bounded memory).

    Returns ``(best_val, (n, row, col), best_map, best_per_heading, argmax_per_heading)``; ties within
    ``tol`` go to the smallest heading index, then the first row and column. ``argmax_per_heading``
    holds the flat cell index of each heading's maximum. With ``n_peaks`` > 0 a sixth item: the
    ``(value, n, row, col)`` of up to ``4·n_peaks`` largest local maxima (5×5 cells) per chunk of
    headings (``local_peaks``), for ``distinct_peaks`` (ours, issue 25).
    """
    if specs is None:
        specs = map_spectra(Mv, stamps, S, o, dtype=dtype, workers=workers)
    best_per = np.full(headings.size, -np.inf)
    arg_per = np.zeros(headings.size, dtype=np.int64)
    best_val, best_idx, best_map = -np.inf, None, None
    peaks = []
    for heads, D in iter_scores(specs, stamps, np.arange(headings.size), S, chunk, norm):
        if n_peaks:
            peaks.append(local_peaks(D, heads, 4 * n_peaks))
        flat_D = D.reshape(D.shape[0], -1)
        am = flat_D.argmax(axis=1)
        per = flat_D[np.arange(am.size), am]
        best_per[heads], arg_per[heads] = per, am
        m = float(per.max())
        if m > best_val + tol or (m >= best_val - tol and best_idx is not None and heads.min() < best_idx[0]):
            cand = np.nonzero(per >= max(m, best_val) - tol)[0]
            k = cand[np.argmin(heads[cand])]
            if best_idx is None or m > best_val + tol or heads[k] < best_idx[0]:
                flat = int(np.argmax(D[k].ravel() >= max(m, best_val) - tol))
                best_val = max(m, best_val)
                best_idx = (int(heads[k]), *np.unravel_index(flat, D.shape[1:]))
                best_map = np.ascontiguousarray(D[k])
    if n_peaks:
        return best_val, best_idx, best_map, best_per, arg_per, np.vstack(peaks)
    return best_val, best_idx, best_map, best_per, arg_per


def local_peaks(D: np.ndarray, heads: np.ndarray, k: int) -> np.ndarray:
    """``(value, n, row, col)`` rows of the ``k`` largest local maxima (over 5×5 cells) among the ``64·k``
    largest cells of the maps ``D`` (a cell is a local maximum when no cell within 2 rows and columns of its
    map is larger)."""
    _n, H, W = D.shape
    flat = D.reshape(-1)
    m = min(64 * k, flat.size)
    top = np.argpartition(flat, flat.size - m)[flat.size - m:]
    n, rc = np.divmod(top, H * W)
    r, c = np.divmod(rc, W)
    val = flat[top]
    is_peak = np.ones(top.size, dtype=bool)
    for dr in range(-2, 3):
        for dc in range(-2, 3):
            rr, cc = r + dr, c + dc
            inside = (rr >= 0) & (rr < H) & (cc >= 0) & (cc < W)
            nb = D[n[inside], rr[inside], cc[inside]]
            is_peak[np.nonzero(inside)[0][nb > val[inside]]] = False
    n, r, c, val = n[is_peak], r[is_peak], c[is_peak], val[is_peak].astype(np.float64)
    if val.size > k:
        sel = np.argpartition(-val, k - 1)[:k]
        n, r, c, val = n[sel], r[sel], c[sel], val[sel]
    return np.column_stack([val, heads[n], r, c])


def distinct_peaks(peaks: np.ndarray, headings: np.ndarray, k: int, radius_cells: float, heading_rad: float):
    """The ``k`` best of ``peaks`` (rows ``(value, n, row, col)``) that lie more than ``radius_cells`` or
    ``heading_rad`` from every better one kept (greedy non-maximum suppression)."""
    kept = []
    for val, n, r, c in peaks[np.argsort(-peaks[:, 0], kind="stable")]:
        if all(np.hypot(r - r2, c - c2) > radius_cells or abs(wrap_angle(headings[int(n)] - headings[int(n2)]))
               > heading_rad for _v, n2, r2, c2 in kept):
            kept.append((val, n, r, c))
            if len(kept) == k:
                break
    return np.array(kept).reshape(-1, 4)


def rival_search(specs, stamps, headings, S, best_idx, best_per, arg_per, *, radius_cells, heading_rad, chunk,
                  norm: ExploredNorm | None = None):
    """Best pose more than ``radius_cells`` or ``heading_rad`` away from the peak ``best_idx`` (ours).

    Headings farther than ``heading_rad`` count with their whole map (their maxima are already known);
    the others are scored again with the disc of radius ``radius_cells`` around the peak cell masked.
    Returns ``(score, (n, row, col))``, ``(-inf, None)`` when no such pose exists.
    """
    n0, r0, c0 = best_idx
    H, W = specs[next(iter(specs))].shape
    dh = np.abs(wrap_angle(headings - headings[n0]))
    far = np.nonzero(dh > heading_rad + 1e-12)[0]
    val, idx = -np.inf, None
    if far.size:
        k = far[np.argmax(best_per[far])]
        val, idx = float(best_per[k]), (int(k), *np.unravel_index(int(arg_per[k]), (H, W)))
    near = np.nonzero(dh <= heading_rad + 1e-12)[0]
    rows, cols = np.ogrid[:H, :W]
    outside = ((rows - r0) ** 2 + (cols - c0) ** 2 > radius_cells ** 2).ravel()
    if not outside.any():
        return val, idx
    cells = np.nonzero(outside)[0]
    for heads, D in iter_scores(specs, stamps, near, S, chunk, norm):
        Dm = D.reshape(D.shape[0], -1)[:, cells]
        am = Dm.argmax(axis=1)
        per = Dm[np.arange(am.size), am]
        k = int(np.argmax(per))
        if per[k] > val:
            val, idx = float(per[k]), (int(heads[k]), *np.unravel_index(int(cells[am[k]]), (H, W)))
    return val, idx
