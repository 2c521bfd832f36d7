"""One route per setting (issue 42, item 1): every field of ``params=`` reaches the code, or is refused by name.

For every public ``run_*`` that takes ``params=``, the test builds the settings object with **every field set to a
non-default value** (a *probe*), runs a small case, and records each read of a field of that settings class during
the run (``Params.__getattribute__`` is patched for the run; reads made by the dataclass machinery, by
``Params``' own helpers and by a class's ``check`` are not uses and are left out). Then, per field:

- **reaches**: every read of the field returned the probe value. A read of another value means some default or
  some argument beat ``params`` (the bug of ``{"detector": "orb"} | overrides``, of ``demo_run``'s
  ``n_particles``) and fails the test;
- **refused**: the run raised a ``ValueError`` naming the field (a study that varies the field itself, such as a
  particle-count sweep): the field is taken out of the probe and the run is repeated with the others;
- **not on this path**: a field read by no run of this study (a Markov-only field in an MCL study, a setting of
  the detector the study does not use) cannot reach it. Such fields are probed once more alone (another probe
  may have closed their path: ``ambiguity=False`` closes the rival search) and are reported, not failed.

The probe of a field is its default moved one step (an int + 1, a float × 1.1, a bool negated, another allowed
string, read from the class's own error message) unless ``PROBES`` names one; every probe is checked to be a
valid value by the class itself. A field with no reasonable probe is in ``NOT_PROBED`` with the reason.
Runs use ``n_jobs=1`` (the reads are recorded in this process).
"""

from __future__ import annotations

import contextlib
import dataclasses
import importlib
import inspect
import re
import sys
import typing

import numpy as np
import pytest

from slamlab._params import Params

# --------------------------------------------------------------------------------------------------- recording

#: reads from these places copy, compare, print or check a settings object: not a use of the value
_SKIP_FILES = ("_params.py", "dataclasses.py", "<string>", "copy.py", "copyreg.py")
_SKIP_CODE = {"check", "__post_init__", "__repr__", "__eq__", "__hash__", "__reduce__", "__getstate__"}


class _Reads:
    def __init__(self):
        self.on = False
        self.reads: list[tuple[type, str, object]] = []


_READS = _Reads()


def _recording_getattribute(self, name):
    value = object.__getattribute__(self, name)
    if _READS.on and not name.startswith("_") and name in type(self).__dataclass_fields__:
        code = sys._getframe(1).f_code
        if not (code.co_filename.endswith(_SKIP_FILES) or code.co_name in _SKIP_CODE):
            _READS.reads.append((type(self), name, value))
    return value


@contextlib.contextmanager
def recording():
    """Record the field reads of every ``Params`` object while the block runs."""
    Params.__getattribute__ = _recording_getattribute
    _READS.reads, _READS.on = [], True
    try:
        yield _READS
    finally:
        _READS.on = False
        del Params.__getattribute__


# ----------------------------------------------------------------------------------------------------- probes

#: (class, field) -> probe, where the automatic step gives no valid or no cheap value
PROBES = {
    ("LocaliseParams", "workers"): 1,
    ("HoughSlamParams", "r_max"): 90.0,
    ("HoughSlamParams", "H_min_retry"): 10,
    ("HoughSlamParams", "suppress_rho"): 3.0,
    ("HoughSlamParams", "suppress_theta_rad"): 0.05,
    ("HoughSlamParams", "band"): 2.0,
    ("HoughSlamParams", "b"): 3.3,
    ("HoughSlamParams", "gate"): 2.0,
    ("StereoParams", "pixel_std_estimate"): True,
    ("StereoParams", "subpixel_stereo"): True,
    ("StereoParams", "same_point_m"): 0.05,
    ("StereoParams", "duplicate_gap_m"): 0.1,
    ("StereoParams", "map_search"): "window",
    ("StereoParams", "view_margin_deg"): 5.0,
    ("StereoParams", "max_correction_rad"): 0.1,
    ("StereoParams", "max_correction_m"): 0.5,
    # cheap counts: a probe must stay a small run
    ("MCLParams", "n_particles"): 120,
    ("PlaneSLAMParams", "n_particles"): 60,
    ("StereoParams", "n_features"): 800,
}

#: (class, field) -> the fields its probe needs beside it (the class checks the pair)
PROBE_NEEDS = {("StereoParams", "pixel_std_estimate"): {"pose_refine": "reprojection"}}

#: (class, field) -> why it is not probed
NOT_PROBED = {
    ("StereoParams", "init_cov_depth"): "its only other value, 'true', is the ablation oracle that needs the "
                                        "simulator's true depths (run_scale_ablation sets them)",
}

#: (class, field) -> (the values the method gives the field on a step of its own, from the probes; why): a read
#: of one of them is a step of the method, not a default beating ``params``
DERIVED = {
    ("HoughSlamParams", "H_min"): (
        lambda q: [q["H_min_retry"]],
        "a scan with fewer than two lines is searched again at H_min_retry (HoughSlamParams)"),
    ("StereoParams", "max_depth_m"): (
        lambda q: [q["max_depth_m"] * q["reobserve_depth_factor"], 1e12],
        ("a point up to reobserve_depth_factor × max_depth_m deep may match a landmark (triangulated to that "
         "depth), and the depth-cut oracle triangulates without a limit (StereoSLAM's frame points)")),
    ("StoreParams", "tree"): (
        lambda q: ["brute"],
        ("the ground truth of recall is a brute-force store, searched by brute force whatever `tree` says "
         "(make_store('brute'))")),
}

_QUOTED = re.compile(r"'([^']+)'")


def probe_value(cls: type, f: dataclasses.Field):
    """A valid non-default value of field ``f`` of ``cls``, or ``dataclasses.MISSING``."""
    key = (cls.__name__, f.name)
    if key in NOT_PROBED:
        return dataclasses.MISSING
    if key in PROBES:
        return PROBES[key]
    d = f.default
    candidates: list = []
    if isinstance(d, bool):
        candidates = [not d]
    elif isinstance(d, int):
        candidates = [d + 1, d - 1, 2 * d]
    elif isinstance(d, float):
        candidates = [d * 1.1, d * 0.9, d + 0.1, d - 0.1] if d else [0.1, 0.01, 1.0]
    elif isinstance(d, tuple) and d and all(isinstance(x, (int, float)) and not isinstance(x, bool) for x in d):
        candidates = [tuple(x * 1.1 if isinstance(x, float) else x + 1 for x in d)]
    elif isinstance(d, str):
        try:
            cls(**{f.name: "\N{SNOWMAN}"})
        except (ValueError, TypeError) as e:
            candidates = [c for c in _QUOTED.findall(str(e)) if c not in (d, "\N{SNOWMAN}")]
    for c in candidates:
        try:
            cls(**{f.name: c, **PROBE_NEEDS.get(key, {})})
        except (ValueError, TypeError):
            continue
        return c
    return dataclasses.MISSING


def _same(a, b) -> bool:
    try:
        r = a == b
    except Exception:  # noqa: BLE001 (arrays of another shape, ...)
        return a is b
    return bool(np.all(r)) if not isinstance(r, bool) else r


# ------------------------------------------------------------------------------------------------------ calls


def _sl():
    import slamlab

    return slamlab


def _turn(n=4):
    sl = _sl()
    return sl.sim.turn_in_place(np.deg2rad(5.0))[:n]


def _highway_scene(rng):
    return _sl().sim.HighwayScene(rng=rng)


#: "package.module.function" under slamlab.studies -> (a small run given the settings, needs real data)
CALLS: dict[str, tuple[typing.Callable, bool]] = {
    # correlation (notebook 06)
    "correlation.experiments.run_table1": (lambda S, p: S.correlation.run_table1(2, n_beams=90, params=p), False),
    "correlation.experiments.run_monte_carlo": (
        lambda S, p: S.correlation.run_monte_carlo(2, n_beams=90, params=p), False),
    "correlation.experiments.run_constants_study": (
        lambda S, p: S.correlation.run_constants_study(2, n_beams=90, choices=((0.0, 1.0, 0.0),), params=p), False),
    "correlation.experiments.run_corridor_tie": (lambda S, p: S.correlation.run_corridor_tie(params=p), False),
    "correlation.experiments.run_aperture_study": (
        lambda S, p: S.correlation.run_aperture_study((0.0, 10.0), 1, n_beams=90, params=p), False),
    "correlation.experiments.run_stamp_trim_study": (
        lambda S, p: S.correlation.run_stamp_trim_study((1.0, 0.5), 1, n_beams=90, params=p), False),
    "correlation.log_experiments.run_log_localisation": (
        lambda S, p: S.correlation.run_log_localisation(scan_indices=(50,), params=p), True),
    "correlation.log_suite.run_log_suite": (
        lambda S, p: S.correlation.run_log_suite(every=200, joined=(1,), params=p), True),
    # hough (notebook 07)
    "hough.experiments.run_sim_slam": (lambda S, p: S.hough.run_sim_slam(6, n_beams=180, params=p), False),
    "hough.experiments.run_noise_study": (
        lambda S, p: S.hough.run_noise_study((0.1,), 1, n_poses=6, params=p), False),
    "hough.logs.run_real_log": (lambda S, p: S.hough.run_real_log(n_scans=5, params=p), True),
    # kdtree (notebook 04)
    "kdtree.experiments.run_store_comparison": (
        lambda S, p: S.kdtree.experiments.run_store_comparison("table2", stores=("rebuild", "multi"), n_iterations=3,
                                                   params=p), False),
    "kdtree.crossover.run_crossover": (
        lambda S, p: S.kdtree.crossover.run_crossover((300,), stores=("rebuild", "multi"), n_queries=20, n_new=20,
                                            repeats=1, params=p), False),
    # localisation (notebook 08)
    "localisation.experiments.run_filter": (
        lambda S, p: S.localisation.run_filter(S.localisation.simulate_run(4, start=0, rng=0), params=p, rng=0),
        False),
    "localisation.experiments.run_markov_vs_mcl": (
        lambda S, p: S.localisation.run_markov_vs_mcl(((8, 12),), (100,), n_runs=1, n_steps=3, params=p), False),
    "localisation.kidnap.run_kidnapped": (
        lambda S, p: S.localisation.run_kidnapped((("defaults", {}),), n_runs=1, n_steps=6, kidnap_step=3,
                                                  params=p), False),
    "localisation.log_protocol.run_log_protocol": (
        lambda S, p: S.localisation.run_log_protocol(("intel",), (200,), n_runs=1, n_scans=3, track_particles=100,
                                                     params=p, track_params=p), True),
    "localisation.logs.run_log_mcl": (
        lambda S, p: S.localisation.run_log_mcl("intel", n_scans=3, n_particles_track=100,
                                                n_particles_global=200, params=p,
                                                global_params=p), True),
    "localisation.markov_study.run_markov_prior": (
        lambda S, p: S.localisation.run_markov_prior(
            (("uniform", "uniform", 0.0),), n_runs=1, n_steps=2, params=p), False),
    "localisation.markov_study.run_markov_kidnap": (
        lambda S, p: S.localisation.run_markov_kidnap((0.0,), n_runs=1, n_steps=4, kidnap_step=2, params=p), False),
    "localisation.side_by_side.run_correlation_side_by_side": (
        lambda S, p: S.localisation.run_correlation_side_by_side(n_runs=1, n_steps=3, params=p), False),
    "localisation.studies.run_global_localisation": (
        lambda S, p: S.localisation.run_global_localisation((100,), n_runs=1, n_steps=3, params=p), False),
    "localisation.studies.run_global_ablation": (
        lambda S, p: S.localisation.run_global_ablation((("as given", {}),), n_runs=1, n_steps=3, params=p), False),
    "localisation.studies.run_score_comparison": (
        lambda S, p: S.localisation.run_score_comparison((("as given", {}),), n_runs=1, global_particles=100,
                                                         kidnap_particles=100, params=p), False),
    # mono (notebook 09)
    "mono.experiments.run_mono_sequence": (
        lambda S, p: S.mono.run_mono_sequence(n_frames=6, size="tiny", params=p), False),
    "mono.experiments.run_failure_cases": (
        lambda S, p: S.mono.run_failure_cases(("normal",), n_frames=6, params=p), False),
    "mono.experiments.run_parameter_sweep": (
        lambda S, p: S.mono.run_parameter_sweep(
            [{"init_disparity_px": 15.0, "max_keyframes": 10, "kf_max_lost_ratio": 0.3, "max_matches": 120}],
            n_frames=6, params=p), False),
    "mono.kitti.run_kitti_mono": (lambda S, p: S.mono.run_kitti_mono(n_frames=4, params=p), True),
    "mono.kitti.run_kitti_ablation": (
        lambda S, p: S.mono.run_kitti_ablation(configs={"as given": {}}, n_frames=4, params=p), True),
    "mono.runs.run_mono": (lambda S, p: S.mono.run_mono(*_mono_images(S), params=p), False),
    "mono.studies.run_ablation": (
        lambda S, p: S.mono.run_ablation({"as given": {}}, cases=("normal",), n_frames=6, params=p), False),
    "mono.studies.run_mono_vs_stereo": (
        lambda S, p: S.mono.run_mono_vs_stereo(n_frames=6, size="tiny", params=p), False),
    "mono.epipolar_subset.run_epipolar_subset": (
        lambda S, p: S.mono.run_epipolar_subset((0, 2), params=p), False),
    "mono.findings.run_still_start": (lambda S, p: S.mono.run_still_start(2, n_frames=6, params=p), False),
    "mono.repeats.run_repeats": (lambda S, p: S.mono.run_repeats(("normal",), n_runs=2, n_frames=6, params=p), False),
    # planes (notebook 10)
    "planes.ablations.run_pairs_ablation": (
        lambda S, p: S.planes.run_pairs_ablation(duration_s=3.0, variants=(("all", 10, 2),), params=p), False),
    "planes.ablations.run_frame_source_ablation": (
        lambda S, p: S.planes.run_frame_source_ablation(duration_s=3.0, params=p), False),
    "planes.ablations.run_incidence_ablation": (
        lambda S, p: S.planes.run_incidence_ablation(duration_s=3.0, fig4_particles=60, params=p,
                                                     fig4_params=p), False),
    "planes.experiments.run_flight": (lambda S, p: S.planes.run_flight(3.0, params=p), False),
    "planes.figures.run_intensity_figure": (lambda S, p: S.planes.run_intensity_figure(params=p), False),
    "planes.figures.run_intensity_spread": (lambda S, p: S.planes.run_intensity_spread((0.01,), params=p), False),
    "planes.figures.run_intensity_study": (lambda S, p: S.planes.run_intensity_study(1, (0.2,), params=p), False),
    # stereo (notebook 05)
    "stereo.experiments.run_stereo_slam": (lambda S, p: S.stereo.run_stereo_slam(_turn(), params=p), False),
    "stereo.experiments.run_stereo_slam_variants": (
        lambda S, p: S.stereo.run_stereo_slam_variants(_turn(), {"as given": {}}, params=p), False),
    "stereo.experiments.run_experiment": (
        lambda S, p: S.stereo.run_experiment("turn in place", n_frames=4, params=p), False),
    "stereo.experiments.run_comparison": (
        lambda S, p: S.stereo.run_comparison(variants={"as given": {}}, n_frames=4, params=p), False),
    "stereo.experiments.run_drift_study": (
        lambda S, p: S.stereo.run_drift_study((0.0,), n_frames=4, params=p), False),
    "stereo.kitti_experiments.run_kitti": (lambda S, p: S.stereo.run_kitti(n_frames=3, params=p), True),
    "stereo.scale_ablation.run_scale_ablation": (
        lambda S, p: S.stereo.run_scale_ablation(_highway_scene, _sl().sim.highway_path(4), {"as given": {}},
                                                 n_seeds=1, params=p), False),
    "stereo.scale_ablation.run_condition_ablation": (
        lambda S, p: S.stereo.scale_ablation.run_condition_ablation({"plain": (_highway_scene, 0.5)}, _sl().sim.highway_path(4),
                                                     {"as given": {}}, n_seeds=1, params=p), False),
}


def _mono_images(S):
    """A few rendered frames, their true poses and K, for run_mono."""
    frames = S.mono.experiments.failure_case_frames("normal", "tiny", 6, rng=0)
    return frames[0], frames[1], frames[2]


def _run_functions_with_params() -> dict[str, typing.Callable]:
    import slamlab.studies as studies_pkg

    out = {}
    import pkgutil

    for info in pkgutil.walk_packages(studies_pkg.__path__, "slamlab.studies."):
        if any(part.startswith("_") for part in info.name.split(".")):
            continue
        mod = importlib.import_module(info.name)
        for name, obj in vars(mod).items():
            if (name.startswith("run_") and inspect.isfunction(obj) and obj.__module__ == mod.__name__
                    and "params" in inspect.signature(obj).parameters):
                out[f"{mod.__name__.removeprefix('slamlab.studies.')}.{name}"] = obj
    return out


def _settings_class(fn) -> type:
    hints = typing.get_type_hints(fn)
    ann = hints.get("params")
    args = [a for a in typing.get_args(ann) if isinstance(a, type) and issubclass(a, Params)] if ann else []
    if not args:
        raise AssertionError(f"{fn.__module__}.{fn.__name__}: annotate `params` as `XParams | None`; got {ann!r}")
    return args[0]  # the first: the settings of the default method (run_filter: MCL)


def test_every_run_with_params_is_walked():
    found = set(_run_functions_with_params())
    assert found == set(CALLS), (f"add to CALLS: {sorted(found - set(CALLS))}; "
                                 f"gone, remove: {sorted(set(CALLS) - found)}")


def walk(fn, call, cls):
    """Run ``call(params)`` with every probe; return (reached, refused, not on the path, wrong, probes)."""
    probes = {}
    for f in dataclasses.fields(cls):
        v = probe_value(cls, f)
        if v is not dataclasses.MISSING:
            probes[f.name] = v
    refused: dict[str, str] = {}
    for _ in range(len(probes) + 1):
        with recording() as rec:
            try:
                call(cls(**probes))
                break
            except ValueError as e:
                named = [f for f in probes if re.search(rf"\b{re.escape(f)}\b", str(e))]
                if not named:
                    raise AssertionError(f"a ValueError that names no probed field: {e}") from e
                for f in named:
                    refused[f] = str(e)
                    del probes[f]
                    for need in PROBE_NEEDS.get((cls.__name__, f), {}):
                        probes.pop(need, None)
    reads = [(n, v) for c, n, v in rec.reads if c is cls]
    read_values: dict[str, list] = {}
    for n, v in reads:
        read_values.setdefault(n, []).append(v)
    unread = [f for f in probes if f not in read_values]
    if unread:  # another probe may have closed their path: probe them alone
        alone = {f: probes[f] for f in unread}
        for f in unread:
            alone.update({k: v for k, v in PROBE_NEEDS.get((cls.__name__, f), {}).items() if k in probes})
        with recording() as rec:
            call(cls(**alone))
        for c, n, v in rec.reads:
            if c is cls and n in unread:
                read_values.setdefault(n, []).append(v)
    def allowed(f, v):
        if _same(v, probes[f]):
            return True
        derived = DERIVED.get((cls.__name__, f))
        try:
            return derived is not None and any(_same(v, d) for d in derived[0](probes))
        except KeyError:  # a field it derives from was refused
            return False

    wrong = {f: sorted({repr(v) for v in read_values[f] if not allowed(f, v)})
             for f in probes if f in read_values and any(not allowed(f, v) for v in read_values[f])}
    reached = [f for f in probes if f in read_values and f not in wrong]
    off_path = [f for f in probes if f not in read_values]
    return reached, refused, off_path, wrong, probes


@pytest.mark.parametrize("key", sorted(CALLS))
def test_every_field_reaches_the_run_or_is_refused(key, request):
    call, real = CALLS[key]
    if real:
        request.getfixturevalue("real_data")
    modname, fname = key.rsplit(".", 1)
    fn = getattr(importlib.import_module(f"slamlab.studies.{modname}"), fname)
    cls = _settings_class(fn)
    S = _sl().studies
    reached, refused, _off_path, wrong, probes = walk(fn, lambda p: call(S, p), cls)
    assert not wrong, (f"{key}: these fields of {cls.__name__} were read with another value than the one "
                       f"`params` set (probe → values read): "
                       + "; ".join(f"{f}: {probes[f]!r} → {v}" for f, v in wrong.items()))
    for f, message in refused.items():
        assert "`" + f + "`" in message or f in message
    assert reached, f"{key}: no field of {cls.__name__} reached the run"


# ------------------------------------------------------------------------------------------ the walk itself


@dataclasses.dataclass(frozen=True)
class _Toy(Params):
    n: int = 3
    kind: str = "a"

    def check(self):
        if self.kind not in ("a", "b"):
            raise ValueError(f"`kind` must be one of 'a', 'b'; got {self.kind!r}")


def test_the_walk_finds_a_default_that_beats_params_and_accepts_a_refusal():
    def beaten(p):  # the bug: a default instance is used instead of the caller's
        return _Toy().n + len(p.kind)

    reached, refused, off_path, wrong, probes = walk(None, beaten, _Toy)
    assert probes == {"n": 4, "kind": "b"}
    assert wrong == {"n": ["3"]}
    assert reached == ["kind"]

    def refuses(p):
        if p.n != 3:
            raise ValueError(f"`n` is set by this study itself; got {p.n}")
        return p.kind

    reached, refused, off_path, wrong, probes = walk(None, refuses, _Toy)
    assert list(refused) == ["n"]
    assert reached == ["kind"]
    assert not wrong

    def ignores(p):
        return None

    reached, refused, off_path, wrong, probes = walk(None, ignores, _Toy)
    assert off_path == ["n", "kind"]
    assert not reached

    def other_error(p):
        raise ValueError("something else")

    with pytest.raises(AssertionError, match="names no probed field"):
        walk(None, other_error, _Toy)
