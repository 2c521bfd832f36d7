"""Descriptor streams that reproduce 000's two store runs (000 §4.2, Tables 1 and 2).

000 measured its stores inside the stereo SLAM loop. We replace the camera by a
generator (our addition) that produces, per iteration, the queries (~400) and the
new points (several hundred) of a SLAM run with 64-d SURF-like descriptors:

- a landmark's descriptor is drawn around one of ``n_clusters`` texture
  prototypes (clustered, like real descriptors); SURF layout: 16 sub-regions x
  ``(sum dx, sum dy, sum |dx|, sum |dy|)``, unit length, float32;
- every new point starts a *track*: it is re-observed in each of the next
  iterations with probability ``p_track`` (geometric track length), so recent
  landmarks are re-sighted; ``n_old`` queries per iteration re-observe older
  base landmarks (revisits, the loop of Table 1); ``n_clutter`` queries are
  features of no stored landmark;
- a re-observation is the landmark's descriptor plus Gaussian noise
  ``sigma_obs`` (renormalised).

Table 1 (loop, ~13000 points): base after 3 sightings within 7 iterations, the
rest dropped. Table 2 (room, ~65000 points): every point base at once.
``clustered=False`` draws descriptors uniformly on the unit sphere instead --
the case where Best-Bin-First recall collapses.
"""

from __future__ import annotations

from dataclasses import dataclass, fields, replace

import numpy as np

from ..._validate import as_rng, check_choice, check_int
from ...kdtree.store_params import StoreParams, resolve_store_params
from ...kdtree.stores import LandmarkStore, SightingBook

__all__ = ["SCENARIOS", "SCENARIO_FIELDS", "Iteration", "Scenario", "Workload", "make_workload", "scenario",
           "surf_like_descriptors"]

DIM = 64
_BLOCK = 8192  # rows per block of surf_like_descriptors (4 MiB per float64 temporary)


@dataclass(frozen=True)
class Scenario:
    """Parameters of a descriptor stream (our choices where 000 is silent).

    Attributes
    ----------
    name : str
        Scenario name.
    n_iterations : int
        Iterations of the stream.
    n_new : int
        New points per iteration.
    p_track : float
        Probability in [0, 1) that a tracked landmark is re-seen in the next iteration.
    n_old : int
        Queries re-observing older base landmarks per iteration.
    n_clutter : int
        Queries of features that are not stored landmarks, per iteration.
    base_seen_times : int
        000's BaseSeenTimes (3 in Table 1; 1 = all base at once): given by each scenario.
    max_non_base_time : int
        000's MaxNonBaseTime in iterations (default :class:`~slamlab.kdtree.store_params.StoreParams`' 7).
    n_clusters : int
        Texture prototypes the descriptors are drawn around.
    sigma_cluster : float
        Spread of landmarks around their prototype (before normalising).
    sigma_obs : float
        Descriptor noise of a re-observation (before normalising).
    clustered : bool
        False: descriptors uniform on the unit sphere.
    """

    name: str
    n_iterations: int
    n_new: int  # new points per iteration
    p_track: float  # probability that a tracked landmark is re-seen in the next iteration
    n_old: int  # queries re-observing older base landmarks per iteration
    n_clutter: int  # queries of features that are not stored landmarks
    base_seen_times: int  # 000: BaseSeenTimes (3 in Table 1; 1 = all base at once)
    max_non_base_time: int = StoreParams().max_non_base_time  # 000: MaxNonBaseTime (its one default)
    n_clusters: int = 256
    sigma_cluster: float = 0.35  # spread of landmarks around their prototype (before normalising)
    sigma_obs: float = 0.08  # descriptor noise of a re-observation (before normalising)
    clustered: bool = True


#: the fields of :class:`Scenario` (the changes :func:`make_workload` takes)
SCENARIO_FIELDS = tuple(f.name for f in fields(Scenario))

#: 000's two runs. Table 1: ~13000 stored points at the end, points base after 3 sightings within 7 iterations;
#: Table 2: ~65000, every point base at once (000 §4.2).
SCENARIOS = {
    "table1": Scenario("table1", n_iterations=150, n_new=300, p_track=0.5, n_old=60, n_clutter=40,
                       base_seen_times=3),
    "table2": Scenario("table2", n_iterations=130, n_new=500, p_track=0.4, n_old=60, n_clutter=40,
                       base_seen_times=1),
}


def scenario(name: str = "table2", **changes) -> Scenario:
    """One of :data:`SCENARIOS` with fields changed, e.g. ``scenario("table2", n_iterations=20)``.

    Parameters
    ----------
    name : {'table1', 'table2'}
        Key of :data:`SCENARIOS`.
    **changes
        :class:`Scenario` fields to replace (``ValueError`` for an unknown field).

    Returns
    -------
    Scenario

    Examples
    --------
    >>> scenario("table1", n_iterations=5).n_iterations
    5
    """
    check_choice(name, "name", SCENARIOS)
    try:
        return replace(SCENARIOS[name], **changes)
    except TypeError as e:
        raise ValueError(f"unknown scenario field in {sorted(changes)}; fields are those of Scenario") from e


def _normalise(X):
    X /= np.linalg.norm(X, axis=1, keepdims=True) + 1e-12
    return X


def surf_like_descriptors(n: int, *, n_clusters: int = 256, sigma_cluster: float = 0.35, clustered: bool = True,
                          rng=None, prototypes=None):
    """``n`` unit 64-d SURF-like descriptors: 16 x (Σdx, Σdy, Σ|dx|, Σ|dy|) around texture prototypes.

    Returns ``(X float32 (n, 64), prototypes (n_clusters, 64))``. With
    ``clustered=False`` the descriptors are uniform on the unit sphere.

    Parameters
    ----------
    n : int
        Number of descriptors.
    n_clusters : int
        Prototypes drawn when ``prototypes`` is None.
    sigma_cluster : float
        Spread around the prototype (before normalising).
    clustered : bool
        Draw around prototypes; False: uniform on the unit sphere (prototypes None).
    rng : numpy.random.Generator, int or None
        Randomness: a Generator, or an int seed for a new one.
    prototypes : (n_clusters, 64) float, optional
        Prototypes to reuse (from an earlier call).

    Returns
    -------
    X : (n, 64) float32
        Unit-length descriptors.
    prototypes : (n_clusters, 64) float or None

    Examples
    --------
    >>> X, P = surf_like_descriptors(5, rng=0)
    >>> X.shape, X.dtype.name, bool(np.allclose(np.linalg.norm(X, axis=1), 1, atol=1e-5))
    ((5, 64), 'float32', True)
    """
    n = check_int(n, "n", minimum=0)
    rng = as_rng(rng)
    out = np.empty((n, DIM), np.float32)
    if not clustered:
        for s0 in range(0, n, _BLOCK):
            out[s0:s0 + _BLOCK] = _normalise(rng.standard_normal((min(_BLOCK, n - s0), DIM)))
        return out, None
    if prototypes is None:
        n_clusters = check_int(n_clusters, "n_clusters", minimum=1)
        g = rng.standard_normal((n_clusters, 16, 2)) * rng.gamma(2.0, 0.5, (n_clusters, 16, 1))
        absg = np.abs(g) + np.abs(rng.standard_normal((n_clusters, 16, 2))) * 0.5
        prototypes = _normalise(np.concatenate([g, absg], axis=2).reshape(n_clusters, DIM))
    c = rng.integers(0, prototypes.shape[0], n)
    # in blocks of rows (memory: four float64 arrays of the whole set took 128 MiB for Table 2's 65 000 points);
    # the normal draws follow one another as in one call, and every step is per row: the same descriptors
    for s0 in range(0, n, _BLOCK):
        cb = c[s0:s0 + _BLOCK]
        X = prototypes[cb] + sigma_cluster / np.sqrt(DIM) * rng.standard_normal((cb.size, DIM))
        X = X.reshape(-1, 16, 4)
        X[:, :, 2:] = np.abs(X[:, :, 2:])  # the |d| sums stay non-negative
        out[s0:s0 + _BLOCK] = _normalise(X.reshape(-1, DIM))
    return out, prototypes


def _observe(X, sigma, rng):
    Y = X.astype(np.float64) + sigma / np.sqrt(DIM) * rng.standard_normal(X.shape)
    Y = Y.reshape(-1, 16, 4)
    Y[:, :, 2:] = np.abs(Y[:, :, 2:])
    return _normalise(Y.reshape(-1, DIM)).astype(np.float32)


@dataclass(frozen=True)
class Iteration:
    """One SLAM iteration: the queries (with their true landmark, -1 = none) and the new points.

    Attributes
    ----------
    queries : (M, 64) float32
        Query descriptors.
    truth : (M,) int
        Id of the landmark each query observes, -1 for clutter (or unknown).
    new_X : (m, 64) float32
        Descriptors of the new points.
    new_ids : (m,) int
        Their ids.
    observed_ids : (K,) int or None
        Ids the SLAM loop re-sighted (a recorded stream); None: taken from ``truth``.
    """

    queries: np.ndarray  # (M, 64) float32
    truth: np.ndarray  # (M,) id of the landmark observed, -1 for clutter (or unknown)
    new_X: np.ndarray  # (m, 64) float32
    new_ids: np.ndarray  # (m,)
    observed_ids: np.ndarray | None = None  # set by a recorded stream: the ids the SLAM loop re-sighted

    @property
    def observed(self) -> np.ndarray:
        """Ids re-sighted this iteration (what the base rule counts)."""
        if self.observed_ids is not None:
            return self.observed_ids
        return self.truth[self.truth >= 0]


@dataclass(frozen=True)
class Workload:
    """A descriptor stream and the number of stored points after each iteration.

    Attributes
    ----------
    scenario : Scenario
        The stream's parameters.
    iterations : tuple of Iteration
        The stream.
    stored : (T,) int
        Points kept after each iteration (base + non-base), by the base rule.
    """

    scenario: Scenario
    iterations: tuple[Iteration, ...]
    stored: np.ndarray  # (T,) points kept after each iteration (base + non-base), by the base rule

    def __len__(self) -> int:
        return len(self.iterations)

    def __str__(self) -> str:
        q = np.mean([it.queries.shape[0] for it in self.iterations])
        return (f"workload {self.scenario.name}: {len(self)} iterations × ({q:.0f} queries, "
                f"{self.scenario.n_new} new points), {int(self.stored[-1])} stored at the end")


def make_workload(name_or_scenario="table2", *, rng=None, **changes) -> Workload:
    """Generate the descriptor stream of a scenario (000 §4.2 runs, reproduced synthetically).

    Parameters
    ----------
    name_or_scenario : str or Scenario
        A key of :data:`SCENARIOS` or a :class:`Scenario`.
    rng : numpy.random.Generator, int or None
        Randomness of the descriptors, tracks and query order.
    **changes
        :class:`Scenario` fields to replace.

    Returns
    -------
    Workload
        The iterations and the points stored after each.

    Examples
    --------
    >>> w = make_workload("table1", n_iterations=10, rng=0)
    >>> len(w), w.iterations[0].queries.shape[1]
    (10, 64)
    """
    if isinstance(name_or_scenario, Scenario):
        sc = replace(name_or_scenario, **changes)
    elif isinstance(name_or_scenario, str):
        sc = scenario(name_or_scenario, **changes)
    else:
        raise TypeError(f"`name_or_scenario` must be a scenario name or a Scenario; got "
                        f"{type(name_or_scenario).__name__}")
    check_int(sc.n_iterations, "n_iterations", minimum=1)
    check_int(sc.n_new, "n_new", minimum=1)
    check_int(sc.n_old, "n_old", minimum=0)
    check_int(sc.n_clutter, "n_clutter", minimum=0)
    StoreParams(base_seen_times=sc.base_seen_times, max_non_base_time=sc.max_non_base_time)  # checks the rule
    if not 0 <= sc.p_track < 1:
        raise ValueError(f"`p_track` must be in [0, 1); got {sc.p_track}")
    rng = as_rng(rng)
    total = sc.n_iterations * sc.n_new
    desc, protos = surf_like_descriptors(total, n_clusters=sc.n_clusters, sigma_cluster=sc.sigma_cluster,
                                         clustered=sc.clustered, rng=rng)
    # track lengths: re-seen in the next L iterations, P(L >= j) = p_track^j
    L = rng.geometric(1.0 - sc.p_track, total) - 1
    born = np.repeat(np.arange(sc.n_iterations), sc.n_new)
    book = SightingBook(sc.base_seen_times, sc.max_non_base_time)
    alive = np.zeros(total, dtype=bool)
    base = np.zeros(total, dtype=bool)
    its, stored = [], []
    for t in range(sc.n_iterations):
        age = t - born
        tracked = np.flatnonzero(alive & (age >= 1) & (age <= L))
        min_age = sc.max_non_base_time if sc.base_seen_times > 1 else 0  # older than the tracks' window
        old_pool = np.flatnonzero(base & alive & (age > min_age))
        old = rng.choice(old_pool, min(sc.n_old, old_pool.size), replace=False) if old_pool.size else old_pool
        seen = np.concatenate([tracked, old]).astype(np.int64)
        Qs = _observe(desc[seen], sc.sigma_obs, rng) if seen.size else np.empty((0, DIM), np.float32)
        clutter, _ = surf_like_descriptors(sc.n_clutter, sigma_cluster=sc.sigma_cluster, clustered=sc.clustered,
                                           rng=rng, prototypes=protos)
        Q = np.concatenate([Qs, clutter])
        truth = np.concatenate([seen, np.full(sc.n_clutter, -1, dtype=np.int64)])
        o = rng.permutation(Q.shape[0])
        new_ids = np.arange(t * sc.n_new, (t + 1) * sc.n_new, dtype=np.int64)
        its.append(Iteration(Q[o], truth[o], desc[new_ids], new_ids))
        # the base rule, as the stores apply it (same order: observe, add, end of iteration)
        if sc.base_seen_times > 1:
            book.observe(seen)
            book.add(new_ids)
            promoted, dropped = book.step()
            base[promoted] = True
            alive[new_ids] = True
            alive[dropped] = False
        else:
            base[new_ids] = True
            alive[new_ids] = True
        stored.append(int(alive.sum()))
    return Workload(sc, tuple(its), np.array(stored))


class RecordingStore(LandmarkStore):
    """Wraps a landmark store and records every call as a descriptor stream (our addition).

    The stereo pipeline (:class:`slamlab.stereo.StereoSLAM`) talks to its store
    through the :class:`~slamlab.kdtree.stores.LandmarkStore` interface; this wrapper
    passes each call on and keeps what it saw, one :class:`Iteration` per
    ``end_iteration``. :meth:`workload` turns the recording into a
    :class:`Workload` that :func:`~slamlab.studies.kdtree.experiments.run_store_comparison`
    replays through any store.

    Parameters
    ----------
    store : LandmarkStore
        The store every call is passed on to.
    """

    def __init__(self, store: LandmarkStore):
        if not isinstance(store, LandmarkStore):
            raise TypeError(f"`store` must be a LandmarkStore; got {type(store).__name__}")
        super().__init__()
        self.store = store
        self.binary_ok = store.binary_ok
        self.name = f"recording of {store.name}"
        self.iterations: list[Iteration] = []
        self._q, self._obs, self._X, self._ids = [], [], [], []

    def __len__(self) -> int:
        return len(self.store)

    def query(self, Q, k: int = 2):
        """Record the queries and pass them on (:meth:`LandmarkStore.query`).

        Parameters
        ----------
        Q : (M, d) array
            Query points.
        k : int
            Neighbours per query.

        Returns
        -------
        dist, ids : (M, k) arrays
            The wrapped store's answer.
        """
        self._q.append(np.asarray(Q))
        return self.store.query(Q, k=k)

    def query_among(self, Q, among, k: int = 2):
        """Record the queries and pass them on (:meth:`LandmarkStore.query_among`).

        Parameters
        ----------
        Q : (M, d) array
            Query points.
        among : int array
            Ids of the stored points to search.
        k : int
            Neighbours per query.

        Returns
        -------
        dist, ids : (M, k) arrays
            The wrapped store's answer.
        """
        self._q.append(np.asarray(Q))
        return self.store.query_among(Q, among, k=k)

    def observe(self, ids) -> None:
        """Record re-sighted ids and pass them on.

        Parameters
        ----------
        ids : (K,) int
            Ids seen again this iteration.
        """
        self._obs.append(np.asarray(ids, dtype=np.int64))
        self.store.observe(ids)

    def add(self, X, ids) -> None:
        """Record new points and pass them on.

        Parameters
        ----------
        X : (N, d) array
            New points.
        ids : (N,) int
            Their ids.
        """
        self._X.append(np.asarray(X))
        self._ids.append(np.asarray(ids, dtype=np.int64))
        self.store.add(X, ids)

    def _add(self, X, ids):  # pragma: no cover - add() forwards
        self.store.add(X, ids)

    def _query(self, Q, k):  # pragma: no cover - query() forwards
        return self.store.query(Q, k)

    def _stored(self):
        return self.store.stored()

    def end_iteration(self) -> None:
        self.store.end_iteration()
        Q = np.concatenate(self._q) if self._q else np.empty((0, 0), np.float32)
        X = np.concatenate(self._X) if self._X else np.empty((0, Q.shape[1] if Q.ndim == 2 else 0), np.float32)
        ids = np.concatenate(self._ids) if self._ids else np.empty(0, np.int64)
        obs = np.concatenate(self._obs) if self._obs else np.empty(0, np.int64)
        self.iterations.append(Iteration(Q, np.full(len(Q), -1, np.int64), X, ids, obs))
        self._q, self._obs, self._X, self._ids = [], [], [], []

    def workload(self, name: str = "recorded", *, params: StoreParams | None = None,
                 base_seen_times: int | None = None, max_non_base_time: int | None = None) -> Workload:
        """The recording as a :class:`Workload` (points stored per iteration counted by the base rule).

        Parameters
        ----------
        name : str
            Name of the workload's scenario.
        params : StoreParams, optional
            Settings whose base rule counts the stored points (default
            :class:`~slamlab.kdtree.store_params.StoreParams`: 000's 3 and 7).
        base_seen_times, max_non_base_time : int, optional
            Change the base rule of ``params`` (the recorded store's rule, to count what it kept).

        Returns
        -------
        Workload
            The recorded iterations (empty ones dropped).
        """
        p = resolve_store_params(params, base_seen_times=base_seen_times, max_non_base_time=max_non_base_time)
        base_seen_times, max_non_base_time = p.base_seen_times, p.max_non_base_time
        its = tuple(it for it in self.iterations if it.queries.size or it.new_X.size)
        if not its:
            raise ValueError("nothing was recorded: run the SLAM loop with this store first")
        dim = next(it.queries.shape[1] for it in its if it.queries.size)
        its = tuple(it if it.queries.size else Iteration(np.empty((0, dim), np.float32), it.truth, it.new_X,
                                                         it.new_ids, it.observed_ids) for it in its)
        book = SightingBook(base_seen_times, max_non_base_time)
        stored, n = [], 0
        for it in its:  # the base rule, as the stores apply it: observe, add, end of iteration
            n += len(it.new_ids)
            if base_seen_times > 1:
                book.observe(it.observed)
                book.add(it.new_ids)
                n -= len(book.step()[1])
            stored.append(n)
        sc = Scenario(name=name, n_iterations=len(its), n_new=max(1, int(np.mean([len(it.new_ids) for it in its]))),
                      p_track=0.0, n_old=0, n_clutter=0, base_seen_times=base_seen_times,
                      max_non_base_time=max_non_base_time)
        return Workload(sc, its, np.asarray(stored))
