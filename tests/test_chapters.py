"""The chapter map agrees with the notebooks folder and SPEC's numbering."""

from __future__ import annotations

import dataclasses
import importlib.util
import re
from pathlib import Path

import pytest

from slamlab import chapters

NOTEBOOKS = Path(__file__).resolve().parent.parent / "notebooks"


def test_numbers_unique_and_in_order():
    numbers = [c.number for c in chapters.CHAPTERS]
    assert numbers == list(range(len(numbers)))
    assert numbers[0] == 0
    assert numbers[-1] == 10


def test_notebook_names_match_numbers():
    names = [c.notebook for c in chapters.CHAPTERS]
    assert len(set(names)) == len(names)
    for c in chapters.CHAPTERS:
        assert re.fullmatch(rf"{c.number:02d}_[a-z0-9_]+\.ipynb", c.notebook), c.notebook


def test_status_values():
    assert {c.status for c in chapters.CHAPTERS} <= {"available", "planned"}
    available = [c.number for c in chapters.CHAPTERS if c.status == "available"]
    assert available[:2] == [0, 1]


@pytest.mark.parametrize(
    "chapter", [c for c in chapters.CHAPTERS if c.status == "available"], ids=lambda c: c.notebook
)
def test_available_chapter_has_notebook_and_code(chapter):
    assert (NOTEBOOKS / chapter.notebook).is_file(), f"{chapter.notebook} is marked available but missing"
    for name in chapter.subpackages:
        assert importlib.util.find_spec(name) is not None, f"{name} of chapter {chapter.number} not found"


def test_every_notebook_is_an_available_chapter():
    listed = {c.notebook: c for c in chapters.CHAPTERS}
    for path in sorted(NOTEBOOKS.glob("*.ipynb")):
        assert path.name in listed, f"{path.name} is not in slamlab.chapters.CHAPTERS"
        assert listed[path.name].status == "available", f"{path.name} exists but is marked planned"


def test_chapters_are_frozen():
    with pytest.raises(dataclasses.FrozenInstanceError):
        chapters.CHAPTERS[0].title = "x"


def test_subpackages_and_sources_named():
    for c in chapters.CHAPTERS:
        assert c.subpackages
        assert all(name.startswith("slamlab.") for name in c.subpackages)
        assert re.match(r"00[0234]\b", c.sources), c.sources


def test_get_chapter():
    assert chapters.get_chapter(5).title == "Stereo SLAM"
    with pytest.raises(ValueError, match=r"`number` must be one of \[0, 1, .*10\]; got 12"):
        chapters.get_chapter(12)


def test_chapter_str():
    assert str(chapters.get_chapter(1)) == (
        "01 Kalman filter variants: KF, EKF, UKF (01_kalman_filters.ipynb; 000 §1.2, §3.6; 003 §2.1.1; available)"
    )


def test_chapter_table_is_fixed_width():
    table = chapters.chapter_table()
    n = len(chapters.CHAPTERS) + len(chapters.SHARED_TOPICS)
    what, where = table.split("\n\n")  # two tables: title, sources, status; then notebook and subpackages
    for block, head in ((what, ["NN", "chapter", "source", "status"]), (where, ["NN", "notebook", "subpackage"])):
        lines = block.splitlines()
        assert len(lines) == 2 + n
        assert lines[0].split() == head
        assert set(lines[1]) == {"-", " "}
        # every column starts at the same offset in every row
        starts = [m.start() for m in re.finditer(r"(?<=  )\S", lines[0])]
        for line in lines[2:]:
            for start in starts:
                assert line[start - 1] == " "
                assert line[start] != " "
    for c in chapters.CHAPTERS:
        row = next(line for line in what.splitlines() if line.startswith(f"{c.number:02d}  "))
        assert c.title in row
        assert row.endswith(c.status)
        row = next(line for line in where.splitlines() if line.startswith(f"{c.number:02d}  "))
        assert c.notebook in row
        assert row.endswith(", ".join(c.subpackages))
    assert "slamlab.evaluation" in where
    # every line fits JupyterLab's output area
    assert max(len(line) for line in table.splitlines()) <= 110
    assert max(len(line) for line in chapters.overview_vs_source().splitlines()) <= 110
