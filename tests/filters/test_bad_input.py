"""Bad input raises the documented errors, naming the argument."""

import numpy as np
import pytest

from slamlab.filters import (
    ExtendedKalmanFilter,
    KalmanFilter,
    UnscentedKalmanFilter,
    ekf_predict,
    ekf_update,
    kf_predict,
    kf_update,
    sigma_weights,
    ukf_predict,
    ukf_update,
)

I2 = np.eye(2)


@pytest.mark.parametrize(
    ("call", "exc", "match"),
    [
        (lambda: kf_predict([0, 0], I2, np.eye(3), I2), ValueError, r"`F` must have shape \(2, 2\); got shape \(3, 3\)"),
        (lambda: kf_predict([0, np.nan], I2, I2, I2), ValueError, r"`x` must be finite; got 1 NaN/inf"),
        (lambda: kf_predict([0, 0], [[1, 0], [0, -1]], I2, I2), ValueError,
         r"`P` must be symmetric positive semi-definite; smallest eigenvalue -1\.00e\+00"),
        (lambda: kf_predict([0, 0], [[1, 0.5], [0, 1]], I2, I2), ValueError, r"`P` must be symmetric"),
        (lambda: kf_predict([0, 0], I2, I2, I2, B=np.ones((2, 1))), ValueError, r"`B` and `u` must be given together"),
        (lambda: kf_predict(["a", "b"], I2, I2, I2), TypeError, r"`x` must be a numeric array; got dtype <U1"),
        (lambda: kf_update([0, 0], I2, [1, 2, 3], [[1, 0]], [[1]]), ValueError, r"`z` must have length 1"),
        (lambda: kf_update([0, 0], I2, [1], [[1, 0]], [[-1]]), ValueError, r"`R` must be symmetric positive"),
        (lambda: kf_update([0, 0], I2, [1], [[1, 0]], [[1]], form="long"), ValueError,
         r"`form` must be one of 'short', 'joseph'; got 'long'"),
        (lambda: ekf_predict([0, 0], I2, "f", lambda x, u: I2, I2), TypeError, r"`f` must be callable; got str"),
        (lambda: ekf_predict([0, 0], I2, lambda x, u: x, lambda x, u: np.eye(3), I2), ValueError,
         r"`F_jac\(x, u\)` must have shape \(2, 2\)"),
        (lambda: ekf_update([0, 0], I2, [1], lambda x: x[:1], lambda x: np.ones((1, 2)), [[np.inf]]), ValueError,
         r"`R` must be finite"),
        (lambda: ukf_predict([0, 0], I2, lambda x, u, w: x, I2, alpha=-1), ValueError, r"`alpha` must be > 0"),
        (lambda: ukf_predict([0, 0], I2, lambda x, u: x, np.eye(3), form="additive"), ValueError,
         r"`Q` must have shape \(2, 2\)"),
        (lambda: ukf_update([0, 0], I2, [1], lambda x, v: x[:1], I2, form="sideways"), ValueError,
         r"`form` must be one of 'augmented', 'additive'"),
        (lambda: sigma_weights(2, alpha=1.0, kappa=-3.0), ValueError, r"`kappa` must give L \+ lambda > 0"),
        (lambda: sigma_weights(0), ValueError, r"`L` must be >= 1"),
        (lambda: KalmanFilter([0, 0], I2, I2, I2, [[1, 0]], [[1]]).update([np.nan]), ValueError, r"`z` must be finite"),
        (lambda: KalmanFilter([0, 0], I2, I2, I2, [[1, 0]], [[1]]).predict(u=[1.0]), ValueError,
         r"`u` was given but the filter has no control matrix `B`"),
        (lambda: ExtendedKalmanFilter([0, 0], I2, None, None, I2, None, None, [[1]]), TypeError,
         r"`f` must be callable"),
        (lambda: UnscentedKalmanFilter([0, 0], [[1, 2], [2, 1]], lambda x, u, w: x, I2, lambda x, v: x, I2),
         ValueError, r"`P` must be symmetric positive semi-definite"),
    ],
)
def test_bad_input(call, exc, match):
    with pytest.raises(exc, match=match):
        call()
