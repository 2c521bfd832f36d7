"""ATE and RPE equal evo's on the shared trajectories (1e-9 relative), with evo called here."""

import numpy as np
import pytest

evo_metrics = pytest.importorskip("evo.core.metrics")
from evo.core import sync
from evo.tools import file_interface

from slamlab.evaluation import ate, read_kitti, read_tum, rpe

pytestmark = pytest.mark.realdata

TUM_CASES = [
    ("evo-trajectories/tum/freiburg1_xyz-groundtruth.txt", "evo-trajectories/tum/freiburg1_xyz-rgbdslam.txt", "se3"),
    ("evo-trajectories/tum/freiburg1_xyz-groundtruth.txt", "evo-trajectories/tum/freiburg1_xyz-ORB_kf_mono.txt",
     "sim3"),
    ("evo-trajectories/euroc/V101_gt.txt", "evo-trajectories/euroc/V101_openvins.txt", "se3"),
]
KITTI_CASES = [
    ("evo-trajectories/kitti/KITTI_00_gt.txt", "evo-trajectories/kitti/KITTI_00_ORB.txt"),
    ("evo-trajectories/kitti/KITTI_00_gt.txt", "evo-trajectories/kitti/KITTI_00_SPTAM.txt"),
    ("kitti-odom-eval/gt_poses/09.txt", "kitti-odom-eval/result/example_0/09.txt"),
    ("kitti-odom-eval/gt_poses/10.txt", "kitti-odom-eval/result/example_1/10.txt"),
]
STATS = ("rmse", "mean", "median", "std", "min", "max", "sse")


def _evo_ape(ref, est, align):
    ape = evo_metrics.APE(evo_metrics.PoseRelation.translation_part)
    if align != "none":
        est.align(ref, correct_scale=(align == "sim3"))
    ape.process_data((ref, est))
    return ape.get_all_statistics()


def _evo_rpe(ref, est, delta, unit, relation, align="none", pairs_from_reference=False):
    if align != "none":
        est.align(ref, correct_scale=(align == "sim3"))
    rel = {"translation": evo_metrics.PoseRelation.translation_part,
           "rotation_deg": evo_metrics.PoseRelation.rotation_angle_deg}[relation]
    u = {"frames": evo_metrics.Unit.frames, "m": evo_metrics.Unit.meters}[unit]
    m = evo_metrics.RPE(rel, delta=delta, delta_unit=u, all_pairs=False, pairs_from_reference=pairs_from_reference)
    m.process_data((ref, est))
    return m.get_all_statistics()


def _assert_same(ours, theirs):
    for k in STATS:
        assert getattr(ours, k) == pytest.approx(theirs[k], rel=1e-9, abs=1e-12), k


@pytest.mark.parametrize(("ref_path", "est_path", "align"), TUM_CASES)
def test_ate_equals_evo_tum(real_data, ref_path, est_path, align):
    ours = ate(read_tum(real_data / ref_path), read_tum(real_data / est_path), align=align)
    ref = file_interface.read_tum_trajectory_file(str(real_data / ref_path))
    est = file_interface.read_tum_trajectory_file(str(real_data / est_path))
    ref, est = sync.associate_trajectories(ref, est, max_diff=0.01)
    _assert_same(ours, _evo_ape(ref, est, align))
    assert ours.n == ref.num_poses


@pytest.mark.parametrize(("ref_path", "est_path", "align"), TUM_CASES)
@pytest.mark.parametrize(("delta", "unit", "relation"), [(1, "frames", "translation"), (10, "frames", "rotation_deg"),
                                                         (0.5, "m", "translation")])
def test_rpe_equals_evo_tum(real_data, ref_path, est_path, align, delta, unit, relation):
    a = "sim3" if align == "sim3" else "none"
    ours = rpe(read_tum(real_data / ref_path), read_tum(real_data / est_path), delta=delta, delta_unit=unit,
               relation=relation, align=a)
    ref = file_interface.read_tum_trajectory_file(str(real_data / ref_path))
    est = file_interface.read_tum_trajectory_file(str(real_data / est_path))
    ref, est = sync.associate_trajectories(ref, est, max_diff=0.01)
    _assert_same(ours, _evo_rpe(ref, est, delta, unit, relation, a))


@pytest.mark.parametrize(("ref_path", "est_path"), KITTI_CASES)
def test_ate_and_rpe_equal_evo_kitti(real_data, ref_path, est_path):
    from evo.core.trajectory import PosePath3D

    r, e = read_kitti(real_data / ref_path), read_kitti(real_data / est_path)
    if e.frame_ids is not None:  # indexed result file (evo cannot read it): give evo the same poses
        ref = PosePath3D(poses_se3=list(r.poses[e.frame_ids]))
        est = PosePath3D(poses_se3=list(e.poses))
    else:
        ref = file_interface.read_kitti_poses_file(str(real_data / ref_path))
        est = file_interface.read_kitti_poses_file(str(real_data / est_path))
    _assert_same(rpe(r, e, delta=10, delta_unit="m"), _evo_rpe(ref, est, 10, "m", "translation"))
    _assert_same(rpe(r, e, delta=10, delta_unit="m", pairs_from="reference"),
                 _evo_rpe(ref, est, 10, "m", "translation", pairs_from_reference=True))
    _assert_same(rpe(r, e, delta=1, relation="rotation_deg"), _evo_rpe(ref, est, 1, "frames", "rotation_deg"))
    _assert_same(ate(r, e, align="se3"), _evo_ape(ref, est, "se3"))


def test_indexed_kitti_result_is_paired_by_frame(real_data):
    gt = read_kitti(real_data / "kitti-odom-eval/gt_poses/09.txt")
    est = read_kitti(real_data / "kitti-odom-eval/result/example_0/09.txt")
    assert len(gt) == 1591
    assert len(est) == 1589
    assert est.frame_ids[0] == 2  # PROVENANCE: frames 0 and 1 absent
    assert ate(gt, est).n == 1589


def test_ate_is_zero_for_a_rigidly_moved_copy(real_data):
    from scipy.spatial.transform import Rotation

    from slamlab.evaluation import Trajectory

    r = read_tum(real_data / TUM_CASES[0][0])
    R = Rotation.from_rotvec([0.2, -0.1, 0.4]).as_matrix()
    moved = Trajectory(r.positions_m @ R.T + [1.0, 2.0, 3.0], R @ r.rotations, r.timestamps_s)
    assert ate(r, moved, align="se3").rmse < 1e-9
    assert ate(r, moved, align="none").rmse > 1.0
    assert rpe(r, moved).rmse < 1e-9
    np.testing.assert_allclose(rpe(r, moved, relation="rotation_deg").max, 0.0, atol=1e-6)
