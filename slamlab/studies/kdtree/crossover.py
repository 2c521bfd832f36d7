"""The crossover of the stores (000 §4.3): iteration time against stored points, measured (re-exported by
:mod:`slamlab.studies.kdtree.experiments`).
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np

from ..._progress import progress_bar
from ..._table import format_table
from ..._validate import as_rng, check_choice, check_int
from ...kdtree.store_params import StoreParams
from ...kdtree.stores import STORE_NAMES, BruteForceStore, make_store
from .tree_studies import recall_at_1
from .workloads import surf_like_descriptors

__all__ = ["STORE_LABELS", "CrossoverResult", "run_crossover"]

#: the stores' short labels in the chapter's tables (keys: :data:`~slamlab.kdtree.stores.STORE_NAMES`)
STORE_LABELS = {"rebuild": "kd-tree", "multi": "multi", "flann": "FLANN", "brute": "brute"}

#: the fields of :class:`~slamlab.kdtree.store_params.StoreParams` that :func:`run_crossover` sets itself
_CROSSOVER_FIXED = ("base_seen_times", "max_non_base_time")


@dataclass(frozen=True)
class CrossoverResult:
    """Iteration time vs stored points for each store (000 §4.3's conclusion, measured).

    Attributes
    ----------
    sizes : (S,) int
        Stored points.
    stores : tuple of str
        Store names.
    recall : dict
        Store → (S,) recall@1 at each size.
    n_queries : int
        Queries per iteration.
    n_new : int
        New points per iteration.
    add_s, search_s : dict
        Store → (S,) add and search seconds per iteration at each size (machine dependent).
    params : StoreParams or None
        The settings every store ran with.
    """

    sizes: np.ndarray
    stores: tuple[str, ...]
    recall: dict  # store -> (S,) recall@1 at each size
    n_queries: int
    n_new: int
    add_s: dict = field(repr=False, default_factory=dict)  # store -> (S,) mean add time at that size (volatile)
    search_s: dict = field(repr=False, default_factory=dict)
    params: StoreParams | None = field(repr=False, default=None)

    def iteration_s(self, store: str) -> np.ndarray:
        """Seconds per iteration (add + search) of ``store`` at each size.

        Parameters
        ----------
        store : str
            One of :attr:`stores`.

        Returns
        -------
        (S,) float
        """
        return self.add_s[store] + self.search_s[store]

    def crossover(self, a: str = "rebuild", b: str = "multi") -> float:
        """Size from which store ``b`` stays faster per iteration than ``a`` (log-interpolated; nan if never).

        "Stays": ``b`` is faster at that size and at every larger one, so a noisy
        small size does not count as the crossover.

        Parameters
        ----------
        a, b : str
            The slower-then-faster pair of stores.

        Returns
        -------
        float
            Stored points at the crossover.
        """
        diff = np.log(self.iteration_s(b)) - np.log(self.iteration_s(a))
        if diff[-1] >= 0:
            return float("nan")
        slower = np.flatnonzero(diff >= 0)
        if not slower.size:
            return float(self.sizes[0])
        i = slower[-1] + 1  # first size of the final run where b is faster
        x0, x1 = np.log(self.sizes[i - 1]), np.log(self.sizes[i])
        f = diff[i - 1] / (diff[i - 1] - diff[i])
        return float(np.exp(x0 + f * (x1 - x0)))

    def __str__(self) -> str:
        return (f"crossover over {len(self.sizes)} sizes {int(self.sizes[0])}-{int(self.sizes[-1])}, "
                f"{self.n_queries} queries and {self.n_new} new points per iteration")

    def table(self) -> str:
        """Recall@1 of each store at each size (stable; times are in :meth:`timed_table`).

        Returns
        -------
        str
            Fixed-precision text table.
        """
        heads = ["stored points", *(f"recall {STORE_LABELS[s]}" for s in self.stores)]
        rows = [[f"{int(n)}", *(f"{self.recall[s][i]:.2f}" for s in self.stores)] for i, n in enumerate(self.sizes)]
        return format_table(heads, rows)

    def timed_table(self) -> str:
        """Milliseconds per iteration of each store at each size and the crossover (volatile).

        Returns
        -------
        str
            Text table and one line on the crossover.
        """
        heads = ["stored points", *(f"{STORE_LABELS[s]} ms" for s in self.stores)]
        rows = [[f"{int(n)}", *(f"{1e3 * self.iteration_s(s)[i]:.0f}" for s in self.stores)]
                for i, n in enumerate(self.sizes)]
        out = format_table(heads, rows)
        if "rebuild" in self.stores and "multi" in self.stores:
            c = self.crossover()
            out += ("\nmulti kd-tree faster than the rebuilt kd-tree from about "
                    + (f"{c:.0f} points on" if np.isfinite(c) else "(never in this range)"))
        return out


def run_crossover(sizes=(1000, 2000, 5000, 10000, 20000), *, stores=("rebuild", "multi", "brute"),
                  n_queries: int = 400, n_new: int = 500, repeats: int = 3, rng=2010, progress: bool | None = None,
                  params: StoreParams | None = None, **overrides) -> CrossoverResult:
    """Mean iteration time (``n_queries`` searches + ``n_new`` inserts) vs stored points (000 §4.3).

    Rebuild, FLANN and brute-force stores have no history: each is filled with
    ``n`` points at once and ``repeats`` iterations are timed. The multi kd-tree's
    add cost depends on its history, so it is filled by a stream of ``n_new``-point
    adds and its add time at size ``n`` is the mean over the fill adds between
    ``n/2`` and ``n`` (the amortised cost of 000's Tables). Timed repeats give
    their median (the machine is shared; one untimed warm-up query runs first). ``progress``: a
    bar over the stores (None: on unless ``$SLAMLAB_PROGRESS=0``).

    The stores run with ``StoreParams.resolve(params, **overrides)`` except the base rule, which the
    study sets itself: the points are added without re-sightings, so every point is base at once
    (``base_seen_times = 1``); ``base_seen_times`` or ``max_non_base_time`` set to anything but their
    default is a ``ValueError``.

    Parameters
    ----------
    sizes : sequence of int
        Stored points, increasing.
    stores : sequence of str
        Stores to time.
    n_queries : int
        Queries per iteration (90 % noisy re-observations, 10 % clutter).
    n_new : int
        Points added per iteration.
    repeats : int
        Timed iterations per size (their median is kept).
    rng : numpy.random.Generator, int or None
        Randomness of the descriptors and queries.
    progress : bool, callable or None
        Progress bar over the stores.
    params : StoreParams, optional
        The stores' settings (default :class:`~slamlab.kdtree.store_params.StoreParams`: ``n1 = 3500``,
        ``q = 5.5``, BBF with 200 checks, leaves of 8).
    **overrides
        :class:`~slamlab.kdtree.store_params.StoreParams` fields to change (``n1``, ``q``, ``tree``,
        ``leaf_size``, ``checks``).

    Returns
    -------
    CrossoverResult
        ``recall`` (stable) and ``add_s``/``search_s`` (timings) per store and size, and the settings.
    """
    sizes = np.asarray(sizes)
    if sizes.ndim != 1 or sizes.size == 0 or np.any(sizes < 1) or np.any(np.diff(sizes) <= 0):
        raise ValueError(f"`sizes` must be increasing positive integers; got {sizes.tolist()}")
    sizes = sizes.astype(np.int64)
    for s in stores:
        check_choice(s, "stores", STORE_NAMES)
    n_queries = check_int(n_queries, "n_queries", minimum=1)
    n_new = check_int(n_new, "n_new", minimum=1)
    repeats = check_int(repeats, "repeats", minimum=1)
    p = StoreParams.resolve(params, **overrides)
    for name in _CROSSOVER_FIXED:
        if getattr(p, name) != getattr(StoreParams(), name):
            raise ValueError(f"`{name}` is set by run_crossover itself: it adds points without re-sightings, so "
                             f"every point is base at once (base_seen_times = 1); got {name}={getattr(p, name)!r}")
    p = p.replace(base_seen_times=1)  # every point base at once
    rng = as_rng(rng)
    total = int(sizes[-1]) + n_new * (repeats + 1)
    X, protos = surf_like_descriptors(total, rng=rng)
    ids = np.arange(total, dtype=np.int64)
    # queries: noisy re-observations of stored points (the first n) plus 10 % clutter
    noise = 0.08 / 8.0
    recall, add_s, search_s = {}, {}, {}
    qsets = []
    for n in sizes:
        pick = rng.integers(0, n, n_queries - n_queries // 10)
        Qo = X[pick] + noise * rng.standard_normal((pick.size, X.shape[1])).astype(np.float32)
        Qc, _ = surf_like_descriptors(n_queries // 10, rng=rng, prototypes=protos)
        Q = np.concatenate([Qo, Qc]).astype(np.float32)
        ref = BruteForceStore()
        ref.add(X[:n], ids[:n])
        qsets.append((Q, ref.query(Q)[0]))
    warm = make_store("multi", params=p)
    warm.add(X[:n_new], ids[:n_new])
    warm.end_iteration()
    warm.query(qsets[0][0])
    for s in progress_bar(stores, desc="crossover: stores", progress=progress):
        rec, a_s, s_s = np.zeros(sizes.size), np.zeros(sizes.size), np.zeros(sizes.size)
        if s == "multi":
            store = make_store("multi", params=p)
            fill_t, fill_n, pos = [], [], 0
            for i, n in enumerate(sizes):
                while pos < n:
                    step = min(n_new, int(n) - pos)
                    t0 = time.perf_counter()
                    store.add(X[pos:pos + step], ids[pos:pos + step])
                    store.end_iteration()
                    fill_t.append((time.perf_counter() - t0) * n_new / step)
                    pos += step
                    fill_n.append(pos)
                fn, ft = np.array(fill_n), np.array(fill_t)
                a_s[i] = ft[(fn > n / 2) & (fn <= n)].mean()  # amortised: the big merges count
                Q, e = qsets[i]
                ts = []
                for _ in range(repeats):
                    t0 = time.perf_counter()
                    d, _ = store.query(Q)
                    ts.append(time.perf_counter() - t0)
                s_s[i], rec[i] = np.median(ts), recall_at_1(d, e)
        else:
            for i, n in enumerate(sizes):
                store = make_store(s, params=p)
                store.add(X[:n], ids[:n])
                store.end_iteration()
                Q, e = qsets[i]
                ta, ts = [], []
                for r in range(repeats):
                    t0 = time.perf_counter()
                    d, _ = store.query(Q)
                    t1 = time.perf_counter()
                    lo = int(n) + r * n_new
                    store.add(X[lo:lo + n_new], ids[lo:lo + n_new])
                    store.end_iteration()
                    t2 = time.perf_counter()
                    ts.append(t1 - t0)
                    ta.append(t2 - t1)
                    if r == 0:
                        rec[i] = recall_at_1(d, e)
                a_s[i], s_s[i] = np.median(ta), np.median(ts)
        recall[s], add_s[s], search_s[s] = rec, a_s, s_s
    return CrossoverResult(sizes, tuple(stores), recall, n_queries, n_new, add_s, search_s, p)
