"""Real data by path: any Oxford-layout folder (a differently named copy), colour images by channel order."""

import shutil

import numpy as np
import pytest

import slamlab.features as F
import slamlab.studies.features as SF


@pytest.fixture
def my_pair(real_data, tmp_path):
    """A two-image Oxford-layout folder under another name (a copy of graf 1, 2 and H1to2p)."""
    src = real_data / "oxford-affine" / "graf"
    dst = tmp_path / "my-wall-pair"
    dst.mkdir()
    for name in ("img1.png", "img2.png", "H1to2p"):
        shutil.copy(src / name, dst / name)
    return dst


@pytest.mark.realdata
def test_pair_evaluation_runs_from_a_str_path_and_names_the_folder(my_pair):
    by_path = SF.run_pair_evaluation(str(my_pair), (2,), detectors=("ORB",), scale=0.5, n_points=200)
    by_name = SF.run_pair_evaluation(("graf",), (2,), detectors=("ORB",), scale=0.5, n_points=200)
    assert by_path.sequences == ("my-wall-pair",)
    np.testing.assert_array_equal(by_path.rep, by_name.rep)
    np.testing.assert_array_equal(by_path.precision, by_name.precision)
    assert "my-wall-pair" in by_path.table()
    assert "graf" not in by_path.table()
    img1, _, H = F.load_oxford_pair(my_pair, 2)  # an os.PathLike works too
    assert img1.dtype == np.uint8
    assert H.shape == (3, 3)


@pytest.mark.realdata
def test_missing_files_are_named(my_pair):
    with pytest.raises(FileNotFoundError, match=r"img3"):
        F.load_oxford_pair(str(my_pair), 3)
    (my_pair / "img3.png").write_bytes((my_pair / "img2.png").read_bytes())
    with pytest.raises(FileNotFoundError, match=r"H1to3p"):
        F.load_oxford_pair(str(my_pair), 3)
    with pytest.raises(ValueError, match=r"one of .*'graf'.* or the path"):
        F.load_oxford_pair("grafitti", 2)
    with pytest.raises(FileNotFoundError, match="no folder"):
        F.load_oxford_pair(str(my_pair / "nowhere"), 2)


def _colour_image(rng):
    """A colour test image with structure in every channel (uint8, B, G, R differ)."""
    yy, xx = np.mgrid[0:120, 0:160]
    base = ((xx // 8 + yy // 8) % 2) * 160 + 40
    noise = rng.integers(0, 40, (120, 160, 3))
    img = np.stack([base, 255 - base, (xx * 1.5).astype(int)], axis=2) + noise
    return np.clip(img, 0, 255).astype(np.uint8)


def test_bgr_from_imread_gives_opencvs_grey(tmp_path):
    cv2 = pytest.importorskip("cv2")
    rng = np.random.default_rng(0)
    path = tmp_path / "colour.png"
    cv2.imwrite(str(path), _colour_image(rng))
    bgr = cv2.imread(str(path))  # OpenCV's order
    ref = cv2.cvtColor(bgr, cv2.COLOR_BGR2GRAY)
    np.testing.assert_array_equal(F.to_gray_uint8(bgr, channel_order="bgr"), ref)
    np.testing.assert_array_equal(F.to_gray_uint8(bgr[..., ::-1], channel_order="rgb"), ref)
    # the float version agrees with OpenCV's grey to its rounding
    np.testing.assert_allclose(F.to_gray_float(bgr, channel_order="bgr") * 255, ref, atol=0.51)
    # reading a BGR image as RGB (the default) is wrong by many grey levels: the order matters
    assert np.abs(F.to_gray_uint8(bgr).astype(int) - ref).max() > 20
    # detect converts once, in the stated order: same keypoints as on OpenCV's grey image
    f_bgr = F.detect(bgr, "orb", channel_order="bgr")
    f_ref = F.detect(ref, "orb")
    assert len(f_ref) > 20
    np.testing.assert_array_equal(f_bgr.uv, f_ref.uv)
    np.testing.assert_array_equal(f_bgr.descriptors, f_ref.descriptors)
    with pytest.raises(ValueError, match="channel_order"):
        F.to_gray_uint8(bgr, channel_order="bgra")
