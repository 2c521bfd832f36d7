"""Fetching registered files through pooch from a local HTTP server: what is kept, what is said (issue 41).

A tiny registry of our own (two sets, a copy, a line excerpt and a PNG made from a PPM) is served
from a temporary mirror folder on 127.0.0.1, laid out as ``<host>/<path>`` like
``python -m slamlab.data mirror`` writes it, and fetched with ``$SLAMLAB_DATA_URL`` pointing there.
"""

from __future__ import annotations

import functools
import hashlib
import http.server
import io
import json
import threading
from pathlib import Path

import numpy as np
import pytest

from slamlab.data import commands, derive, fetch, locate
from slamlab.data.__main__ import main
from slamlab.data.registry import load_registry, upstream_relpath

HOST = "https://data.example.org"


def _sha(b: bytes) -> str:
    return hashlib.sha256(b).hexdigest()


def _ppm(pixels: np.ndarray) -> bytes:
    h, w, _ = pixels.shape
    return f"P6\n# CREATOR: test\n{w} {h}\n255\n".encode() + pixels.tobytes()


@pytest.fixture
def upstream():
    """The upstream files by URL path, and the files as the registry records them."""
    rng = np.random.default_rng(0)
    pixels = rng.integers(0, 256, size=(6, 5, 3), dtype=np.uint8)
    ppm = _ppm(pixels)
    poses = b"".join(f"{i} 0 0\n".encode() for i in range(10))[:-1]  # no final newline, like the source
    return {
        "/repo/c0ffee/log.txt": b"FLASER 3 1 2 3 0 0 0\n" * 50,
        "/repo/c0ffee/poses.txt": poses,
        "/repo/c0ffee/img1.ppm": ppm,
    }, pixels


@pytest.fixture
def reg(tmp_path, upstream, monkeypatch):
    files, pixels = upstream
    header = b"P6\n# CREATOR: test\n5 6\n255\n"
    png = derive._png_bytes(pixels)
    excerpt = b"".join(files["/repo/c0ffee/poses.txt"].splitlines(keepends=True)[:4])
    raw = {"format": 1, "sets": [
        {"name": "logs", "title": "A log", "source": "repo at c0ffee", "licence": "LICENCE-LOGS",
         "citation": "CITE-LOGS", "files": [
             {"path": "log.txt", "url": HOST + "/repo/c0ffee/log.txt", "sha256": _sha(files["/repo/c0ffee/log.txt"]),
              "size": len(files["/repo/c0ffee/log.txt"])}]},
        {"name": "cams", "title": "Images", "source": "repo at c0ffee", "licence": "LICENCE-CAMS",
         "citation": "CITE-CAMS", "files": [
             {"path": "poses.txt", "url": HOST + "/repo/c0ffee/poses.txt", "sha256": _sha(excerpt),
              "size": len(excerpt), "upstream_sha256": _sha(files["/repo/c0ffee/poses.txt"]),
              "upstream_size": len(files["/repo/c0ffee/poses.txt"]), "derive": {"kind": "lines", "count": 4}},
             {"path": "img/img1.png", "url": HOST + "/repo/c0ffee/img1.ppm", "sha256": _sha(png), "size": len(png),
              "upstream_sha256": _sha(files["/repo/c0ffee/img1.ppm"]), "upstream_size": len(files["/repo/c0ffee/img1.ppm"]),
              "derive": {"kind": "png_from_pnm", "pnm_header": header.decode("latin-1")},
              "pixels_sha256": derive.pixels_sha256(pixels)}]},
    ]}
    path = tmp_path / "registry.json"
    path.write_text(json.dumps(raw))
    registry = load_registry(path)
    for module in (fetch, locate, commands):
        monkeypatch.setattr(module, "registry", lambda: registry)
    monkeypatch.setattr(fetch, "_ANNOUNCED", set())
    monkeypatch.setattr(locate, "_CHECKED", {})
    # nothing but the cache: no $SLAMLAB_DATA, no ../shared/data anywhere above the project or working folder
    monkeypatch.delenv(locate.ENV_VAR, raising=False)
    monkeypatch.setattr(locate, "_shared_candidates", lambda: [("$SLAMLAB_DATA", None)])
    monkeypatch.setenv(locate.CACHE_ENV_VAR, str(tmp_path / "cache"))
    return registry


class _Quiet(http.server.SimpleHTTPRequestHandler):
    def log_message(self, *args):
        pass


@pytest.fixture
def server(tmp_path, upstream, monkeypatch):
    """A mirror folder served on 127.0.0.1; ``$SLAMLAB_DATA_URL`` points at it."""
    files, _ = upstream
    root = tmp_path / "mirror"
    for url_path, data in files.items():
        target = root / upstream_relpath(HOST + url_path)
        target.parent.mkdir(parents=True, exist_ok=True)
        target.write_bytes(data)
    httpd = http.server.ThreadingHTTPServer(("127.0.0.1", 0), functools.partial(_Quiet, directory=str(root)))
    thread = threading.Thread(target=httpd.serve_forever, daemon=True)
    thread.start()
    monkeypatch.setenv("SLAMLAB_DATA_URL", f"http://127.0.0.1:{httpd.server_address[1]}/")
    yield root
    httpd.shutdown()
    httpd.server_close()


def _cache_files(tmp_path) -> list[str]:
    cache = tmp_path / "cache"
    return sorted(p.relative_to(cache).as_posix() for p in cache.rglob("*")) if cache.exists() else []


def test_fetch_keeps_the_layout_and_makes_derived_files(reg, server, tmp_path, upstream, capsys):
    files, pixels = upstream
    log = locate.find_data("logs/log.txt")
    assert log == tmp_path / "cache" / "logs" / "log.txt"
    assert log.read_bytes() == files["/repo/c0ffee/log.txt"]
    folder = locate.find_data("cams")
    assert folder == tmp_path / "cache" / "cams"
    # the excerpt: the first 4 upstream lines, ending in a newline
    assert (folder / "poses.txt").read_bytes() == b"0 0 0\n1 0 0\n2 0 0\n3 0 0\n"
    from PIL import Image

    with Image.open(folder / "img" / "img1.png") as im:
        np.testing.assert_array_equal(np.asarray(im), pixels)
    # only the layout is kept: no upstream copies, no temporary files
    assert _cache_files(tmp_path) == ["cams", "cams/img", "cams/img/img1.png", "cams/poses.txt", "logs", "logs/log.txt"]
    err = capsys.readouterr().err
    assert "Fetching logs/log.txt (1 kB) from http://127.0.0.1:" in err
    assert err.count("LICENCE-CAMS") == 1
    assert err.count("CITE-CAMS") == 1
    assert err.count("LICENCE-LOGS") == 1


def test_a_second_find_downloads_nothing(reg, server, tmp_path, capsys):
    locate.find_data("cams")
    capsys.readouterr()
    (server / "data.example.org").rename(server / "gone")  # the server now has nothing
    assert locate.find_data("cams/poses.txt").is_file()
    assert "Fetching" not in capsys.readouterr().err


def test_corrupted_file_on_the_mirror_is_reported_and_not_kept(reg, server, tmp_path, upstream):
    files, _ = upstream
    bad = server / upstream_relpath(HOST + "/repo/c0ffee/log.txt")
    bad.write_bytes(b"tampered\n")
    with pytest.raises(fetch.DataIntegrityError) as info:
        locate.find_data("logs/log.txt")
    msg = str(info.value)
    for part in ("'logs/log.txt'", "set logs", "/repo/c0ffee/log.txt", _sha(files["/repo/c0ffee/log.txt"]),
                 _sha(b"tampered\n"), "deleted and not used"):
        assert part in msg
    assert info.value.__cause__ is None
    assert info.value.__suppress_context__
    assert _cache_files(tmp_path) == []  # no file, no temporary file, no folder made for it


def test_server_down_gives_one_clear_offline_message(reg, tmp_path, monkeypatch):
    import socket

    with socket.socket() as s:  # a port that nothing listens on
        s.bind(("127.0.0.1", 0))
        port = s.getsockname()[1]
    monkeypatch.setenv("SLAMLAB_DATA_URL", f"http://127.0.0.1:{port}/")
    with pytest.raises(fetch.DataUnavailableError) as info:
        locate.find_data("cams/img/img1.png")
    msg = str(info.value)
    for part in ("'cams/img/img1.png'", "set cams", f"http://127.0.0.1:{port}/data.example.org/repo/c0ffee/img1.ppm",
                 "no connection", "../shared/data", "$SLAMLAB_DATA", "SLAMLAB_DATA_URL", "mirror DIR"):
        assert part in msg
    assert isinstance(info.value, FileNotFoundError)  # the realdata marker skips on it
    assert info.value.__cause__ is None
    assert info.value.__suppress_context__
    assert _cache_files(tmp_path) == []


def test_missing_file_on_the_server_names_the_http_status(reg, server):
    (server / upstream_relpath(HOST + "/repo/c0ffee/log.txt")).unlink()
    with pytest.raises(fetch.DataUnavailableError, match=r"the server answered HTTP 404"):
        locate.find_data("logs/log.txt")


def test_interrupted_fetch_leaves_nothing(reg, server, tmp_path, monkeypatch):
    import pooch

    def interrupted(self, url, output_file, pooch_obj, check_only=False):
        Path(output_file).write_bytes(b"FLASER 3 1")  # half a file, then Ctrl-C
        raise KeyboardInterrupt

    monkeypatch.setattr(pooch.HTTPDownloader, "__call__", interrupted)
    with pytest.raises(KeyboardInterrupt):
        locate.find_data("logs/log.txt")
    assert _cache_files(tmp_path) == []


def test_fetch_false_does_not_download(reg, server, tmp_path):
    with pytest.raises(FileNotFoundError, match=r"fetch=False"):
        locate.find_data("logs", fetch=False)
    assert _cache_files(tmp_path) == []


def test_mirror_rebuilds_every_upstream_file_from_the_cache(reg, server, tmp_path, upstream):
    files, _ = upstream
    locate.find_data("logs")
    locate.find_data("cams")
    text = commands.make_mirror(tmp_path / "m2", progress=False)
    assert "3 upstream files" in text
    for url_path, data in files.items():
        assert (tmp_path / "m2" / upstream_relpath(HOST + url_path)).read_bytes() == data
    # the excerpt (4 of 10 lines) cannot give back the upstream file: that one was downloaded
    assert "(1 downloaded)" in text


def test_verify_reports_matches_and_differences(reg, server, tmp_path):
    locate.find_data("logs")
    locate.find_data("cams")
    text, ok = commands.verify_report(commands.verify())
    assert ok
    assert "3 registered files checked: 3 found with matching hashes, 0 not" in text
    (tmp_path / "cache" / "logs" / "log.txt").write_bytes(b"changed")
    text, ok = commands.verify_report(commands.verify())
    assert not ok
    assert "DIFFERS      logs/log.txt" in text
    assert "2 found with matching hashes, 1 not" in text


def test_verify_accepts_a_png_written_by_another_encoder(reg, server, tmp_path, upstream):
    _, pixels = upstream
    locate.find_data("cams")
    from PIL import Image

    out = io.BytesIO()
    Image.fromarray(pixels).save(out, "PNG", compress_level=1)  # other bytes, same pixels
    (tmp_path / "cache" / "cams" / "img" / "img1.png").write_bytes(out.getvalue())
    rows = {r.relpath: r.status for r in commands.verify(["cams"])}
    assert rows["cams/img/img1.png"] == "pixels match"


def test_cli_fetch_verify_list(reg, server, tmp_path, capsys):
    assert main(["fetch", "logs"]) == 0
    assert f"logs: 1 file in {tmp_path / 'cache' / 'logs'}" in capsys.readouterr().out
    assert main(["verify", "logs"]) == 0
    assert main(["verify"]) == 1  # cams is not there yet
    out = capsys.readouterr().out
    assert "cams: 2 of 2 files MISSING" in out
    assert main(["list"]) == 0
    out = capsys.readouterr().out
    assert "logs  (1 file, 1 kB)" in out
    assert "LICENCE-LOGS" in out
    assert "not found (fetched on first use)" in out


def test_cli_fetch_failure_exits_2_with_the_message(reg, server, capsys):
    (server / upstream_relpath(HOST + "/repo/c0ffee/log.txt")).write_bytes(b"x")
    assert main(["fetch", "logs"]) == 2
    assert "error: The file fetched for 'logs/log.txt'" in capsys.readouterr().err


def test_cli_unknown_set_is_a_usage_error(reg, capsys):
    with pytest.raises(SystemExit) as info:
        main(["fetch", "nope"])
    assert info.value.code == 2
    assert "no data set 'nope'" in capsys.readouterr().err
