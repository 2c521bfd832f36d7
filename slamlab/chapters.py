"""The chapter map: which notebook rebuilds which source section, with which subpackage.

Source documents (in ``shared/seeds``): 000 Rodikov 2010 (stereo SLAM, Kalman
filters, SURF, kd-trees), 002 Kazmin 2017 (plane-based Monte Carlo SLAM),
003 diploma 2019 (monocular mapping), 004 research summary (correlation
localisation and Hough SLAM).
"""

from __future__ import annotations

from dataclasses import dataclass

__all__ = ["CHAPTERS", "SHARED_TOPICS", "Chapter", "chapter_table", "get_chapter", "overview_vs_source"]


@dataclass(frozen=True)
class Chapter:
    """One notebook of the lab and what it rebuilds.

    Attributes
    ----------
    number : int
        The notebook number ``NN`` (numbered once, never renumbered).
    title : str
        Short English title.
    notebook : str
        File name in ``notebooks/``, ``NN_topic.ipynb``.
    subpackages : tuple of str
        The slamlab subpackages holding the chapter's code.
    sources : str
        Source document and sections, e.g. ``"000 §1.2, §3.6; 003 §2.1.1"``.
    status : {"available", "planned"}
        Whether the notebook exists yet.
    """

    number: int
    title: str
    notebook: str
    subpackages: tuple[str, ...]
    sources: str
    status: str

    def __str__(self) -> str:
        return f"{self.number:02d} {self.title} ({self.notebook}; {self.sources}; {self.status})"


#: Every chapter in order.
CHAPTERS: tuple[Chapter, ...] = (
    Chapter(0, "Overview: the SLAM problem and the lab", "00_overview.ipynb",
            ("slamlab.plotting",), "000 §1, §1.1", "available"),
    Chapter(1, "Kalman filter variants: KF, EKF, UKF", "01_kalman_filters.ipynb",
            ("slamlab.filters",), "000 §1.2, §3.6; 003 §2.1.1", "available"),
    Chapter(2, "Feature detectors and descriptors", "02_feature_detectors.ipynb",
            ("slamlab.features",), "000 §1.4; 003 §3", "available"),
    Chapter(3, "Feature matching: kd-tree and BBF", "03_feature_matching.ipynb",
            ("slamlab.features", "slamlab.kdtree"), "000 §1.4.3; 003 §3", "available"),
    Chapter(4, "Landmark stores: kd-tree vs multi kd-tree", "04_landmark_stores.ipynb",
            ("slamlab.kdtree",), "000 §3.4, §4", "available"),
    Chapter(5, "Stereo SLAM", "05_stereo_slam.ipynb",
            ("slamlab.stereo",), "000 §3", "available"),
    Chapter(6, "Correlation localisation on a known map", "06_correlation_localisation.ipynb",
            ("slamlab.correlation",), "004", "available"),
    Chapter(7, "Hough-transform SLAM", "07_hough_slam.ipynb",
            ("slamlab.hough",), "004", "available"),
    Chapter(8, "Probabilistic localisation: Markov, MCL", "08_probabilistic_localisation.ipynb",
            ("slamlab.localisation",), "003 §1.2.4, §2.2", "available"),
    Chapter(9, "Monocular mapping", "09_monocular_mapping.ipynb",
            ("slamlab.mono",), "003 §2.1, §4", "available"),
    Chapter(10, "Plane-based 3-D particle-filter SLAM", "10_plane_slam_3d.ipynb",
            ("slamlab.planes",), "002", "available"),
)

#: Library-only topics used by several chapters: (title, where used, subpackage, sources, status).
SHARED_TOPICS: tuple[tuple[str, str, str, str, str], ...] = (
    ("Trajectory evaluation: ATE, RPE", "(library; used by 05, 09)", "slamlab.evaluation", "003 §5.2",
     "available"),
)


def get_chapter(number: int) -> Chapter:
    """The chapter with the given notebook number.

    Parameters
    ----------
    number : int
        Notebook number of the chapter.

    Returns
    -------
    Chapter
        Its entry in ``CHAPTERS``; ``ValueError`` for an unknown number.

    Examples
    --------
    >>> get_chapter(1).notebook
    '01_kalman_filters.ipynb'
    """
    for chapter in CHAPTERS:
        if chapter.number == number:
            return chapter
    raise ValueError(f"`number` must be one of {[c.number for c in CHAPTERS]}; got {number!r}")


def _fixed_width(head: tuple[str, ...], rows: list[tuple[str, ...]]) -> list[str]:
    widths = [max(len(r[i]) for r in [head, *rows]) for i in range(len(head))]

    def fmt(r):
        return "  ".join(cell.ljust(w) for cell, w in zip(r, widths, strict=True)).rstrip()

    return [fmt(head), "  ".join("-" * w for w in widths), *(fmt(r) for r in rows)]


def chapter_table() -> str:
    """The chapter map as two fixed-width text tables (printed in ``00_overview``).

    The first gives each chapter's title, sources and status; the second, under it after a
    blank line, its notebook and the slamlab subpackages holding its code. Split in two, every
    line fits JupyterLab's output area (110 characters).

    Examples
    --------
    >>> print(chapter_table().splitlines()[0])
    NN  chapter                                    source                      status
    >>> max(len(line) for line in chapter_table().splitlines()) <= 110
    True
    """
    what = [(f"{c.number:02d}", c.title, c.sources, c.status) for c in CHAPTERS]
    what += [("--", title, sources, status) for title, _, _, sources, status in SHARED_TOPICS]
    where = [(f"{c.number:02d}", c.notebook, ", ".join(c.subpackages)) for c in CHAPTERS]
    where += [("--", used, package) for _, used, package, _, _ in SHARED_TOPICS]
    lines = _fixed_width(("NN", "chapter", "source", "status"), what)
    lines += ["", *_fixed_width(("NN", "notebook", "subpackage"), where)]
    return "\n".join(lines)


#: What notebook 00 takes from 000 §1, §1.1 and what it does with it: (item, 000, here).
OVERVIEW_VS_SOURCE: tuple[tuple[str, str, str], ...] = (
    ("definition of SLAM (§1)", "given, with requirements on pose and map", "summarised in English"),
    ("five subtasks (§1)", "listed in this order", "same order; numbered in the figure"),
    ("standard scheme (§1.1, Fig. 2)", "a figure (its image is not in our text)", "redrawn from §1.1's description"),
)


def overview_vs_source() -> str:
    """Notebook 00's *Ours vs the source* table (000 §1, §1.1): nothing is measured, so it is a fixed table.

    >>> print(overview_vs_source().splitlines()[1].split())
    ['item', '000', 'here']
    """
    from ._table import format_table

    return format_table(["item", "000", "here"], OVERVIEW_VS_SOURCE, title="Ours vs the source (000 §1, §1.1)")
