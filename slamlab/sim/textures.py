"""Procedural lunar-surface textures for the stereo arena (000 §3.7; our construction).

000 §3.7 covers the arena fence with photographs of the Moon's surface. We
cannot ship those photographs, so we synthesise look-alikes: a height field of
fractal (1/f^beta) noise plus bowl-shaped craters with raised rims, lit from a
low sun (Lambert shading) and multiplied by a slowly varying albedo. Every
texture is periodic along both axes and deterministic from the seed.

Memory: the element-wise steps run on blocks of about :data:`BLOCK_ELEMENTS` texels, so that a
long fence (the 60×60 m arena's 240 m at 4 mm: 125 × 60 000 texels, 57 MiB per float64 array)
needs about three full-size arrays at a time instead of eight (our change; the values are the
same bit for bit as those of the whole-array expressions, see ``tests/sim/test_arena.py``).
"""

from __future__ import annotations

import itertools

import numpy as np

from .._validate import as_rng, as_vector, check_int, check_positive

__all__ = ["crater_heightfield", "fractal_noise", "lunar_texture"]

#: texels per block of the element-wise and 1-D FFT passes (2 MiB of float64; our choice)
BLOCK_ELEMENTS = 1 << 18


def _shape(shape, name="shape"):
    if not isinstance(shape, tuple | list) or len(shape) != 2:
        raise ValueError(f"`{name}` must be (rows, cols); got {shape!r}")
    return tuple(check_int(s, name, minimum=2) for s in shape)


def _blocks(n: int, other: int) -> list[slice]:
    """Slices of ``range(n)`` whose blocks of ``other`` elements each hold about BLOCK_ELEMENTS."""
    step = max(1, BLOCK_ELEMENTS // max(other, 1))
    return [slice(i, min(i + step, n)) for i in range(0, n, step)]


def fractal_noise(shape, beta: float = 2.0, rng=None) -> np.ndarray:
    """Periodic fractal noise with power spectrum ``1 / f^beta``, zero mean, unit std (our texture).

    Peak memory: about twice the float64 result (the half spectrum and the result; the 2-D inverse
    FFT runs as its two 1-D passes on blocks).

    Parameters
    ----------
    shape : tuple of int
        ``(rows, cols)``, each ≥ 2.
    beta : float, default 2.0
        Spectral exponent (0: white noise).
    rng : int or numpy.random.Generator, optional
        Seed or generator.

    Returns
    -------
    numpy.ndarray, shape (rows, cols)

    Examples
    --------
    >>> z = fractal_noise((32, 64), rng=0)
    >>> z.shape, round(float(z.mean()), 12), round(float(z.std()), 12)
    ((32, 64), 0.0, 1.0)
    """
    rows, cols = _shape(shape)
    beta = check_positive(beta, "beta", allow_zero=True)
    rng = as_rng(rng)
    fy = np.fft.fftfreq(rows)[:, None]
    fx = np.fft.rfftfreq(cols)[None, :]
    n_freq = fx.shape[1]
    # spectrum = amplitude × (N(0,1) + i N(0,1)): all real parts are drawn first, then all
    # imaginary parts, in row-major order -- the stream of one draw of the whole array each
    spec = np.empty((rows, n_freq), dtype=np.complex128)
    row_blocks = _blocks(rows, n_freq)
    for part in ("real", "imag"):
        for b in row_blocks:
            getattr(spec, part)[b] = rng.standard_normal((b.stop - b.start, n_freq))
    for b in row_blocks:
        f = np.hypot(fx, fy[b])
        if b.start == 0:
            f[0, 0] = 1.0
        amp = f ** (-beta / 2.0)
        if b.start == 0:
            amp[0, 0] = 0.0  # zero mean
        spec[b] = amp * spec[b]
    # irfft2 = ifft along the columns, then irfft along the rows: each pass is 1-D, so it runs
    # on blocks (in place for the first, into the output for the second)
    for b in _blocks(n_freq, rows):
        spec[:, b] = np.fft.ifft(spec[:, b], axis=0)
    z = np.empty((rows, cols))
    for b in row_blocks:
        np.fft.irfft(spec[b], n=cols, axis=1, out=z[b])
    del spec
    z -= z.mean()
    z /= z.std()
    return z


def crater_heightfield(shape, n_craters: int = 300, radius_px=(3.0, 40.0), slope: float = 2.2, rng=None) -> np.ndarray:
    """Sum of craters: a parabolic bowl inside ``r < R`` and a rim decaying outside (our texture).

    Radii follow a power law ``p(R) ~ R^-slope`` between ``radius_px``; depth is
    ``0.2 R``; the field wraps around both edges.

    Parameters
    ----------
    shape : tuple of int
        ``(rows, cols)``, each ≥ 2.
    n_craters : int, default 300
        Number of craters.
    radius_px : tuple of float
        ``(min, max)`` crater radius [px].
    slope : float, default 2.2
        Power-law exponent of the radius distribution.
    rng : int or numpy.random.Generator, optional
        Seed or generator.

    Returns
    -------
    numpy.ndarray, shape (rows, cols)
        Height [px].

    Examples
    --------
    >>> h = crater_heightfield((64, 64), n_craters=1, radius_px=(10.0, 10.0), rng=0)
    >>> bool(h.min() < 0 < h.max())
    True
    """
    rows, cols = _shape(shape)
    n_craters = check_int(n_craters, "n_craters", minimum=0)
    r_lo, r_hi = (check_positive(r, "radius_px") for r in as_vector(radius_px, "radius_px", 2))
    if r_hi < r_lo:
        raise ValueError(f"`radius_px` must be (min, max) with min <= max; got {tuple(radius_px)}")
    slope = check_positive(slope, "slope")
    rng = as_rng(rng)
    h = np.zeros((rows, cols))
    if n_craters == 0:
        return h
    # inverse-CDF sampling of the power law R^-slope on [r_lo, r_hi]
    u = rng.random(n_craters)
    a = 1.0 - slope
    R = (r_lo**a + u * (r_hi**a - r_lo**a)) ** (1.0 / a) if r_hi > r_lo else np.full(n_craters, r_lo)
    cy = rng.uniform(0, rows, n_craters)
    cx = rng.uniform(0, cols, n_craters)
    ext = np.ceil(2.0 * R).astype(np.intp) + 1  # stamp half-width: rim to r = 2R
    if np.any(2 * ext + 1 > min(rows, cols)):  # a stamp that wraps onto itself: one at a time, as fancy indexing adds
        for Ri, yi, xi, e in zip(R, cy, cx, ext, strict=True):
            ys = np.arange(int(yi) - e, int(yi) + e + 1)
            xs = np.arange(int(xi) - e, int(xi) + e + 1)
            q = np.hypot((ys[:, None] - yi), (xs[None, :] - xi)) / Ri
            h[np.ix_(ys % rows, xs % cols)] += _crater_profile(q, Ri)
        return h
    # all stamps at once, in column blocks of about BLOCK_ELEMENTS stamp texels: a texel's craters are summed
    # in crater order from zero (np.bincount), as the stamp-by-stamp loop above adds them -- the same bits
    side = 2 * ext + 1
    iy, ix = cy.astype(np.intp), cx.astype(np.intp)  # int(): the centres are >= 0
    n_blocks = max(1, min(cols, int(np.ceil(float(np.sum(side * side)) / BLOCK_ELEMENTS))))
    edges = np.linspace(0, cols, n_blocks + 1).round().astype(np.intp)
    for c0, c1 in itertools.pairwise(edges):
        lo, hi = ix - ext, ix + ext  # column span, unwrapped
        hit = np.zeros(n_craters, bool)
        for shift in (-cols, 0, cols):
            hit |= (lo + shift < c1) & (hi + shift >= c0)
        k = np.flatnonzero(hit)  # crater order
        sizes = side[k] * side[k]
        crater = np.repeat(k, sizes)
        j = np.arange(crater.size) - np.repeat(np.cumsum(sizes) - sizes, sizes)  # element within its stamp
        s_k = side[crater]
        ys = iy[crater] - ext[crater] + j // s_k
        xs = ix[crater] - ext[crater] + j % s_k
        cols_w = xs % cols
        keep = (cols_w >= c0) & (cols_w < c1)
        crater, ys, xs, cols_w = crater[keep], ys[keep], xs[keep], cols_w[keep]
        Ri = R[crater]
        q = np.hypot(ys - cy[crater], xs - cx[crater]) / Ri
        flat = (ys % rows) * (c1 - c0) + (cols_w - c0)
        h[:, c0:c1] = np.bincount(flat, weights=_crater_profile(q, Ri), minlength=rows * (c1 - c0)).reshape(rows, c1 - c0)
    return h


def _crater_profile(q, R):
    """Height of a crater of radius ``R`` at ``q = r / R``: a parabolic bowl (depth 0.2 R) and a raised rim."""
    bowl = (q**2 - 1.0) * 0.2 * R  # parabolic floor, zero at the rim
    rim = 0.06 * R * np.exp(-((q - 1.0) ** 2) / 0.04)  # raised rim around r = R
    return np.where(q < 1.0, bowl, 0.0) + rim * (q < 2.0)


def lunar_texture(
    shape,
    *,
    n_craters: int = 300,
    radius_px=(3.0, 40.0),
    noise_beta: float = 2.4,
    noise_amp_px: float = 4.0,
    sun_azimuth_rad: float = 0.6,
    sun_elevation_rad: float = 0.5,
    contrast: float = 1.0,
    rng=None,
) -> np.ndarray:
    """A shaded lunar-surface-like image in ``[0, 1]``, periodic, deterministic from ``rng`` (000 §3.7).

    Height = ``noise_amp_px`` × fractal noise + craters; brightness = albedo × Lambert
    shading under a sun at ``sun_azimuth_rad`` / ``sun_elevation_rad``.

    Parameters
    ----------
    shape : tuple of int
        ``(rows, cols)``, each ≥ 2.
    n_craters : int, default 300
        Number of craters (:func:`crater_heightfield`).
    radius_px : tuple of float
        ``(min, max)`` crater radius [px].
    noise_beta : float, default 2.4
        Spectral exponent of the height noise.
    noise_amp_px : float, default 4.0
        Amplitude of the height noise [px].
    sun_azimuth_rad, sun_elevation_rad : float
        Direction of the sun [rad].
    contrast : float, default 1.0
        Factor on the brightness deviations from the mean.
    rng : int or numpy.random.Generator, optional
        Seed or generator (three child streams: noise, craters, albedo).

    Returns
    -------
    numpy.ndarray, shape (rows, cols)
        Brightness in [0, 1].

    Examples
    --------
    >>> t = lunar_texture((64, 96), rng=3)
    >>> t.shape, bool(0.0 <= t.min() and t.max() <= 1.0)
    ((64, 96), True)
    >>> bool(np.array_equal(t, lunar_texture((64, 96), rng=3)))
    True
    """
    rows, cols = _shape(shape)
    noise_amp_px = check_positive(noise_amp_px, "noise_amp_px", allow_zero=True)
    contrast = check_positive(contrast, "contrast")
    rng = as_rng(rng)
    r_noise, r_crater, r_albedo = rng.spawn(3)
    h = fractal_noise((rows, cols), noise_beta, r_noise)
    h *= noise_amp_px
    h += crater_heightfield((rows, cols), n_craters, radius_px, rng=r_crater)
    sun = np.array(
        [np.cos(sun_elevation_rad) * np.cos(sun_azimuth_rad), np.cos(sun_elevation_rad) * np.sin(sun_azimuth_rad), np.sin(sun_elevation_rad)]
    )
    # Lambert shading from periodic central differences, surface normal (-hx, -hy, 1), on blocks
    # of columns with one wrapped neighbour column on either side
    img = np.empty((rows, cols))
    for b in _blocks(cols, rows):
        hb = h[:, np.arange(b.start - 1, b.stop + 1) % cols]
        hx = 0.5 * (hb[:, 2:] - hb[:, :-2])
        hc = hb[:, 1:-1]
        hy = 0.5 * (np.roll(hc, -1, axis=0) - np.roll(hc, 1, axis=0))
        shade = (-hx * sun[0] - hy * sun[1] + sun[2]) / np.sqrt(hx**2 + hy**2 + 1.0)
        img[:, b] = np.clip(shade, 0.0, None)
    del h
    albedo = fractal_noise((rows, cols), 3.0, r_albedo)
    np.tanh(albedo, out=albedo)
    albedo *= 0.2
    albedo += 0.75
    img *= albedo  # brightness = albedo × shading
    del albedo
    mean, std = img.mean(), img.std()
    img -= mean
    img *= contrast
    img /= 4.0 * std + 1e-12
    img += 0.5
    return np.clip(img, 0.0, 1.0, out=img)
