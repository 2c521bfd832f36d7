"""Scoring a monocular run (ours): correctly tracked frames, ATE over all frames, scale drift."""

from __future__ import annotations

import numpy as np
import pytest

from slamlab.geometry.camera import rotation_xyz
from slamlab.mono.evaluate import score_run


def _poses(xyz):
    T = np.tile(np.eye(4), (len(xyz), 1, 1))
    T[:, :3, 3] = xyz
    return T


def _truth(n=30):
    k = np.arange(n)
    return _poses(np.column_stack([0.1 * k, 0.02 * np.sin(k / 3), 0.05 * k]))


def _similar(T, c=0.25, R=None, t=(1.0, -2.0, 0.5)):
    R = rotation_xyz(0.1, -0.2, 0.3) if R is None else R
    out = T.copy()
    out[:, :3, 3] = c * T[:, :3, 3] @ R.T + t
    return out


def test_a_similar_copy_is_correct_everywhere_with_zero_ate():
    truth = _truth()
    est = _similar(truth)
    s = score_run(truth, est, np.ones(len(truth), bool))
    assert s.correct.all()
    assert s.ate_all_m < 1e-9
    assert s.ate_claimed_m < 1e-9
    np.testing.assert_allclose([s.scale_first, s.scale_last], [4.0, 4.0], rtol=1e-9)  # metres per map unit
    assert s.scale_drift == pytest.approx(1.0)
    assert s.tol_m == pytest.approx(0.05 * s.path_m)


def test_a_frame_off_by_more_than_the_tolerance_is_not_correct_and_counts_in_the_ate():
    truth = _truth()
    est = truth.copy()
    est[20, :3, 3] += [0.0, 0.5, 0.0]  # 0.5 m off, the path is ~3.4 m: tolerance 0.17 m
    claimed = np.ones(len(truth), bool)
    claimed[:3] = False  # initialising: reported at the first pose
    est[:3, :3, 3] = truth[3, :3, 3]
    s = score_run(truth, est, claimed)
    assert not s.correct[20]
    assert not s.correct[:3].any()
    assert s.correct[3:20].all()
    assert s.correct[21:].all()
    assert s.ate_all_m > s.ate_claimed_m > 0  # the initialising frames count in the all-frames ATE only


def test_scale_drift_is_the_ratio_of_the_thirds():
    truth = _truth(30)
    est = truth.copy()
    est[:, :3, 3] = truth[:, :3, 3] * np.where(np.arange(30) < 15, 1.0, 0.5)[:, None]
    est[15:, :3, 3] += truth[15, :3, 3] * 0.5  # continuous path at half the scale
    s = score_run(truth, est, np.ones(30, bool))
    assert s.scale_first == pytest.approx(1.0, rel=1e-6)
    assert s.scale_last == pytest.approx(2.0, rel=1e-6)
    assert s.scale_drift == pytest.approx(2.0, rel=1e-6)


def test_too_few_claimed_frames_give_inf_not_nan():
    truth = _truth(10)
    claimed = np.zeros(10, bool)
    claimed[:2] = True
    s = score_run(truth, truth, claimed)
    assert not s.correct.any()
    assert s.ate_all_m == np.inf
    assert s.ate_claimed_m == np.inf
    assert np.isnan(s.scale_drift)


def test_bad_arguments_name_themselves():
    truth = _truth(10)
    with pytest.raises(ValueError, match="`claimed` must have one flag per frame"):
        score_run(truth, truth, np.ones(9, bool))
    with pytest.raises(ValueError, match="`truth` and `estimate` must both have shape"):
        score_run(truth, truth[:9], np.ones(10, bool))
    with pytest.raises(ValueError, match="`tol_frac`"):
        score_run(truth, truth, np.ones(10, bool), tol_frac=0.0)


def test_one_gross_error_does_not_condemn_the_other_frames():
    truth = _truth(20)
    est = _similar(truth)
    est[19, :3, 3] += [5.0, 0.0, 0.0]  # 20 m off after the 4x scale
    claimed = np.ones(20, bool)
    s = score_run(truth, est, claimed)
    assert not s.correct[19]
    assert s.correct[:19].all()
    plain = score_run(truth, est, claimed, refits=0)
    assert plain.correct.sum() < 19  # the plain least-squares fit is pulled by the gross error
    assert plain.ate_all_m == s.ate_all_m  # the ATE uses the plain fit either way
