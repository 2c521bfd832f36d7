#!/usr/bin/env python
"""Do the stored notebook outputs come out the same on another machine? Re-run them under another set-up and compare.

Usage::

    python tools/check_reproducible.py                      # every notebook and lab, variant "alt", 2 at a time
    python tools/check_reproducible.py notebooks/09_monocular_mapping.ipynb --variant alt
    python tools/check_reproducible.py --variant alt --against build/reproducible/default   # two fresh runs
    python tools/check_reproducible.py --list-variants

Each notebook runs from top to bottom in a fresh kernel of this interpreter (as ``make notebooks``
runs it: cwd ``notebooks/``, ``MPLBACKEND=Agg``, ``SLAMLAB_PROGRESS=0``), under a *variant* of the
machine: the environment variables below, set before the kernel starts, so that numpy, OpenBLAS and
OpenCV read them. A first cell, injected into the copy in memory and left out of the comparison,
changes the state a notebook could silently depend on (OpenCV's global RNG, numpy's and Python's
global random state). Every output of every other cell is then compared with the stored one
(or with the run in ``--against``) the way nbval compares them: the same sanitiser
(``notebooks/nbval_sanitize.cfg``), streams merged, images and widget views skipped, cells tagged
``nbval-ignore-output`` skipped. Differing cells are printed with both texts; the exit status is 1
when any cell differs or fails. Executed copies are written to ``build/reproducible/<variant>/``.

Variants (the main test run, ``make test``, uses the machine as it is):

``alt`` (default)
    another OpenBLAS kernel than the machine's (``OPENBLAS_CORETYPE=Sandybridge``: no FMA, so
    every BLAS product rounds differently from Haswell/SkylakeX/Zen kernels; ``Haswell`` if the
    machine already sets Sandybridge), one BLAS and OpenMP thread, one OpenCV thread
    (``OPENCV_FOR_THREADS_NUM=1``), numpy's and OpenCV's AVX-512 code paths off where the CPU has them.
``default``
    the environment as it is (for ``--against``: two fresh runs of the same set-up).
``nosimd``
    ``alt`` plus numpy's and OpenCV's AVX2/FMA paths off as well: a stricter check than any machine
    of our kind.
"""

from __future__ import annotations

import argparse
import configparser
import os
import re
import sys
import time
from collections import defaultdict
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import nbformat

sys.path.insert(0, str(Path(__file__).resolve().parent))
from run_notebooks import (
    CELL_TIMEOUT_S,
    NOTEBOOK_DIR,
    ROOT,
    _kernel_manager,
    default_notebooks,
    output_problems,
    shutdown,
)

SANITIZE_CFG = NOTEBOOK_DIR / "nbval_sanitize.cfg"
OUT_DIR = ROOT / "build" / "reproducible"
#: Output keys nbval 0.11 leaves out of the comparison (nbval.plugin.IPyNbFile.skip_compare, without nbdime).
SKIP_COMPARE = ("metadata", "traceback", "prompt_number", "output_type", "name", "execution_count",
                "application/vnd.jupyter.widget-view+json", "image/png", "image/jpeg")
IGNORE_TAGS = ("nbval-ignore-output", "nbval-skip")
#: The first cell of every run (not compared): state a notebook must not depend on is moved.
PRELUDE = ("import random as _r, numpy as _np, cv2 as _cv2\n"
           "_cv2.randu(_np.empty((17, 17)), 0.0, 1.0); _cv2.setRNGSeed(4242); _cv2.randu(_np.empty((5, 5)), 0.0, 1.0)\n"
           "_np.random.seed(777); _np.random.rand(13); _r.seed(99); _r.random()\n"
           "del _r, _np, _cv2")


def _cpu_flags() -> set[str]:
    try:
        text = Path("/proc/cpuinfo").read_text()
    except OSError:
        return set()
    m = re.search(r"^flags\s*:(.*)$", text, re.MULTILINE)
    return set(m.group(1).split()) if m else set()


def _numpy_dispatch(prefixes: tuple[str, ...]) -> list[str]:
    """numpy's dispatchable CPU features starting with ``prefixes`` that this CPU has (others may not be named)."""
    from numpy._core._multiarray_umath import __cpu_dispatch__, __cpu_features__

    return [f for f in __cpu_dispatch__ if f.startswith(prefixes) and __cpu_features__.get(f)]


def variant_env(name: str) -> dict[str, str]:
    """The environment variables of variant ``name`` (see the module docstring)."""
    if name == "default":
        return {}
    if name not in ("alt", "nosimd"):
        raise ValueError(f"unknown variant {name!r}; expected one of default, alt, nosimd")
    coretype = "Haswell" if os.environ.get("OPENBLAS_CORETYPE", "").lower() == "sandybridge" else "Sandybridge"
    env = {"OPENBLAS_CORETYPE": coretype, "OPENBLAS_NUM_THREADS": "1", "OMP_NUM_THREADS": "1",
           "OPENCV_FOR_THREADS_NUM": "1"}
    npy_off = _numpy_dispatch(("AVX512", "X86_V4"))
    # OpenCV warns about a name its CPU detection did not find: name AVX-512 only where the CPU has it
    has_avx512 = any(f.startswith("avx512") for f in _cpu_flags())
    cv_off = ["AVX512_SKX", "AVX512_COMMON", "AVX512_ICL", "AVX512_CLX", "AVX512_CNL"] if has_avx512 else []
    if name == "nosimd":
        npy_off += _numpy_dispatch(("AVX2", "FMA3", "X86_V3"))
        cv_off += ["AVX2", "FMA3", "FP16", "AVX"]
    if npy_off:
        env["NPY_DISABLE_CPU_FEATURES"] = " ".join(sorted(set(npy_off)))
    if cv_off:
        env["OPENCV_CPU_DISABLE"] = ",".join(cv_off)
    return env


def sanitize_patterns() -> list[tuple[str, str]]:
    """The (regex, replacement) pairs of nbval's sanitiser file, in order."""
    cfg = configparser.ConfigParser()
    cfg.read(SANITIZE_CFG)
    return [(cfg[s]["regex"], cfg[s]["replace"]) for s in cfg.sections()]


def comparable(outputs, patterns) -> dict[str, list]:
    """A cell's outputs as nbval compares them: streams merged, keys flattened, skipped keys out, sanitised."""
    from nbval.plugin import coalesce_streams, transform_streams_for_comparison

    def clean(value):
        if isinstance(value, list):
            value = "".join(value)
        if isinstance(value, str):
            for regex, repl in patterns:
                value = re.sub(regex, repl, value)
        return value

    flat = defaultdict(list)
    outs = transform_streams_for_comparison(coalesce_streams([nbformat.from_dict(o) for o in outputs]))
    for out in outs:
        for key, value in out.items():
            if key in SKIP_COMPARE:
                continue
            if key == "data":
                for mime, data in value.items():
                    if mime not in SKIP_COMPARE:
                        flat[mime].append(clean(data))
            else:
                flat[key].append(clean(value))
    return dict(flat)


def execute(path: Path, env: dict[str, str]):
    """Run a copy of ``path`` (prelude first) in a fresh kernel with ``env`` added; the executed copy."""
    from nbclient import NotebookClient

    nb = nbformat.read(path, as_version=4)
    nb.cells.insert(0, nbformat.v4.new_code_cell(PRELUDE))
    km = _kernel_manager()
    client = NotebookClient(nb, km=km, timeout=CELL_TIMEOUT_S, allow_errors=True, record_timing=False,
                            store_widget_state=True, resources={"metadata": {"path": str(NOTEBOOK_DIR)}})
    full_env = {**os.environ, "MPLBACKEND": "Agg", "SLAMLAB_PROGRESS": "0", "SLAMLAB_LAB_ATTEMPTS": "memory", **env}
    try:
        client.execute(env=full_env)
    finally:
        shutdown(km)
    nb.cells.pop(0)
    return nb


def compare(stored, fresh, patterns) -> list[str]:
    """Cells whose compared outputs differ: one report string each (both texts)."""
    code_s = [c for c in stored.cells if c.cell_type == "code"]
    code_f = [c for c in fresh.cells if c.cell_type == "code"]
    if len(code_s) != len(code_f):
        return [f"different numbers of code cells: {len(code_s)} stored, {len(code_f)} fresh"]
    diffs = []
    for n, (cs, cf) in enumerate(zip(code_s, code_f, strict=True)):
        tags = cs.metadata.get("tags", [])
        if any(t in tags for t in IGNORE_TAGS):
            continue
        a, b = comparable(cs.outputs, patterns), comparable(cf.outputs, patterns)
        if a != b:
            first = cs.source.strip().splitlines()[0][:70] if cs.source.strip() else ""
            lines = [f"Cell {n} ({first!r}) differs:"]
            for key in sorted(set(a) | set(b)):
                if a.get(key) != b.get(key):
                    lines.append(f"  [{key}] reference:\n" + _indent(a.get(key)))
                    lines.append(f"  [{key}] this run:\n" + _indent(b.get(key)))
            diffs.append("\n".join(lines))
    return diffs


def _indent(values) -> str:
    text = "\n".join(str(x) for x in (values or ["<none>"]))
    return "\n".join("      " + line for line in text.splitlines())


def check(path: Path, env: dict[str, str], variant: str, against: Path | None, patterns) -> tuple[str, list[str], float]:
    start = time.perf_counter()
    fresh = execute(path, env)
    wall = time.perf_counter() - start
    rel = path.relative_to(NOTEBOOK_DIR)
    out = OUT_DIR / variant / rel
    out.parent.mkdir(parents=True, exist_ok=True)
    nbformat.write(fresh, out)
    problems = output_problems(fresh, str(rel))
    ref_path = path if against is None else against / rel
    problems += compare(nbformat.read(ref_path, as_version=4), fresh, patterns)
    return str(rel), problems, wall


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("notebooks", nargs="*", type=Path, help="notebooks to check (default: every notebook and lab)")
    parser.add_argument("--variant", default="alt", help="alt (default), default or nosimd")
    parser.add_argument("--against", type=Path, help="compare with the executed copies in this folder, not the stored outputs")
    parser.add_argument("--jobs", type=int, default=2, help="notebooks run at the same time (default 2)")
    parser.add_argument("--list-variants", action="store_true", help="print each variant's environment and exit")
    args = parser.parse_args(argv)
    if args.list_variants:
        for name in ("default", "alt", "nosimd"):
            print(f"{name}: {variant_env(name) or '(the environment as it is)'}")
        return 0
    env = variant_env(args.variant)
    paths = [p.resolve() for p in args.notebooks] or default_notebooks()
    patterns = sanitize_patterns()
    print(f"variant {args.variant}: {env or '(the environment as it is)'}; reference: "
          f"{args.against or 'the stored outputs'}", flush=True)
    start = time.perf_counter()
    failed = 0
    with ThreadPoolExecutor(max_workers=max(1, args.jobs)) as pool:
        futures = [pool.submit(check, p, env, args.variant, args.against, patterns) for p in paths]
        for fut in futures:
            name, problems, wall = fut.result()
            print(f"{name}: {'same' if not problems else 'DIFFERS'} ({wall:.0f} s)", flush=True)
            for problem in problems:
                print("  " + problem.replace("\n", "\n  "), flush=True)
            failed += bool(problems)
    print(f"{len(paths) - failed} of {len(paths)} notebooks reproduce under variant {args.variant} "
          f"({time.perf_counter() - start:.0f} s)")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
