"""Shared test set-up: the ``realdata`` marker and the ``real_data`` fixture.

A test marked ``@pytest.mark.realdata`` needs the registered real data sets. They are taken
from the first data folder that holds every registered file (``$SLAMLAB_DATA``,
``../shared/data``, or the cache that ``make data`` fills); when none does, they are fetched
into the cache once per session. When that fails (no network, no mirror) the test is skipped
with the reason -- unless the environment sets ``SLAMLAB_REQUIRE_REALDATA=1`` (CI does), in
which case it fails.
"""

from __future__ import annotations

import functools
import os
from pathlib import Path

import pytest

from slamlab import data as sl_data
from slamlab.data import fetch as sl_fetch

REQUIRE_ENV = "SLAMLAB_REQUIRE_REALDATA"

# No progress bars on the tests' stderr, nor in the kernels nbval starts (they inherit this environment).
os.environ["SLAMLAB_PROGRESS"] = "0"
# The labs' exploration attempts are counted in each kernel only (no lab_attempts.json in the repository, and a
# fresh kernel counts from 1, as the stored outputs do); tests of the file set their own path.
os.environ["SLAMLAB_LAB_ATTEMPTS"] = "memory"
# The grading's accepted ranges are cached for this session (one folder per test worker; the kernels that nbval and
# nbgrader start inherit it), not in the user's home.
if "SLAMLAB_GRADING_CACHE" not in os.environ:
    import tempfile

    os.environ["SLAMLAB_GRADING_CACHE"] = tempfile.mkdtemp(prefix="slamlab-grading-cache-")


def _require_realdata() -> bool:
    return os.environ.get(REQUIRE_ENV, "").strip() not in ("", "0")


def _find_real_data() -> Path:
    """A data folder holding every registered file, fetching into the cache when none does."""
    files = sl_data.registry().files
    for _label, folder in sl_data.data_locations():
        if folder is not None and all((folder / f.relpath).is_file() for f in files):
            return folder
    # none holds them all: download into the cache every file it lacks
    cache = sl_data.cache_dir()
    sl_fetch.fetch_files([f for f in files if not (cache / f.relpath).is_file()], cache, progress=False)
    return cache


@functools.cache
def _real_data_or_reason() -> Path | str:
    """The folder, or why there is none (looked up once per session)."""
    try:
        return _find_real_data()
    except FileNotFoundError as err:  # DataUnavailableError is one
        return f"real data not available: {err}"


def _locate_real_data() -> Path:
    """The real-data folder, or skip/fail the current test with the reason."""
    found = _real_data_or_reason()
    if isinstance(found, Path):
        return found
    if _require_realdata():
        pytest.fail(f"{found}\n({REQUIRE_ENV}=1 makes missing data an error)", pytrace=False)
    pytest.skip(found)


@pytest.fixture(scope="session")
def real_data() -> Path:
    """A data folder holding every registered file in the shared layout (skips or fails when there is none)."""
    return _locate_real_data()


def pytest_runtest_setup(item: pytest.Item) -> None:
    """Give every ``realdata`` test the skip/fail behaviour, fixture or not."""
    if item.get_closest_marker("realdata") is not None:
        _locate_real_data()
