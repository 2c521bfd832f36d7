"""Single-tree studies (000 §1.4.3, §4.1.2): C = C1/C2 calibrated on this machine, exact search vs
Best-Bin-First by dimension, and recall@1 (re-exported by :mod:`slamlab.studies.kdtree.experiments`).
"""

from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np

from ..._table import format_table
from ..._validate import as_rng, check_int
from ...kdtree.cost_model import calibrate_C, minimise_iter_time
from ...kdtree.tree import KDTree
from .workloads import surf_like_descriptors

__all__ = ["CFitResult", "DimensionStudyResult", "fit_C", "recall_at_1", "run_dimension_study"]


def recall_at_1(dist, exact_dist, *, rtol: float = 1e-4) -> float:
    """Share of queries whose first neighbour is as close as the exact one (ties count as found).

    Parameters
    ----------
    dist : (M, k) float
        Distances found (column 0 is used).
    exact_dist : (M, k) float
        Exact distances; queries with an infinite exact distance are skipped.
    rtol : float
        Relative tolerance of "as close".

    Returns
    -------
    float
        Recall in [0, 1]; NaN when no query has an exact neighbour.

    Examples
    --------
    >>> recall_at_1(np.array([[1.0], [2.0]]), np.array([[1.0], [1.5]]))
    0.5
    """
    d = np.asarray(dist, dtype=float)[:, 0]
    e = np.asarray(exact_dist, dtype=float)[:, 0]
    ok = np.isfinite(e)
    if not ok.any():
        return float("nan")
    return float(np.mean(d[ok] <= e[ok] * (1 + rtol) + 1e-6))


@dataclass(frozen=True)
class CFitResult:
    """``C = C1/C2`` measured on this machine with the teaching tree (000 §4.1.2's calibration).

    Attributes
    ----------
    n, s, m : int
        Points in the tree, searches timed, inserts modelled.
    t_search_s : float
        Time of the ``s`` searches in seconds.
    t_build_s : float
        Time of one rebuild of ``n + m`` points in seconds.
    C : float
        The calibrated ratio.
    n1, q : float
        The cost model's optimum with this ``C``.
    """

    n: int
    s: int
    m: int
    t_search_s: float
    t_build_s: float
    C: float
    n1: float
    q: float

    def __str__(self) -> str:
        return (f"C = {self.C:.1f} ({self.s} BBF searches {1e3 * self.t_search_s:.0f} ms, {self.n} points rebuilt "
                f"{1e3 * self.t_build_s:.0f} ms); optimum n1 = {self.n1:.0f}, q = {self.q:.2f}; 000: C = 8.98")


def fit_C(*, n: int = 44828, s: int = 526, m: int = 678, checks: int = 200, leaf_size: int = 8, rng=2010,
          n_model: float = 50000, s_model: float = 500, m_model: float = 500) -> CFitResult:
    """Calibrate ``C`` as 000 did (one tree of ``n`` points: ``s`` searches vs a rebuild) and re-optimise.

    000 modelled an insert of ``m`` points as a rebuild of all ``n``; we time
    exactly that with the teaching tree (BBF, ``checks`` points per search) and
    return the optimum of the Appendix reading for ``n_model, s_model, m_model``.
    Timings: volatile.

    Parameters
    ----------
    n : int
        Points in the tree (000: 44828).
    s : int
        Searches timed (000: 526).
    m : int
        Inserted points (000: 678).
    checks : int
        Points examined per BBF search.
    leaf_size : int
        Points per leaf.
    rng : numpy.random.Generator, int or None
        Randomness of the descriptors and queries.
    n_model, s_model, m_model : float
        ``n``, ``s``, ``m`` of the cost model that is re-optimised.

    Returns
    -------
    CFitResult
        ``C`` and the optimum ``n1``, ``q``.
    """
    n = check_int(n, "n", minimum=2)
    s = check_int(s, "s", minimum=1)
    m = check_int(m, "m", minimum=1)
    rng = as_rng(rng)
    X, _protos = surf_like_descriptors(n + m, rng=rng)
    Q = X[rng.integers(0, n, s)] + 0.01 * rng.standard_normal((s, X.shape[1])).astype(np.float32)
    tree = KDTree(X[:n], leaf_size=leaf_size)
    t0 = time.perf_counter()
    tree.query(Q, 2, max_leaves=max(1, -(-checks // leaf_size)))
    t_s = time.perf_counter() - t0
    t0 = time.perf_counter()
    KDTree(X, leaf_size=leaf_size)
    t_m = time.perf_counter() - t0
    C = calibrate_C(s, t_s, m, t_m, n)
    n1, q, *_ = minimise_iter_time(n=n_model, s=s_model, m=m_model, C=C)
    return CFitResult(n, s, m, t_s, t_m, C, n1, q)


@dataclass(frozen=True)
class DimensionStudyResult:
    """Exact kd-tree search vs Best-Bin-First in growing dimension (000 §1.4.3, §3.4).

    Attributes
    ----------
    rows : tuple of (str, int, float, float, float)
        Per case: data, dimension, % leaves and % distances an exact search visits, BBF recall@1.
    n : int
        Points per tree.
    n_queries : int
        Queries per case.
    checks : int
        Points examined per BBF search.
    leaf_size : int
        Points per leaf.
    """

    rows: tuple[tuple[str, int, float, float, float], ...]  # (data, dim, exact leaves %, exact evals %, BBF recall)
    n: int
    n_queries: int
    checks: int
    leaf_size: int

    def __str__(self) -> str:
        return f"exact vs BBF search on {self.n} points, {self.n_queries} queries, checks = {self.checks}"

    def table(self) -> str:
        """% leaves and % distances an exact search visits and BBF recall, per case.

        Returns
        -------
        str
            Fixed-precision text table.
        """
        rows = [[d, f"{k}", f"{lv:.1f}", f"{ev:.1f}", f"{r:.2f}"] for d, k, lv, ev, r in self.rows]
        return format_table(["data", "dim", "exact: % leaves visited", "exact: % distances", "BBF recall@1"],
                            rows, title=str(self))


def run_dimension_study(dims=(2, 8, 16, 64), *, n: int = 5000, n_queries: int = 100, checks: int = 200,
                        leaf_size: int = 8, rng=2010) -> DimensionStudyResult:
    """Share of the tree an *exact* search visits, and BBF recall, by dimension and data (000 §1.4.3).

    Uniform data: points and queries uniform on the unit sphere of each dimension
    in ``dims``. Clustered data: 64-d SURF-like descriptors, queries = noisy
    re-observations of stored points (90 %) and clutter (10 %).

    Parameters
    ----------
    dims : sequence of int
        Dimensions of the uniform cases.
    n : int
        Points per tree.
    n_queries : int
        Queries per case.
    checks : int
        Points examined per BBF search.
    leaf_size : int
        Points per leaf.
    rng : numpy.random.Generator, int or None
        Randomness of points and queries.

    Returns
    -------
    DimensionStudyResult
    """
    n = check_int(n, "n", minimum=10)
    n_queries = check_int(n_queries, "n_queries", minimum=1)
    checks = check_int(checks, "checks", minimum=1)
    leaf_size = check_int(leaf_size, "leaf_size", minimum=1)
    dims = [check_int(d, "dims", minimum=1) for d in dims]
    rng = as_rng(rng)
    cases = []
    for d in dims:
        X = rng.standard_normal((n + n_queries, d))
        X /= np.linalg.norm(X, axis=1, keepdims=True)
        cases.append((f"uniform {d}-d", d, X[:n], X[n:]))
    X, protos = surf_like_descriptors(n, rng=rng)
    nq = n_queries - n_queries // 10
    Qo = X[rng.integers(0, n, nq)] + 0.01 * rng.standard_normal((nq, 64)).astype(np.float32)
    Qc, _ = surf_like_descriptors(n_queries - nq, rng=rng, prototypes=protos)
    cases.append(("clustered SURF-like", 64, X, np.concatenate([Qo, Qc])))
    rows = []
    for name, d, P, Q in cases:
        tree = KDTree(P, leaf_size=leaf_size)
        e, _ = tree.query(Q, 2)
        st = tree.last_stats
        b, _ = tree.query(Q, 2, max_leaves=max(1, -(-checks // leaf_size)))
        rows.append((name, d, 100.0 * st.mean_leaves / tree.n_leaves, 100.0 * st.mean_distance_evals / tree.n,
                     recall_at_1(b, e)))
    return DimensionStudyResult(tuple(rows), n, n_queries, checks, leaf_size)
