"""FAST equals OpenCV's FastFeatureDetector; the n=12 high-speed test loses nothing; Moravec basics."""

import cv2
import numpy as np
import pytest

from slamlab.features import fast_corner_mask, fast_cv, fast_detect, moravec_detect, moravec_response


def _cv_fast(img, t, nonmax):
    det = cv2.FastFeatureDetector_create(t, nonmax, cv2.FAST_FEATURE_DETECTOR_TYPE_9_16)
    return sorted((int(k.pt[0]), int(k.pt[1]), float(k.response)) for k in det.detect(img))


def _ours(img, t, nonmax):
    f = fast_detect(img, t, nonmax=nonmax)
    resp = f.response if nonmax else np.zeros(len(f))  # OpenCV reports score 0 without NMS
    return sorted((int(u), int(v), float(r)) for (u, v), r in zip(f.uv, resp, strict=True))


def _synthetic(seed):
    rng = np.random.default_rng(seed)
    img = np.full((120, 160), 100, np.uint8)
    for _ in range(25):  # rectangles, triangles-ish blocks and noise
        r, c = rng.integers(0, 110), rng.integers(0, 150)
        img[r:r + rng.integers(3, 30), c:c + rng.integers(3, 30)] = rng.integers(0, 256)
    noise = rng.integers(-6, 7, img.shape)
    return np.clip(img.astype(int) + noise, 0, 255).astype(np.uint8)


@pytest.mark.parametrize("seed", [0, 1, 2])
@pytest.mark.parametrize("t", [5, 20, 60])
@pytest.mark.parametrize("nonmax", [True, False])
def test_fast_equals_opencv_synthetic(seed, t, nonmax):
    img = _synthetic(seed)
    assert _ours(img, t, nonmax) == _cv_fast(img, t, nonmax)


@pytest.mark.realdata
@pytest.mark.parametrize(("seq", "t"), [("graf", 20), ("boat", 10), ("bark", 25)])
@pytest.mark.parametrize("nonmax", [True, False])
def test_fast_equals_opencv_real(real_data, seq, t, nonmax):
    img = cv2.imread(str(real_data / "oxford-affine" / seq / "img1.png"), cv2.IMREAD_GRAYSCALE)[:320, :400]
    ref = _cv_fast(img, t, nonmax)
    assert len(ref) > 50
    assert _ours(img, t, nonmax) == ref


def test_fast_cv_wrapper_matches():
    img = _synthetic(3)
    a, b = fast_detect(img, 20), fast_cv(img, threshold=20)
    np.testing.assert_array_equal(np.lexsort(a.uv.T), np.lexsort(b.uv.T))
    assert sorted(map(tuple, a.uv.tolist())) == sorted(map(tuple, b.uv.tolist()))


def test_high_speed_test_is_exact_for_n12_and_n12_subset_of_n9():
    img = _synthetic(4)
    full = fast_corner_mask(img, 15, 12, high_speed=False)
    fast = fast_corner_mask(img, 15, 12, high_speed=True)
    np.testing.assert_array_equal(full, fast)
    n9 = fast_corner_mask(img, 15, 9)
    assert full.sum() > 0
    assert np.all(n9[full])
    assert n9.sum() > full.sum()


def test_single_bright_and_dark_pixel_and_ramp():
    img = np.full((15, 15), 100, np.uint8)
    img[7, 7] = 200
    img[2, 11] = 0
    f = fast_detect(img, 20)
    assert sorted(f.uv.tolist()) == [[7.0, 7.0]]  # (11, 2) lies in the 3-pixel border
    ramp = np.tile(np.arange(0, 150, 10, dtype=np.uint8), (15, 1))
    assert len(fast_detect(ramp, 5)) == 0  # an edge is not a corner


def test_fast_bad_input():
    with pytest.raises(ValueError, match=r"`high_speed` .* valid only for n >= 12"):
        fast_corner_mask(np.zeros((10, 10), np.uint8), 10, 9, high_speed=True)
    with pytest.raises(ValueError, match="`n` must be <= 12"):
        fast_detect(np.zeros((10, 10), np.uint8), 10, n=13)
    with pytest.raises(ValueError, match="`threshold` must be <= 255"):
        fast_detect(np.zeros((10, 10), np.uint8), 300)
    with pytest.raises(ValueError, match="`image` must not be empty"):
        fast_detect(np.zeros((0, 10), np.uint8))
    with pytest.raises(ValueError, match=r"`image` must have shape \(H, W\) or \(H, W, 3\)"):
        fast_detect(np.zeros(10, np.uint8))
    with pytest.raises(TypeError, match="`image` must be a numeric image array"):
        fast_detect(np.array([["a"]]))


def test_moravec_corner_not_edge():
    img = np.zeros((40, 40))
    img[20:, 20:] = 1.0  # one corner at (20, 20); edges along row 20 and column 20
    R = moravec_response(img, 3)
    r, c = np.unravel_index(np.argmax(R), R.shape)
    assert abs(r - 20) <= 1
    assert abs(c - 20) <= 1
    assert R[30, 20] == pytest.approx(0.0)  # on the vertical edge a vertical shift changes nothing
    f = moravec_detect(img, 0.5)
    assert len(f) >= 1
    assert np.all(np.abs(f.uv - 20) <= 1.5)


def test_moravec_matches_direct_sum():
    rng = np.random.default_rng(0)
    img = rng.random((20, 20))
    R = moravec_response(img, 3)
    y, x = 9, 11
    best = np.inf
    for du, dv in [(1, 0), (-1, 0), (0, 1), (0, -1), (1, 1), (-1, -1), (1, -1), (-1, 1)]:
        e = sum((img[y + j + dv, x + i + du] - img[y + j, x + i]) ** 2 for i in (-1, 0, 1) for j in (-1, 0, 1))
        best = min(best, e)
    assert R[y, x] == pytest.approx(best, rel=1e-12)


def test_moravec_bad_input():
    with pytest.raises(ValueError, match="`window` must be odd"):
        moravec_response(np.zeros((10, 10)), 4)
    with pytest.raises(ValueError, match="`threshold` must be > 0"):
        moravec_detect(np.zeros((10, 10)), 0.0)
    with pytest.raises(ValueError, match="`image` must be finite"):
        moravec_detect(np.full((10, 10), np.nan))
