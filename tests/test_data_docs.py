"""The README's data table and the site's data pages follow slamlab's data registry (and nothing else)."""

from __future__ import annotations

import importlib.util
import re
import sys
from pathlib import Path

import pytest

from slamlab.data import data_table_markdown, registry
from slamlab.data.registry import format_size

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "tools"))


def _load(name: str):
    spec = importlib.util.spec_from_file_location(name, ROOT / "tools" / f"{name}.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


data_table = _load("data_table")
build_site = _load("build_site")


def _unescape(markdown: str) -> str:
    r"""The text a reader sees of escaped Markdown (``mbicp\_tro`` -> ``mbicp_tro``)."""
    return re.sub(r"\\(.)", r"\1", markdown)


def test_readme_data_table_is_the_registry_table():
    readme = (ROOT / "README.md").read_text(encoding="utf-8")
    assert readme.count(data_table.BEGIN) == 1
    assert readme.count(data_table.END) == 1
    block = readme.split(data_table.BEGIN, 1)[1].split(data_table.END, 1)[0]
    assert block == data_table_markdown(), "README.md's data table is stale: run python tools/data_table.py"
    for name in registry().set_names:
        assert f"| `{name}` |" in block
    total = format_size(sum(s.size for s in registry().sets))
    assert f"make data    # fetches the real data sets ({total})" in readme


def test_data_table_check_flags_a_stale_readme(tmp_path, monkeypatch, capsys):
    readme = (ROOT / "README.md").read_text(encoding="utf-8")
    stale = readme.replace("| **all** |", "| **everything** |")
    assert stale != readme
    copy = tmp_path / "README.md"
    copy.write_text(stale, encoding="utf-8")
    monkeypatch.setattr(data_table, "README", copy)
    assert data_table.main(["--check"]) == 1
    assert "run python tools/data_table.py" in capsys.readouterr().err
    assert copy.read_text(encoding="utf-8") == stale  # --check changes nothing
    assert data_table.main([]) == 0
    assert copy.read_text(encoding="utf-8") == readme
    assert data_table.main(["--check"]) == 0


def test_data_table_refuses_a_readme_without_markers():
    with pytest.raises(ValueError, match="data-table"):
        data_table.expected_readme("# slamlab\n\nno table here\n")


def test_data_pages_one_page_per_set_from_the_registry(tmp_path, monkeypatch):
    # the pages come from the registry alone: no data folder is looked at
    monkeypatch.setenv("SLAMLAB_DATA", str(tmp_path / "nowhere"))
    reg = registry()
    names = build_site.data_pages(tmp_path / "data")
    assert names == list(reg.set_names)
    assert sorted(p.name for p in (tmp_path / "data").iterdir()) == sorted([*(f"{n}.md" for n in names), "index.md"])

    index = (tmp_path / "data" / "index.md").read_text(encoding="utf-8")
    assert index.startswith((ROOT / "docs" / "site" / "data.md").read_text(encoding="utf-8").splitlines()[0])
    assert _unescape(data_table_markdown()) in _unescape(index)
    toctree = index.split("```{toctree}", 1)[1].split("```", 1)[0]
    assert [line for line in toctree.splitlines()[3:] if line] == names
    assert "PROVENANCE" not in index

    for s in reg.sets:
        page = (tmp_path / "data" / f"{s.name}.md").read_text(encoding="utf-8")
        seen = _unescape(page)
        assert page.startswith(f"# {s.name}\n")
        for text in (s.title, s.source, s.licence, s.citation, s.note):
            assert text in seen
        assert f"python -m slamlab.data fetch {s.name}" in page
        rows = [line for line in page.splitlines() if line.startswith("| `")]
        assert len(rows) == len(s.files)
        for f, row in zip(s.files, rows, strict=True):
            assert row.startswith(f"| `{f.path}` | {format_size(f.size)} |")
            assert f"]({f.url})" in row
            assert f"`{f.sha256}`" in row
            if f.derive is None:
                assert row.endswith("| as is |")
            elif f.derive["kind"] == "lines":
                assert f"first {f.derive['count']} lines of the upstream file" in row
                assert f.upstream_sha256 in row
            else:
                assert "the upstream PPM/PGM stored as lossless PNG; same pixels" in row
                assert f.upstream_sha256 in row


def test_data_pages_keep_the_table_cells_and_no_raw_html():
    # a '|' in a cell would split the row; '<x>' would be read as an HTML tag and vanish from the page
    s = registry().set("oxford-affine")
    assert "<sequence>" in s.source
    page = build_site.data_set_page(s)
    assert "\\<sequence>" in page
    assert " <sequence>" not in page
    assert build_site._md_text("a|b <c> d_e") == "a\\|b \\<c> d\\_e"
    header = next(line for line in page.splitlines() if line.startswith("| file |"))
    for row in (line for line in page.splitlines() if line.startswith("| `")):
        assert row.count(" | ") == header.count(" | ")
