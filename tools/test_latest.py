#!/usr/bin/env python
"""Dependency drift: run every notebook and lab under the newest versions ``pyproject.toml`` allows.

Usage::

    python tools/test_latest.py                 # every notebook and lab (make test-latest)
    python tools/test_latest.py --only 02 05    # notebooks/02_*.ipynb, notebooks/labs/02_*.ipynb, and 05's
    python tools/test_latest.py --jobs 2 --keep # two pytest-xdist workers; keep the venv (its path is printed)

``constraints.txt`` (the lock) keeps courses safe; ``pyproject.toml``'s bounds are wider. This tool makes a
temporary venv with the interpreter that runs it, installs ``-e '.[test]'`` and ``-e ./grading`` there
*without* the lock (so pip takes the newest release each bound allows), and runs nbval over
``notebooks/*.ipynb`` and ``notebooks/labs/*.ipynb`` (the instructor's sources, as ``make test`` collects
them) with ``make test``'s nbval flags, in that venv. It then prints:

- each differing cell: notebook, the cell's index in the ``.ipynb`` (0-based, nbval's code-cell number
  beside it), the output key and its first differing line, stored vs new (or the error a cell raised);
- the packages whose installed version differs from the lock.

Exit status 0 when no cell differs, 1 otherwise. Not part of ``make test``; run it before ``make lock``, on a
clean working tree (the venv installs the working tree: the report names the changed files of ``slamlab/`` and
``notebooks/`` when a cell differs, since a cell may differ because of them rather than the versions).
The differences are recorded by a small pytest plugin (this module, loaded with ``-p test_latest``) that
wraps nbval's output comparison, so the stored and new texts are the ones nbval compared (sanitised).
"""

from __future__ import annotations

import argparse
import json
import os
import re
import subprocess
import sys
import tempfile
import time
from dataclasses import dataclass
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
NOTEBOOK_DIR = ROOT / "notebooks"
#: The nbval flags of ``make test`` (Makefile, PYTEST_ARGS).
NBVAL_ARGS = ["--nbval", "--nbval-current-env", "--nbval-sanitize-with", "notebooks/nbval_sanitize.cfg",
              "-p", "no:cacheprovider"]
#: Distributions left out of the version comparison (the project itself and the installer).
SKIP = {"slamlab", "slamlab-grading", "pip", "setuptools", "wheel", "distribute"}
#: Environment variable naming the folder the plugin writes its records to.
RECORD_ENV = "SLAMLAB_TEST_LATEST_RECORD"
MAX_LINE = 100
_ANSI = re.compile(r"\x1b\[[0-9;]*m")


# ----------------------------------------------------------------------------------------- versions
def canonical(name: str) -> str:
    """A distribution name in PEP 503 normal form ("Foo_Bar.baz" -> "foo-bar-baz")."""
    return re.sub(r"[-_.]+", "-", name.strip()).lower()


def _marker_holds(marker: str) -> bool:
    """Whether an environment marker holds for this interpreter (True when ``packaging`` is absent)."""
    try:
        from packaging.markers import Marker
    except ImportError:  # pragma: no cover - packaging comes with pip's and pytest's venvs
        return True
    return Marker(marker).evaluate()


def parse_constraints(text: str, marker_holds=_marker_holds) -> dict[str, str]:
    """``{name: version}`` of the ``name==version[; marker]`` lines whose marker holds (comments skipped)."""
    pins = {}
    for raw in text.splitlines():
        line = raw.split("#", 1)[0].strip()
        if not line:
            continue
        spec, _, marker = line.partition(";")
        if marker.strip() and not marker_holds(marker.strip()):
            continue
        name, sep, version = spec.partition("==")
        if sep:
            pins[canonical(name)] = version.strip()
    return pins


def parse_freeze(text: str) -> dict[str, str]:
    """``{name: version}`` from ``pip freeze`` output (editable and direct-URL lines skipped)."""
    return parse_constraints("\n".join(line for line in text.splitlines()
                                       if "==" in line and not line.startswith("-e")),
                             marker_holds=lambda _m: True)


def version_diff(lock: dict[str, str], new: dict[str, str]) -> list[tuple[str, str | None, str | None]]:
    """``(name, lock version, new version)`` of every package whose version differs (None: absent), by name."""
    names = sorted((set(lock) | set(new)) - SKIP)
    return [(n, lock.get(n), new.get(n)) for n in names if lock.get(n) != new.get(n)]


def format_version_diff(diff) -> str:
    """The version differences as a text table (or a sentence when there are none)."""
    if not diff:
        return "every installed package has the lock's version"
    width = max(len("package"), *(len(n) for n, _, _ in diff))
    lines = [f"{'package':<{width}}  {'lock':>14}  {'latest':>14}", f"{'-' * width}  {'-' * 14}  {'-' * 14}"]
    lines += [f"{n:<{width}}  {old or '—':>14}  {new or '—':>14}" for n, old, new in diff]
    return "\n".join(lines)


# ----------------------------------------------------------------------------------------- cells
@dataclass(frozen=True)
class CellDiff:
    """One differing output (or failing cell) of one notebook."""

    notebook: str          # path relative to the repository
    code_cell: int         # nbval's "Cell N": N-th code cell, 0-based
    cell_index: int | None # index in the notebook's cell list, 0-based (None when unknown)
    key: str               # output key ("stdout", "text/plain", ...) or "error"
    line: int | None       # first differing line, 1-based (None for an error)
    stored: str
    new: str


def split_nodeid(nodeid: str) -> tuple[str, int]:
    """``"notebooks/x.ipynb::Cell 13"`` -> ``("notebooks/x.ipynb", 13)``."""
    m = re.fullmatch(r"(.+\.ipynb)::Cell (\d+)", nodeid)
    if m is None:
        raise ValueError(f"`nodeid` is not an nbval cell id: {nodeid!r}")
    return m.group(1), int(m.group(2))


def first_difference(stored: str, new: str) -> tuple[int, str, str] | None:
    """The first line (1-based) where two texts differ, with both lines ("<none>" past an end); None if equal."""
    a, b = stored.splitlines(), new.splitlines()
    for i in range(max(len(a), len(b))):
        x = a[i] if i < len(a) else "<none>"
        y = b[i] if i < len(b) else "<none>"
        if x != y:
            return i + 1, x, y
    return None


def code_cell_indices(notebook: Path) -> list[int]:
    """The ``.ipynb`` index of every code cell, in order (nbval's "Cell N" is entry N)."""
    cells = json.loads(Path(notebook).read_text(encoding="utf-8"))["cells"]
    return [i for i, c in enumerate(cells) if c["cell_type"] == "code"]


def _text(value) -> str:
    if isinstance(value, list):
        value = "".join(map(str, value))
    return value if isinstance(value, str) else json.dumps(value, sort_keys=True)


def cells_from_records(records: list[dict], root: Path = ROOT) -> list[CellDiff]:
    """The differing cells from the plugin's records, sorted by notebook and cell.

    A record is ``{"nodeid", "key", "stored", "new"}`` (one mismatching output) or
    ``{"nodeid", "failed": true, "message"}`` (a failed cell); a failed cell with no mismatch
    recorded raised an error, and is reported with its message.
    """
    mismatched = {r["nodeid"] for r in records if "key" in r}
    index_cache: dict[str, list[int]] = {}
    out = []
    for r in records:
        if "key" not in r and (not r.get("failed") or r["nodeid"] in mismatched):
            continue
        notebook, n = split_nodeid(r["nodeid"])
        if notebook not in index_cache:
            try:
                index_cache[notebook] = code_cell_indices(root / notebook)
            except (OSError, ValueError, KeyError):
                index_cache[notebook] = []
        idx = index_cache[notebook]
        cell_index = idx[n] if n < len(idx) else None
        if "key" in r:
            stored, new = _text(r["stored"]), _text(r["new"])
            first = first_difference(stored, new) or (None, stored, new)
            out.append(CellDiff(notebook, n, cell_index, r["key"], first[0], first[1], first[2]))
        else:
            out.append(CellDiff(notebook, n, cell_index, "error", None, "", r.get("message", "")))
    return sorted(set(out), key=lambda c: (c.notebook, c.code_cell, c.key))


def _clip(line: str, start: int = 0) -> str:
    """``line`` cut to ``MAX_LINE`` characters, from ``start`` (marked "…" where cut)."""
    if len(line) <= MAX_LINE:
        return line
    head = "…" if start > 0 else ""
    body = line[start:start + MAX_LINE - len(head)]
    return head + (body[:-1] + "…" if start + len(body) < len(line) else body)


def _window(stored: str, new: str) -> int:
    """Where to start showing two long lines so that their first differing character is in view."""
    pairs = enumerate(zip(stored, new, strict=False))
    col = next((i for i, (a, b) in pairs if a != b), min(len(stored), len(new)))
    if col < MAX_LINE - 10:
        return 0
    return max(0, min(col - MAX_LINE // 2, max(len(stored), len(new)) - (MAX_LINE - 1)))


def uncommitted_changes(root: Path = ROOT) -> list[str]:
    """Tracked files under ``slamlab/`` and ``notebooks/`` changed in the working tree (``git status``; [] without git)."""
    try:
        out = subprocess.run(["git", "status", "--porcelain", "--untracked-files=no", "--", "slamlab", "notebooks"],
                             cwd=root, capture_output=True, text=True, check=True).stdout
    except (OSError, subprocess.CalledProcessError):
        return []
    return [line[3:] for line in out.splitlines() if line.strip()]


def format_report(cells: list[CellDiff], diff, n_notebooks: int, changed: list[str] = ()) -> str:
    """The report: one block per differing cell, then the packages whose versions differ from the lock.

    ``changed``: files of the working tree that differ from the last commit; when a cell differs they are named,
    since the cell may differ because of them rather than because of the versions.
    """
    lines = []
    if cells:
        n_cells = len({(c.notebook, c.code_cell) for c in cells})
        n_nb = len({c.notebook for c in cells})
        lines.append(f"{n_cells} cell(s) differ in {n_nb} of {n_notebooks} notebook(s):")
        for c in cells:
            where = f"cell {c.cell_index}" if c.cell_index is not None else "cell ?"
            head = f"{c.notebook} {where} (nbval Cell {c.code_cell})"
            if c.key == "error":
                lines += [f"  {head}: error", f"      {_clip(c.new)}"]
            else:
                start = _window(c.stored, c.new)
                lines += [f"  {head}, {c.key} line {c.line}" + (f" from column {start + 1}" if start else "") + ":",
                          f"      stored: {_clip(c.stored, start)}", f"      new:    {_clip(c.new, start)}"]
        if changed:
            lines += ["changed in the working tree since the last commit (a cell may differ because of them, not of",
                      "the versions): " + ", ".join(changed)]
    else:
        lines.append(f"no cell differs in {n_notebooks} notebook(s)")
    lines += ["", "packages whose version differs from constraints.txt:", format_version_diff(diff)]
    return "\n".join(lines)


def read_records(folder: Path) -> list[dict]:
    """Every record the plugin wrote into ``folder`` (one JSON object a line, one file per process)."""
    records = []
    for f in sorted(Path(folder).glob("*.jsonl")):
        records += [json.loads(line) for line in f.read_text(encoding="utf-8").splitlines() if line.strip()]
    return records


# ----------------------------------------------------------------------------------------- pytest plugin
def _record(obj: dict) -> None:
    folder = os.environ.get(RECORD_ENV)
    if folder:
        with open(Path(folder) / f"{os.getpid()}.jsonl", "a", encoding="utf-8") as f:
            f.write(json.dumps(obj) + "\n")


def pytest_configure(config) -> None:
    """Wrap nbval's comparison so that each mismatch (stored, new) is recorded."""
    from nbval.plugin import IPyNbCell

    original = IPyNbCell.format_output_compare
    if getattr(original, "_test_latest", False):
        return

    def format_output_compare(self, key, left, right):
        _record({"nodeid": self.nodeid, "key": key, "stored": left, "new": right})
        return original(self, key, left, right)

    format_output_compare._test_latest = True
    IPyNbCell.format_output_compare = format_output_compare


def pytest_runtest_logreport(report) -> None:
    """Record every failed cell with the last line of its failure text."""
    if report.failed and "::Cell " in report.nodeid:
        text = [ln.strip() for ln in _ANSI.sub("", report.longreprtext).splitlines() if ln.strip()]
        _record({"nodeid": report.nodeid, "failed": True, "message": text[-1] if text else report.when})


# ----------------------------------------------------------------------------------------- main
def select_notebooks(only: list[str] | None) -> list[Path]:
    """``notebooks/*.ipynb`` then ``notebooks/labs/*.ipynb`` (all of them, or those starting with an ``only``)."""
    paths = sorted(NOTEBOOK_DIR.glob("*.ipynb")) + sorted((NOTEBOOK_DIR / "labs").glob("*.ipynb"))
    if only:
        paths = [p for p in paths if any(p.name.startswith(f"{o}_") for o in only)]
        if not paths:
            raise ValueError(f"`--only` {only} selects no notebook")
    return paths


def _run(cmd, **kwargs) -> subprocess.CompletedProcess:
    print("+", " ".join(map(str, cmd)), flush=True)
    return subprocess.run(cmd, check=True, cwd=ROOT, **kwargs)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--only", nargs="+", metavar="NN", help="only these chapters (and their labs)")
    parser.add_argument("--jobs", type=int, default=1, help="pytest-xdist workers (-n; 1: no xdist)")
    parser.add_argument("--keep", action="store_true", help="keep the temporary venv")
    args = parser.parse_args(argv)
    if args.jobs < 1:
        parser.error("--jobs must be >= 1")
    notebooks = select_notebooks(args.only)

    tmp = Path(tempfile.mkdtemp(prefix="slamlab-test-latest-"))
    venv, records = tmp / "venv", tmp / "records"
    records.mkdir()
    py = venv / "bin" / "python"
    t0 = time.perf_counter()
    try:
        _run([sys.executable, "-m", "venv", venv])
        _run([py, "-m", "pip", "install", "-q", "--upgrade", "pip"])
        _run([py, "-m", "pip", "install", "-q", "-e", ".[test]", "-e", "./grading"])
        freeze = subprocess.run([py, "-m", "pip", "freeze"], check=True, cwd=ROOT, capture_output=True,
                                text=True).stdout
        diff = version_diff(parse_constraints((ROOT / "constraints.txt").read_text()), parse_freeze(freeze))
        env = {**os.environ, "MPLBACKEND": "Agg", "SLAMLAB_PROGRESS": "0", "SLAMLAB_LAB_ATTEMPTS": "memory",
               "SLAMLAB_GRADING_CACHE": str(tmp / "grading-cache"), RECORD_ENV: str(records),
               "PYTHONPATH": os.pathsep.join(filter(None, [str(ROOT / "tools"), os.environ.get("PYTHONPATH")]))}
        xdist = ["-n", str(args.jobs), "--dist", "loadfile"] if args.jobs > 1 else []
        cmd = [py, "-m", "pytest", *[p.relative_to(ROOT) for p in notebooks], *NBVAL_ARGS, "-p", "test_latest",
               "-q", "--tb=no", *xdist]
        print("+", " ".join(map(str, cmd)), flush=True)
        status = subprocess.run(cmd, check=False, cwd=ROOT, env=env).returncode
        cells = cells_from_records(read_records(records))
    finally:
        if args.keep:
            print(f"venv kept: {venv}")
        else:
            import shutil

            shutil.rmtree(tmp, ignore_errors=True)
    print(f"\n== test-latest: {len(notebooks)} notebook(s), {time.perf_counter() - t0:.0f} s")
    print(format_report(cells, diff, len(notebooks), uncommitted_changes()))
    if status not in (0, 1):
        print(f"pytest stopped with status {status} (not a cell comparison: see its output above)")
    return 0 if status == 0 and not cells else 1


if __name__ == "__main__":
    sys.exit(main())
