"""Issue 42: the chapter's logs, read by one rule (as_carmen_log) and named by one (short_log_name)."""

import pytest

from slamlab.studies.correlation.carmen_logs import (
    DEFAULT_CARMEN_LOG,
    SHARED_CARMEN_LOGS,
    as_carmen_log,
    short_log_name,
)


def test_short_names_of_the_shared_logs():
    assert [short_log_name(p.split("/")[-1]) for p in SHARED_CARMEN_LOGS] == ["csail", "fhw", "intel", "orebro",
                                                                              "seattle"]
    assert DEFAULT_CARMEN_LOG in SHARED_CARMEN_LOGS
    assert short_log_name("my.log") == "my"


def test_bad_log_names_the_argument():
    with pytest.raises(TypeError, match=r"`path` must be a str, os\.PathLike or CarmenLog; got bool"):
        as_carmen_log(True)
    with pytest.raises(TypeError, match=r"`paths\[2\]` must be a str, os\.PathLike or CarmenLog; got int"):
        as_carmen_log(3, "paths[2]")


@pytest.mark.realdata
def test_a_path_is_read_and_a_log_passes_through(real_data):
    log = as_carmen_log(real_data / "carmen-radish-corrected" / "intel-corrected.log.gz")
    assert log.name == "intel-corrected.log.gz"
    assert as_carmen_log(log) is log
    assert as_carmen_log(str(real_data / "carmen-radish-corrected" / "fhw-corrected.log.gz")).n_scans > 0
