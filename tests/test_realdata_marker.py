"""The ``realdata`` marker and ``real_data`` fixture: skip without the data, fail when CI requires them."""

from __future__ import annotations

import hashlib
import json
from pathlib import Path
from types import SimpleNamespace

import pytest

from slamlab import data
from slamlab.data import commands, locate
from slamlab.data import fetch as sl_fetch
from slamlab.data.registry import load_registry

REQUIRE_ENV = "SLAMLAB_REQUIRE_REALDATA"
SEARCHED = "shared data folder not found; searched:\n  - $SLAMLAB_DATA: (not set)"


@pytest.fixture
def conftest_module(request):
    """The ``tests/conftest.py`` module as pytest loaded it (its once-per-session look-up forgotten)."""
    here = Path(__file__).resolve().parent / "conftest.py"
    for plugin in request.config.pluginmanager.get_plugins():
        if Path(getattr(plugin, "__file__", "") or "").resolve() == here:
            plugin._real_data_or_reason.cache_clear()
            yield plugin
            plugin._real_data_or_reason.cache_clear()
            return
    raise LookupError("tests/conftest.py is not loaded")  # pragma: no cover


@pytest.fixture
def no_real_data(conftest_module, monkeypatch):
    """``_find_real_data`` finds nothing and cannot fetch; returns the list of its calls."""
    calls = []

    def missing():
        calls.append(1)
        raise FileNotFoundError(SEARCHED)

    monkeypatch.setattr(conftest_module, "_find_real_data", missing)
    return calls


@pytest.mark.parametrize("value", [None, "", "0"])
def test_missing_data_skips_with_searched_places(conftest_module, no_real_data, monkeypatch, value):
    if value is None:
        monkeypatch.delenv(REQUIRE_ENV, raising=False)
    else:
        monkeypatch.setenv(REQUIRE_ENV, value)
    with pytest.raises(pytest.skip.Exception, match=r"(?s)^real data not available: .*searched:"):
        conftest_module._locate_real_data()


def test_missing_data_fails_when_required(conftest_module, no_real_data, monkeypatch):
    monkeypatch.setenv(REQUIRE_ENV, "1")
    expected = r"(?s)^real data not available: .*searched:.*SLAMLAB_REQUIRE_REALDATA=1 makes missing data"
    with pytest.raises(pytest.fail.Exception, match=expected):
        conftest_module._locate_real_data()


def test_failed_download_skips(conftest_module, monkeypatch):
    def offline():
        raise data.DataUnavailableError("Cannot fetch 'x/y' (set x, 1 kB) from https://h/x/y: no connection")

    monkeypatch.setattr(conftest_module, "_find_real_data", offline)
    monkeypatch.delenv(REQUIRE_ENV, raising=False)
    with pytest.raises(pytest.skip.Exception, match="real data not available: Cannot fetch"):
        conftest_module._locate_real_data()


def test_missing_data_is_looked_up_once(conftest_module, no_real_data, monkeypatch):
    monkeypatch.delenv(REQUIRE_ENV, raising=False)
    for _ in range(3):
        with pytest.raises(pytest.skip.Exception):
            conftest_module._locate_real_data()
    assert no_real_data == [1]


@pytest.mark.parametrize("value", ["", "0", " 0 "])
def test_require_flag_off_values(conftest_module, monkeypatch, value):
    monkeypatch.setenv(REQUIRE_ENV, value)
    assert conftest_module._require_realdata() is False


@pytest.mark.parametrize("value", ["1", "yes"])
def test_require_flag_on_values(conftest_module, monkeypatch, value):
    monkeypatch.setenv(REQUIRE_ENV, value)
    assert conftest_module._require_realdata() is True


def test_present_data_is_returned(conftest_module, tmp_path, monkeypatch):
    calls = []
    monkeypatch.setattr(conftest_module, "_find_real_data", lambda: calls.append(1) or tmp_path)
    monkeypatch.setenv(REQUIRE_ENV, "1")
    assert conftest_module._locate_real_data() == tmp_path
    assert conftest_module._locate_real_data() == tmp_path
    assert calls == [1]


def test_realdata_marker_runs_the_lookup(conftest_module, no_real_data, monkeypatch):
    monkeypatch.delenv(REQUIRE_ENV, raising=False)
    marked = SimpleNamespace(get_closest_marker=lambda name: object() if name == "realdata" else None)
    unmarked = SimpleNamespace(get_closest_marker=lambda name: None)
    conftest_module.pytest_runtest_setup(unmarked)
    assert no_real_data == []
    with pytest.raises(pytest.skip.Exception, match="real data not available"):
        conftest_module.pytest_runtest_setup(marked)


# ----------------------------------------------------------------------------------------------
# _find_real_data itself, on a registry of two tiny sets (nothing real is read or fetched)

CONTENT = {"set-a/a.txt": b"a\n", "set-a/b.txt": b"bb\n", "set-b/c.txt": b"ccc\n", "set-b/d.txt": b"dddd\n"}


@pytest.fixture
def fake_data(tmp_path, monkeypatch):
    """A fake project, cache and registry; returns (shared, cache, fetched relpaths)."""
    sets = [
        {"name": name, "title": name, "source": "test", "licence": "CC0", "citation": "nobody",
         "files": [{"path": rel.split("/", 1)[1],
                    "url": f"https://raw.githubusercontent.com/o/r/{'0' * 40}/{rel}",
                    "sha256": hashlib.sha256(b).hexdigest(), "size": len(b)}
                   for rel, b in CONTENT.items() if rel.startswith(name + "/")]}
        for name in ("set-a", "set-b")
    ]
    (tmp_path / "registry.json").write_text(json.dumps({"format": 1, "sets": sets}))
    reg = load_registry(tmp_path / "registry.json")
    for module in (data, locate, commands):
        monkeypatch.setattr(module, "registry", lambda: reg)
    project = tmp_path / "work" / "project"
    project.mkdir(parents=True)
    monkeypatch.setattr(locate, "project_root", lambda: project)
    monkeypatch.chdir(project)
    monkeypatch.delenv(data.ENV_VAR, raising=False)
    cache = tmp_path / "cache"
    monkeypatch.setenv(data.CACHE_ENV_VAR, str(cache))
    monkeypatch.setattr(locate, "_CHECKED", {})
    fetched: list[str] = []

    def fake_fetch_files(entries, folder, progress=None):
        for e in entries:
            fetched.append(e.relpath)
            (Path(folder) / e.relpath).parent.mkdir(parents=True, exist_ok=True)
            (Path(folder) / e.relpath).write_bytes(CONTENT[e.relpath])

    monkeypatch.setattr(locate, "fetch_files", fake_fetch_files)
    monkeypatch.setattr(sl_fetch, "fetch_files", fake_fetch_files)  # conftest's own download of what is missing
    return tmp_path / "work" / "shared" / "data", cache.resolve(), fetched


def _put(folder: Path, relpaths) -> None:
    for rel in relpaths:
        (folder / rel).parent.mkdir(parents=True, exist_ok=True)
        (folder / rel).write_bytes(CONTENT[rel])


def test_find_real_data_returns_a_complete_shared_folder(conftest_module, fake_data):
    shared, _cache, fetched = fake_data
    _put(shared, CONTENT)
    assert conftest_module._find_real_data() == shared.resolve()
    assert fetched == []


def test_find_real_data_fetches_into_the_cache(conftest_module, fake_data):
    _shared, cache, fetched = fake_data
    assert conftest_module._find_real_data() == cache
    assert sorted(fetched) == sorted(CONTENT)
    assert all((cache / rel).is_file() for rel in CONTENT)


def test_find_real_data_returns_a_folder_holding_every_file(conftest_module, fake_data):
    shared, _cache, _fetched = fake_data
    _put(shared, ["set-a/a.txt", "set-a/b.txt"])  # set-a whole in ../shared/data, set-b nowhere
    folder = conftest_module._find_real_data()
    assert [rel for rel in CONTENT if not (folder / rel).is_file()] == []
