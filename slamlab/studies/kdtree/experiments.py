"""Store experiments: 000's Tables 1 and 2 on our machine, the crossover, C fitted here (000 §4.2-4.3).

Every store sees the same descriptor stream (:mod:`slamlab.studies.kdtree.workloads`); per
iteration it answers the queries (the *search* time), then takes the
re-sightings and the new points and closes the iteration (the *add* time: the
rebuild, the merges, the buffer). Recall@1 is counted against exact search over
the same stored points (a brute-force store fed the same stream).
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np

from ..._progress import progress_bar
from ..._table import format_table
from ..._validate import check_choice, check_int
from ...kdtree.cost_model import calibrate_C
from ...kdtree.store_params import StoreParams
from ...kdtree.stores import STORE_NAMES, FlannStore, make_store
from .crossover import STORE_LABELS, CrossoverResult, run_crossover
from .tree_studies import CFitResult, DimensionStudyResult, fit_C, recall_at_1, run_dimension_study
from .workloads import SCENARIO_FIELDS, Scenario, Workload, make_workload

__all__ = [
    "TABLES_000",
    "CFitResult",
    "CrossoverResult",
    "DimensionStudyResult",
    "StoreComparisonResult",
    "fit_C",
    "ours_vs_source",
    "recall_at_1",
    "run_crossover",
    "run_dimension_study",
    "run_store_comparison",
]

#: 000's Tables 1 and 2 (ms): mean/max add, mean/max search, mean/max iteration ("<" bounds for the max).
TABLES_000 = {
    "table1": {"kd-tree": (85, 204, 70, 157, 155, 360), "multi kd-tree": (25, 141, 174, 375, 200, 515)},
    "table2": {"kd-tree": (524, 1219, 55, 110, 579, 1329), "multi kd-tree": (33, 609, 164, 406, 199, 1015)},
}
_ROWS = ("mean add", "max add", "mean search", "max search", "mean iteration", "max iteration")



@dataclass(frozen=True)
class StoreComparisonResult:
    """000's Table 1 or 2 rerun for several stores on one descriptor stream.

    Attributes
    ----------
    scenario : str
        Workload name ("table1", "table2" or a recorded stream's).
    stores : tuple of str
        Store names (:data:`~slamlab.kdtree.stores.STORE_NAMES`).
    n_iterations : int
        Iterations run.
    stored_end : int
        Points stored at the end.
    queries_per_iteration : float
        Mean queries per iteration.
    recall : dict
        Store → recall@1 over all queries, against exact search.
    ops : dict
        Store → per-iteration operation counts (``rebuilt_mean``, ``rebuilt_max``, ``evals_mean``,
        ``evals_max``, ``trees_mean``).
    params : StoreParams
        The settings every store ran with (the base rule is the scenario's).
    add_s, search_s : dict
        Store → (T,) add and search seconds per iteration (machine dependent).
    """

    scenario: str
    stores: tuple[str, ...]
    n_iterations: int
    stored_end: int
    queries_per_iteration: float
    recall: dict  # store -> recall@1 over all queries
    ops: dict  # store -> dict of per-iteration operation counts (mean/max rebuilt points, evals per query, trees)
    params: StoreParams
    add_s: dict = field(repr=False, default_factory=dict)  # store -> (T,) seconds (volatile)
    search_s: dict = field(repr=False, default_factory=dict)

    @property
    def n1(self) -> int:
        """The multi kd-tree's ``n1`` the stores ran with."""
        return int(self.params.n1)

    @property
    def q(self) -> float:
        """The multi kd-tree's ``q`` the stores ran with."""
        return float(self.params.q)

    @property
    def checks(self) -> int:
        """The BBF budget (and FLANN's checks) the stores ran with."""
        return int(self.params.checks)

    def __str__(self) -> str:
        r = ", ".join(f"{STORE_LABELS[s]} {self.recall[s]:.3f}" for s in self.stores)
        return (f"{self.scenario}: {self.n_iterations} iterations, {self.stored_end} points at the end, "
                f"recall@1 {r}")

    def table(self) -> str:
        """Operation counts and recall (stable; what nbval checks).

        Returns
        -------
        str
            Fixed-precision text table.
        """
        heads = ["per iteration", *(STORE_LABELS[s] for s in self.stores)]
        rows = []
        for key, label, fmt in (("rebuilt_mean", "mean points rebuilt (add)", "{:.0f}"),
                                ("rebuilt_max", "max points rebuilt (add)", "{:.0f}"),
                                ("evals_mean", "mean distances per query (search)", "{:.0f}"),
                                ("evals_max", "max distances per query (search)", "{:.0f}"),
                                ("trees_mean", "mean trees searched", "{:.2f}")):
            rows.append([label, *("n/a" if np.isnan(self.ops[s][key]) else fmt.format(self.ops[s][key])
                                  for s in self.stores)])
        rows.append(["recall@1 vs exact", *(f"{self.recall[s]:.3f}" for s in self.stores)])
        name = f"000 {self.scenario.replace('table', 'Table ')}" if self.scenario in ("table1", "table2") else self.scenario
        title = (f"{name} workload: {self.n_iterations} iterations, {self.stored_end} points at the end\n"
                 f"~{self.queries_per_iteration:.0f} queries per iteration; "
                 f"multi kd-tree n1 = {self.n1}, q = {self.q:g}; BBF checks = {self.checks}")
        return format_table(heads, rows, title=title)

    def times_ms(self, store: str) -> tuple[float, ...]:
        """(mean add, max add, mean search, max search, mean iteration, max iteration) in ms.

        Parameters
        ----------
        store : str
            One of :attr:`stores`.

        Returns
        -------
        tuple of 6 float
        """
        a, s = 1e3 * self.add_s[store], 1e3 * self.search_s[store]
        it = a + s
        return (a.mean(), a.max(), s.mean(), s.max(), it.mean(), it.max())

    def timed_table(self, *, with_000: bool = True) -> str:
        """000's rows in ms, 000's figures beside ours (volatile: print in an ignored cell).

        Parameters
        ----------
        with_000 : bool
            Add 000's columns (for the scenarios "table1" and "table2").

        Returns
        -------
        str
        """
        ref = TABLES_000.get(self.scenario) if with_000 else None
        heads = ["ms", *(f"000 {k}" for k in (ref or {})), *(f"ours {STORE_LABELS[s]}" for s in self.stores)]
        ours = {s: self.times_ms(s) for s in self.stores}
        rows = []
        for r, name in enumerate(_ROWS):
            refc = [("<" if name == "max iteration" else "") + str(vals[r]) for vals in (ref or {}).values()]
            rows.append([name, *refc, *(f"{ours[s][r]:.0f}" for s in self.stores)])
        out = format_table(heads, rows)
        if "rebuild" in self.stores:
            base = ours["rebuild"][4]
            ratios = ", ".join(f"{STORE_LABELS[s]} {base / ours[s][4]:.1f}x" for s in self.stores if s != "rebuild")
            out += f"\nmean iteration speed-up over the rebuilt kd-tree: {ratios}"
            if ref:
                out += f" (000: multi {ref['kd-tree'][4] / ref['multi kd-tree'][4]:.1f}x)"
        return out


def _exact_stream(iterations, params):
    """Exact first-neighbour distances of every iteration's queries over the points stored then."""
    ref = make_store("brute", params=params)
    out = []
    for it in iterations:
        out.append(ref.query(it.queries)[0])
        ref.observe(it.observed)
        ref.add(it.new_X, it.new_ids)
        ref.end_iteration()
    return out


def _run_stream(store, iterations, exact=None):
    T = len(iterations)
    add_s, search_s = np.zeros(T), np.zeros(T)
    rebuilt, evals, trees = np.zeros(T), np.zeros(T), np.zeros(T)
    hits, total = 0.0, 0
    prev = _counters(store)
    for t, it in enumerate(iterations):
        t0 = time.perf_counter()
        d, _ = store.query(it.queries)
        t1 = time.perf_counter()
        store.observe(it.observed)
        store.add(it.new_X, it.new_ids)
        store.end_iteration()
        t2 = time.perf_counter()
        add_s[t], search_s[t] = t2 - t1, t1 - t0
        if exact is not None and np.isfinite(exact[t][:, 0]).any():
            n = int(np.isfinite(exact[t][:, 0]).sum())
            hits += recall_at_1(d, exact[t]) * n
            total += n
        c = _counters(store)
        rebuilt[t] = c["points_rebuilt"] - prev["points_rebuilt"]
        evals[t] = (c["distance_evals"] - prev["distance_evals"]) / max(it.queries.shape[0], 1)
        if isinstance(getattr(store, "base", None), FlannStore):  # FLANN does not report its work
            evals[t] = np.nan
        trees[t] = c["trees_searched"] - prev["trees_searched"]
        prev = c
    ops = {"rebuilt_mean": rebuilt.mean(), "rebuilt_max": rebuilt.max(), "evals_mean": float(np.mean(evals)),
           "evals_max": float(np.max(evals)), "trees_mean": trees.mean()}
    return add_s, search_s, ops, (hits / total if total else float("nan"))


def _counters(store):
    c = store.all_counters if hasattr(store, "all_counters") else store.counters
    return c.as_dict()


#: the fields of :class:`~slamlab.kdtree.store_params.StoreParams` that the scenario sets (its base rule)
_SCENARIO_RULE = ("base_seen_times", "max_non_base_time")


def run_store_comparison(scenario="table2", *, stores=("rebuild", "multi", "flann", "brute"),
                         params: StoreParams | None = None, n_iterations: int | None = None, rng=2010,
                         progress: bool | None = None, **changes) -> StoreComparisonResult:
    """Run 000's Table 1 (``"table1"``) or Table 2 (``"table2"``) workload through every store (000 §4.2).

    ``scenario`` may also be a recorded :class:`~slamlab.studies.kdtree.workloads.Workload`
    (:class:`~slamlab.studies.kdtree.workloads.RecordingStore`), replayed as recorded.

    ``n_iterations`` shortens the run (the notebook's small size). The stores run with
    ``StoreParams.resolve(params, **store_changes)`` and the base rule of the scenario (Table 1: 3 sightings
    within 7 iterations; Table 2: every point base at once), applied by every store
    (:func:`~slamlab.kdtree.stores.make_store`): the base rule is changed as a scenario field
    (``base_seen_times=``, ``max_non_base_time=``); in ``params`` anything but the defaults is a
    ``ValueError``. ``progress``: a bar over the stores (None: on unless ``$SLAMLAB_PROGRESS=0``).

    Parameters
    ----------
    scenario : str or Workload
        "table1", "table2" or a recorded :class:`~slamlab.studies.kdtree.workloads.Workload`.
    stores : sequence of str
        Stores to run (:data:`~slamlab.kdtree.stores.STORE_NAMES`).
    params : StoreParams, optional
        The stores' settings (default :class:`~slamlab.kdtree.store_params.StoreParams`: ``n1 = 3500``,
        ``q = 5.5``, BBF with 200 checks, leaves of 8).
    n_iterations : int, optional
        Shorten the generated stream to this many iterations.
    rng : numpy.random.Generator, int or None
        Randomness of the generated stream.
    progress : bool, callable or None
        Progress bar over the stores.
    **changes
        :class:`~slamlab.kdtree.store_params.StoreParams` fields (``n1``, ``q``, ``tree``, ``leaf_size``,
        ``checks``) and :class:`~slamlab.studies.kdtree.workloads.Scenario` fields (the base rule among them)
        to change.

    Returns
    -------
    StoreComparisonResult
        ``recall`` and ``ops`` per store (stable), ``add_s``/``search_s`` (timings), the settings.
    """
    stores = tuple(stores)
    if not stores:
        raise ValueError("`stores` must name at least one store")
    for s in stores:
        check_choice(s, "stores", STORE_NAMES)
    store_fields = set(StoreParams.field_names()) - set(_SCENARIO_RULE)
    unknown = sorted(set(changes) - store_fields - set(SCENARIO_FIELDS))
    if unknown:
        raise TypeError(f"run_store_comparison got unknown keyword(s) {', '.join(map(repr, unknown))}; the changes "
                        f"are StoreParams fields ({', '.join(sorted(store_fields))}) or Scenario fields "
                        f"({', '.join(SCENARIO_FIELDS)})")
    store_changes = {k: changes.pop(k) for k in list(changes) if k in store_fields}
    if params is not None:
        StoreParams.resolve(params)  # a `params` of the wrong type fails here, naming it
        for name in _SCENARIO_RULE:
            if getattr(params, name) != getattr(StoreParams(), name):
                raise ValueError(f"`{name}` is the scenario's (its base rule): change it as a scenario field, "
                                 f"run_store_comparison(..., {name}=...), not in `params`; got "
                                 f"params.{name}={getattr(params, name)!r}")
    if isinstance(scenario, Workload):  # a recorded stream (e.g. RecordingStore.workload() of a stereo run)
        if n_iterations is not None or changes:
            raise ValueError("a recorded Workload is replayed as it is: no `n_iterations` or scenario changes")
        w = scenario
    else:
        if n_iterations is not None:
            changes["n_iterations"] = check_int(n_iterations, "n_iterations", minimum=1)
        w = make_workload(scenario, rng=rng, **changes)
    sc: Scenario = w.scenario
    p = StoreParams.resolve(params, **store_changes, base_seen_times=sc.base_seen_times,
                            max_non_base_time=sc.max_non_base_time)
    recall, ops, add_s, search_s = {}, {}, {}, {}
    exact = _exact_stream(w.iterations, p)
    for s in progress_bar(stores, desc=f"{sc.name}: stores", progress=progress):
        a, se, o, r = _run_stream(make_store(s, params=p), w.iterations, exact)
        add_s[s], search_s[s], ops[s], recall[s] = a, se, o, r
    qpi = float(np.mean([it.queries.shape[0] for it in w.iterations]))
    return StoreComparisonResult(sc.name, stores, len(w), int(w.stored[-1]), qpi, recall, ops, p, add_s, search_s)


def ours_vs_source(cost, dimension: DimensionStudyResult, table1: StoreComparisonResult,
                   table2: StoreComparisonResult, real: StoreComparisonResult | None = None) -> str:
    """000's figures beside ours, from the chapter's runs (000 §4, Appendix); timings stay in the timed tables.

    Parameters
    ----------
    cost : CostModelResult
        From :func:`~slamlab.kdtree.cost_model.run_cost_model`.
    dimension : DimensionStudyResult
        From :func:`run_dimension_study`.
    table1, table2 : StoreComparisonResult
        :func:`run_store_comparison` of the two scenarios (with the stores "rebuild" and "multi").
    real : StoreComparisonResult, optional
        The same for the recorded stereo stream.

    Returns
    -------
    str
        A table: quantity, 000's figure, ours.
    """
    _, n1_lit, q_lit, _, _ = cost.literal
    _, n1, q, _, _ = cost.optimum
    exact64 = [r for r in dimension.rows if r[1] == 64]
    rows = [
        ["optimum n1, q: the Appendix as printed", "n1 ≈ 3500, q = 5.5 (plot)", f"n1 = {n1_lit:.0f}, q = {q_lit:.2f}"],
        ["optimum n1, q: search term C s T_search", "n1 ≈ 3500, q = 5.5 (plot)", f"n1 = {n1:.0f}, q = {q:.2f}"],
        ["within 1 % of that optimum", "—", (f"n1 {cost.flat_n1[0]:.0f}-{cost.flat_n1[1]:.0f}, "
                                              f"q {cost.flat_q[0]:.2f}-{cost.flat_q[1]:.2f}")],
        ["C = C1/C2 from 000's one-tree timings", "≈ 9", f"{calibrate_C(526, 0.079, 678, 0.750, 44828):.2f}"],
    ]
    if exact64:
        rows.append(["exact search in 64-d: % leaves visited", "O(log n) per search",
                     ", ".join(f"{lv:.0f} ({d.split()[0]})" for d, _, lv, _, _ in exact64)])
    for name, res, n_000 in (("Table 1", table1, "~13000"), ("Table 2", table2, "65000")):
        rows.append([f"{name}: points stored at the end", n_000, f"{res.stored_end} ({res.n_iterations} iterations)"])
        rows.append([f"{name}: recall@1 kd-tree / multi", "— (not measured)",
                     f"{res.recall['rebuild']:.3f} / {res.recall['multi']:.3f}"])
    rows.append(["multi: mean points rebuilt per iteration", "~3000-point tree update",
                 f"{table2.ops['multi']['rebuilt_mean']:.0f} (Table 2), {table1.ops['multi']['rebuilt_mean']:.0f} (Table 1)"])
    if real is not None:
        rows.append(["recorded stream: recall@1 kd-tree / multi", "—",
                     f"{real.recall['rebuild']:.3f} / {real.recall['multi']:.3f} ({real.stored_end} points)"])
    return format_table(["quantity", "000", "ours"], rows, title="Landmark stores: 000 beside ours (times: timed tables)")
