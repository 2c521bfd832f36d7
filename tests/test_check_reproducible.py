"""`make reproducible` (tools/check_reproducible.py): compares as nbval does, flags what nbval would flag."""

from __future__ import annotations

import importlib.util
import sys
from pathlib import Path

import nbformat

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "tools"))
_spec = importlib.util.spec_from_file_location("check_reproducible", ROOT / "tools" / "check_reproducible.py")
cr = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(cr)


def _nb(*cells):
    nb = nbformat.v4.new_notebook()
    for source, outputs, tags in cells:
        c = nbformat.v4.new_code_cell(source)
        c.outputs = [nbformat.from_dict(o) for o in outputs]
        if tags:
            c.metadata["tags"] = list(tags)
        nb.cells.append(c)
    return nb


def _stream(text):
    return {"output_type": "stream", "name": "stdout", "text": text}


def _result(text, png=None):
    data = {"text/plain": text}
    if png:
        data["image/png"] = png
    return {"output_type": "execute_result", "execution_count": 1, "data": data, "metadata": {}}


def test_a_changed_number_is_reported_with_both_texts():
    stored = _nb(("print(x)", [_stream("keyframes 5\n")], ()))
    fresh = _nb(("print(x)", [_stream("keyframes 6\n")], ()))
    diffs = cr.compare(stored, fresh, cr.sanitize_patterns())
    assert len(diffs) == 1
    assert "keyframes 5" in diffs[0]
    assert "keyframes 6" in diffs[0]


def test_what_nbval_ignores_is_ignored():
    pats = cr.sanitize_patterns()
    stored = _nb(("a", [_result("<Figure size 640x480 with 1 Axes>", png="AAAA")], ()),
                 ("b", [_stream("obj at 0x7f00aa\n")], ()),
                 ("c", [_stream("wall time 3.2 s\n")], ("nbval-ignore-output",)),
                 ("d", [_stream("one "), _stream("line\n")], ()))
    fresh = _nb(("a", [_result("<Figure size 640x480 with 1 Axes>", png="BBBB")], ()),  # PNGs: skipped
                ("b", [_stream("obj at 0x55bb00\n")], ()),  # addresses: sanitised
                ("c", [_stream("wall time 9.9 s\n")], ("nbval-ignore-output",)),  # tagged
                ("d", [_stream("one line\n")], ()))  # streams merged
    assert cr.compare(stored, fresh, pats) == []


def test_alt_variant_changes_the_blas_kernel_and_threads(monkeypatch):
    monkeypatch.delenv("OPENBLAS_CORETYPE", raising=False)
    env = cr.variant_env("alt")
    assert env["OPENBLAS_CORETYPE"] == "Sandybridge"
    assert env["OPENBLAS_NUM_THREADS"] == "1"
    assert env["OPENCV_FOR_THREADS_NUM"] == "1"
    monkeypatch.setenv("OPENBLAS_CORETYPE", "SANDYBRIDGE")  # a machine that already sets it: use another
    assert cr.variant_env("alt")["OPENBLAS_CORETYPE"] == "Haswell"
    assert cr.variant_env("default") == {}
