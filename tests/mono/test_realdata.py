"""The monocular pipeline on the left camera of the shared KITTI 06 snippet (20 frames, real data)."""

from __future__ import annotations

import numpy as np
import pytest

from slamlab.mono.experiments import run_kitti_mono


@pytest.mark.realdata
def test_kitti_left_camera(shared_data):
    r = run_kitti_mono(shared_data / "kitti-odometry-06-stereo")
    first = int(np.argmax(r.tracked))
    assert r.tracked.any()
    assert first <= 2  # initialised by frame 2 (the car moves > 15 px per frame)
    assert r.tracked.sum() >= 4
    assert r.ate_m < 0.5  # metres, Sim(3) alignment over the tracked frames
    assert np.all(np.isfinite(r.estimate))
