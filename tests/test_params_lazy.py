"""The shared parameter base (slamlab._params) and lazy package attributes (slamlab._lazy)."""

from __future__ import annotations

import sys
from dataclasses import FrozenInstanceError, dataclass

import pytest

from slamlab import _validate as v
from slamlab._lazy import lazy_exports
from slamlab._params import Params, param


@dataclass(frozen=True)
class _Demo(Params):
    H_min: int = param(15, "004 §5")
    band_m: float = param(0.1, "ours")

    def check(self):
        v.check_int(self.H_min, "H_min", minimum=1)
        v.check_positive(self.band_m, "band_m")


def test_params_check_runs_on_construction_and_replace():
    with pytest.raises(ValueError, match="`H_min` must be >= 1; got 0"):
        _Demo(H_min=0)
    with pytest.raises(TypeError, match="`band_m` must be a real number"):
        _Demo().replace(band_m="wide")


def test_params_are_frozen_and_know_their_sources():
    p = _Demo()
    with pytest.raises(FrozenInstanceError):
        p.H_min = 3
    assert _Demo.sources() == {"H_min": "004 §5", "band_m": "ours"}
    assert "004 §5" in p.table()
    assert "band_m" in p.table()


def test_resolve_applies_overrides_and_rejects_unknown_names():
    base = _Demo(H_min=20)
    got = _Demo.resolve(base, band_m=0.5)
    assert (got.H_min, got.band_m) == (20, 0.5)
    assert _Demo.resolve(None) == _Demo()
    assert got.changed() == {"H_min": 20, "band_m": 0.5}
    with pytest.raises(TypeError, match=r"_Demo has no field\(s\) 'Hmin'; fields are: H_min, band_m"):
        _Demo.resolve(None, Hmin=3)
    with pytest.raises(TypeError, match="`params` must be a _Demo or None; got dict"):
        _Demo.resolve({"H_min": 3})


def test_as_overrides_merges_params_and_overrides_for_worker_tasks():
    assert _Demo.as_overrides(None, band_m=0.5) == {"band_m": 0.5}  # params=None: the overrides unchanged
    assert _Demo.as_overrides(_Demo(H_min=20)) == {"H_min": 20}  # only fields that differ from the defaults
    ov = _Demo.as_overrides(_Demo(H_min=20, band_m=0.3), band_m=0.5)
    assert ov == {"H_min": 20, "band_m": 0.5}
    assert _Demo.resolve(None, **ov) == _Demo.resolve(_Demo(H_min=20, band_m=0.3), band_m=0.5)
    with pytest.raises(TypeError, match=r"_Demo has no field\(s\) 'Hmin'"):
        _Demo.as_overrides(None, Hmin=3)
    with pytest.raises(TypeError, match="`params` must be a _Demo or None; got dict"):
        _Demo.as_overrides({"H_min": 3})


def test_param_rejects_mutable_default_and_missing_source():
    with pytest.raises(TypeError, match="immutable"):
        param([1, 2], "ours")
    with pytest.raises(TypeError, match="source"):
        param(1, "")


def test_lazy_exports_import_on_first_use(monkeypatch):
    import types

    pkg = types.ModuleType("slamlab_lazy_demo")
    monkeypatch.setitem(sys.modules, "slamlab_lazy_demo", pkg)
    pkg.__getattr__, pkg.__dir__ = lazy_exports("slamlab_lazy_demo", {"sqrt": "math", "nothing": "math"})
    assert pkg.__getattr__("sqrt")(9.0) == 3.0
    assert "sqrt" in vars(pkg)  # cached after the first look-up
    assert "nothing" in pkg.__dir__()
    with pytest.raises(AttributeError, match="has no attribute 'missing'"):
        pkg.__getattr__("missing")


@dataclass(frozen=True)
class _Long(Params):
    a_long_field_name: float = param(0.5, "ours: " + "a long explanation of the value " * 8)
    short: int = param(3, "004 §5")
    pair: tuple = param((2.0, 0.17453292519943295), "ours (the pair)")


def test_table_fits_the_output_area_with_long_sources_in_notes():
    t = _Long().table()
    lines = t.splitlines()
    assert max(map(len, lines)) <= 110
    assert lines[3].endswith("ours [1]")  # the source's first clause, marked
    assert lines[4].endswith("004 §5")  # a short source stays in its column
    assert "(2, 0.174533)" in lines[5]  # tuples of numbers at the precision of single numbers
    notes = " ".join(line.strip() for line in lines[6:])
    assert notes == "[1] a_long_field_name: " + _Long.sources()["a_long_field_name"].strip()
    assert max(map(len, _Long().table(width=60).splitlines())) <= 60


def test_every_params_table_of_the_library_fits_110_characters():
    import importlib

    for m in ("correlation.settings", "hough.slam", "kdtree.store_params", "localisation.markov",
              "localisation.mcl_params", "mono.params", "planes.filter", "sim.planes_room", "stereo.params"):
        importlib.import_module(f"slamlab.{m}")

    def subclasses(cls):
        for s in cls.__subclasses__():
            yield s
            yield from subclasses(s)

    found = [c for c in subclasses(Params) if c.__module__.startswith("slamlab.")]
    assert len(found) >= 10
    for c in found:
        assert max(map(len, c().table().splitlines())) <= 110, c.__name__
