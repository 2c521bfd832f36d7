"""One interface for every detector; Features validation; plots and widgets run without errors."""

import matplotlib

matplotlib.use("Agg")

import matplotlib.pyplot as plt
import numpy as np
import pytest
from scipy import ndimage

import slamlab.features as F
import slamlab.studies.features as SF
from slamlab.kdtree import KDTree, bbf_trace, plot_kdtree_2d


def _image():
    rng = np.random.default_rng(0)
    img = np.full((120, 160), 90.0)
    for _ in range(30):
        r, c = rng.integers(0, 110), rng.integers(0, 150)
        img[r:r + rng.integers(4, 25), c:c + rng.integers(4, 25)] = rng.integers(0, 256)
    return np.clip(ndimage.gaussian_filter(img, 1.0), 0, 255).astype(np.uint8)


@pytest.mark.parametrize("method", F.DETECTORS)
def test_every_detector_returns_features(method):
    f = F.detect(_image(), method)
    assert isinstance(f, F.Features)
    assert f.uv.shape == (len(f), 2)
    assert np.all((f.uv >= 0) & (f.uv < [160, 120]))
    assert np.all((f.orientation_rad >= 0) & (f.orientation_rad < 2 * np.pi))
    if f.descriptors is not None:
        assert len(f.descriptors) == len(f)
    g = F.detect(_image(), method, max_points=5)
    assert len(g) <= 5


@pytest.mark.parametrize("method", ["orb", "sift"])
def test_features_from_keypoints_reads_every_keypoint_field(method):
    """The conversion of cv2.KeyPoint lists (000 §1.4.1) against the fields read one keypoint at a time: position,
    size / 2, angle in radians in [0, 2π) (-1: 0), response, octave (SIFT's packed byte unpacked)."""
    import cv2

    det = cv2.ORB_create(500, fastThreshold=5) if method == "orb" else cv2.SIFT_create()
    kp, d = det.detectAndCompute(_image(), None)
    kp = [*kp, cv2.KeyPoint(3.25, 4.5, 7.0, -1.0, 0.5, 2)]  # an angle of -1: none
    f = F.features_from_keypoints(kp, np.vstack([d, d[:1]]), method.upper())
    assert len(kp) > 20
    np.testing.assert_array_equal(f.uv, [k.pt for k in kp])
    np.testing.assert_array_equal(f.scale_px, [k.size / 2 for k in kp])
    np.testing.assert_array_equal(f.response, [k.response for k in kp])
    ang = np.array([k.angle for k in kp])
    np.testing.assert_allclose(f.orientation_rad, np.where(ang < 0, 0.0, np.deg2rad(ang) % (2 * np.pi)), rtol=0, atol=0)
    octave = [k.octave for k in kp]
    if method == "sift":
        octave = [(o & 255) - 256 if (o & 255) >= 128 else o & 255 for o in octave]
    assert f.octave.tolist() == octave
    assert f.octave.dtype == np.int64
    assert f.uv.dtype == np.float64


def test_colour_and_float_images_are_accepted():
    img = _image()
    rgb = np.repeat(img[:, :, None], 3, axis=2)
    a = F.detect(img, "surf", descriptors=False)
    b = F.detect(rgb, "surf", descriptors=False)
    c = F.detect(img / 255.0, "surf", descriptors=False)
    np.testing.assert_allclose(a.uv, c.uv)
    # a grey image repeated in three channels is the same grey image (BT.601 weights sum to 1)
    np.testing.assert_allclose(F.to_gray_float(rgb), F.to_gray_float(img), atol=1e-15)
    assert len(b) == len(a)  # the same points, to the rounding of the weighted sum
    np.testing.assert_allclose(b.uv, a.uv, rtol=1e-12)
    np.testing.assert_allclose(b.response, a.response, rtol=1e-9)


def test_features_validation_and_helpers():
    z = np.zeros(2)
    with pytest.raises(ValueError, match="`scale_px` must have 2 entries"):
        F.Features(np.zeros((2, 2)), np.zeros(3), z, z, z.astype(int))
    with pytest.raises(ValueError, match="`descriptors` must have 2 rows"):
        F.Features(np.zeros((2, 2)), z, z, z, z.astype(int), np.zeros((3, 64)))
    f = F.Features(np.array([[1.0, 2], [3, 4]]), z, z, np.array([1.0, 5.0]), z.astype(int), None, "x")
    assert f.strongest(1).uv.tolist() == [[3.0, 4.0]]
    assert len(F.Features.empty("x", 64)) == 0
    with pytest.raises(ValueError, match="`method` must be one of"):
        F.detect(_image(), "akaze")
    with pytest.raises(TypeError, match=r"`features` must be slamlab\.features\.Features"):
        F.describe_surf(_image(), np.zeros((3, 2)))
    with pytest.raises(TypeError, match=r"`f1` must be slamlab\.features\.Features"):
        F.repeatability(np.zeros((3, 2)), f, np.eye(3), (10, 10), (10, 10))
    with pytest.raises(ValueError, match=r"`H` must have shape \(3, 3\)"):
        F.project(np.eye(2), [[0.0, 0.0]])


def test_plots_run():
    img = _image()
    f = F.detect(img, "surf")
    g = F.detect(np.ascontiguousarray(img[:, ::-1]), "surf")
    m = F.match_descriptors(f.descriptors, g.descriptors, rule="ratio")
    F.plot_keypoints(img, f)
    fig = F.plot_detector_gallery(img, F.DETECTOR_GALLERY[:2] + F.DETECTOR_GALLERY[3:5])
    visible = [ax for ax in fig.axes if ax.get_visible()]
    assert [ax.get_title().split(":")[0] for ax in visible] == ["SURF (ours)", "SIFT (OpenCV)", "FAST-9 (ours)", "Moravec (ours)"]
    assert len(fig.axes) == 6  # a 2x3 grid, two panels hidden
    F.plot_matches(img, img[:, ::-1], f, g, m, np.ones(len(m), bool))
    F.plot_box_filters(15)
    F.plot_fast_circle(img, 60, 80)
    rng = np.random.default_rng(0)
    tree = KDTree(rng.random((30, 2)))
    _, _, ev = bbf_trace(tree, [0.5, 0.5], max_leaves=5)
    plot_kdtree_2d(tree, query=[0.5, 0.5], events=ev)
    with pytest.raises(ValueError, match="`tree` must hold 2-D points"):
        plot_kdtree_2d(KDTree(rng.random((5, 3))))
    plt.close("all")


@pytest.mark.realdata
def test_widgets_never_raise(real_data, capsys):
    # interactive() swallows exceptions of its callback, so call the callback itself
    w = SF.explore_detectors()
    for det in ("SURF (ours)", "FAST-9 (ours)", "MSER (OpenCV)"):
        for frac in (0.0, 1.0):
            w.f(**{**w.kwargs, "detector": det, "threshold_fraction": frac, "draw": False})
            out = capsys.readouterr().out
            assert out.strip(), "the widget printed nothing"
            assert "Traceback" not in out
    m = SF.explore_matching()
    for leaves, ratio in ((200, 0.3), (0, 1.0), (10, 0.6)):
        m.f(**{**m.kwargs, "max_leaves": leaves, "ratio": ratio, "draw": False})
        out = capsys.readouterr().out
        assert out.strip(), "the widget printed nothing"
    plt.close("all")
    # drawing: one figure each, made by the plot module (two keypoint panels; one match panel)
    w.f(**{**w.kwargs, "draw": True})
    assert [len(plt.figure(n).axes) for n in plt.get_fignums()] == [2]
    plt.close("all")
    m.f(**{**m.kwargs, "draw": True})
    assert [len(plt.figure(n).axes) for n in plt.get_fignums()] == [1]
    plt.close("all")
