"""The fast paths of SURF (issue 17) against the plain implementations they replace.

- The phase-split response maps and the shared layers of consecutive octaves give the same values
  as :func:`hessian_response` on its strided views, bit for bit, on sizes that are and are not
  multiples of the grid steps.
- Orientation (angle bins) and descriptors (padded integral image, grouped chunks, sub-region sums)
  equal Bay 2008 §4.1-4.2 written out per keypoint with :func:`haar_xy`, for keypoints inside the
  image, near and past its edges (clipped boxes), at several window and step sizes.
- The survivor-filtering NMS gives the set and order of ``scipy.ndimage.maximum_filter``.
"""

import numpy as np
import pytest
from scipy import ndimage

from slamlab.features import (
    filter_sizes,
    haar_xy,
    hessian_response,
    integral_image,
    surf_describe,
    surf_orientation,
)
from slamlab.features._padded_ii import PaddedIntegralImage
from slamlab.features.surf_response import _interior_maxima, _response_stacks


@pytest.mark.parametrize(("shape", "init_step", "n_octaves", "phase_octaves"),
                         [((96, 128), 2, 4, 1), ((101, 67), 2, 4, 4), ((77, 93), 1, 4, 2), ((64, 61), 3, 4, 4),
                          ((90, 120), 2, 6, 6), ((90, 120), 2, 6, 1)])
def test_response_stacks_equal_hessian_response_bitwise(shape, init_step, n_octaves, phase_octaves):
    """Phases (sliced from the padded image, or gathered where it is too small: octaves 5-6),
    strided views of the padded image or of a fresh one (octaves 5-6), shared layers."""
    rng = np.random.default_rng(3)
    II = integral_image(rng.random(shape))
    L = filter_sizes(n_octaves)
    stacks = _response_stacks(II, n_octaves, init_step, workers=2, phase_octaves=phase_octaves)
    for o, (D, step) in enumerate(stacks):
        assert step == init_step * 2**o
        for i in range(4):
            det, _ = hessian_response(II, int(L[o, i]), step)
            np.testing.assert_array_equal(D[i], det)


def _random_keypoints(rng, H, W, n):
    """Keypoints over the whole image and past its edges, scales 1.2-30 px: the large ones near the
    edges reach past the 128-pixel padding and take the clipped path."""
    uv = np.column_stack([rng.uniform(-3, W + 3, n), rng.uniform(-3, H + 3, n)])
    return uv, np.where(rng.random(n) < 0.8, rng.uniform(1.2, 6.0, n), rng.uniform(6.0, 30.0, n))


def _orientation_direct(II, uv, sigma, window_rad, step_rad):
    """Bay 2008 §4.1 written out: every window's sums over the samples it holds, then the longest."""
    I, J = np.meshgrid(np.arange(-6, 7), np.arange(-6, 7), indexing="ij")
    m = I**2 + J**2 < 36
    I, J = I[m], J[m]
    g = np.exp(-(I**2 + J**2) / (2 * 2.5**2))
    starts = np.arange(0.0, 2 * np.pi, step_rad)
    out = []
    for (u, v), sg in zip(uv, sigma, strict=True):
        s = max(int(np.rint(sg)), 1)
        dx, dy = haar_xy(II, int(np.rint(v)) + J * s, int(np.rint(u)) + I * s, 2 * s)
        dx, dy = dx * g, dy * g
        a = np.arctan2(dy, dx) % (2 * np.pi)
        inside = ((starts[:, None] <= a) & (a < starts[:, None] + window_rad)) | (a + 2 * np.pi < starts[:, None] + window_rad)
        sx, sy = inside @ dx, inside @ dy
        b = np.argmax(sx**2 + sy**2)
        out.append(np.arctan2(sy[b], sx[b]) % (2 * np.pi))
    return np.array(out)


@pytest.mark.parametrize(("window_rad", "step_rad"), [(np.pi / 3, 0.15), (np.pi / 2, 0.2), (0.3, 0.1), (1.0, 0.25)])
def test_orientation_bins_equal_direct_window_sums(window_rad, step_rad):
    rng = np.random.default_rng(5)
    img = ndimage.gaussian_filter(rng.random((90, 120)), 2.0)
    II = integral_image(img)
    uv, sigma = _random_keypoints(rng, 90, 120, 300)
    got = surf_orientation(II, uv, sigma, window_rad=window_rad, step_rad=step_rad, chunk=16, workers=2)
    ref = _orientation_direct(II, uv, sigma, window_rad, step_rad)
    np.testing.assert_allclose(np.angle(np.exp(1j * (got - ref))), 0.0, atol=1e-9)


def _describe_direct(II, uv, sigma, theta, extended):
    """Bay 2008 §4.2 written out per keypoint: rotated grid, Haar, rotated responses, 16 sub-region sums."""
    off = np.arange(20) - 9.5
    X, Y = np.meshgrid(off, off, indexing="xy")
    g = np.exp(-(X**2 + Y**2) / (2 * 3.3**2))
    out = []
    for (u, v), sg, th in zip(uv, sigma, theta, strict=True):
        c, s = np.cos(th), np.sin(th)
        cols = np.rint(u + (X * c - Y * s) * sg).astype(int)
        rows = np.rint(v + (X * s + Y * c) * sg).astype(int)
        dx, dy = haar_xy(II, rows, cols, max(int(np.rint(sg)), 1))
        rx, ry = (c * dx + s * dy) * g, (c * dy - s * dx) * g
        feats = []
        for by in range(4):
            for bx in range(4):
                px, py = rx[5 * by:5 * by + 5, 5 * bx:5 * bx + 5], ry[5 * by:5 * by + 5, 5 * bx:5 * bx + 5]
                if extended:
                    ny, nx = py < 0, px < 0
                    feats += [px[ny].sum(), np.abs(px[ny]).sum(), px[~ny].sum(), np.abs(px[~ny]).sum(),
                              py[nx].sum(), np.abs(py[nx]).sum(), py[~nx].sum(), np.abs(py[~nx]).sum()]
                else:
                    feats += [px.sum(), py.sum(), np.abs(px).sum(), np.abs(py).sum()]
        d = np.array(feats)
        out.append(d / np.linalg.norm(d))
    return np.array(out)


@pytest.mark.parametrize("extended", [False, True])
def test_descriptors_equal_direct_computation(extended):
    rng = np.random.default_rng(6)
    img = ndimage.gaussian_filter(rng.random((90, 120)), 1.5)
    II = integral_image(img)
    uv, sigma = _random_keypoints(rng, 90, 120, 200)
    theta = rng.uniform(0, 2 * np.pi, uv.shape[0])
    got = surf_describe(II, uv, sigma, theta, extended=extended, chunk=8, workers=2)
    np.testing.assert_allclose(got, _describe_direct(II, uv, sigma, theta, extended), rtol=0, atol=1e-6)


def _maxima_direct(D, threshold):
    m = ndimage.maximum_filter(D, size=3, mode="nearest")
    keep = (m == D) & (threshold < D)
    keep[[0, -1]] = False
    keep[:, [0, -1]] = False
    keep[:, :, [0, -1]] = False
    return np.nonzero(keep)


@pytest.mark.parametrize("levels", [None, 4])
def test_interior_maxima_equal_maximum_filter(levels):
    """Same set and order as ``scipy.ndimage.maximum_filter``, ties (integer levels) included."""
    rng = np.random.default_rng(8)
    D = rng.random((4, 37, 51))
    if levels:
        D = np.floor(D * levels)
    got = _interior_maxima(D, 0.2)
    for a, b in zip(got, _maxima_direct(D, 0.2), strict=True):
        np.testing.assert_array_equal(a, b)


@pytest.mark.parametrize("shape", [(40, 57), (90, 120)])
def test_padded_integral_image_from_the_image_equals_padded_integral_image(shape):
    img = np.random.default_rng(9).random(shape)
    II = integral_image(img)
    P = PaddedIntegralImage(image=img, pad=20, extra=7, workers=2)
    np.testing.assert_array_equal(P.E, np.pad(II, ((20, 27), (20, 27)), mode="edge"))
    np.testing.assert_array_equal(P.II, II)


def test_clipped_haar_on_the_padded_image_equals_haar_xy():
    rng = np.random.default_rng(10)
    II = integral_image(rng.random((50, 70)))
    P = PaddedIntegralImage(II, pad=8)
    rows, cols = rng.integers(-40, 90, (6, 30)), rng.integers(-40, 110, (6, 30))
    half = rng.integers(1, 30, (6, 1))
    for got, ref in zip(P.haar_clipped(rows, cols, half), haar_xy(II, rows, cols, half), strict=True):
        np.testing.assert_array_equal(got, ref)


def test_orientation_ties_go_to_the_first_window():
    """A bright quadrant, symmetric about the diagonal: windows holding the 0 and π/4 samples and the
    π/4 and π/2 samples have the same sum length; the first of the tied windows wins (not rounding)."""
    img = np.zeros((60, 60))
    img[30:, 30:] = 1.0
    assert np.array_equal(img, img.T)
    II = integral_image(img)
    uv, sigma = np.array([[30.0, 30.0]]), np.array([2.0])
    s, I, J = 2, *np.meshgrid(np.arange(-6, 7), np.arange(-6, 7), indexing="ij")
    m = I**2 + J**2 < 36
    g = np.exp(-(I[m] ** 2 + J[m] ** 2) / (2 * 2.5**2))
    dx, dy = haar_xy(II, 30 + J[m] * s, 30 + I[m] * s, 2 * s)
    dx, dy = dx * g, dy * g
    a = np.arctan2(dy, dx) % (2 * np.pi)
    starts = np.arange(0.0, 2 * np.pi, 0.15)
    inside = ((starts[:, None] <= a) & (a < starts[:, None] + np.pi / 3)) | (a + 2 * np.pi < starts[:, None] + np.pi / 3)
    sx, sy = inside @ dx, inside @ dy
    n2 = sx**2 + sy**2
    tied = np.flatnonzero(n2 >= (1 - 1e-12) * n2.max())
    assert tied.size >= 2  # tied windows ...
    assert np.ptp(np.arctan2(sy[tied], sx[tied])) > 0.1  # ... with different angles
    expected = np.arctan2(sy[tied[0]], sx[tied[0]]) % (2 * np.pi)
    got = surf_orientation(II, uv, sigma)
    np.testing.assert_allclose(got, [expected], atol=1e-12)
