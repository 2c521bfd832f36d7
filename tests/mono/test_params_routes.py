"""Every setting reaches the run or is refused by name (issue 42, item 1): the mono studies that set fields themselves."""

from __future__ import annotations

import numpy as np
import pytest

from slamlab.mono import MonoParams
from slamlab.studies.mono import experiments as ex
from slamlab.studies.mono import kitti, studies


def test_failure_case_frames_say_which_settings_the_case_makes():
    imgs, Ts, K, ov = ex.failure_case_frames("bad_initial_map", "tiny", 3, rng=0)
    assert imgs.shape == (3, 144, 192)
    assert Ts.shape == (3, 4, 4)
    assert K.shape == (3, 3)
    assert ov == ex.FAILURE_SETTINGS["bad_initial_map"]
    assert ex.failure_case_frames("normal", "tiny", 2, rng=0)[3] == {}
    with pytest.raises(ValueError, match="`case` must be one of"):
        ex.failure_case_frames("spiral", "tiny", 2)


def test_failure_cases_refuse_a_field_the_case_sets_and_pass_the_others(monkeypatch):
    with pytest.raises(ValueError, match=r"`init_disparity_px` is set by this study itself \(the failure case 'bad_initial_map' sets it\)"):
        ex.run_failure_cases(("normal", "bad_initial_map"), params=MonoParams(init_disparity_px=5.0))
    with pytest.raises(ValueError, match="`init_min_parallax_deg`"):
        ex.run_failure_cases(("bad_initial_map",), init_min_parallax_deg=2.0)
    seen = {}

    def fake_run_mono(imgs, Ts, K, *, name, params, progress, **ov):
        seen[name] = params.replace(**ov)

    monkeypatch.setattr(ex, "run_mono", fake_run_mono)
    ex.run_failure_cases(("normal", "bad_initial_map"), n_frames=2, params=MonoParams(zncc_min=0.7), max_matches=50)
    assert seen["normal"] == MonoParams(zncc_min=0.7, max_matches=50)
    assert seen["bad_initial_map"] == MonoParams(zncc_min=0.7, max_matches=50, **ex.FAILURE_SETTINGS["bad_initial_map"])


def test_parameter_sweep_refuses_the_fields_it_sweeps():
    for field, value in (("max_keyframes", 5), ("kf_min_frames", 20), ("init_disparity_px", 8.0)):
        with pytest.raises(ValueError, match=rf"`{field}` is set by this study itself \(the sweep's grid sets it\)"):
            ex.run_parameter_sweep(params=MonoParams(**{field: value}))
    with pytest.raises(ValueError, match="`max_matches`"):
        ex.run_parameter_sweep(max_matches=10)
    with pytest.raises(TypeError, match="has no field"):
        ex.run_parameter_sweep(typo=1)


def test_ablations_refuse_the_fields_their_configurations_set():
    with pytest.raises(ValueError, match=r"`refine` is set by this study itself \(the configurations or cases of run_ablation set it\)"):
        studies.run_ablation(params=MonoParams(refine=False))
    with pytest.raises(ValueError, match="`init_disparity_px`"):  # the case sets it
        studies.run_ablation(cases=("bad_initial_map",), init_disparity_px=5.0)
    with pytest.raises(TypeError, match="has no field"):
        studies.run_ablation(configs={"x": {"typo": 1}})
    with pytest.raises(ValueError, match=r"`warp_patches` is set by this study itself \(the configurations of run_kitti_ablation set it\)"):
        kitti.run_kitti_ablation("/nonexistent", params=MonoParams(warp_patches=False))  # refused before loading


def test_ablation_runs_every_configuration_on_params(monkeypatch):
    seen = {}
    monkeypatch.setattr(ex, "render_sequence", lambda sim, poses, **kw: (np.zeros((len(poses), 144, 192), np.uint8),
                                                                          np.tile(np.eye(4), (len(poses), 1, 1))))
    monkeypatch.setattr(studies, "run_mono", lambda imgs, Ts, K, *, name, params, progress, **ov:
                        seen.setdefault(name, params.replace(**ov)))
    studies.run_ablation({"a": {}, "b": {"refine": False}}, cases=("normal",), n_frames=2,
                         params=MonoParams(zncc_min=0.7))
    assert seen == {"normal, a": MonoParams(zncc_min=0.7), "normal, b": MonoParams(zncc_min=0.7, refine=False)}
