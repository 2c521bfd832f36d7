"""The SURF stage and the evaluation helpers made public (issue 42): their values are the ones the pipeline and
the studies use, and bad input raises naming the argument."""

import numpy as np
import pytest

import slamlab.features as F
from slamlab.features.surf_response import hessian_maxima


def _blobs():
    yy, xx = np.mgrid[0:120, 0:140]
    return sum(np.exp(-((xx - u) ** 2 + (yy - v) ** 2) / (2 * s**2)) for u, v, s in
               ((40, 50, 3.0), (95, 60, 5.0), (70, 95, 4.0)))


def test_hessian_maxima_are_surf_detects_keypoints():
    img = _blobs()
    m = hessian_maxima(F.integral_image(img), threshold=1e-4, workers=2)
    f = F.surf_detect(img, 1e-4, descriptors=False)
    assert len(f) >= 3
    np.testing.assert_array_equal(np.column_stack([m["u"], m["v"]]), f.uv)
    np.testing.assert_array_equal(m["det"], f.response)
    np.testing.assert_array_equal(1.2 * m["L"] / 9.0, f.scale_px)
    # the threshold sweep counts the same maxima
    assert F.threshold_sweep(img, [1e-4])[0] == int(np.count_nonzero(m["det"] > 1e-4))


def test_hessian_maxima_bad_input():
    II = F.integral_image(_blobs())
    with pytest.raises(ValueError, match="`threshold` must be >= 0"):
        hessian_maxima(II, threshold=-1.0)
    with pytest.raises(ValueError, match="`n_octaves` must be <= 6"):
        hessian_maxima(II, threshold=1e-4, n_octaves=7)
    with pytest.raises(ValueError, match="`init_step` must be >= 1"):
        hessian_maxima(II, threshold=1e-4, init_step=0)
    with pytest.raises(ValueError, match="`II` must be 2-dimensional"):
        hessian_maxima(II[0], threshold=1e-4)


@pytest.mark.realdata
def test_detect_for_evaluation_and_the_matching_workload(real_data):
    from slamlab.studies.features.experiments import EVAL_DETECTORS, detect_for_evaluation
    from slamlab.studies.features.matching_workload import matching_workload, surf_features

    img1, _, _ = F.load_oxford_pair("graf", 2, scale=0.5)
    f, seconds = detect_for_evaluation(img1, "ORB", 200)
    assert len(f) == 200
    assert seconds > 0
    g, _ = detect_for_evaluation(img1, "SURF", 300)
    ref = F.detect(img1, EVAL_DETECTORS["SURF"][0], max_points=300, **EVAL_DETECTORS["SURF"][1])
    np.testing.assert_array_equal(g.uv, ref.uv)
    with pytest.raises(ValueError, match="`name` must be one of"):
        detect_for_evaluation(img1, "BRISK", 10)
    with pytest.raises(ValueError, match="`n_points` must be >= 1"):
        detect_for_evaluation(img1, "SIFT", 0)
    f1, q, train, H = matching_workload(3000, 100)
    assert train.shape == (3000, 64)
    assert len(q) == 100
    assert H.shape == (3, 3)
    np.testing.assert_array_equal(train[:len(f1)], f1.descriptors)  # image 1 first, then the distractors
    assert len(f1) == min(len(surf_features(img1, 5e-5)), 3000)
    with pytest.raises(ValueError, match="`n_queries` must be >= 1"):
        matching_workload(100, 0)
