"""Locating data: project ``data/``, ``$SLAMLAB_DATA``, ``../shared/data``."""

from __future__ import annotations

from pathlib import Path

import pytest

from slamlab import data


@pytest.fixture
def isolated(tmp_path, monkeypatch):
    """No real data anywhere: a fake project root and working folder under ``tmp_path``."""
    project = tmp_path / "work" / "project"
    (project / "data").mkdir(parents=True)
    (project / "pyproject.toml").write_text("")
    monkeypatch.setattr(data, "project_root", lambda: project)
    monkeypatch.chdir(project)
    monkeypatch.delenv(data.ENV_VAR, raising=False)
    return project


def test_project_root_is_the_checkout():
    root = data.project_root()
    assert root is not None
    assert (root / "pyproject.toml").is_file()
    assert (root / "slamlab" / "data.py").is_file()


def test_project_data_dir_is_data_folder():
    assert data.project_data_dir() == data.project_root() / "data"


def test_project_data_dir_missing_names_the_path(isolated, monkeypatch):
    (isolated / "data").rmdir()
    with pytest.raises(FileNotFoundError, match=r"project data folder not found; searched: .*data"):
        data.project_data_dir()


def test_project_data_dir_outside_checkout(monkeypatch):
    monkeypatch.setattr(data, "project_root", lambda: None)
    with pytest.raises(FileNotFoundError, match="not running from a source checkout"):
        data.project_data_dir()


def test_env_var_wins(isolated, tmp_path, monkeypatch):
    shared = tmp_path / "elsewhere"
    (shared / "set").mkdir(parents=True)
    (shared / "set" / "a.txt").write_text("a")
    monkeypatch.setenv(data.ENV_VAR, str(shared))
    assert data.shared_data_dir() == shared.resolve()
    assert data.data_root() == shared.resolve()
    assert data.find_data("set/a.txt") == shared.resolve() / "set" / "a.txt"


def test_project_data_comes_before_shared(isolated, tmp_path, monkeypatch):
    shared = tmp_path / "elsewhere"
    shared.mkdir()
    (shared / "map.txt").write_text("shared")
    (isolated / "data" / "map.txt").write_text("project")
    monkeypatch.setenv(data.ENV_VAR, str(shared))
    assert data.find_data("map.txt").read_text() == "project"
    assert data.find_data(Path("map.txt")) == isolated / "data" / "map.txt"


def test_shared_beside_project_root(isolated):
    shared = isolated.parent / "shared" / "data"
    shared.mkdir(parents=True)
    assert data.shared_data_dir() == shared.resolve()


def test_shared_found_from_working_folder_parents(isolated, tmp_path, monkeypatch):
    # project root has no ../shared/data; the working folder's grandparent does
    notebooks = tmp_path / "course" / "lab" / "notebooks"
    notebooks.mkdir(parents=True)
    shared = tmp_path / "course" / "shared" / "data"
    shared.mkdir(parents=True)
    monkeypatch.chdir(notebooks)
    assert data.shared_data_dir() == shared.resolve()


def test_missing_shared_names_every_place(isolated, monkeypatch):
    monkeypatch.setenv(data.ENV_VAR, str(isolated / "nowhere"))
    with pytest.raises(FileNotFoundError) as info:
        data.shared_data_dir()
    message = str(info.value)
    assert message.startswith("shared data folder not found; searched:")
    assert f"${data.ENV_VAR}: {(isolated / 'nowhere').resolve()}" in message
    assert str(isolated.parent / "shared" / "data") in message
    assert "SLAMLAB_DATA" in message.splitlines()[-1]


def test_missing_env_var_is_reported_as_not_set(isolated):
    with pytest.raises(FileNotFoundError, match=r"\$SLAMLAB_DATA: \(not set\)"):
        data.shared_data_dir()


def test_find_data_missing_names_every_path(isolated, monkeypatch):
    monkeypatch.setenv(data.ENV_VAR, str(isolated / "env"))
    with pytest.raises(FileNotFoundError) as info:
        data.find_data("x/y.png")
    message = str(info.value)
    assert message.startswith("'x/y.png' not found in any data folder; searched:")
    assert str(isolated / "data" / "x" / "y.png") in message
    assert str((isolated / "env").resolve() / "x" / "y.png") in message
    assert str(isolated.parent / "shared" / "data" / "x" / "y.png") in message


def test_data_root_kinds(isolated):
    assert data.data_root("project") == isolated / "data"
    with pytest.raises(ValueError, match=r"`kind` must be one of 'shared', 'project'; got 'real'"):
        data.data_root("real")


@pytest.mark.parametrize(
    ("relpath", "error", "match"),
    [
        (3, TypeError, r"`relpath` must be a str or path; got int"),
        (None, TypeError, r"`relpath` must be a str or path; got NoneType"),
        ("", ValueError, r"`relpath` must name a file or folder; got an empty path"),
        ("/etc/passwd", ValueError, r"`relpath` must be relative to a data folder; got absolute path"),
        ("../secret.txt", ValueError, r"`relpath` must stay inside the data folder; got '../secret.txt'"),
    ],
)
def test_find_data_rejects_bad_relpath(relpath, error, match):
    with pytest.raises(error, match=match):
        data.find_data(relpath)


@pytest.mark.realdata
def test_real_shared_data_is_found(real_data):
    provenance = data.find_data("oxford-affine/PROVENANCE.md")
    assert provenance.is_file()
    assert provenance == real_data / "oxford-affine" / "PROVENANCE.md"
