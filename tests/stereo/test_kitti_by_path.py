"""run_kitti on a differently named KITTI folder (3 frames, official calib.txt with P0..P3 labels), from a str."""

import shutil

import numpy as np
import pytest

from slamlab.io import read_kitti_calib
from slamlab.studies.stereo import run_kitti

pytestmark = pytest.mark.realdata

N = 3


@pytest.fixture(scope="module")
def my_kitti(real_data, tmp_path_factory):
    src = real_data / "kitti-odometry-06-stereo"
    dst = tmp_path_factory.mktemp("kitti") / "my-drive-07"
    for cam in ("image_0", "image_1"):
        (dst / cam).mkdir(parents=True)
        for i in range(N):
            shutil.copy(src / cam / f"{i:06d}.png", dst / cam / f"{i:06d}.png")
    rows = (src / "poses.txt").read_text().splitlines()[:N]
    (dst / "poses.txt").write_text("\n".join(rows) + "\n")
    P0, P1 = np.loadtxt(src / "calib.txt").reshape(2, 12)
    P2, P3 = P0.copy(), P1.copy()
    P2[3], P3[3] = 46.0, -333.0  # the colour cameras: other offsets (values of no concern here)
    fmt = lambda v: " ".join(f"{x:.12e}" for x in v)
    Tr = np.r_[np.eye(3), np.zeros((1, 3))].T.ravel()
    lines = [f"P{i}: {fmt(P)}" for i, P in enumerate((P0, P1, P2, P3))] + [f"Tr: {fmt(Tr)}"]
    (dst / "calib.txt").write_text("\n".join(lines) + "\n")
    return dst


def test_official_and_stripped_calib_give_the_same_matrices(real_data, my_kitti):
    official = read_kitti_calib(str(my_kitti / "calib.txt"))
    stripped = read_kitti_calib(real_data / "kitti-odometry-06-stereo" / "calib.txt")
    assert sorted(official) == ["P0", "P1", "P2", "P3", "Tr"]
    assert sorted(stripped) == ["P0", "P1"]
    for k in ("P0", "P1"):
        np.testing.assert_allclose(official[k], stripped[k], rtol=1e-12)


def test_run_kitti_from_a_str_path_names_the_run_after_the_folder(real_data, my_kitti):
    res = run_kitti(str(my_kitti), rng=0)
    ref = run_kitti(real_data / "kitti-odometry-06-stereo", n_frames=N, rng=0)
    assert res.name == "my-drive-07"
    assert "my-drive-07, frames 0-2" in res.table()
    assert str(res).startswith("my-drive-07, 3 frames")
    np.testing.assert_array_equal(res.estimate, ref.estimate)
    assert res.n_degenerate == 0


def test_missing_frame_and_bad_calib_are_named(my_kitti, tmp_path):
    broken = tmp_path / "broken"
    shutil.copytree(my_kitti, broken)
    (broken / "image_1" / "000002.png").unlink()
    with pytest.raises(FileNotFoundError, match=r"image_1[/\\]000002\.png"):
        run_kitti(str(broken), rng=0)
    (broken / "calib.txt").write_text("P0: 1 2 3\n")
    with pytest.raises(ValueError, match=r"'P0' must have 12 numbers"):
        read_kitti_calib(broken / "calib.txt")
    with pytest.raises(FileNotFoundError, match="no folder"):
        run_kitti(str(tmp_path / "nowhere"))
