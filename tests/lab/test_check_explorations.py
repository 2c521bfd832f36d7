"""Labs 01-07's explorations: accepted ranges against independent computations, typical wrong answers rejected
with the hint naming their misconception, hints without code, questions without ready-made calls (issue 26)."""

from __future__ import annotations

import json
import re
from pathlib import Path

import numpy as np
import pytest

from slamlab_grading import core
from slamlab_grading import tasks_filters as tf
from slamlab_grading import tasks_stereo as tst
from slamlab_grading import tasks_stores as tso

ROOT = Path(__file__).resolve().parent.parent.parent
LABS_01_07 = sorted((ROOT / "notebooks" / "labs").glob("0[1-7]_*_lab.ipynb"))
CHAPTERS = ("01", "02", "03", "04", "05", "06", "07")


def _tasks(kind):
    return {k: t for k, t in core.all_tasks().items() if k[:2] in CHAPTERS and isinstance(t, kind)}


EXPLORATIONS = _tasks(core.ExplorationTask)
WITH_RANGE = sorted(k for k, t in EXPLORATIONS.items() if t.accepted is not None)


@pytest.fixture(autouse=True)
def _fresh_attempts(monkeypatch):
    # attempts: the student side records them (slamlab.lab.attempts)
    monkeypatch.delenv("NBGRADER_EXECUTION", raising=False)


# --- the scan: no ready-made library call in an exploration's question ------------------------------------

_CALL = re.compile(r"\bsl\.[A-Za-z_][\w.]*\s*\(")


def ready_made_calls(labs) -> list[tuple[str, str, str]]:
    """``(lab, grade_id, call)`` for every ``sl.`` call spelt out in the markdown of an exploration's cells.

    An exploration's cells are its question (grade id ``labNN_eK_text``) and any other markdown cell whose
    grade id has the ``_eK_`` part; naming a library function (``sl.studies.filters.run_cv_target``) is allowed,
    writing the call (``sl.studies.filters.run_cv_target(...)``) is not.
    """
    found = []
    for lab in labs:
        nb = json.loads(Path(lab).read_text(encoding="utf-8"))
        for cell in nb["cells"]:
            gid = cell.get("metadata", {}).get("nbgrader", {}).get("grade_id", "")
            if cell["cell_type"] == "markdown" and re.search(r"_e\d+_", gid):
                src = "".join(cell["source"])
                found += [(Path(lab).name, gid, m.group(0)) for m in _CALL.finditer(src)]
    return found


def test_the_scan_finds_a_ready_made_call(tmp_path):
    nb = {"cells": [{"cell_type": "markdown", "metadata": {"nbgrader": {"grade_id": "lab99_e1_text"}},
                     "source": ["Use `sl.studies.filters.run_cv_target` ", "or run `sl.sweep.sweep(f, grid)`."]}]}
    p = tmp_path / "99_x_lab.ipynb"
    p.write_text(json.dumps(nb))
    assert ready_made_calls([p]) == [("99_x_lab.ipynb", "lab99_e1_text", "sl.sweep.sweep(")]


def test_labs_01_07_explorations_spell_no_call():
    assert len(LABS_01_07) == 7
    assert ready_made_calls(LABS_01_07) == []


def test_every_exploration_of_labs_01_07_is_a_question_cell():
    for lab in LABS_01_07:
        nb = json.loads(lab.read_text(encoding="utf-8"))
        texts = [c for c in nb["cells"] if re.search(r"_e\d+_text$", c["metadata"].get("nbgrader", {})
                                                      .get("grade_id", ""))]
        assert len(texts) == 2, lab.name
        for c in texts:
            assert "?" in "".join(c["source"]), (lab.name, c["metadata"]["nbgrader"]["grade_id"])


# --- hints: no code, no answer ----------------------------------------------------------------------------

_CODE = re.compile(r"\b(sl|np|numpy|cv2|scipy)\.\w|\w\(\.\.\.|\b\w+=['\"\w]|\bimport\b|\[\s*:|\w\[[^\]]*:[^\]]*\]")


def _hints(t):
    yield t.hint
    if isinstance(t, core.ExplorationTask):
        yield t.more
        for w in t.wrong:
            yield w.hint
            yield w.more


@pytest.mark.parametrize("task_id", sorted(_tasks((core.Task, core.ExplorationTask))))
def test_hints_hold_no_code(task_id):
    for h in _hints(core.task(task_id)):
        assert not _CODE.search(h), f"{task_id}: code in the hint {h!r}"


@pytest.mark.parametrize("task_id", sorted(EXPLORATIONS))
def test_exploration_states_its_accepted_range_and_why(task_id):
    t = EXPLORATIONS[task_id]
    assert len(t.why) > 40
    assert t.hint


# --- accepted ranges against independent computations ------------------------------------------------------


def _kf_monte_carlo_rmse(pos_std_m, n_runs, n_steps, seed):
    """The constant-velocity target tracked by a KF written here (vectorised over runs), 2-D position RMSE."""
    rng = np.random.default_rng(seed)
    F1 = np.array([[1.0, 1.0], [0.0, 1.0]])
    Q1 = 0.2**2 * np.array([[1 / 3, 1 / 2], [1 / 2, 1.0]])
    L = np.linalg.cholesky(Q1)
    se = 0.0
    for _axis in range(2):
        P = np.diag([pos_std_m**2, 1.0])
        x_true = np.array([0.0, 1.0]) + rng.normal(size=(n_runs, 2)) * np.array([pos_std_m, 1.0])
        x_est = np.tile([0.0, 1.0], (n_runs, 1))
        for _ in range(n_steps):
            x_true = x_true @ F1.T + rng.normal(size=(n_runs, 2)) @ L.T
            z = x_true[:, 0] + pos_std_m * rng.normal(size=n_runs)
            x_est = x_est @ F1.T
            P = F1 @ P @ F1.T + Q1
            K = P[:, 0] / (P[0, 0] + pos_std_m**2)
            x_est = x_est + (z - x_est[:, 0])[:, None] * K[None, :]
            P = P - np.outer(K, P[0])
            se += float(np.sum((x_est[:, 0] - x_true[:, 0]) ** 2))
    return np.sqrt(se / (n_runs * n_steps))


def test_rmse_range_holds_for_other_seeds_run_counts_and_lengths_and_the_library():
    lo, hi = core.task("01.explore.rmse_quarter_metre").accepted_range()
    assert lo <= core.task("01.explore.rmse_quarter_metre").expected() <= hi  # the library's Monte Carlo
    for seed, n_runs, n_steps in ((1, 50, 50), (7, 100, 50), (3, 50, 200), (11, 200, 100)):
        assert lo <= _kf_monte_carlo_rmse(0.25, n_runs, n_steps, seed) <= hi, (seed, n_runs, n_steps)
    # the analytic recursion agrees with a long Monte Carlo written here
    assert _kf_monte_carlo_rmse(1.0, 400, 50, 5) == pytest.approx(tf.cv_position_rmse_analytic(1.0), rel=0.03)


def test_literal_n1_range_holds_for_the_library_grid_and_a_continuous_minimiser():
    from scipy.optimize import minimize

    from slamlab.kdtree.cost_model import iter_time, minimise_iter_time

    lo, hi = core.task("04.explore.literal_n1").accepted_range()
    assert lo <= minimise_iter_time(n=50000, s=500, m=500, C=9.0, reading="literal")[0] <= hi
    coarse = minimise_iter_time(n=50000, s=500, m=500, C=9.0, reading="literal", grid=(196, 86))  # steps 100, 0.1
    assert lo <= coarse[0] <= hi
    res = minimize(lambda v: float(tso.literal_iter_time(v[0], v[1])), x0=[3000.0, 4.0], method="Nelder-Mead",
                   options={"xatol": 1e-3, "fatol": 1e-6, "maxiter": 4000})
    assert res.success
    assert lo <= res.x[0] <= hi
    # the restatement is Task 3's formula: it agrees with the library's literal reading
    rng = np.random.default_rng(0)
    n1, q = rng.uniform(500, 20000, 20), rng.uniform(1.5, 10, 20)
    np.testing.assert_allclose(tso.literal_iter_time(n1, q),
                               iter_time(n1, q, n=50000, s=500, m=500, C=9.0, reading="literal"), rtol=1e-12)


@pytest.mark.parametrize(("n1", "q", "batches"), [(1000, 3.0, (500,) * 40), (100, 2.0, (30, 70, 10, 250, 5) * 6),
                                                  (4, 2.0, (3, 3, 3)), (50, 1.5, (1,) * 120)])
def test_points_rebuilt_count_from_sizes_matches_the_store(n1, q, batches):
    from slamlab.kdtree.stores import MultiKDTree

    store = MultiKDTree(n1, q, tree="ckdtree")
    rng = np.random.default_rng(3)
    start = 0
    for b in batches:
        store.add(rng.random((b, 8)), np.arange(start, start + b))
        start += b
    assert store.counters.points_rebuilt == tso.rebuilt_count(n1, q, batches)


def test_points_rebuilt_range_is_the_exact_count():
    t = core.task("04.explore.points_rebuilt")
    lo, hi = t.accepted_range()
    assert lo == hi == t.expected()


def test_depth_error_range_holds_for_triangulation_and_the_first_order_formula():
    t = core.task("05.explore.depth_error")
    lo, hi = t.accepted_range()
    first, exact = tst.depth_error_formulas()
    assert lo <= first <= hi
    assert lo <= exact <= hi
    assert t.expected() == pytest.approx(exact, rel=1e-6)  # the library's triangulation is the exact value
    # and by hand, from the projected pixels (the rig is rectified: same rows, u shifts by f B / Z)
    from slamlab_grading.experiments import stereo_rig

    rig = stereo_rig()
    uvl, uvr = rig.project(np.array([[0.0, 0.0, 8.0]]))
    d = uvl[0, 0] - uvr[0, 0]
    assert lo <= rig.left.fx * rig.baseline_m / (d - 0.5) - 8.0 <= hi


# --- typical wrong answers: outside the range, answered with their misconception ------------------------------


@pytest.mark.parametrize("task_id", sorted(k for k, t in EXPLORATIONS.items() if t.wrong))
def test_typical_wrong_answers_are_rejected_with_their_hint_and_never_the_answer(task_id):
    t = core.task(task_id)
    lo, hi = t.accepted_range()
    for w in t.wrong:
        v = float(w.value())
        assert not lo <= v <= hi, f"{task_id}: the wrong answer {w.label!r} ({v}) is accepted"
        first = core.answer(task_id, v, quiet=True)
        assert first.status == "failed"
        assert w.hint in first.message
        if w.more:
            assert w.more not in first.message
            assert w.more in core.answer(task_id, v, quiet=True).message
        for shown in {f"{lo:g}", f"{hi:g}", f"{(lo + hi) / 2:g}"} - {"0"}:
            assert shown not in first.message.split("Hint:", 1)[1], f"{task_id}: the hint gives {shown}"


@pytest.mark.realdata
def test_fast_threshold_range_is_opencvs_answer_and_opencv_counts_as_the_library():
    import cv2

    from slamlab.features import fast_detect, load_oxford_image
    from slamlab_grading import tasks_features as tfe

    t = core.task("02.explore.fast_threshold")
    lo, hi = t.accepted_range()
    assert lo == hi == t.expected()
    img = np.ascontiguousarray(load_oxford_image("graf", 1, size=(768, 576)), dtype=np.uint8)
    for thr in (20, 30, 35, 40):  # around the answer: the two detectors agree corner count for corner count
        fd = cv2.FastFeatureDetector_create(threshold=thr, nonmaxSuppression=True,
                                            type=cv2.FAST_FEATURE_DETECTOR_TYPE_9_16)
        assert len(fd.detect(img)) == len(fast_detect(img, thr))
    assert tfe.fast_threshold_opencv(nonmax=False) > hi


@pytest.mark.parametrize("lab", LABS_01_07, ids=[p.name for p in LABS_01_07])
def test_lab_has_an_open_investigation_with_a_rubric_and_a_time_plan(lab):
    nb = json.loads(lab.read_text(encoding="utf-8"))
    by_id = {c["metadata"].get("nbgrader", {}).get("grade_id"): c for c in nb["cells"]}
    n = lab.name[:2]
    text, answer = by_id[f"lab{n}_inv_text"], by_id[f"lab{n}_inv_answer"]
    meta = answer["metadata"]["nbgrader"]
    assert answer["cell_type"] == "markdown"
    assert meta["grade"]
    assert meta["solution"]
    assert meta["points"] == 4
    rubric = "".join(answer["source"])
    assert "Rubric" in rubric
    assert rubric.count("1 point") == 4  # what earns each point
    assert "?" in "".join(text["source"])
    assert not _CALL.search("".join(text["source"]))
    assert "Time plan" in "".join(by_id[f"lab{n}_intro"]["source"])


# --- labs 08-10: the same rules (issue 26) ----------------------------------------------------------------

CHAPTERS_08_10 = ("08", "09", "10")
LABS_08_10 = sorted(p for c in CHAPTERS_08_10 for p in (ROOT / "notebooks" / "labs").glob(f"{c}_*_lab.ipynb"))


def _tasks_08_10(kind):
    return {k: t for k, t in core.all_tasks().items() if k[:2] in CHAPTERS_08_10 and isinstance(t, kind)}


EXPLORATIONS_08_10 = _tasks_08_10(core.ExplorationTask)


def test_labs_08_10_explorations_spell_no_call():
    assert len(LABS_08_10) == len(CHAPTERS_08_10)
    assert ready_made_calls(LABS_08_10) == []


@pytest.mark.parametrize("task_id", sorted(_tasks_08_10((core.Task, core.ExplorationTask))))
def test_hints_of_labs_08_10_hold_no_code(task_id):
    test_hints_hold_no_code(task_id)


@pytest.mark.parametrize("task_id", sorted(EXPLORATIONS_08_10))
def test_exploration_of_labs_08_10_has_an_independent_range_why_and_typical_wrong_answers(task_id):
    t = EXPLORATIONS_08_10[task_id]
    assert t.accepted is not None  # an independent range, not the library's own seeded run
    assert len(t.why) > 40
    assert t.hint
    assert t.more
    assert t.wrong
    test_typical_wrong_answers_are_rejected_with_their_hint_and_never_the_answer(task_id)
    lo, hi = t.accepted_range()
    assert core.answer(task_id, (lo + hi) / 2, quiet=True).passed


@pytest.mark.parametrize("lab", LABS_08_10, ids=[p.name for p in LABS_08_10])
def test_labs_08_10_explorations_are_questions_with_an_investigation_rubric_and_time_plan(lab):
    nb = json.loads(lab.read_text(encoding="utf-8"))
    texts = [c for c in nb["cells"] if re.search(r"_e\d+_text$", c["metadata"].get("nbgrader", {}).get("grade_id", ""))]
    assert len(texts) == 2
    assert all("?" in "".join(c["source"]) for c in texts)
    test_lab_has_an_open_investigation_with_a_rubric_and_a_time_plan(lab)


# --- the scan (issue 43, item 2): no exploration's text names a public function that computes its answer -----

ALL_LABS = sorted((ROOT / "notebooks" / "labs").glob("*_lab.ipynb"))


def _exploration_text(lab: Path, part: str) -> str:
    """The markdown of exploration ``part`` ("e1") of ``lab``: every markdown cell whose grade id has ``_eK_``."""
    nb = json.loads(lab.read_text(encoding="utf-8"))
    return "\n".join("".join(c["source"]) for c in nb["cells"] if c["cell_type"] == "markdown"
                     and f"_{part}_" in c["metadata"].get("nbgrader", {}).get("grade_id", ""))


def named_answers(lab: Path, part: str, answered_by) -> list[str]:
    """The names of ``answered_by`` that the exploration's text spells: the dotted name (``slamlab.`` or ``sl.``
    or none) or its last component as a word."""
    text = _exploration_text(lab, part)
    found = []
    for name in answered_by:
        last = name.rsplit(".", 1)[-1]
        if re.search(rf"(?<![\w.]){re.escape(last)}\b", text) or name.split("slamlab.", 1)[-1] in text:
            found.append(name)
    return found


def test_the_name_scan_finds_a_named_function(tmp_path):
    nb = {"cells": [{"cell_type": "markdown", "metadata": {"nbgrader": {"grade_id": "lab99_e1_text"}},
                     "source": ["**How many?** `run_sim_slam` runs the experiment."]},
                    {"cell_type": "markdown", "metadata": {"nbgrader": {"grade_id": "lab99_e2_text"}},
                     "source": ["**How many?** Use the `sl.hough` package's building blocks."]}]}
    p = tmp_path / "99_x_lab.ipynb"
    p.write_text(json.dumps(nb))
    names = ("slamlab.studies.hough.run_sim_slam",)
    assert named_answers(p, "e1", names) == list(names)
    assert named_answers(p, "e2", names) == []


@pytest.mark.parametrize("lab", ALL_LABS, ids=[p.name for p in ALL_LABS])
def test_no_exploration_names_the_function_that_answers_it(lab):
    import importlib

    assert ready_made_calls([lab]) == []
    tasks = {k: t for k, t in core.all_tasks().items() if k.startswith(lab.name[:2] + ".")}
    nb = json.loads(lab.read_text(encoding="utf-8"))
    for c in nb["cells"]:
        gid = c["metadata"].get("nbgrader", {}).get("grade_id", "")
        if not (gid.endswith("_check") and "_e" in gid):
            continue
        tid = re.search(r'sl\.lab\.answer\("([^"]+)"', "".join(c["source"])).group(1)
        t = tasks[tid]  # answered_by may be empty: no public function computes the answer
        for name in t.answered_by:  # each a real public name of slamlab
            mod, _, attr = name.rpartition(".")
            while mod and attr:
                try:
                    obj = importlib.import_module(mod)
                    break
                except ModuleNotFoundError:
                    mod, _, head = mod.rpartition(".")
                    attr = f"{head}.{attr}"
            for a in attr.split("."):
                obj = getattr(obj, a)
            assert callable(obj), name
        part = gid.split("_")[1]
        assert named_answers(lab, part, t.answered_by) == [], f"{lab.name} {part} names {t.answered_by}"
