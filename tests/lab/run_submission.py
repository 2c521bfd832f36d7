#!/usr/bin/env python
"""Build one lab's submission (tests/lab/submissions/labNN.py) from the instructor source and run it as nbgrader's
autograder would (hidden tests in, ``NBGRADER_EXECUTION=autograde``); print each check cell's outcome.

Usage: ``.venv/bin/python tests/lab/run_submission.py NN KIND`` (KIND a submission's kind, or "all").
A quick check for whoever writes submissions; the autograde test (tests/lab/test_labs.py) runs nbgrader itself.
"""

from __future__ import annotations

import os
import sys
import tempfile
import time
from pathlib import Path

from nbclient import NotebookClient

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "tests" / "lab"))
from submissions import build, lost_cells, of_lab


def run(num: str, kind: str) -> None:
    lab = next((ROOT / "notebooks" / "labs").glob(f"{num}_*_lab.ipynb"))
    subs = [s for s in of_lab(num) if kind in ("all", s.kind)]
    if not subs:
        raise SystemExit(f"lab {num} has no submission {kind!r}")
    for sub in subs:
        nb = build(lab, sub)
        with tempfile.TemporaryDirectory() as tmp:
            os.environ["NBGRADER_EXECUTION"] = "autograde"
            os.environ["SLAMLAB_LAB_ATTEMPTS"] = str(Path(tmp) / "lab_attempts.json")
            os.environ.setdefault("MPLBACKEND", "Agg")
            t0 = time.perf_counter()
            NotebookClient(nb, timeout=600, allow_errors=True, resources={"metadata": {"path": tmp}}).execute()
            took = time.perf_counter() - t0
        print(f"== lab {num} {sub.kind}: {sub.description} ({took:.0f} s)")
        lost = []
        for c in nb.cells:
            gid = c.metadata.get("nbgrader", {}).get("grade_id", "")
            errors = [o for o in c.get("outputs", []) if o.output_type == "error"]
            if gid.endswith("_check"):
                part = gid.split("_")[1]
                if errors:
                    lost.append(part)
                status = f"LOST ({errors[0].ename}: {errors[0].evalue.splitlines()[0][:150]})" if errors else "scored"
                print(f"  {part}: {status}")
            elif errors and c.cell_type == "code":
                print(f"  ERROR outside a check cell ({gid or 'no id'}): {errors[0].ename}: {errors[0].evalue[:200]}")
        expected = sorted(lost_cells(lab, sub))  # a mistake's explorations without a body are left not done
        ok = sorted(lost) == expected
        print(f"  expected lost {expected}, lost {sorted(lost)}: {'OK' if ok else 'MISMATCH'}")


if __name__ == "__main__":
    if len(sys.argv) != 3:
        raise SystemExit(__doc__)
    run(sys.argv[1], sys.argv[2])
