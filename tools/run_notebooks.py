#!/usr/bin/env python
"""Re-execute slamlab notebooks in place, or check the stored ones (``--check``).

Usage::

    python tools/run_notebooks.py                 # every notebooks/*.ipynb and labs/*_lab.ipynb
    python tools/run_notebooks.py notebooks/01_kalman_filters.ipynb
    python tools/run_notebooks.py --check         # validate stored notebooks only

Execution runs each notebook with a fresh python kernel of *this* interpreter
(cwd = ``notebooks/``, ``MPLBACKEND=Agg``, ``SLAMLAB_PROGRESS=0``, 600 s per cell), then fails, naming
the notebook and the cell, if any cell has an error output or printed to
stderr (a warning printed by a cell is a bug to fix in the code, not to hide).
On success it strips volatile metadata (widget state, execution timings,
interpreter version), renumbers execution counts in order and writes the
notebook back with its outputs: they are nbval's reference.

``--check`` performs the same validation on the stored notebooks without
running them: every code cell executed, in order from 1; no error or stderr
output; no widget state or timing metadata.
"""

from __future__ import annotations

import argparse
import os
import sys
import time
from pathlib import Path

import nbformat

ROOT = Path(__file__).resolve().parent.parent
NOTEBOOK_DIR = ROOT / "notebooks"
CELL_TIMEOUT_S = 600

#: Per-cell metadata keys written by Jupyter/nbclient that change run to run.
VOLATILE_CELL_METADATA = ("execution", "collapsed", "scrolled", "ExecuteTime")
#: Notebook-level metadata keys that hold volatile state.
VOLATILE_NB_METADATA = ("widgets",)
#: ``language_info`` keys that depend on the machine.
VOLATILE_LANGUAGE_INFO = ("version",)


def default_notebooks() -> list[Path]:
    """Every ``notebooks/*.ipynb``, then every lab ``notebooks/labs/*_lab.ipynb``, sorted by name."""
    return sorted(NOTEBOOK_DIR.glob("*.ipynb")) + sorted((NOTEBOOK_DIR / "labs").glob("*_lab.ipynb"))


def _cell_label(index: int, cell) -> str:
    first = cell.source.strip().splitlines()[0] if cell.source.strip() else ""
    return f"cell {index} ({first[:60]!r})"


def output_problems(nb, name: str) -> list[str]:
    """Problems in a notebook's outputs: errors and stderr streams."""
    problems = []
    for index, cell in enumerate(nb.cells):
        if cell.cell_type != "code":
            continue
        for out in cell.get("outputs", []):
            if out.output_type == "error":
                problems.append(f"{name}: {_cell_label(index, cell)} raised {out.ename}: {out.evalue}")
            elif out.output_type == "stream" and out.name == "stderr":
                text = "".join(out.text).strip().splitlines()
                problems.append(
                    f"{name}: {_cell_label(index, cell)} wrote to stderr: {text[0] if text else ''!r}"
                )
    return problems


def check_notebook(nb, name: str) -> list[str]:
    """Every problem that makes a stored notebook unfit for nbval (empty list when clean)."""
    problems = output_problems(nb, name)
    for key in VOLATILE_NB_METADATA:
        if key in nb.metadata:
            problems.append(f"{name}: notebook metadata holds volatile {key!r} (run tools/run_notebooks.py)")
    expected = 1
    for index, cell in enumerate(nb.cells):
        for key in VOLATILE_CELL_METADATA:
            if key in cell.metadata:
                problems.append(f"{name}: {_cell_label(index, cell)} has volatile metadata {key!r}")
        if cell.cell_type != "code":
            continue
        if not cell.source.strip():
            problems.append(f"{name}: {_cell_label(index, cell)} is an empty code cell")
            continue
        if cell.execution_count != expected:
            problems.append(
                f"{name}: {_cell_label(index, cell)} has execution count {cell.execution_count}, "
                f"expected {expected} (not executed in order)"
            )
        expected += 1
    return problems


def strip_volatile(nb) -> None:
    """Remove widget state and run-dependent metadata; renumber execution counts in place."""
    for key in VOLATILE_NB_METADATA:
        nb.metadata.pop(key, None)
    info = nb.metadata.get("language_info")
    if info is not None:
        for key in VOLATILE_LANGUAGE_INFO:
            info.pop(key, None)
    count = 0
    for cell in nb.cells:
        for key in VOLATILE_CELL_METADATA:
            cell.metadata.pop(key, None)
        if cell.cell_type != "code":
            continue
        count += 1
        cell.execution_count = count
        for out in cell.outputs:
            if out.output_type == "execute_result":
                out.execution_count = count


def _kernel_manager():
    """A kernel manager that runs ipykernel on this very interpreter (not a user kernelspec)."""
    import ipykernel.kernelspec
    from jupyter_client.kernelspec import KernelSpecManager
    from jupyter_client.manager import AsyncKernelManager

    class CurrentEnvKernelSpecManager(KernelSpecManager):
        def get_kernel_spec(self, kernel_name):
            return self.kernel_spec_class(
                resource_dir=ipykernel.kernelspec.RESOURCES, **ipykernel.kernelspec.get_kernel_dict()
            )

    return AsyncKernelManager(kernel_name="python3", kernel_spec_manager=CurrentEnvKernelSpecManager())


def shutdown(km) -> None:
    """Stop a kernel that nbclient was handed (it only shuts down kernels it started itself)."""
    from jupyter_core.utils import run_sync

    if run_sync(km.is_alive)():
        run_sync(km.shutdown_kernel)(now=True)


def execute_notebook(path: Path) -> list[str]:
    """Run ``path`` in place; return problems (the file is only written when there are none)."""
    from nbclient import NotebookClient
    from nbclient.exceptions import CellExecutionError

    nb = nbformat.read(path, as_version=4)
    km = _kernel_manager()
    client = NotebookClient(
        nb,
        km=km,
        timeout=CELL_TIMEOUT_S,
        allow_errors=True,  # collect every error, report them all with cell numbers below
        record_timing=False,
        store_widget_state=True,  # nbclient needs it for interactive Output widgets; stripped on write
        resources={"metadata": {"path": str(NOTEBOOK_DIR)}},
    )
    try:
        client.execute()
    except CellExecutionError as err:  # pragma: no cover - allow_errors=True reports in outputs
        return [f"{path.name}: {err}"]
    finally:
        shutdown(km)
    problems = output_problems(nb, path.name)
    if problems:
        return problems
    strip_volatile(nb)
    nbformat.validate(nb)
    nbformat.write(nb, path)
    return []


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("notebooks", nargs="*", type=Path, help="notebooks to run (default: all, sorted)")
    parser.add_argument("--check", action="store_true", help="only validate the stored notebooks")
    args = parser.parse_args(argv)
    paths = args.notebooks or default_notebooks()
    if not paths:
        print(f"no notebooks found in {NOTEBOOK_DIR}", file=sys.stderr)
        return 1
    os.environ["MPLBACKEND"] = "Agg"
    os.environ["SLAMLAB_PROGRESS"] = "0"  # no progress bars in the stored outputs (nbval's reference)
    os.environ["SLAMLAB_LAB_ATTEMPTS"] = "memory"  # the labs count attempts per kernel: no file, counts from 1
    failed = []
    for path in paths:
        if args.check:
            problems = check_notebook(nbformat.read(path, as_version=4), path.name)
            status = "ok" if not problems else "FAILED"
            print(f"{path.name}: {status}")
        else:
            start = time.perf_counter()
            problems = execute_notebook(path)
            wall = time.perf_counter() - start
            print(f"{path.name}: {'ok' if not problems else 'FAILED'} in {wall:.1f} s", flush=True)
        for problem in problems:
            print("  " + problem, file=sys.stderr)
        failed += problems
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
