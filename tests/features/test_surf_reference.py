"""SURF unchanged by the speed work (issue 17): keypoints and descriptors against stored reference values.

``data/surf_reference.npz`` was written by the SURF of main at the commit stored in its ``commit``
entry, *before* the issue-17 speed changes, on (a) a synthetic 288×384 image (:func:`_synthetic`, the same function here,
threshold 1e-3; 64-d, extended 128-d and upright) and (b) OpenCV-resized graf img1 at 768×576
(threshold 4e-4, the benchmark's image). It is an independent reference for "unchanged": positions,
scales, orientations, responses and descriptors must agree to 1e-6, and the keypoint sets exactly.
"""

from pathlib import Path

import numpy as np
import pytest
from scipy import ndimage

from slamlab.features import surf_detect

REF = Path(__file__).parent / "data" / "surf_reference.npz"


def _synthetic(seed=7, shape=(288, 384)):
    """Smoothed noise plus 15 light and dark Gaussian blobs of 2-25 px, in [0, 1]."""
    rng = np.random.default_rng(seed)
    img = ndimage.gaussian_filter(rng.random(shape), 3.0)
    img = (img - img.min()) / (img.max() - img.min())
    yy, xx = np.mgrid[0:shape[0], 0:shape[1]]
    for _ in range(15):
        cy, cx, s = rng.uniform(0, shape[0]), rng.uniform(0, shape[1]), rng.uniform(2, 25)
        img += rng.choice([-0.5, 0.5]) * np.exp(-((xx - cx) ** 2 + (yy - cy) ** 2) / (2 * s * s))
    return np.clip(img, 0, 1)


def _check(f, ref, name):
    assert f.uv.shape == ref[f"{name}_uv"].shape
    np.testing.assert_array_equal(f.octave, ref[f"{name}_octave"])
    np.testing.assert_allclose(f.uv, ref[f"{name}_uv"], rtol=0, atol=1e-6)
    np.testing.assert_allclose(f.scale_px, ref[f"{name}_scale"], rtol=0, atol=1e-6)
    np.testing.assert_allclose(f.response, ref[f"{name}_resp"], rtol=1e-6, atol=1e-12)
    # orientations on the circle
    d_ori = np.angle(np.exp(1j * (f.orientation_rad - ref[f"{name}_ori"])))
    np.testing.assert_allclose(d_ori, 0.0, atol=1e-6)
    np.testing.assert_allclose(f.descriptors, ref[f"{name}_desc"], rtol=0, atol=1e-6)


@pytest.mark.parametrize(("name", "kw"), [("syn", {}), ("syn_ext", {"extended": True}),
                                          ("syn_up", {"upright": True})])
def test_surf_matches_stored_reference_on_synthetic_image(name, kw):
    ref = np.load(REF)
    _check(surf_detect(_synthetic(), 1e-3, **kw), ref, name)


@pytest.mark.realdata
def test_surf_matches_stored_reference_on_graf_768x576():
    import cv2

    from slamlab.features import load_oxford_image

    ref = np.load(REF)
    img = cv2.resize(load_oxford_image("graf", 1), (768, 576), interpolation=cv2.INTER_AREA)
    _check(surf_detect(img, 4e-4), ref, "graf")


@pytest.mark.parametrize("workers", [1, 3])
def test_surf_result_does_not_depend_on_threads_or_chunks(workers):
    img = _synthetic()
    ref = surf_detect(img, 1e-3, workers=2)
    f = surf_detect(img, 1e-3, workers=workers)
    np.testing.assert_array_equal(f.uv, ref.uv)
    np.testing.assert_array_equal(f.descriptors, ref.descriptors)
    from slamlab.features import integral_image, surf_describe, surf_orientation

    II = integral_image(img)
    ori = surf_orientation(II, ref.uv, ref.scale_px, chunk=7, workers=workers)
    np.testing.assert_array_equal(ori, ref.orientation_rad)
    desc = surf_describe(II, ref.uv, ref.scale_px, ori, chunk=1000, workers=workers)
    np.testing.assert_allclose(desc, ref.descriptors, rtol=0, atol=1e-7)


def test_surf_workers_and_chunk_are_checked():
    with pytest.raises(ValueError, match="workers"):
        surf_detect(_synthetic(), 1e-3, workers=0)
    from slamlab.features import integral_image, surf_describe

    with pytest.raises(ValueError, match="chunk"):
        surf_describe(integral_image(_synthetic()), np.zeros((1, 2)) + 50, [2.0], [0.0], chunk=0)
