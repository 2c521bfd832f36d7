"""The one homography mapping against the homogeneous product and OpenCV."""

import cv2
import numpy as np
import pytest

from slamlab.features import project
from slamlab.geometry import apply_homography


def _H():
    return np.array([[1.1, 0.05, 12.0], [-0.03, 0.95, -7.0], [2e-4, -1e-4, 1.0]])


def test_matches_the_homogeneous_product_and_cv2():
    rng = np.random.default_rng(0)
    uv = rng.uniform(0, 640, (50, 2))
    h = np.c_[uv, np.ones(50)] @ _H().T  # independent reference: H [u, v, 1], then divide
    np.testing.assert_allclose(apply_homography(_H(), uv), h[:, :2] / h[:, 2:], rtol=1e-13)
    ref = cv2.perspectiveTransform(uv[None], _H())[0]
    np.testing.assert_allclose(apply_homography(_H(), uv), ref, rtol=1e-12)


def test_scale_of_h_does_not_matter_and_one_point_is_accepted():
    uv = np.array([3.0, 4.0])
    np.testing.assert_allclose(apply_homography(5.0 * _H(), uv), apply_homography(_H(), uv[None]), rtol=1e-15)
    assert apply_homography(_H(), uv).shape == (1, 2)


def test_features_project_is_this_function():
    assert project is apply_homography


def test_bad_input():
    with pytest.raises(ValueError, match=r"`H` must have shape \(3, 3\)"):
        apply_homography(np.eye(2), [[0.0, 0.0]])
    with pytest.raises(ValueError, match=r"`uv` must have shape \(N, 2\) or \(2,\); got \(2, 3\)"):
        apply_homography(np.eye(3), np.zeros((2, 3)))
    with pytest.raises(ValueError, match="`uv` must be finite"):
        apply_homography(np.eye(3), [[np.nan, 0.0]])
