"""Issue 25: is a CARMEN log's beam layout read right? (endpoint_agreement, map_check)."""

import numpy as np
import pytest

from slamlab.io import read_carmen
from slamlab.studies import correlation as CS


@pytest.fixture
def tiny_log(tmp_path):
    p = tmp_path / "tiny.log"
    p.write_text("".join(f"FLASER 3 1.0 2.0 1.5 {0.1 * i} 0.0 0.0 0 0 0 {i}.0 pippo {i}.0\n" for i in range(4)))
    return read_carmen(p)


def test_map_check_bad_input(tiny_log):
    with pytest.raises(TypeError, match="`log` must be a CarmenLog"):
        CS.endpoint_agreement("x.log")
    with pytest.raises(ValueError, match="`fov_rad` must be <= 2π"):
        CS.endpoint_agreement(tiny_log, fov_rad=7.0)
    with pytest.raises(TypeError, match="`reverse` must be a bool"):
        CS.endpoint_agreement(tiny_log, reverse=1)
    with pytest.raises(ValueError, match="`offset_rad` must be finite"):
        CS.endpoint_agreement(tiny_log, offset_rad=np.inf)
    with pytest.raises(TypeError, match="`laser_x_m` must be a real number"):
        CS.endpoint_agreement(tiny_log, laser_x_m="0.1")
    with pytest.raises(ValueError, match="`range_scale`"):
        CS.endpoint_agreement(tiny_log, range_scale=0.0)
    with pytest.raises(ValueError, match="`every`"):
        CS.endpoint_agreement(tiny_log, every=0)
    with pytest.raises(TypeError, match="`paths` must be a list or tuple of logs"):
        CS.map_check("x.log")
    with pytest.raises(TypeError, match=r"`paths` must hold str, os\.PathLike or CarmenLog"):
        CS.map_check([3])
    with pytest.raises(ValueError, match="`layouts` must be a non-empty sequence"):
        CS.map_check([tiny_log], layouts=())


def test_endpoint_agreement_on_a_tiny_log(tiny_log):
    on, on_seen = CS.endpoint_agreement(tiny_log, every=1, exclude=0, cell_m=0.5)
    assert 0.0 <= on <= on_seen <= 1.0
    table = CS.map_check([tiny_log], layouts=(("CARMEN", {}), ("reversed", {"reverse": True})), every=1, exclude=0,
                        cell_m=0.5)
    assert "tiny" in table
    assert "reversed" in table
    assert "*" in table


@pytest.mark.realdata
def test_orebro_layout_is_carmens(real_data):
    """The reversed beam order puts far fewer end points on the other scans' walls than CARMEN's layout."""
    log = read_carmen(real_data / "carmen-radish-corrected" / "orebro-corrected.log.gz")
    carmen = CS.endpoint_agreement(log, every=20)
    rev = CS.endpoint_agreement(log, reverse=True, every=20)
    assert carmen[0] > 2 * rev[0]
    assert carmen[1] >= carmen[0]


def _box_log(path, poses, logged):
    """A CARMEN log of a robot in an 8 m x 5 m box: each scan's 181 ranges (CARMEN's layout, -90°..90°) cast
    exactly from ``poses``, written with the poses ``logged``."""
    W, H = 8.0, 5.0
    lines = []
    for t, (q, lq) in enumerate(zip(poses, logged, strict=True)):
        a = q[2] + np.linspace(-np.pi / 2, np.pi / 2, 181)
        c, s = np.cos(a), np.sin(a)
        with np.errstate(divide="ignore"):
            tx = np.where(c > 0, (W - q[0]) / c, np.where(c < 0, -q[0] / c, np.inf))
            ty = np.where(s > 0, (H - q[1]) / s, np.where(s < 0, -q[1] / s, np.inf))
        r = np.minimum(tx, ty)
        lines.append("FLASER 181 " + " ".join(f"{v:.4f}" for v in r) + f" {lq[0]} {lq[1]} {lq[2]} {lq[0]} {lq[1]} "
                     f"{lq[2]} {t}.0 box {t}.0\n")
    path.write_text("".join(lines))
    return read_carmen(path)


def test_logged_pose_check_finds_a_pose_its_neighbours_disagree_with(tmp_path):
    # five scans 0.5 m apart along the box; scan 2's logged pose is 0.3 m ahead of where it was taken, scan 3's
    # turned by 4°: the alignment to the neighbours' scans moves them back by that much, the others by ~0
    true = np.array([[2.0 + 0.5 * i, 2.5, 0.1] for i in range(5)])
    logged = true.copy()
    logged[2, 0] += 0.3
    logged[3, 2] += np.radians(4.0)
    log = _box_log(tmp_path / "box.log", true, logged)
    d = CS.logged_pose_check(log, [1, 2, 3], neighbours=(-1, 1))
    # scan 1's neighbours include the shifted scan 2, so allow it a little: it is still far below the doubt
    assert d["doubtful"].tolist() == [False, True, True]
    assert d["move_m"][1] == pytest.approx(0.3, abs=0.02)
    assert d["turn_deg"][2] == pytest.approx(4.0, abs=0.3)
    assert d["move_m"][0] < 0.1
    # the first scan has only its next neighbour: aligned to it alone
    assert not CS.logged_pose_check(log, [0])["doubtful"][0]
    with pytest.raises(ValueError, match="has no neighbour"):
        CS.logged_pose_check(log, [0], neighbours=(-2, -1))
    with pytest.raises(ValueError, match=r"`scan_indices` must lie in \[0, 4\]"):
        CS.logged_pose_check(log, [2, 5])
    with pytest.raises(ValueError, match="`neighbours` must be a non-empty list of non-zero"):
        CS.logged_pose_check(log, [2], neighbours=(0, 1))
    with pytest.raises(ValueError, match="`scan_indices` must be a non-empty list of ints"):
        CS.logged_pose_check(log, [])
    with pytest.raises(TypeError, match="`log` must be a CarmenLog"):
        CS.logged_pose_check("box.log", [2])
    with pytest.raises(ValueError, match="`doubt_m`"):
        CS.logged_pose_check(log, [2], doubt_m=-1.0)
