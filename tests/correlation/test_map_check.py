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
