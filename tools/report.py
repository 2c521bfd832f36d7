#!/usr/bin/env python
"""Run a chapter notebook with other parameters into ``reports/`` (papermill).

Usage::

    python tools/report.py 01 CV_RUNS=10 SEED=7         # -> reports/01_kalman_filters-CV_RUNS=10-SEED=7.ipynb
    make report NB=01 PARAMS="CV_RUNS=10 SEED=7"

Each notebook has one cell tagged ``parameters`` (its defaults give the stored outputs);
papermill adds a cell after it with the values given here. A value is read as a Python
literal (``10``, ``0.5``, ``"orb"``, ``(1, 2)``), else kept as a string (``detector=orb``).
Reports run one after another: concurrent kernels race for ports.
"""

from __future__ import annotations

import argparse
import ast
import os
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
NOTEBOOK_DIR = ROOT / "notebooks"
REPORT_DIR = ROOT / "reports"


def find_notebook(number: str) -> Path:
    """``notebooks/NN_*.ipynb`` for ``NN`` (``"1"`` and ``"01"`` both work)."""
    if not number.isdigit():
        raise SystemExit(f"NB must be a chapter number such as 05; got {number!r}")
    hits = sorted(NOTEBOOK_DIR.glob(f"{int(number):02d}_*.ipynb"))
    if len(hits) != 1:
        raise SystemExit(f"no single notebook numbered {int(number):02d} in {NOTEBOOK_DIR}: {hits}")
    return hits[0]


def parse_params(items: list[str]) -> dict[str, object]:
    """``["A=1", "detector=orb"]`` -> ``{"A": 1, "detector": "orb"}``."""
    out: dict[str, object] = {}
    for item in items:
        name, sep, text = item.partition("=")
        if not sep or not name.isidentifier():
            raise SystemExit(f"parameters are NAME=value pairs; got {item!r}")
        try:
            out[name] = ast.literal_eval(text)
        except (ValueError, SyntaxError):
            out[name] = text
    return out


def run_report(number: str, params: dict[str, object], out_dir: Path = REPORT_DIR) -> Path:
    """Execute notebook ``number`` with ``params``; return the path of the executed copy."""
    import papermill as pm
    from papermill.translators import PythonTranslator, papermill_translators

    class TupleTranslator(PythonTranslator):
        """papermill's Python translator writes a tuple as its str in quotes; this one writes a tuple."""

        @classmethod
        def translate(cls, val):
            if isinstance(val, tuple):
                return "(" + "".join(f"{cls.translate(x)}, " for x in val) + ")"
            return super().translate(val)

    papermill_translators.register("python", TupleTranslator)
    src = find_notebook(number)
    suffix = "".join(f"-{k}={v}" for k, v in params.items()).replace("/", "_").replace(" ", "")
    out_dir.mkdir(parents=True, exist_ok=True)
    dst = out_dir / f"{src.stem}{suffix}.ipynb"
    os.environ.setdefault("MPLBACKEND", "Agg")
    pm.execute_notebook(str(src), str(dst), parameters=params, cwd=str(NOTEBOOK_DIR), kernel_name="python3",
                        progress_bar=False)
    return dst


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("number", help="chapter number, e.g. 05")
    parser.add_argument("params", nargs="*", help="NAME=value pairs")
    parser.add_argument("--out", type=Path, default=REPORT_DIR, help="output folder (default: reports/)")
    args = parser.parse_args(argv)
    dst = run_report(args.number, parse_params(args.params), args.out)
    print(dst.relative_to(ROOT) if dst.is_relative_to(ROOT) else dst)
    return 0


if __name__ == "__main__":
    sys.exit(main())
