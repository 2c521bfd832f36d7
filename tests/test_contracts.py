"""One contract per concern (CONVENTIONS "API", issue 23): every public ``run_*`` takes ``params=`` and ``rng=``.

The test imports every module of slamlab (pkgutil + importlib), collects each public module-level
function named ``run_*`` defined there, and fails naming every one without a ``params`` or an
``rng`` parameter. A function where one of them truly makes no sense is listed in ``ALLOWED``
with the reason; an entry that no longer applies (the function is gone, or now takes the
parameter) fails too, so the list never goes stale.

The same walk over every public function, class and method checks the one randomness contract
(issue 42): no public callable takes a ``seed`` parameter.
"""

from __future__ import annotations

import importlib
import inspect
import pkgutil

import pytest

import slamlab

_NO_RANDOMNESS = "deterministic: draws no random numbers, so there is no stream to take"
_REPLAY = "a deterministic replay of recorded data (real images or a real log): no random numbers"
_NO_PIPELINE = ("no pipeline Params dataclass: a textbook experiment whose every knob is an explicit keyword "
                "(a Params class here would spell each setting twice)")

#: function (module.name) -> {missing parameter: why it makes no sense there}
ALLOWED: dict[str, dict[str, str]] = {
    # correlation: the constructed corridor is built without noise; its settings are LocaliseParams (params=)
    "slamlab.studies.correlation.experiments.run_corridor_tie": {"rng": _NO_RANDOMNESS + " (a noise-free corridor)"},
    # features: detectors and matchers on the Oxford images; their settings are the detectors' own arguments
    "slamlab.studies.features.experiments.run_pair_evaluation": {"params": _NO_PIPELINE, "rng": _NO_RANDOMNESS},
    "slamlab.studies.features.detector_experiments.run_detector_summary": {"params": _NO_PIPELINE, "rng": _NO_RANDOMNESS},
    "slamlab.studies.features.detector_experiments.run_surf_threshold": {"params": _NO_PIPELINE, "rng": _NO_RANDOMNESS},
    "slamlab.studies.features.matching_experiments.run_knn_comparison": {
        "params": _NO_PIPELINE, "rng": _NO_RANDOMNESS + " (FLANN's trees: cv2.setRNGSeed(0) in kdtree.knn)"},
    "slamlab.studies.features.matching_experiments.run_recall_vs_leaves": {"params": _NO_PIPELINE, "rng": _NO_RANDOMNESS},
    "slamlab.studies.features.matching_experiments.run_ratio_tradeoff": {"params": _NO_PIPELINE, "rng": _NO_RANDOMNESS},
    "slamlab.studies.features.detector_experiments.run_blob_scale": {"params": _NO_PIPELINE, "rng": _NO_RANDOMNESS},
    # filters: each experiment is one model (F, Q, H, R from its keywords) run through the filters
    "slamlab.studies.filters.experiments.run_cv_target": {"params": _NO_PIPELINE},
    "slamlab.studies.filters.studies.run_joseph_vs_short": {"params": _NO_PIPELINE},
    "slamlab.studies.filters.experiments.run_unicycle_comparison": {"params": _NO_PIPELINE},
    "slamlab.studies.filters.experiments.run_stabilising_noise": {"params": _NO_PIPELINE},
    "slamlab.studies.filters.experiments.run_sigma_alpha_study": {"params": _NO_PIPELINE},
    "slamlab.studies.filters.studies.run_landmark_filter": {"params": _NO_PIPELINE},
    # hough
    "slamlab.studies.hough.example.run_example_line": {
        "params": "004's worked example: one line, both transforms at 004's resolutions (no Hough SLAM run)",
        "rng": _NO_RANDOMNESS},
    "slamlab.studies.hough.logs.run_real_log": {"rng": _REPLAY},
    # kdtree: the stores are compared at the workload's own sizes; no pipeline settings
    "slamlab.kdtree.cost_model.run_cost_model": {
        "params": "evaluates 000's cost formula at four numbers (n, s, m, C): nothing else to set",
        "rng": _NO_RANDOMNESS},
    "slamlab.studies.kdtree.tree_studies.run_dimension_study": {"params": _NO_PIPELINE},
    # mono: MonoSLAM draws no random numbers (OpenCV's RANSAC is reseeded to 0 before each call,
    # mono/twoview.py); the streams are the renderer's, taken by the run_* that render
    "slamlab.studies.mono.runs.run_mono": {"rng": _NO_RANDOMNESS + " (MonoSLAM on given images)"},
    "slamlab.studies.mono.kitti.run_kitti_mono": {"rng": _REPLAY},
    "slamlab.studies.mono.kitti.run_kitti_ablation": {"rng": _REPLAY},
    "slamlab.studies.mono.convergence.run_depth_filter_convergence": {
        "params": "the depth filter's maths on synthetic seeds (τ, outlier rates are the study's axes): "
                  "no MonoSLAM run, so no MonoParams"},
    "slamlab.studies.mono.convergence.run_convergence_tests": {
        "params": "the two convergence tests on synthetic seeds (τ from the geometry, L_max the axis): "
                  "no MonoSLAM run, so no MonoParams"},
    # planes: Fig. 2 is 002's bare LM system (noise-free planes, no prior, 40 iterations), not the filter
    "slamlab.studies.planes.figures.run_pairs_figure": {
        "params": "002 Fig. 2: the bare LM solve of 1, 2, 3 plane pairs, no filter (none of PlaneSLAMParams "
                  "applies: no prior, no weights, its own iteration count)"},
    # stereo: draws a finished result
    "slamlab.studies.stereo.plot.run_figure": {
        "params": "draws a finished StereoRunResult: no settings", "rng": _NO_RANDOMNESS},
}

REQUIRED = ("params", "rng")


def _modules():
    """Every module of slamlab, imported (pyplot on the Agg backend)."""
    import matplotlib

    matplotlib.use("Agg")
    mods = [slamlab]
    for info in pkgutil.walk_packages(slamlab.__path__, prefix="slamlab."):
        mods.append(importlib.import_module(info.name))
    return mods


def _run_functions():
    """``{"module.name": function}`` of every public module-level ``run_*`` defined in a public module."""
    out = {}
    for mod in _modules():
        if any(part.startswith("_") for part in mod.__name__.split(".")):
            continue
        for name, obj in vars(mod).items():
            if name.startswith("run_") and inspect.isfunction(obj) and obj.__module__ == mod.__name__:
                out[f"{mod.__name__}.{name}"] = obj
    return out


@pytest.fixture(scope="module")
def run_functions():
    return _run_functions()


def test_the_walk_finds_the_experiments(run_functions):
    # a guard against a walk that silently finds nothing (e.g. an import path change)
    assert len(run_functions) > 40
    assert "slamlab.studies.localisation.studies.run_global_localisation" in run_functions
    assert "slamlab.studies.mono.experiments.run_parameter_sweep" in run_functions


def test_every_run_takes_params_and_rng(run_functions):
    missing = []
    for qual, fn in sorted(run_functions.items()):
        names = inspect.signature(fn).parameters
        for arg in REQUIRED:
            if arg not in names and arg not in ALLOWED.get(qual, {}):
                missing.append(f"{qual} has no `{arg}=`")
    assert not missing, "run_* without the contract's parameters:\n" + "\n".join(missing)


def test_the_allow_list_is_current_and_says_why(run_functions):
    stale = []
    for qual, entries in ALLOWED.items():
        if qual not in run_functions:
            stale.append(f"{qual}: no such public run_* any more")
            continue
        names = inspect.signature(run_functions[qual]).parameters
        for arg, why in entries.items():
            assert arg in REQUIRED, f"{qual}: allow-list entry for an unknown parameter {arg!r}"
            assert isinstance(why, str), f"{qual}: the reason for `{arg}` must be a sentence"
            assert len(why) > 20, f"{qual}: say why `{arg}` makes no sense"
            if arg in names:
                stale.append(f"{qual}: takes `{arg}` now; drop its allow-list entry")
    assert not stale, "\n".join(stale)


def _public_callables():
    """``{"module.name": callable}`` of every public function, class (its constructor) and public method defined
    in a public module of slamlab (functions wrapped by a decorator such as ``functools.lru_cache`` included)."""
    out = {}
    for mod in _modules():
        if any(part.startswith("_") for part in mod.__name__.split(".")):
            continue
        for name, obj in vars(mod).items():
            if name.startswith("_") or getattr(obj, "__module__", None) != mod.__name__:
                continue
            if inspect.isclass(obj):
                out[f"{mod.__name__}.{name}"] = obj
                for meth_name, meth in vars(obj).items():
                    if meth_name.startswith("_"):
                        continue
                    if isinstance(meth, (staticmethod, classmethod)):
                        meth = meth.__func__
                    if inspect.isfunction(inspect.unwrap(meth)):
                        out[f"{mod.__name__}.{name}.{meth_name}"] = meth
            elif callable(obj) and inspect.isfunction(inspect.unwrap(obj)):
                out[f"{mod.__name__}.{name}"] = obj
    return out


def test_no_public_callable_takes_seed():
    # one randomness contract (issue 42): streams come through `rng=` (a Generator, an int seed or None);
    # a seed of something else (OpenCV's global RNG) is named for what it seeds (`opencv_seed=`)
    callables = _public_callables()
    # the walk works: functions, classes (constructors), methods and lru_cache-wrapped functions are in it
    assert "slamlab.sweep.sweep" in callables
    assert "slamlab.sim.arena.StereoArena" in callables
    assert "slamlab.lab.feedback.load" in callables  # functools.cache-wrapped
    bad = []
    for qual, fn in sorted(callables.items()):
        try:
            params = inspect.signature(fn).parameters
        except (TypeError, ValueError):  # a builtin without a signature
            continue
        if "seed" in params:
            bad.append(qual)
    assert not bad, "public callables with a `seed` parameter (take `rng=`): " + ", ".join(bad)


def test_progress_follows_the_one_contract(run_functions):
    # `progress` defaults to None (a bar unless $SLAMLAB_PROGRESS=0) or False; never a private convention
    bad = [qual for qual, fn in sorted(run_functions.items())
           if "progress" in inspect.signature(fn).parameters
           and inspect.signature(fn).parameters["progress"].default not in (None, False)]
    assert not bad, "run_* whose `progress` default is not None/False: " + ", ".join(bad)
