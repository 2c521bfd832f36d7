"""CONVENTIONS, imports: `import slamlab` stays light; no cycle; only sim, the studies and the labs reach sim.

The graph is read from the source (every ``import`` statement, at module level and inside
functions, since an import hidden in a function still closes a cycle when it runs).
"""

from __future__ import annotations

import ast
import json
import subprocess
import sys
from pathlib import Path

import pytest

PKG = Path(__file__).resolve().parent.parent / "slamlab"
HEAVY = ("cv2", "ipywidgets", "matplotlib.pyplot")


def _module_names() -> dict[str, Path]:
    mods = {}
    for f in PKG.rglob("*.py"):
        parts = f.relative_to(PKG.parent).with_suffix("").parts
        if parts[-1] == "__init__":
            parts = parts[:-1]
        mods[".".join(parts)] = f
    return mods


def _imports(name: str, path: Path, mods: dict[str, Path]) -> set[str]:
    """The slamlab modules that ``name`` imports (the longest module prefix of each imported name)."""
    package = name.split(".") if path.name == "__init__.py" else name.split(".")[:-1]
    found = set()
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        if isinstance(node, ast.Import):
            targets = [a.name for a in node.names]
        elif isinstance(node, ast.ImportFrom):
            base = package[: len(package) - node.level + 1] if node.level else []
            mod = ".".join([*base, node.module] if node.module else base)
            targets = [f"{mod}.{a.name}" for a in node.names] + [mod]
        else:
            continue
        for t in targets:
            while t and t not in mods:
                t = t.rpartition(".")[0]
            # a module's own parent packages are imported by Python anyway: not an edge
            if t and t != name and not name.startswith(t + "."):
                found.add(t)
    return found


def _graph() -> dict[str, set[str]]:
    mods = _module_names()
    return {m: _imports(m, p, mods) for m, p in mods.items()}


def _subpackage(module: str) -> str:
    parts = module.split(".")
    return parts[1] if len(parts) > 1 else ""


def _cycles_across_subpackages(graph: dict[str, set[str]], key=None) -> list[list[str]]:
    """Strongly connected components (Tarjan) that span more than one subpackage (more than one ``key``)."""
    key = key or _subpackage
    index, low, stack, on_stack, out = {}, {}, [], set(), []
    counter = [0]

    def visit(v):
        index[v] = low[v] = counter[0]
        counter[0] += 1
        stack.append(v)
        on_stack.add(v)
        for w in graph[v]:
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on_stack:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            comp = []
            while True:
                w = stack.pop()
                on_stack.discard(w)
                comp.append(w)
                if w == v:
                    break
            if len({key(c) for c in comp}) > 1:
                out.append(sorted(comp))

    sys.setrecursionlimit(max(sys.getrecursionlimit(), 10_000))
    for v in graph:
        if v not in index:
            visit(v)
    return out


def test_graph_reader_sees_imports_inside_functions():
    graph = _graph()
    # slamlab.stereo.landmark_filter imports the landmark filter; a known edge must be found
    assert "slamlab.filters.landmark" in graph["slamlab.stereo.landmark_filter"]
    # and one made inside a function (StereoSLAM.run imports the progress bar)
    assert "slamlab._progress" in graph["slamlab.stereo.slam"]
    # and a cycle made of two modules of different subpackages is reported
    assert _cycles_across_subpackages({"slamlab.a.x": {"slamlab.b.y"}, "slamlab.b.y": {"slamlab.a.x"}})
    # a circle inside one package is seen when the key is the module, and only then
    inside = {"slamlab.a.x": {"slamlab.a.y"}, "slamlab.a.y": {"slamlab.a.x"}}
    assert not _cycles_across_subpackages(inside)
    assert _cycles_across_subpackages(inside, key=lambda module: module)


def test_import_graph_has_no_cycle_across_subpackages():
    cycles = _cycles_across_subpackages(_graph())
    assert not cycles, "import cycles: " + "; ".join(" -> ".join(c) for c in cycles)


def test_import_graph_has_no_cycle_at_all():
    """Inside a package too (issue 42, item 3): a circle closed by an import inside a function is still a circle."""
    cycles = _cycles_across_subpackages(_graph(), key=lambda module: module)
    assert not cycles, "import cycles: " + "; ".join(" -> ".join(c) for c in cycles)


#: CONVENTIONS' layers, lowest first. A module may import its own layer's modules of its own package and any lower
#: layer; the packages of one layer are peers and do not import each other. kdtree sits below features: its
#: ``knn`` is the shared nearest-neighbour layer that features.matching uses (CONVENTIONS lists the packages
#: in reading order, features first). ``sim`` is a peer of the algorithm packages: it makes scans, grids and
#: images from the layers below, and no algorithm imports it (CONVENTIONS: algorithm modules never import sim).
LAYERS: tuple[tuple[str, ...], ...] = (
    ("_validate", "_table", "_lazy", "_compiled", "_threads", "_heap"),
    ("_params", "_progress", "plotting", "chapters"),
    ("data", "sweep", "widgets"),
    ("geometry",),
    ("scans",),
    ("io", "filters", "kdtree"),
    ("features",),
    ("sim", "stereo", "correlation", "hough", "localisation", "planes", "mono", "evaluation"),
    ("studies",),
    ("lab",),
)


def _layer(module: str) -> tuple[int, str]:
    """The layer index and the layer's package (or root module) name of a ``slamlab.…`` module."""
    top = _subpackage(module)
    for i, names in enumerate(LAYERS):
        if top in names:
            return i, top
    raise KeyError(f"{module}: its package {top!r} is in no layer of LAYERS")


def _upward_imports(graph: dict[str, set[str]]) -> list[str]:
    bad = []
    for m, targets in graph.items():
        if m == "slamlab":  # the package's lazy front door names every subpackage
            continue
        (i, top) = _layer(m)
        for t in targets:
            if t == "slamlab":
                continue
            (j, other) = _layer(t)
            if j > i or (j == i and other != top):
                bad.append(f"{m} -> {t}")
    return sorted(bad)


def test_layer_check_sees_an_upward_and_a_sideways_import():
    graph = {"slamlab.geometry.se2": {"slamlab.scans.grid"}, "slamlab.hough.slam": {"slamlab.localisation.mcl"},
             "slamlab.scans.grid": {"slamlab.geometry.se2"}, "slamlab.localisation.mcl": set()}
    assert _upward_imports(graph) == ["slamlab.geometry.se2 -> slamlab.scans.grid",
                                      "slamlab.hough.slam -> slamlab.localisation.mcl"]


def test_every_module_is_in_a_layer():
    for m in _graph():
        if m != "slamlab":
            _layer(m)


def test_imports_run_down_the_layers():
    bad = _upward_imports(_graph())
    assert not bad, f"{len(bad)} imports go up or sideways across CONVENTIONS' layers:\n" + "\n".join(bad)


#: the layers that may use the simulator: the simulator itself, the chapters' studies and the labs' feedback
SIM_LAYERS = ("sim", "studies", "lab")


def _with_parents(module: str) -> set[str]:
    """``module`` and the packages Python imports before it (``slamlab.a.b`` -> ``slamlab.a``; not ``slamlab``)."""
    parts = module.split(".")
    return {".".join(parts[:i]) for i in range(2, len(parts) + 1)}


def _reach(graph: dict[str, set[str]]) -> dict[str, set[str]]:
    """Every slamlab module each module loads when imported: its imports, their packages' ``__init__``, and so on."""
    edges = {m: set().union(*(_with_parents(t) for t in ts), _with_parents(m)) - {m} for m, ts in graph.items()}
    edges = {m: {t for t in ts if t in graph} for m, ts in edges.items()}
    reach: dict[str, set[str]] = {}
    for start in graph:
        seen, todo = set(), [start]
        while todo:
            for t in edges[todo.pop()]:
                if t not in seen:
                    seen.add(t)
                    todo.append(t)
        reach[start] = seen - {start}
    return reach


def test_reach_follows_imports_and_packages():
    graph = {"slamlab.a": set(), "slamlab.a.x": {"slamlab.b.y"}, "slamlab.b": {"slamlab.c.z"}, "slamlab.b.y": set(),
             "slamlab.c": set(), "slamlab.c.z": set()}
    # a.x imports b.y, whose package b imports c.z: a.x reaches c.z through b's __init__
    assert _reach(graph)["slamlab.a.x"] == {"slamlab.a", "slamlab.b", "slamlab.b.y", "slamlab.c", "slamlab.c.z"}


def test_no_module_outside_sim_studies_and_lab_reaches_sim():
    reach = _reach(_graph())
    bad = sorted(f"{m} -> {', '.join(sorted(t for t in ts if _subpackage(t) == 'sim'))}" for m, ts in reach.items()
                 if _subpackage(m) not in SIM_LAYERS and m != "slamlab" and any(_subpackage(t) == "sim" for t in ts))
    assert not bad, f"{len(bad)} modules reach slamlab.sim:\n" + "\n".join(bad)


def test_only_the_labs_import_the_studies():
    bad = sorted(f"{m} -> {t}" for m, ts in _graph().items() for t in ts
                 if _subpackage(t) == "studies" and _subpackage(m) not in ("studies", "lab"))
    assert not bad, "algorithm modules import slamlab.studies: " + ", ".join(bad)


#: the sim-free helpers of an experiments.py (issue 23): results, tables, loops; the dependency is one way
EXPERIMENT_HELPERS = ("slamlab.studies.filters.results", "slamlab.studies.filters.studies",
                      "slamlab.studies.filters.source_table", "slamlab.studies.correlation.studies",
                      "slamlab.studies.correlation.study_results", "slamlab.studies.stereo.run_results",
                      "slamlab.studies.stereo.disparity_check")


def test_experiment_helpers_import_neither_sim_nor_experiments():
    graph = _graph()
    bad = [f"{m} -> {t}" for m in EXPERIMENT_HELPERS for t in graph[m]
           if _subpackage(t) == "sim" or t.split(".")[-1] == "experiments"]
    assert not bad, "experiment helpers import the simulator or an experiments module: " + ", ".join(sorted(bad))


SUBPACKAGES = ["slamlab", "slamlab.geometry", "slamlab.scans", "slamlab.io", "slamlab.sim", "slamlab.filters",
               "slamlab.features", "slamlab.kdtree", "slamlab.stereo", "slamlab.correlation", "slamlab.hough",
               "slamlab.planes", "slamlab.evaluation", "slamlab.lab", "slamlab.sweep", "slamlab.mono", "slamlab.localisation",
               "slamlab.data", "slamlab.studies", *(f"slamlab.studies.{p.parent.name}"
                                                   for p in sorted((PKG / "studies").glob("*/__init__.py")))]


def test_every_subpackage_is_listed():
    found = {f"slamlab.{p.parent.name}" for p in PKG.glob("*/__init__.py")}
    assert found <= set(SUBPACKAGES), f"add to SUBPACKAGES: {sorted(found - set(SUBPACKAGES))}"


@pytest.fixture(scope="module")
def heavy_loaded_by() -> dict[str, list[str]]:
    """One fresh interpreter imports every subpackage in turn and records, after each import, the heavy modules
    that appeared with it. Imports only ever add modules, so a heavy module loaded by any subpackage shows up
    under the first one that loads it (one interpreter instead of one per subpackage: ~2 s instead of ~50 s)."""
    code = (f"import importlib, json, sys\nheavy = {HEAVY!r}\nout = {{}}\nseen = set()\n"
            f"for m in {SUBPACKAGES!r}:\n"
            "    importlib.import_module(m)\n"
            "    now = {h for h in heavy if h in sys.modules}\n"
            "    out[m] = sorted(now - seen)\n"
            "    seen |= now\n"
            "print(json.dumps(out))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    return json.loads(out)


def test_the_heavy_import_check_sees_a_heavy_module():
    code = f"import sys, json; import matplotlib.pyplot; print(json.dumps([h for h in {HEAVY!r} if h in sys.modules]))"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    assert "matplotlib.pyplot" in json.loads(out)


@pytest.mark.parametrize("module", SUBPACKAGES)
def test_import_loads_no_widgets_pyplot_or_cv2(module, heavy_loaded_by):
    assert heavy_loaded_by[module] == [], f"`import {module}` imported {heavy_loaded_by[module]}"


#: at most this many from-imports of another module's underscore-private name (issue 42, item 3: a private
#: name is used in its own module; shared machinery lives in a package-private module named as such, ``_pairs``,
#: whose own names carry no underscore)
PRIVATE_IMPORT_BUDGET = 0


def _private_name_imports(source: str) -> list[str]:
    """The names starting with one underscore that ``source`` imports from slamlab (absolute or relative)."""
    names = []
    for node in ast.walk(ast.parse(source)):
        if isinstance(node, ast.ImportFrom) and (node.level or (node.module or "").split(".")[0] == "slamlab"):
            names += [a.name for a in node.names if a.name.startswith("_") and not a.name.startswith("__")]
    return names


def test_private_import_reader_sees_relative_absolute_and_nested_imports():
    src = ("from ._pairs import two_nearest\nfrom .frame import _check_pair, clock\n"
           "from slamlab.geometry.registration import _umeyama\nfrom numpy import _globals\n"
           "def f():\n    from ..scans import _private\n")
    assert _private_name_imports(src) == ["_check_pair", "_umeyama", "_private"]


def test_private_names_stay_in_their_modules():
    found = [f"{f.relative_to(PKG.parent)}: {name}" for f in sorted(PKG.rglob("*.py"))
             for name in _private_name_imports(f.read_text(encoding="utf-8"))]
    assert len(found) <= PRIVATE_IMPORT_BUDGET, (f"{len(found)} imports of another module's private names "
                                                 f"(budget {PRIVATE_IMPORT_BUDGET}):\n" + "\n".join(found))
