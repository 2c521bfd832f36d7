#!/usr/bin/env python
"""Peak memory of a student's kernel: run each notebook in a fresh kernel and read its peak RSS.

Usage::

    python tools/kernel_memory.py                       # every notebooks/*.ipynb (and notebooks/labs/)
    python tools/kernel_memory.py notebooks/05_stereo_slam.ipynb

Each notebook runs as ``make notebooks`` runs it (this interpreter's ipykernel, cwd ``notebooks/``),
nothing is written back; a last cell added to the copy in memory prints the kernel's
``ru_maxrss`` (peak resident set, Linux: KiB) and that of the processes it waited for. Prints a
Markdown table for environment.md.
"""

from __future__ import annotations

import os
import sys
import time
from pathlib import Path

import nbformat

sys.path.insert(0, str(Path(__file__).resolve().parent))
from run_notebooks import NOTEBOOK_DIR, _kernel_manager, shutdown

PROBE = ("import resource as _r\n"
         "print('PEAK_RSS_KIB', _r.getrusage(_r.RUSAGE_SELF).ru_maxrss, _r.getrusage(_r.RUSAGE_CHILDREN).ru_maxrss)")


def peak_rss_mib(path: Path) -> tuple[float, float, float]:
    """(kernel peak RSS MiB, largest child's peak RSS MiB, wall seconds) of running ``path``."""
    from nbclient import NotebookClient

    nb = nbformat.read(path, as_version=4)
    nb.cells.append(nbformat.v4.new_code_cell(PROBE))
    km = _kernel_manager()
    client = NotebookClient(nb, km=km, timeout=600, allow_errors=False, record_timing=False,
                            resources={"metadata": {"path": str(NOTEBOOK_DIR)}})
    t0 = time.perf_counter()
    try:
        client.execute()
    finally:
        shutdown(km)
    wall = time.perf_counter() - t0
    text = "".join(o.get("text", "") for o in nb.cells[-1].outputs)
    _, own, children = text.split()
    return int(own) / 1024, int(children) / 1024, wall


def main(argv: list[str]) -> int:
    os.environ["MPLBACKEND"] = "Agg"
    os.environ["SLAMLAB_PROGRESS"] = "0"
    paths = [Path(a) for a in argv] or sorted(NOTEBOOK_DIR.glob("*.ipynb")) + sorted(NOTEBOOK_DIR.glob("labs/*.ipynb"))
    print("| notebook | kernel peak RSS [MiB] | largest child [MiB] | wall [s] |")
    print("|---|---:|---:|---:|")
    for p in paths:
        own, child, wall = peak_rss_mib(p)
        print(f"| `{p.name}` | {own:.0f} | {child:.0f} | {wall:.0f} |", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
