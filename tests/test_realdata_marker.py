"""The ``realdata`` marker: skip when the data are missing, fail when CI requires them."""

from __future__ import annotations

from pathlib import Path

import pytest

from slamlab import data


@pytest.fixture
def conftest_module(request):
    """The ``tests/conftest.py`` module as pytest loaded it."""
    here = Path(__file__).resolve().parent / "conftest.py"
    for plugin in request.config.pluginmanager.get_plugins():
        if Path(getattr(plugin, "__file__", "") or "").resolve() == here:
            return plugin
    raise LookupError("tests/conftest.py is not loaded")  # pragma: no cover


@pytest.fixture
def no_shared_data(monkeypatch):
    def missing():
        raise FileNotFoundError("shared data folder not found; searched:\n  - $SLAMLAB_DATA: (not set)")

    monkeypatch.setattr(data, "shared_data_dir", missing)


def test_missing_data_skips_with_searched_places(conftest_module, no_shared_data, monkeypatch):
    monkeypatch.delenv("SLAMLAB_REQUIRE_REALDATA", raising=False)
    with pytest.raises(pytest.skip.Exception, match=r"(?s)real data not available: .*searched:"):
        conftest_module._locate_shared_data()


def test_missing_data_fails_when_required(conftest_module, no_shared_data, monkeypatch):
    monkeypatch.setenv("SLAMLAB_REQUIRE_REALDATA", "1")
    with pytest.raises(pytest.fail.Exception, match=r"(?s)real data not available: .*SLAMLAB_REQUIRE_REALDATA=1"):
        conftest_module._locate_shared_data()


@pytest.mark.parametrize("value", ["", "0"])
def test_require_flag_off_values(conftest_module, monkeypatch, value):
    monkeypatch.setenv("SLAMLAB_REQUIRE_REALDATA", value)
    assert conftest_module._require_realdata() is False


def test_present_data_is_returned(conftest_module, tmp_path, monkeypatch):
    monkeypatch.setattr(data, "shared_data_dir", lambda: tmp_path)
    assert conftest_module._locate_shared_data() == tmp_path
