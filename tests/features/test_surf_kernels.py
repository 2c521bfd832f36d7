"""SURF's compiled kernels (issue 45, speed) give the numpy path's numbers bit for bit.

The reference is the numpy path (``SLAMLAB_NO_NUMBA=1``), code the kernels do not share, and for the response
maps also :func:`hessian_response` on strided views. Compared: keypoints (positions, scales, responses,
octaves, orientations) and descriptors of whole detections, float32 and float64 images, every setting that
takes another branch (64-d / 128-d, upright, octaves past the padding, 1 or 2 workers), images with flat
areas (ties in the orientation windows and in the non-maximum suppression), keypoints near and past the image
edges (the clipped paths stay in numpy), plus each kernel on its own. A negative control shows the comparison
sees a one-ulp change.
"""

import numpy as np
import pytest

from slamlab._compiled import loaded_kernels, numba_enabled
from slamlab.features import filter_sizes, hessian_response, surf_describe, surf_detect, surf_orientation
from slamlab.features._padded_ii import PaddedIntegralImage
from slamlab.features.surf_response import _interior_maxima, _response_stacks

pytestmark = pytest.mark.skipif(not numba_enabled(), reason="numba not importable (or SLAMLAB_NO_NUMBA set)")

_FIELDS = ("uv", "scale_px", "orientation_rad", "response", "octave", "descriptors")


def _both(monkeypatch, fn, *args, **kwargs):
    """``fn(*args, **kwargs)`` on the numpy path (SLAMLAB_NO_NUMBA=1), then on the compiled one."""
    monkeypatch.setenv("SLAMLAB_NO_NUMBA", "1")
    ref = fn(*args, **kwargs)
    monkeypatch.delenv("SLAMLAB_NO_NUMBA")
    return ref, fn(*args, **kwargs)


def _assert_same_features(a, b):
    assert len(a) == len(b)
    for f in _FIELDS:
        x, y = getattr(a, f), getattr(b, f)
        if x is None:
            assert y is None
            continue
        assert x.dtype == y.dtype, f
        assert x.shape == y.shape, f
        np.testing.assert_array_equal(x, y, err_msg=f)
        np.testing.assert_array_equal(np.signbit(x), np.signbit(y), err_msg=f)  # -0.0 and 0.0 too


def _scene(rng, shape):
    """Blobs and edges on a noisy background with a flat band (ties) and a saturated corner."""
    H, W = shape
    yy, xx = np.mgrid[0:H, 0:W]
    img = 0.3 + 0.05 * rng.standard_normal(shape)
    for _ in range(25):
        u, v, s = rng.uniform(0, W), rng.uniform(0, H), rng.uniform(1.5, 12.0)
        img += rng.uniform(-0.4, 0.4) * np.exp(-((xx - u) ** 2 + (yy - v) ** 2) / (2 * s * s))
    img[H // 3:H // 3 + 15] = 0.5  # flat band: equal responses
    img[: H // 5, : W // 5] = 1.0
    return np.clip(img, 0.0, 1.0)


@pytest.mark.parametrize("dtype", [np.float64, np.float32])
@pytest.mark.parametrize(("shape", "kw", "threshold"), [
    ((160, 224), {}, 2e-4),
    ((160, 224), {"extended": True}, 2e-4),
    ((160, 224), {"upright": True}, 1e-4),
    ((143, 201), {"n_octaves": 5, "init_step": 1}, 1e-4),
    ((150, 190), {"n_octaves": 6, "init_step": 3, "workers": 1}, 0.0),
    ((97, 131), {"workers": 1}, 5e-5),
])
def test_detect_same_as_numpy_path(monkeypatch, dtype, shape, kw, threshold):
    img = _scene(np.random.default_rng(7), shape).astype(dtype)
    ref, new = _both(monkeypatch, surf_detect, img, threshold, **kw)
    assert len(ref) > 10  # enough keypoints to compare (the flat band's and edges' too)
    _assert_same_features(ref, new)


def test_kernels_were_used(monkeypatch):
    """The comparisons above compare two paths: after a compiled detection every SURF kernel has run."""
    monkeypatch.delenv("SLAMLAB_NO_NUMBA", raising=False)
    surf_detect(_scene(np.random.default_rng(1), (120, 160)), 1e-4)
    names = {n.rsplit(".", 1)[-1] for n in loaded_kernels() if ".features._surf_kernels." in n}
    assert names == {"integral_body", "hessian_det", "interior_maxima", "haar_samples", "orientation_best",
                     "describe_sums"}


@pytest.mark.parametrize("shape", [(1, 1), (1, 7), (9, 1), (57, 83)])
def test_integral_image_kernel(monkeypatch, shape):
    """The padded integral image (inside and padding) equals numpy's two cumulative sums, bit for bit."""
    img = np.random.default_rng(4).random(shape)
    img[0, 0] = -0.0  # a signed zero stays signed, as in np.cumsum
    ref, new = _both(monkeypatch, PaddedIntegralImage, image=img)
    np.testing.assert_array_equal(ref.E, new.E)
    np.testing.assert_array_equal(np.signbit(ref.E), np.signbit(new.E))
    II = np.zeros((shape[0] + 1, shape[1] + 1))
    II[1:, 1:] = np.cumsum(np.cumsum(img, axis=0), axis=1)
    np.testing.assert_array_equal(new.II, II)


@pytest.mark.parametrize(("shape", "init_step", "n_octaves"), [((96, 128), 2, 4), ((101, 67), 1, 5),
                                                               ((90, 120), 3, 6)])
def test_response_kernel_equals_hessian_response(monkeypatch, shape, init_step, n_octaves):
    """Every map of every octave (computed or shared) equals :func:`hessian_response`, bit for bit."""
    monkeypatch.delenv("SLAMLAB_NO_NUMBA", raising=False)
    rng = np.random.default_rng(3)
    P = PaddedIntegralImage(image=rng.random(shape))
    L = filter_sizes(n_octaves)
    for o, (D, step) in enumerate(_response_stacks(P.II, n_octaves, init_step, workers=2, padded=P)):
        for i in range(4):
            np.testing.assert_array_equal(D[i], hessian_response(P.II, int(L[o, i]), step)[0])


@pytest.mark.parametrize("threshold", [0.0, 1e-3])
def test_maxima_kernel_same_set_and_order(monkeypatch, threshold):
    """Plateaus (equal neighbours are kept), NaN-free ties, threshold at 0: the same indices in the same order."""
    rng = np.random.default_rng(5)
    D = np.round(rng.random((4, 40, 50)), 1) * 1e-3  # coarse values: many equal neighbours
    D[:, 10:14, 20:25] = 2e-3  # a plateau
    ref, new = _both(monkeypatch, _interior_maxima, D, threshold)
    assert ref[0].size > 20
    for a, b in zip(ref, new, strict=True):
        assert a.dtype == b.dtype
        np.testing.assert_array_equal(a, b)


def test_orientation_and_descriptor_kernels_with_edges(monkeypatch):
    """Keypoints over the image, near and past its edges (those take the clipped numpy path), scales 1-30 px,
    and the same 2-pixel scale for many (one chunk of many keypoints), windows of several widths."""
    rng = np.random.default_rng(11)
    img = _scene(rng, (120, 170))
    P = PaddedIntegralImage(image=img)
    n = 300
    uv = np.column_stack([rng.uniform(-5, 175, n), rng.uniform(-5, 125, n)])
    sigma = np.where(rng.random(n) < 0.5, 2.0, rng.uniform(1.0, 30.0, n))
    for window, step in ((np.pi / 3, 0.15), (1.0, 0.2), (np.pi / 2, 0.1)):
        ref, new = _both(monkeypatch, surf_orientation, P.II, uv, sigma, window_rad=window, step_rad=step,
                         _padded=P)
        np.testing.assert_array_equal(ref, new)
    ori = new
    for extended in (False, True):
        ref, new = _both(monkeypatch, surf_describe, P.II, uv, sigma, ori, extended=extended, _padded=P)
        np.testing.assert_array_equal(ref, new)


def test_flat_patch_orientation_ties(monkeypatch):
    """A flat image: every sample's response is 0, every window ties; the first window wins on both paths."""
    img = np.full((80, 90), 0.25)
    P = PaddedIntegralImage(image=img)
    uv = np.array([[40.0, 40.0], [10.0, 70.0], [85.0, 5.0]])
    ref, new = _both(monkeypatch, surf_orientation, P.II, uv, np.array([2.0, 3.0, 1.2]), _padded=P)
    np.testing.assert_array_equal(ref, new)


def test_comparison_sees_one_ulp(monkeypatch):
    """Negative control: the equality the tests use fails for a descriptor moved by one ulp."""
    img = _scene(np.random.default_rng(2), (100, 140))
    ref, new = _both(monkeypatch, surf_detect, img, 1e-4)
    bumped = new.descriptors.copy()
    bumped[0, 0] = np.nextafter(bumped[0, 0], np.float32(2))
    with pytest.raises(AssertionError):
        np.testing.assert_array_equal(ref.descriptors, bumped)


@pytest.mark.realdata
def test_graf_same_as_numpy_path(monkeypatch, real_data):
    """graf img1 (full size and the benchmark's 768x576), 64-d and 128-d."""
    import cv2

    from slamlab.features import load_oxford_image

    full = load_oxford_image("graf", 1)
    for img in (full, cv2.resize(full, (768, 576), interpolation=cv2.INTER_AREA)):
        for kw in ({}, {"extended": True}):
            ref, new = _both(monkeypatch, surf_detect, img, 4e-4, **kw)
            assert len(ref) > 500
            _assert_same_features(ref, new)
