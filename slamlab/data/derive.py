"""Derived files: how a registered file is made from its upstream file, and back for a mirror.

Two rules occur in the registry (its ``derive`` field):

- ``{"kind": "lines", "count": n}``: the first ``n`` lines of the upstream text file, ending
  in a newline (KITTI's ``poses.txt`` excerpts).
- ``{"kind": "png_from_pnm", "pnm_header": ...}``: the upstream binary PPM/PGM image stored
  as a lossless PNG (the Oxford affine images). The PNG's bytes depend on the zlib that wrote
  it, so the file is also accepted when its decoded pixels hash to ``pixels_sha256``.

:func:`make_derived` goes forward (fetch, then derive); :func:`upstream_candidates` goes back
(a mirror rebuilds the upstream bytes from a derived file where the rule loses nothing, and the
caller keeps a candidate only when its sha256 is the upstream one).
"""

from __future__ import annotations

import hashlib
import io
import re

import numpy as np

from .registry import DataFile

__all__ = ["file_matches", "make_derived", "pixels_sha256", "sha256_bytes", "upstream_candidates"]

_PNM = re.compile(rb"P([56])\s+(?:#[^\n]*\n\s*)*(\d+)\s+(?:#[^\n]*\n\s*)*(\d+)\s+(?:#[^\n]*\n\s*)*(\d+)\s")


def sha256_bytes(data: bytes) -> str:
    """Hex sha256 of ``data``.

    Parameters
    ----------
    data : bytes
        Any bytes.

    Returns
    -------
    str
        64 hex digits.
    """
    return hashlib.sha256(data).hexdigest()


def pixels_sha256(pixels: np.ndarray) -> str:
    """The hash of an image's pixels, shape and dtype included (independent of the file's encoding).

    Parameters
    ----------
    pixels : ndarray
        A decoded image, e.g. ``(H, W)`` or ``(H, W, 3)`` ``uint8``.

    Returns
    -------
    str
        64 hex digits.

    Examples
    --------
    >>> pixels_sha256(np.zeros((2, 3), np.uint8)) == pixels_sha256(np.zeros((3, 2), np.uint8))
    False
    """
    a = np.ascontiguousarray(pixels)
    return sha256_bytes(f"{a.shape}|{a.dtype.str}|".encode() + a.tobytes())


def _pnm_pixels(data: bytes, header: bytes) -> np.ndarray:
    m = _PNM.match(data)
    if m is None or data[: m.end()] != header:
        raise ValueError("the upstream image does not start with the registered PNM header")
    colour, width, height, maxval = m.group(1) == b"6", int(m.group(2)), int(m.group(3)), int(m.group(4))
    if maxval != 255:
        raise ValueError(f"only 8-bit PNM images are registered; got maxval {maxval}")
    pixels = np.frombuffer(data, np.uint8, offset=m.end())
    shape = (height, width, 3) if colour else (height, width)
    if pixels.size != int(np.prod(shape)):
        raise ValueError(f"the PNM image holds {pixels.size} bytes of pixels for a {shape} image")
    return pixels.reshape(shape)


def _png_pixels(data: bytes) -> np.ndarray:
    from PIL import Image  # matplotlib's dependency; loaded only here

    with Image.open(io.BytesIO(data)) as im:
        return np.asarray(im)


def _png_bytes(pixels: np.ndarray) -> bytes:
    from PIL import Image

    out = io.BytesIO()
    # optimize=True: the setting the shared copies were written with (their bytes come out identical)
    Image.fromarray(pixels).save(out, "PNG", optimize=True)
    return out.getvalue()


def make_derived(entry: DataFile, upstream: bytes) -> bytes:
    """The registered file's bytes made from the upstream file's bytes by ``entry.derive``.

    Parameters
    ----------
    entry : DataFile
        A derived entry of the registry.
    upstream : bytes
        The upstream file (already checked against ``entry.upstream_sha256``).

    Returns
    -------
    bytes

    Examples
    --------
    >>> from slamlab.data.registry import DataFile
    >>> e = DataFile("s", "p.txt", "https://h/p.txt", "", 0, derive={"kind": "lines", "count": 2})
    >>> make_derived(e, b"a\\nb\\nc")
    b'a\\nb\\n'
    """
    rule = entry.derive or {}
    kind = rule.get("kind")
    if kind == "lines":
        out = b"".join(upstream.splitlines(keepends=True)[: int(rule["count"])])
        return out if out.endswith(b"\n") else out + b"\n"
    if kind == "png_from_pnm":
        return _png_bytes(_pnm_pixels(upstream, rule["pnm_header"].encode("latin-1")))
    raise ValueError(f"{entry.relpath}: unknown derive rule {rule!r}")


def file_matches(entry: DataFile, data: bytes) -> bool:
    """Whether ``data`` is the registered file: its sha256, or for an image its pixels' hash.

    Parameters
    ----------
    entry : DataFile
        The registered file.
    data : bytes
        A file's contents.

    Returns
    -------
    bool
    """
    if sha256_bytes(data) == entry.sha256:
        return True
    if entry.pixels_sha256 is not None:
        try:
            return pixels_sha256(_png_pixels(data)) == entry.pixels_sha256
        except (OSError, ValueError, SyntaxError):  # not a readable image (PIL raises these): not the file
            return False
    return False


def upstream_candidates(entry: DataFile, data: bytes) -> list[bytes]:
    """Byte strings that may be the upstream file of ``entry``, rebuilt from the file's ``data``.

    A copy gives itself; a line excerpt gives itself and itself without its final newline (the
    upstream when the excerpt kept every line); a PNG gives the PNM header plus its pixels. The
    caller keeps the one whose sha256 is ``entry.fetched_sha256``.

    Parameters
    ----------
    entry : DataFile
        The registered file.
    data : bytes
        Its contents as found.

    Returns
    -------
    list of bytes
    """
    rule = entry.derive
    if rule is None:
        return [data]
    if rule["kind"] == "lines":
        return [data, data[:-1]] if data.endswith(b"\n") else [data]
    if rule["kind"] == "png_from_pnm":
        pixels = _png_pixels(data)
        return [rule["pnm_header"].encode("latin-1") + np.ascontiguousarray(pixels).tobytes()]
    return []
