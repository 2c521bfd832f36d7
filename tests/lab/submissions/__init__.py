"""The submissions the autograde test hands in for every lab (issue 43: what students really hand in).

Each lab's module ``labNN.py`` lists :class:`Submission` s: a correct one done by methods other than
the instructor's solution (written independently here), a correct one with another allowed seed or
setting, and at least two named mistakes. The test adds the untouched student version ("empty").
A submission replaces the code between ``### BEGIN SOLUTION`` and ``### END SOLUTION`` of the named
solution cells (grade-id parts "t1".."t5", "e1".."e3"); cells it does not name keep the instructor's
solution, except the explorations of a mistake submission, which it leaves not done (``raise
NotImplementedError()``: a mistake submission runs no experiment it is not about, so the autograde test stays
quick). ``lost`` names the autograded check cells (by the same parts) that must score zero, and
:func:`lost_cells` adds those explorations; every other check cell must score its full points.
"""

from __future__ import annotations

import importlib
import textwrap
from dataclasses import dataclass, field
from pathlib import Path

import nbformat


@dataclass(frozen=True)
class Submission:
    """One handed-in notebook of a lab.

    Parameters
    ----------
    kind : str
        "independent", "other_seed" or "mistake_<name>".
    description : str
        What the student did.
    bodies : dict
        Grade-id part ("t1", "e2") -> the code between the solution markers (unindented; the test indents it).
    lost : tuple of str
        The check cells (by part) that must score zero.
    """

    kind: str
    description: str
    bodies: dict[str, str] = field(default_factory=dict)
    lost: tuple[str, ...] = ()


def of_lab(num: str) -> list[Submission]:
    """The submissions of lab ``num`` ("08"), from ``labNN.py`` (an empty list when it has none yet)."""
    try:
        mod = importlib.import_module(f"{__name__}.lab{num}")
    except ModuleNotFoundError:
        return []
    return list(mod.SUBMISSIONS)


def replace_solution(source: str, body: str) -> str:
    """``source`` with the code between ``### BEGIN SOLUTION`` and ``### END SOLUTION`` replaced by ``body``
    (indented like the markers)."""
    begin, end = source.index("### BEGIN SOLUTION"), source.index("### END SOLUTION")
    indent = source[source.rindex("\n", 0, begin) + 1:begin] if "\n" in source[:begin] else source[:begin]
    text = textwrap.indent(textwrap.dedent(body).strip("\n"), indent)
    return source[:begin] + "### BEGIN SOLUTION\n" + text + "\n" + indent + source[end:]


def _not_done(lab_nb, sub: Submission) -> dict[str, str]:
    """The explorations a mistake submission leaves not done: every exploration it has no body for."""
    if not sub.kind.startswith("mistake_"):
        return {}
    parts = {c.metadata["nbgrader"]["grade_id"].split("_")[1] for c in lab_nb.cells
             if c.metadata.get("nbgrader", {}).get("grade_id", "").endswith("_solution")}
    return {p: "raise NotImplementedError()" for p in parts if p.startswith("e") and p not in sub.bodies}


def lost_cells(lab: Path, sub: Submission) -> set[str]:
    """The check cells (by part) that submission ``sub`` of ``lab`` must lose: its ``lost`` and its not-done
    explorations."""
    return set(sub.lost) | set(_not_done(nbformat.read(lab, as_version=4), sub))


def build(lab: Path, sub: Submission) -> nbformat.NotebookNode:
    """The notebook of submission ``sub`` of ``lab`` (from the instructor's source: nbgrader replaces the check
    cells by the source's at autograde anyway)."""
    nb = nbformat.read(lab, as_version=4)
    bodies = {**_not_done(nb, sub), **sub.bodies}
    unknown = set(sub.bodies)
    for c in nb.cells:
        gid = c.metadata.get("nbgrader", {}).get("grade_id", "")
        part = gid.split("_")[1] if gid.count("_") >= 2 else ""
        if gid.endswith("_solution") and c.cell_type == "code" and part in bodies:
            c.source = replace_solution(c.source, bodies[part])
            unknown.discard(part)
    if unknown:
        raise ValueError(f"{lab.name}: no solution cells for {sorted(unknown)}")
    return nb
