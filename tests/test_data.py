"""Finding data (issue 41): the package's files, ``$SLAMLAB_DATA``, ``../shared/data``, the cache, a fetch.

Every test but the last two runs against a small registry of its own (two sets of tiny text
files) in a fake project under ``tmp_path``, with the cache there too and the downloader
replaced by one that writes the registered bytes and records what it was asked for: nothing
here reads the real data or the network.
"""

from __future__ import annotations

import hashlib
import json
import os
import re
from dataclasses import dataclass, field
from pathlib import Path

import pytest

from slamlab import data
from slamlab.data import derive, locate
from slamlab.data.registry import load_registry

COMMIT = "0123456789abcdef0123456789abcdef01234567"

#: The fake registry's files (relpath -> bytes): set-a has a subfolder, set-b two files.
CONTENT = {
    "set-a/a1.txt": b"first file of set a\n",
    "set-a/a2.txt": b"second file of set a\n",
    "set-a/sub/a3.txt": b"a file in a subfolder of set a\n",
    "set-b/b1.txt": b"b1\n",
    "set-b/b2.txt": b"the second file of set b\n",
}
SET_A = ("set-a/a1.txt", "set-a/a2.txt", "set-a/sub/a3.txt")
SET_B = ("set-b/b1.txt", "set-b/b2.txt")


def _sha(b: bytes) -> str:
    return hashlib.sha256(b).hexdigest()


def _write_registry(path: Path) -> Path:
    sets = []
    for name in ("set-a", "set-b"):
        files = [
            {
                "path": rel.split("/", 1)[1],
                "url": f"https://raw.githubusercontent.com/owner/repo/{COMMIT}/{rel}",
                "sha256": _sha(b),
                "size": len(b),
            }
            for rel, b in CONTENT.items()
            if rel.startswith(name + "/")
        ]
        sets.append({"name": name, "title": f"test {name}", "source": "test", "licence": "CC0",
                     "citation": "nobody", "files": files})
    path.write_text(json.dumps({"format": 1, "sets": sets}), encoding="utf-8")
    return path


@dataclass
class Env:
    """The isolated set-up: the fake project, its data folders and the downloader's calls."""

    project: Path
    shared: Path  # ../shared/data beside the project (not created)
    cache: Path  # $SLAMLAB_CACHE (not created)
    fetches: list[list[str]] = field(default_factory=list)

    def put(self, folder: Path, relpaths, *, changed: tuple[str, ...] = ()) -> None:
        """Write the registered bytes of ``relpaths`` under ``folder`` (``changed`` ones altered)."""
        for rel in relpaths:
            path = folder / rel
            path.parent.mkdir(parents=True, exist_ok=True)
            path.write_bytes(CONTENT[rel].upper() if rel in changed else CONTENT[rel])

    @property
    def fetched(self) -> list[str]:
        """Every relpath the downloader was asked for, in order."""
        return [rel for call in self.fetches for rel in call]


@pytest.fixture
def isolated(tmp_path, monkeypatch) -> Env:
    """No real data anywhere: a fake project, working folder, cache and registry under ``tmp_path``."""
    project = tmp_path / "work" / "project"
    project.mkdir(parents=True)
    (project / "pyproject.toml").write_text("")
    monkeypatch.setattr(locate, "project_root", lambda: project)
    monkeypatch.chdir(project)
    monkeypatch.delenv(data.ENV_VAR, raising=False)
    monkeypatch.delenv(data.DATA_URL_ENV_VAR, raising=False)
    cache = tmp_path / "cache"
    monkeypatch.setenv(data.CACHE_ENV_VAR, str(cache))
    reg = load_registry(_write_registry(tmp_path / "registry.json"))
    monkeypatch.setattr(locate, "registry", lambda: reg)
    monkeypatch.setattr(locate, "_CHECKED", {})
    env = Env(project=project, shared=tmp_path / "work" / "shared" / "data", cache=cache.resolve())

    def fake_fetch_files(entries, cache, progress=None):
        entries = list(entries)
        env.fetches.append([e.relpath for e in entries])
        out = []
        for e in entries:
            path = Path(cache) / e.relpath
            path.parent.mkdir(parents=True, exist_ok=True)
            path.write_bytes(CONTENT[e.relpath])
            out.append(path)
        return out

    monkeypatch.setattr(locate, "fetch_files", fake_fetch_files)
    # the working folder's parents are searched too: none of their ../shared/data may exist here
    outside = [p for _label, p in locate.data_locations() if p is not None and p.exists()]
    assert outside == [], f"a data folder outside tmp_path exists: {outside}"
    return env


# ----------------------------------------------------------------------------------------------
# the folders


def test_project_root_is_the_checkout():
    root = data.project_root()
    assert root is not None
    assert (root / "pyproject.toml").is_file()
    assert (root / "slamlab" / "data" / "__init__.py").is_file()
    assert (root / "slamlab" / "data" / "registry.json").is_file()


def test_bundled_data_dir_is_inside_the_package():
    assert data.bundled_data_dir() == Path(data.__file__).resolve().parent / "bundled"
    assert data.project_data_dir() == data.bundled_data_dir()
    assert (data.bundled_data_dir() / "test_room_200.txt").is_file()


def test_shared_beside_project_root(isolated):
    isolated.shared.mkdir(parents=True)
    assert data.shared_data_dir() == isolated.shared.resolve()


def test_shared_found_from_working_folder_parents(isolated, tmp_path, monkeypatch):
    # the project root has no ../shared/data; the working folder's grandparent does
    notebooks = tmp_path / "course" / "lab" / "notebooks"
    notebooks.mkdir(parents=True)
    shared = tmp_path / "course" / "shared" / "data"
    shared.mkdir(parents=True)
    monkeypatch.chdir(notebooks)
    assert data.shared_data_dir() == shared.resolve()


def test_env_var_comes_before_shared(isolated, tmp_path, monkeypatch):
    env = tmp_path / "elsewhere"
    isolated.put(env, SET_A)
    isolated.put(isolated.shared, SET_A)
    (env / "own.txt").write_text("env")
    (isolated.shared / "own.txt").write_text("shared")
    monkeypatch.setenv(data.ENV_VAR, str(env))
    assert data.shared_data_dir() == env.resolve()
    assert data.data_root() == env.resolve()
    assert data.find_data("own.txt").read_text() == "env"  # not registered
    assert data.find_data("set-a/a1.txt") == env.resolve() / "set-a" / "a1.txt"
    assert data.find_data("set-a") == env.resolve() / "set-a"
    assert isolated.fetches == []


def test_locations_in_search_order(isolated, tmp_path, monkeypatch):
    monkeypatch.setenv(data.ENV_VAR, str(tmp_path / "env"))
    labels, paths = zip(*data.data_locations(), strict=True)
    assert labels[:2] == (f"${data.ENV_VAR}", "project root ../shared/data")
    assert paths[:2] == ((tmp_path / "env").resolve(), isolated.shared.resolve())
    assert paths[-1] == isolated.cache
    assert labels[-1].startswith("cache")
    assert len(set(paths)) == len(paths)  # the project root's and the working folder's are one


def test_missing_shared_names_every_place(isolated, monkeypatch):
    monkeypatch.setenv(data.ENV_VAR, str(isolated.project / "nowhere"))
    with pytest.raises(FileNotFoundError) as info:
        data.shared_data_dir()
    message = str(info.value)
    assert message.startswith("shared data folder not found; searched:")
    assert f"${data.ENV_VAR}: {(isolated.project / 'nowhere').resolve()}" in message
    assert f"project root ../shared/data: {isolated.shared.resolve()}" in message
    assert "SLAMLAB_DATA" in message.splitlines()[-1]


def test_missing_env_var_is_reported_as_not_set(isolated):
    with pytest.raises(FileNotFoundError, match=r"\$SLAMLAB_DATA: \(not set\)"):
        data.shared_data_dir()


def test_data_root_kinds(isolated):
    assert data.data_root("bundled") == data.bundled_data_dir()
    assert data.data_root("cache") == isolated.cache == data.cache_dir()
    with pytest.raises(FileNotFoundError, match="shared data folder not found"):
        data.data_root("shared")
    isolated.shared.mkdir(parents=True)
    assert data.data_root("shared") == data.data_root() == isolated.shared.resolve()
    with pytest.raises(ValueError, match=r"must be one of 'shared', 'bundled', 'cache'; got 'project'"):
        data.data_root("project")


def test_cache_dir_defaults_to_the_user_cache(monkeypatch):
    import pooch

    monkeypatch.delenv(data.CACHE_ENV_VAR, raising=False)
    assert data.cache_dir() == Path(pooch.os_cache("slamlab")).resolve()
    monkeypatch.setenv(data.CACHE_ENV_VAR, "  ")  # blank is unset
    assert data.cache_dir() == Path(pooch.os_cache("slamlab")).resolve()


# ----------------------------------------------------------------------------------------------
# find_data: arguments, unregistered paths


@pytest.mark.parametrize(
    ("relpath", "error", "match"),
    [
        (3, TypeError, r"`relpath` must be a str or path; got int"),
        (None, TypeError, r"`relpath` must be a str or path; got NoneType"),
        (b"set-a", TypeError, r"`relpath` must be a str or path; got bytes"),
        ("", ValueError, r"`relpath` must name a file or folder; got an empty path"),
        (".", ValueError, r"`relpath` must name a file or folder; got an empty path"),
        ("/etc/passwd", ValueError, r"`relpath` must be relative to a data folder; got absolute path"),
        ("../secret.txt", ValueError, r"`relpath` must stay inside the data folder; got '../secret.txt'"),
        ("set-a/../../x", ValueError, r"`relpath` must stay inside the data folder"),
    ],
)
def test_find_data_rejects_bad_relpath(isolated, relpath, error, match):
    with pytest.raises(error, match=match):
        data.find_data(relpath)
    assert isolated.fetches == []


def test_unregistered_missing_names_every_place(isolated, monkeypatch):
    monkeypatch.setenv(data.ENV_VAR, str(isolated.project / "env"))
    with pytest.raises(FileNotFoundError) as info:
        data.find_data("x/y.png")
    message = str(info.value)
    assert message.startswith(
        "'x/y.png' not found in any data folder, and no registered data set holds it; searched:"
    )
    assert f"bundled: {data.bundled_data_dir()}" in message
    assert f"$SLAMLAB_DATA: {(isolated.project / 'env').resolve()}" in message
    assert str(isolated.shared.resolve()) in message
    assert str(isolated.cache) in message
    assert isolated.fetches == []


def test_set_name_prefix_is_not_a_set(isolated):
    # "set" is the start of "set-a" and "set-b" but no registered folder: nothing to fetch
    with pytest.raises(FileNotFoundError, match="no registered data set holds it"):
        data.find_data("set")
    with pytest.raises(FileNotFoundError, match="no registered data set holds it"):
        data.find_data("set-a/a")
    assert isolated.fetches == []


def test_unregistered_file_is_found_in_any_folder(isolated):
    (isolated.cache / "mine").mkdir(parents=True)
    (isolated.cache / "mine" / "x.txt").write_text("cache")
    assert data.find_data("mine/x.txt") == isolated.cache / "mine" / "x.txt"
    assert data.find_data(Path("mine")) == isolated.cache / "mine"
    (isolated.shared / "mine").mkdir(parents=True)
    (isolated.shared / "mine" / "x.txt").write_text("shared")
    assert data.find_data("mine/x.txt").read_text() == "shared"
    # an unregistered file inside a registered set's folder is looked for too
    isolated.put(isolated.shared, SET_A)
    (isolated.shared / "set-a" / "notes.md").write_text("mine")
    assert data.find_data("set-a/notes.md") == isolated.shared.resolve() / "set-a" / "notes.md"
    assert isolated.fetches == []


# ----------------------------------------------------------------------------------------------
# find_data: the bundled files


def test_bundled_files_win_over_everything(isolated, tmp_path, monkeypatch):
    env = tmp_path / "env"
    for folder in (env, isolated.shared, isolated.cache):
        folder.mkdir(parents=True)
        (folder / "test_room_200.txt").write_text("not the bundled map")
    monkeypatch.setenv(data.ENV_VAR, str(env))
    found = data.find_data("test_room_200.txt")
    assert found == data.bundled_data_dir() / "test_room_200.txt"
    assert found.read_text() != "not the bundled map"
    assert data.find_data(Path("test_room_200.txt"), fetch=False) == found


def test_bundled_registered_file_is_not_fetched_nor_hashed(isolated, tmp_path, monkeypatch):
    bundled = tmp_path / "bundled"
    (bundled / "set-b").mkdir(parents=True)
    (bundled / "set-b" / "b1.txt").write_bytes(b"whatever the package ships")
    monkeypatch.setattr(locate, "_BUNDLED_DIR", bundled)
    isolated.put(isolated.shared, SET_B)
    assert data.find_data("set-b/b1.txt") == bundled / "set-b" / "b1.txt"
    assert data.find_data("set-b/b2.txt") == isolated.shared.resolve() / "set-b" / "b2.txt"
    assert isolated.fetches == []


# ----------------------------------------------------------------------------------------------
# find_data: registered files and sets


def test_missing_file_is_fetched_into_the_cache(isolated):
    found = data.find_data("set-a/a2.txt")
    assert found == isolated.cache / "set-a" / "a2.txt"
    assert found.read_bytes() == CONTENT["set-a/a2.txt"]
    assert isolated.fetches == [["set-a/a2.txt"]]
    # found in the cache from now on
    assert data.find_data("set-a/a2.txt") == found
    assert data.find_data("set-a/a2.txt", fetch=False) == found
    assert isolated.fetches == [["set-a/a2.txt"]]


def test_missing_set_is_fetched_whole(isolated):
    found = data.find_data("set-a")
    assert found == isolated.cache / "set-a"
    assert sorted(isolated.fetched) == sorted(SET_A)
    assert len(isolated.fetches) == 1
    for rel in SET_A:
        assert (isolated.cache / rel).read_bytes() == CONTENT[rel]
    assert not (isolated.cache / "set-b").exists()


def test_progress_is_passed_to_the_downloader(isolated, monkeypatch):
    seen = []
    monkeypatch.setattr(locate, "fetch_files", lambda entries, cache, progress=None: seen.append(progress))
    data.find_data("set-b/b1.txt", progress=False)
    assert seen == [False]


def test_set_complete_in_shared_is_returned_without_fetch(isolated):
    isolated.put(isolated.shared, SET_A)
    shared = isolated.shared.resolve()
    assert data.find_data("set-a") == shared / "set-a"
    assert data.find_data("set-a/sub") == shared / "set-a" / "sub"
    assert data.find_data("set-a/a1.txt") == shared / "set-a" / "a1.txt"
    assert data.find_data("set-a", fetch=False) == shared / "set-a"
    assert data.find_data("set-a/") == shared / "set-a"
    assert data.find_data("./set-a/sub/a3.txt") == shared / "set-a" / "sub" / "a3.txt"
    assert isolated.fetches == []
    assert not isolated.cache.exists()


def test_set_partly_in_shared_is_completed_in_the_cache(isolated):
    isolated.put(isolated.shared, ["set-a/a1.txt", "set-a/a2.txt"])
    isolated.put(isolated.cache, ["set-a/a2.txt"])
    # a file the shared folder holds is still returned from there
    assert data.find_data("set-a/a1.txt") == isolated.shared.resolve() / "set-a" / "a1.txt"
    # the set is returned whole from one folder: the cache, after fetching what the cache lacks
    assert data.find_data("set-a") == isolated.cache / "set-a"
    assert isolated.fetches == [["set-a/a1.txt", "set-a/sub/a3.txt"]]
    for rel in SET_A:
        assert (isolated.cache / rel).read_bytes() == CONTENT[rel]
    # and a subfolder complete in the shared folder is returned from there
    isolated.put(isolated.shared, ["set-a/sub/a3.txt"])
    assert data.find_data("set-a/sub") == isolated.shared.resolve() / "set-a" / "sub"


def test_set_complete_in_the_cache_is_not_fetched(isolated):
    isolated.put(isolated.cache, SET_B)
    assert data.find_data("set-b") == isolated.cache / "set-b"
    assert data.find_data("set-b", fetch=False) == isolated.cache / "set-b"
    assert isolated.fetches == []


@pytest.mark.parametrize("relpath", ["set-b", "set-b/b2.txt", "set-a/sub"])
def test_fetch_false_raises_naming_every_place(isolated, relpath):
    isolated.put(isolated.shared, ["set-b/b1.txt"])
    with pytest.raises(FileNotFoundError) as info:
        data.find_data(relpath, fetch=False)
    assert isinstance(info.value, data.DataUnavailableError)
    message = str(info.value)
    assert message.startswith(f"{relpath!r}: ")
    assert "fetch=False; searched:" in message
    assert "$SLAMLAB_DATA: (not set)" in message
    assert str(isolated.shared.resolve()) in message
    assert str(isolated.cache) in message
    assert isolated.fetches == []


def test_failed_fetch_is_a_file_not_found_error(isolated, monkeypatch):
    def offline(entries, cache, progress=None):
        raise data.DataUnavailableError("Cannot fetch 'set-b/b1.txt': no connection to the host")

    monkeypatch.setattr(locate, "fetch_files", offline)
    with pytest.raises(FileNotFoundError, match="no connection"):
        data.find_data("set-b")


# ----------------------------------------------------------------------------------------------
# find_data: hashes


@pytest.mark.parametrize("same_size", [True, False], ids=["same-size", "other-size"])
def test_changed_shared_file_warns_and_is_returned(isolated, same_size):
    isolated.put(isolated.shared, SET_A, changed=("set-a/a2.txt",))
    changed = isolated.shared.resolve() / "set-a" / "a2.txt"
    if not same_size:
        changed.write_bytes(b"shorter")
    with pytest.warns(data.DataHashWarning, match=re.escape(str(changed))) as record:
        found = data.find_data("set-a")
    assert found == isolated.shared.resolve() / "set-a"
    assert len(record) == 1
    message = str(record[0].message)
    assert "project root ../shared/data" in message
    assert _sha(CONTENT["set-a/a2.txt"]) in message
    assert "python -m slamlab.data verify" in message
    assert record[0].filename == __file__  # the warning points at the caller of find_data
    assert isolated.fetches == []


def test_changed_env_file_warns(isolated, tmp_path, monkeypatch):
    env = tmp_path / "env"
    isolated.put(env, SET_B, changed=SET_B)
    monkeypatch.setenv(data.ENV_VAR, str(env))
    with pytest.warns(data.DataHashWarning, match=r"\(\$SLAMLAB_DATA\) differs") as record:
        assert data.find_data("set-b/b2.txt") == env.resolve() / "set-b" / "b2.txt"
    assert len(record) == 1
    with pytest.warns(data.DataHashWarning) as record:
        assert data.find_data("set-b") == env.resolve() / "set-b"
    assert len(record) == 2
    assert isolated.fetches == []


def test_changed_cached_file_is_deleted_and_fetched_again(isolated):
    isolated.put(isolated.cache, SET_B, changed=("set-b/b1.txt",))
    stale = isolated.cache / "set-b" / "b1.txt"
    os.utime(stale, ns=(10**18, 10**18))  # an older mtime than the fetched file will have
    assert data.find_data("set-b") == isolated.cache / "set-b"  # no warning: filterwarnings=error
    assert isolated.fetches == [["set-b/b1.txt"]]
    assert stale.read_bytes() == CONTENT["set-b/b1.txt"]
    assert data.find_data("set-b") == isolated.cache / "set-b"
    assert isolated.fetches == [["set-b/b1.txt"]]


def test_changed_cached_file_is_fetched_again_alone(isolated):
    isolated.put(isolated.cache, SET_A, changed=("set-a/sub/a3.txt",))
    found = data.find_data("set-a/sub/a3.txt")
    assert found == isolated.cache / "set-a" / "sub" / "a3.txt"
    assert found.read_bytes() == CONTENT["set-a/sub/a3.txt"]
    assert isolated.fetches == [["set-a/sub/a3.txt"]]


def test_changed_cached_file_in_a_partial_set_is_fetched_again(isolated):
    isolated.put(isolated.cache, ["set-a/a1.txt", "set-a/a2.txt"], changed=("set-a/a1.txt",))
    assert data.find_data("set-a") == isolated.cache / "set-a"
    assert isolated.fetches == [["set-a/a1.txt", "set-a/sub/a3.txt"]]
    for rel in SET_A:
        assert (isolated.cache / rel).read_bytes() == CONTENT[rel]


def test_changed_cached_file_with_fetch_false_raises(isolated):
    isolated.put(isolated.cache, SET_B, changed=("set-b/b2.txt",))
    with pytest.raises(FileNotFoundError, match="fetch=False"):
        data.find_data("set-b", fetch=False)
    assert isolated.fetches == []


def test_changed_file_in_cache_named_by_env_var_falls_back_to_shared(isolated, monkeypatch):
    # $SLAMLAB_DATA and $SLAMLAB_CACHE name one folder: it is searched first, and it is the cache
    monkeypatch.setenv(data.ENV_VAR, str(isolated.cache))
    isolated.put(isolated.cache, SET_B, changed=("set-b/b1.txt",))
    isolated.put(isolated.shared, SET_B)
    assert data.find_data("set-b") == isolated.shared.resolve() / "set-b"
    assert isolated.fetches == []


def test_shared_file_is_hashed_once_per_process(isolated, monkeypatch):
    calls = []
    real = derive.file_matches

    def counting(entry, data_bytes):
        calls.append(entry.relpath)
        return real(entry, data_bytes)

    monkeypatch.setattr(derive, "file_matches", counting)
    isolated.put(isolated.shared, SET_A)
    for _ in range(3):
        assert data.find_data("set-a") == isolated.shared.resolve() / "set-a"
        assert data.find_data("set-a/a1.txt") == isolated.shared.resolve() / "set-a" / "a1.txt"
    assert sorted(calls) == sorted(SET_A)
    assert len(locate._CHECKED) == 3
    assert all(locate._CHECKED.values())
    # a file changed since (another size) is hashed again, and warns
    (isolated.shared / "set-a" / "a1.txt").write_bytes(b"edited")
    with pytest.warns(data.DataHashWarning, match="a1.txt"):
        data.find_data("set-a/a1.txt")
    assert len(locate._CHECKED) == 4
    assert isolated.fetches == []


# ----------------------------------------------------------------------------------------------
# the real registry and the real data


def _registry_problems(reg) -> list[str]:
    """Everything wrong with a registry, one line each."""
    hex64 = re.compile(r"[0-9a-f]{64}")
    commit = re.compile(r"/[0-9a-f]{40}/")
    bad = []

    def check(ok, what):
        if not ok:
            bad.append(what)

    check(len(reg.sets) > 0, "no sets")
    check(len(set(reg.set_names)) == len(reg.set_names), "a set name is registered twice")
    relpaths = [f.relpath for s in reg.sets for f in s.files]
    check(len(set(relpaths)) == len(relpaths), "a relpath is registered twice")
    for s in reg.sets:
        check(len(s.files) > 0, f"{s.name}: no files")
        for key in ("title", "source", "licence", "citation"):
            check(getattr(s, key).strip() != "", f"{s.name}: no {key}")
        check("/" not in s.name and s.name == s.name.strip(), f"{s.name!r}: not a folder name")
    for f in reg.files:
        check(hex64.fullmatch(f.sha256) is not None, f"{f.relpath}: sha256 {f.sha256!r}")
        check(isinstance(f.size, int) and f.size > 0, f"{f.relpath}: size {f.size!r}")
        check(f.url.startswith("https://raw.githubusercontent.com/"), f"{f.relpath}: url {f.url}")
        check(commit.search(f.url) is not None, f"{f.relpath}: the URL names no pinned commit")
        check(not f.path.startswith("/") and ".." not in f.path.split("/"), f"{f.relpath}: path")
        if f.derive is None:
            check(f.upstream_sha256 is None and f.upstream_size is None and f.pixels_sha256 is None,
                  f"{f.relpath}: upstream or pixel hash without a derive rule")
            continue
        check(f.upstream_sha256 is not None and hex64.fullmatch(f.upstream_sha256) is not None,
              f"{f.relpath}: derived without an upstream_sha256")
        check(f.upstream_sha256 != f.sha256, f"{f.relpath}: derived, yet upstream_sha256 == sha256")
        check(isinstance(f.upstream_size, int) and f.upstream_size > 0, f"{f.relpath}: upstream_size")
        kind = f.derive.get("kind")
        check(kind in ("lines", "png_from_pnm"), f"{f.relpath}: unknown derive kind {kind!r}")
        if kind == "lines":
            count = f.derive.get("count")
            check(isinstance(count, int) and count > 0, f"{f.relpath}: lines count {count!r}")
        elif kind == "png_from_pnm":
            check(str(f.derive.get("pnm_header")).startswith(("P5\n", "P6\n")), f"{f.relpath}: pnm_header")
            check(f.pixels_sha256 is not None and hex64.fullmatch(f.pixels_sha256) is not None,
                  f"{f.relpath}: a PNG without pixels_sha256")
            check(f.path.endswith(".png"), f"{f.relpath}: png_from_pnm but not a .png")
    return bad


def test_real_registry_is_well_formed():
    reg = data.registry()
    assert _registry_problems(reg) == []
    assert all(reg.files_under(f.relpath) == (f,) for f in reg.files)


def test_registry_check_finds_problems(tmp_path):
    raw = json.loads(_write_registry(tmp_path / "registry.json").read_text())
    raw["sets"][0]["licence"] = ""
    raw["sets"][0]["files"][0]["sha256"] = "abc"
    raw["sets"][0]["files"][1]["url"] = "https://example.org/x"
    raw["sets"][1]["files"][0]["derive"] = {"kind": "zip"}
    raw["sets"][1]["files"][1]["path"] = "b1.txt"  # set-b/b1.txt twice
    (tmp_path / "bad.json").write_text(json.dumps(raw))
    problems = _registry_problems(load_registry(tmp_path / "bad.json"))
    assert "set-a: no licence" in problems
    assert "set-a/a1.txt: sha256 'abc'" in problems
    assert "set-a/a2.txt: the URL names no pinned commit" in problems
    assert "set-b/b1.txt: derived without an upstream_sha256" in problems
    assert "set-b/b1.txt: unknown derive kind 'zip'" in problems
    assert "a relpath is registered twice" in problems
    assert _registry_problems(load_registry(tmp_path / "registry.json")) == []


@pytest.mark.realdata
def test_real_data_holds_every_registered_file(real_data):
    missing = [f.relpath for f in data.registry().files if not (real_data / f.relpath).is_file()]
    assert missing == []
    graf = data.find_data("oxford-affine/graf", fetch=False)
    assert graf.is_dir()
    assert graf.parts[-2:] == ("oxford-affine", "graf")
    assert (graf / "img1.png").is_file()
