"""The real registry end to end: a mirror made from the real data, served on 127.0.0.1, fetched into an empty cache.

The registry's upstream hashes are independent of our copies: the Oxford images' upstream PPM hashes are the
ones ``PROVENANCE.md`` lists for the original files, and every mirror file was compared with the git blob at
the pinned commit when the registry was made. So a mirror whose every file hashes to its upstream sha256 shows
that the rebuilding (PNG back to PPM, excerpts back to whole files) is exact.
"""

from __future__ import annotations

import functools
import hashlib
import http.server
import threading

import pytest

from slamlab.data import commands, fetch, locate, registry
from slamlab.data.registry import upstream_relpath

pytestmark = pytest.mark.realdata


class _Quiet(http.server.SimpleHTTPRequestHandler):
    def log_message(self, *args):
        pass


@pytest.fixture(scope="module")
def mirror(real_data, tmp_path_factory):
    root = tmp_path_factory.mktemp("mirror")
    text = commands.make_mirror(root, progress=False)
    return root, text


def test_mirror_holds_every_upstream_file_with_its_hash(mirror):
    root, text = mirror
    by_url = {f.url: f for f in registry().files}
    assert f"mirror: {len(by_url)} upstream files (0 downloaded)" in text
    for url, entry in by_url.items():
        data = (root / upstream_relpath(url)).read_bytes()
        assert hashlib.sha256(data).hexdigest() == entry.fetched_sha256, url
        assert len(data) == entry.fetched_size


def test_files_fetched_from_the_mirror_equal_the_real_ones(mirror, real_data, tmp_path, monkeypatch):
    root, _ = mirror
    httpd = http.server.ThreadingHTTPServer(("127.0.0.1", 0), functools.partial(_Quiet, directory=str(root)))
    threading.Thread(target=httpd.serve_forever, daemon=True).start()
    try:
        monkeypatch.setenv("SLAMLAB_DATA_URL", f"http://127.0.0.1:{httpd.server_address[1]}/")
        monkeypatch.setenv(locate.CACHE_ENV_VAR, str(tmp_path / "cache"))
        monkeypatch.setattr(locate, "_shared_candidates", lambda: [("$SLAMLAB_DATA", None)])
        monkeypatch.setattr(fetch, "_ANNOUNCED", set())
        # a copy, a line excerpt (KITTI 06's first 20 poses) and a PNG made from the upstream PPM (graf img1)
        for rel in ("carmen-radish-corrected/orebro-corrected.log.gz", "kitti-odometry-06-stereo/poses.txt",
                    "oxford-affine/graf/img1.png", "oxford-affine/boat/img2.png"):
            got = locate.find_data(rel)
            assert got == tmp_path / "cache" / rel
            assert got.read_bytes() == (real_data / rel).read_bytes(), rel
    finally:
        httpd.shutdown()
        httpd.server_close()
