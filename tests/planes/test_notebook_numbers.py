"""Notebook 10: every number in its prose is one that a cell prints (issue 28's "every prose number printed").

Numbers in the markdown cells (outside LaTeX, code spans, figure/section/reference labels and source ids) must
each equal, at the prose's precision, a number in the stored outputs of the code cells. A necessary check, not a
sufficient one (a small integer is easy to find); the closing note of the notebook says so.
"""

import json
import re
from pathlib import Path

NB = Path(__file__).resolve().parents[2] / "notebooks" / "10_plane_slam_3d.ipynb"

_SKIP = [
    r"\$\$.*?\$\$", r"\$[^$]*\$", r"`[^`]*`",                       # LaTeX, code spans
    r"\b(Figs?\.?|§|issue|Ch\.|Table)\s*\d+(\s*(,|and|\u2013|-)\s*\d+)*", r"\[\d+(,\s*\d+)*\]",  # labels, references
    r"\(\w+, (19|20)\d\d\)", r"\b00[0-4]\b", r"\b[23]-D\b", r"S[EO]\(3\)", r"^#+\s*\d+(\.\d+)?", r"\bi5-\d+U\b", r"UTM-30LX",
]
_NUM = re.compile(r"(?<![\w.])\d{1,3}(?: \d{3})+(?![\d.])|(?<![\w.])\d+(?:\.\d+)?(?:e-?\d+)?(?![\w])")


def _cells():
    return json.loads(NB.read_text(encoding="utf-8"))["cells"]


def prose_numbers():
    out = []
    for c in _cells():
        if c["cell_type"] != "markdown":
            continue
        text = "".join(c["source"])
        for pat in _SKIP:
            text = re.sub(pat, " ", text, flags=re.DOTALL | re.MULTILINE)
        out += [m.group(0) for m in _NUM.finditer(text)]
    return out


def printed_numbers():
    text = []
    for c in _cells():
        for o in c.get("outputs", []) if c["cell_type"] == "code" else []:
            text.append("".join(o.get("text", "")) + "".join(o.get("data", {}).get("text/plain", "")))
    return {float(m.group(0)) for m in re.finditer(r"-?\d+(?:\.\d+)?(?:e-?\d+)?", "\n".join(text))}


def _found(num: str, printed) -> bool:
    x = float(num.replace(" ", ""))
    d = len(num.split(".")[1]) if "." in num else 0
    return any(round(abs(p), d) == round(x, d) for p in printed)


def test_every_prose_number_is_printed():
    printed = printed_numbers()
    missing = sorted({n for n in prose_numbers() if not _found(n, printed)})
    assert not missing, f"numbers in notebook 10's prose that no cell prints: {missing}"
