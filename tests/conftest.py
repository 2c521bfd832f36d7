"""Shared test set-up: the ``realdata`` marker and the ``shared_data`` fixture.

A test marked ``@pytest.mark.realdata`` needs the shared data folder
(``$SLAMLAB_DATA`` or ``../shared/data``). When the folder is missing the test is
skipped with a message naming every place searched -- unless the environment
sets ``SLAMLAB_REQUIRE_REALDATA=1`` (CI does), in which case it fails.
"""

from __future__ import annotations

import os
from pathlib import Path

import pytest

from slamlab import data as sl_data

REQUIRE_ENV = "SLAMLAB_REQUIRE_REALDATA"

# No progress bars on the tests' stderr, nor in the kernels nbval starts (they inherit this environment).
os.environ["SLAMLAB_PROGRESS"] = "0"


def _require_realdata() -> bool:
    return os.environ.get(REQUIRE_ENV, "").strip() not in ("", "0")


def _locate_shared_data() -> Path:
    """The shared data folder, or skip/fail the current test with the searched places."""
    try:
        return sl_data.shared_data_dir()
    except FileNotFoundError as err:
        message = f"real data not available: {err}"
    if _require_realdata():
        pytest.fail(f"{message}\n({REQUIRE_ENV}=1 makes a missing folder an error)", pytrace=False)
    pytest.skip(message)


@pytest.fixture(scope="session")
def shared_data() -> Path:
    """Root of the shared real-data folder (skips or fails when it is missing)."""
    return _locate_shared_data()


def pytest_runtest_setup(item: pytest.Item) -> None:
    """Give every ``realdata`` test the skip/fail behaviour, fixture or not."""
    if item.get_closest_marker("realdata") is not None:
        _locate_shared_data()
