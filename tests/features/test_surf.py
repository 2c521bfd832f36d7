"""SURF from the paper: integral image, box filters, blob scale, rotation, descriptors, bad input."""

import numpy as np
import pytest
from scipy import ndimage
from scipy.spatial import cKDTree

from slamlab.features import (
    SURF,
    filter_sizes,
    haar_xy,
    hessian_response,
    integral_image,
    surf_detect,
    threshold_sweep,
)


def _blob(s, size=161, centre=80.0):
    yy, xx = np.mgrid[0:size, 0:size]
    return np.exp(-((xx - centre) ** 2 + (yy - centre) ** 2) / (2 * s**2))


def _textured(seed=0, shape=(161, 201)):  # odd sides: the rotated sampling grid is the same grid
    rng = np.random.default_rng(seed)
    return ndimage.gaussian_filter(rng.random(shape), 2.0)


def test_integral_image_box_sums_match_direct_sums():
    rng = np.random.default_rng(0)
    img = rng.random((30, 40))
    II = integral_image(img)
    assert II[7, 9] == pytest.approx(img[:7, :9].sum())
    dx, dy = haar_xy(II, np.array([15]), np.array([20]), 3)
    assert dx[0] == pytest.approx(img[12:18, 20:23].sum() - img[12:18, 17:20].sum())
    assert dy[0] == pytest.approx(img[15:18, 17:23].sum() - img[12:15, 17:23].sum())


def test_filter_sizes_of_the_paper():
    np.testing.assert_array_equal(filter_sizes(4), [[9, 15, 21, 27], [15, 27, 39, 51], [27, 51, 75, 99],
                                                    [51, 99, 147, 195]])


def test_box_filters_equal_explicit_kernels():
    """Dxx, Dyy, Dxy of the 9x9 filter = correlation with the explicit lobe kernels of Bay's Fig. 1."""
    rng = np.random.default_rng(1)
    img = rng.random((40, 40))
    kxx = np.zeros((9, 9))
    kxx[2:7, :] = 1.0
    kxx[2:7, 3:6] = -2.0
    kyy = kxx.T
    kxy = np.zeros((9, 9))
    kxy[1:4, 5:8] = 1.0
    kxy[5:8, 1:4] = 1.0
    kxy[1:4, 1:4] = -1.0
    kxy[5:8, 5:8] = -1.0
    Dxx = ndimage.correlate(img, kxx, mode="constant") / 81
    Dyy = ndimage.correlate(img, kyy, mode="constant") / 81
    Dxy = ndimage.correlate(img, kxy, mode="constant") / 81
    det, tr = hessian_response(integral_image(img), 9, 1)
    np.testing.assert_allclose(det, Dxx * Dyy - 0.81 * Dxy**2, atol=1e-12)
    np.testing.assert_allclose(tr, Dxx + Dyy, atol=1e-12)


def test_blob_is_found_at_its_centre_and_scale_grows_with_the_blob():
    """Scale follows the blob linearly: σ_SURF / s stays within ±12 % over s = 3..8 (box filters peak
    at σ = 1.2 L / 9 ≈ 0.7 s, where the Gaussian det-of-Hessian peaks at σ = s: see the notebook)."""
    ratios = []
    for s in (3.0, 4.0, 5.0, 6.0, 8.0):
        f = surf_detect(_blob(s), 1e-4, descriptors=False)
        best = np.argmax(f.response)
        np.testing.assert_allclose(f.uv[best], [80.0, 80.0], atol=0.5)
        ratios.append(f.scale_px[best] / s)
    ratios = np.array(ratios)
    assert np.all(np.abs(ratios / ratios.mean() - 1) < 0.12)
    assert 0.55 < ratios.mean() < 0.85


def test_gaussian_det_of_hessian_reference_peaks_at_blob_scale():
    """Independent reference: scale-normalised det of Gaussian derivatives peaks at σ = s (closed form)."""
    img = _blob(4.0)
    sigmas = np.linspace(2.0, 7.0, 26)
    vals = []
    for sg in sigmas:
        dxx = ndimage.gaussian_filter(img, sg, order=(0, 2))
        dyy = ndimage.gaussian_filter(img, sg, order=(2, 0))
        dxy = ndimage.gaussian_filter(img, sg, order=(1, 1))
        vals.append(sg**4 * (dxx * dyy - dxy**2)[80, 80])
    assert sigmas[int(np.argmax(vals))] == pytest.approx(4.0, abs=0.21)


def _structured(seed, shape=(161, 201)):
    """Smoothed random rectangles: corners and edges give well-defined orientations."""
    rng = np.random.default_rng(seed)
    img = np.full(shape, 0.4)
    for _ in range(40):
        r, c = rng.integers(0, shape[0] - 10), rng.integers(0, shape[1] - 10)
        img[r:r + rng.integers(4, 30), c:c + rng.integers(4, 30)] = rng.random()
    return ndimage.gaussian_filter(img, 1.0)


@pytest.mark.parametrize("seed", [0, 1])
def test_rotation_by_90_degrees_rotates_orientations(seed):
    """Same keypoints, orientations shifted by -90° (v down) for most; the Haar boxes are one pixel
    asymmetric (right box starts at the centre column) so the rotation is not bit-exact."""
    img = _structured(seed)
    f = surf_detect(img, 2e-4)
    rot = np.ascontiguousarray(np.rot90(img))  # new[i, j] = old[j, W-1-i]
    g = surf_detect(rot, 2e-4)
    W = img.shape[1]
    mapped = np.column_stack([f.uv[:, 1], W - 1 - f.uv[:, 0]])
    d, i = cKDTree(g.uv).query(mapped)
    ok = (d < 0.5) & (np.abs(np.log(g.scale_px[i] / f.scale_px)) < 0.05)
    assert ok.sum() > 0.9 * len(f)
    diff = (g.orientation_rad[i[ok]] - (f.orientation_rad[ok] - np.pi / 2) + np.pi) % (2 * np.pi) - np.pi
    assert np.mean(np.abs(diff) < np.radians(6)) > 0.7
    desc_d = np.linalg.norm(g.descriptors[i[ok]] - f.descriptors[ok], axis=1)
    assert np.median(desc_d) < 0.2  # rotated descriptors stay close (random pairs: ~0.8)


def test_descriptors_unit_norm_and_extended_and_upright():
    img = _textured(1)
    f = surf_detect(img, 2e-4)
    assert f.descriptors.shape == (len(f), 64)
    assert f.descriptors.dtype == np.float32
    np.testing.assert_allclose(np.linalg.norm(f.descriptors, axis=1), 1.0, atol=1e-5)
    e = surf_detect(img, 2e-4, extended=True)
    assert e.descriptors.shape == (len(f), 128)
    np.testing.assert_allclose(np.linalg.norm(e.descriptors, axis=1), 1.0, atol=1e-5)
    # the extended sums split the plain ones: Σdx = Σdx|dy<0 + Σdx|dy>=0 (before normalisation, up to scale)
    plain = f.descriptors.reshape(-1, 16, 4)
    ext = e.descriptors.reshape(-1, 16, 8)
    sum_dx = ext[:, :, 0] + ext[:, :, 2]
    scale = np.linalg.norm(plain[:, :, 0], axis=1) / np.maximum(np.linalg.norm(sum_dx, axis=1), 1e-12)
    np.testing.assert_allclose(sum_dx * scale[:, None], plain[:, :, 0], atol=1e-5)
    u = surf_detect(img, 2e-4, upright=True)
    assert np.all(u.orientation_rad == 0)
    np.testing.assert_allclose(u.uv, f.uv)


def test_threshold_sweep_and_class_agree():
    img = _textured(2)
    counts = threshold_sweep(img, [1e-4, 4e-4, 1e-3])
    assert counts[0] >= counts[1] >= counts[2]
    assert counts[1] == len(SURF(4e-4).detect(img, descriptors=False))


def test_surf_bad_input():
    with pytest.raises(ValueError, match="`image` must be at least 16x16"):
        surf_detect(np.zeros((10, 40)))
    with pytest.raises(ValueError, match="`threshold` must be >= 0"):
        surf_detect(np.zeros((40, 40)), -1.0)
    with pytest.raises(ValueError, match="`n_octaves` must be <= 6"):
        surf_detect(np.zeros((40, 40)), n_octaves=9)
    with pytest.raises(TypeError, match="`init_step` must be an integer"):
        SURF(init_step=1.5)
    with pytest.raises(ValueError, match="`image` must be finite"):
        surf_detect(np.full((40, 40), np.inf))
