"""TUM/KITTI round trips, association rules and bad input."""

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from slamlab.evaluation import Trajectory, associate, ate, read_kitti, read_tum, rpe, write_kitti, write_tum


def _traj(n=20, seed=0, t0=0.0, dt=0.1):
    rng = np.random.default_rng(seed)
    R = Rotation.from_rotvec(rng.normal(scale=0.5, size=(n, 3))).as_matrix()
    return Trajectory(np.cumsum(rng.normal(size=(n, 3)), axis=0), R, t0 + dt * np.arange(n))


def test_round_trips(tmp_path):
    t = _traj()
    write_tum(tmp_path / "a.txt", t)
    write_kitti(tmp_path / "b.txt", t)
    a, b = read_tum(tmp_path / "a.txt"), read_kitti(tmp_path / "b.txt")
    np.testing.assert_allclose(a.positions_m, t.positions_m, atol=1e-9)
    np.testing.assert_allclose(a.rotations, t.rotations, atol=1e-8)
    np.testing.assert_allclose(b.poses, t.poses, atol=1e-8)
    assert b.timestamps_s is None


def test_association_takes_nearest_within_tolerance():
    ref = _traj(10, dt=0.1)
    est = Trajectory(ref.positions_m[::2], ref.rotations[::2], ref.timestamps_s[::2] + 0.004)
    r, _e = associate(ref, est, max_diff_s=0.01)
    np.testing.assert_allclose(r.timestamps_s, ref.timestamps_s[::2])
    with pytest.raises(ValueError, match="no matching timestamps within max_diff_s"):
        associate(ref, est, max_diff_s=0.001)


def test_bad_input(tmp_path):
    (tmp_path / "bad.txt").write_text("0 1 2 3\n")
    with pytest.raises(ValueError, match=r"a TUM line needs 8 numbers \(the same on every line\); got 4"):
        read_tum(tmp_path / "bad.txt")
    with pytest.raises(ValueError, match=r"`rotations` must have shape \(2, 3, 3\)"):
        Trajectory(np.zeros((2, 3)), np.zeros((3, 3, 3)))
    t = _traj(5)
    with pytest.raises(ValueError, match="`align` must be one of 'se3', 'sim3', 'none'"):
        ate(t, t, align="affine")
    with pytest.raises(ValueError, match="no pose pairs to evaluate"):
        rpe(t, t, delta=10)
    with pytest.raises(ValueError, match="trajectories without timestamps must have equal length"):
        associate(Trajectory.from_poses(t.poses[:3]), Trajectory.from_poses(t.poses))


def test_non_numeric_token_names_file_line_and_token(tmp_path):
    f = tmp_path / "est.txt"
    f.write_text("0 0 0 0 0 0 0 1\n1 0 0 x1 0 0 0 1\n")
    with pytest.raises(ValueError, match=r"est\.txt:2 \(TUM line\): field 3 is not a number: 'x1'"):
        read_tum(str(f))
