"""Cost model of the multi kd-tree and its optimum (000 §4.1.2 and Appendix).

A multi kd-tree keeps static trees with maximum sizes ``n1, q n1, q^2 n1, ...``;
``p`` is the number of non-empty trees. 000 bounds ``p`` by (1)-(3)::

    log_q(n/n1 (q-1) + 1) <= p <= log_q(n/n1) + 1

and estimates, with all logarithms base 2 (the Appendix's ``log_2``)::

    T_search(n1, q) = p log n1 + p(p-1)/2 log q                  (one query over p trees)
    T_modify(n1, q) = m q p log n1 + m q p(p-1)/2 log q          (mean cost of merges per iteration)
    iterTime        = n1 log n1 + T_modify + C s T_search         (per iteration)

with ``C = C1/C2`` the cost of one search step relative to one build step,
calibrated by 000 from one tree (``s = 526`` searches in 79 ms, ``m = 678``
inserts in 750 ms at ``n = 44828``, an insert costing a rebuild of all ``n``
points): ``C = (79/526)/(750/44828) = 8.98``.

The Appendix's Maple text, literally (:func:`search_kd`, :func:`add_kd`,
``iter_time(..., reading="literal")``)::

    searchKd = p log n1 + C p(p-1)/2 log q
    addKd    = n1 log n1 + m q p log n1 + m q/2 p(p-1) log q     (build term + T_modify)
    iterTime = addKd + C searchKd                                 (s := 500 defined, unused)

gives the optimum ``n1 ≈ 1200, q ≈ 2.3``, far from the ``q = 5.5, n1 ≈ 3500`` that
000 reads off its Maple plot (``n = 50000, s = m = 500, C = 9``). One change brings
it back: the search term becomes §4.1.2's ``C s T_search`` (``C`` on the whole search,
which has no ``C`` inside, times ``s`` searches): ``iterTime = addKd + C s T_search``
(``reading="adjusted"``, the default) gives ``n1 ≈ 3430, q ≈ 5.3``. Without the build
term (§4.1.2's ``f``) the optimum runs to the edge ``n1 = 20000``.
:func:`run_cost_model` prints every reading's optimum.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from .._table import format_table
from .._validate import check_choice, check_positive

__all__ = [
    "P_RULES",
    "READINGS",
    "CostModelResult",
    "add_kd",
    "calibrate_C",
    "iter_time",
    "minimise_iter_time",
    "p_bounds",
    "run_cost_model",
    "search_kd",
    "t_modify",
    "t_search",
]

#: How ``p`` is taken from the bounds (3): 000's surface uses a real ``p``.
P_RULES = ("upper", "lower", "integer")
#: "literal": the Appendix as printed, ``addKd + C searchKd``; "adjusted": ``addKd + C s T_search``
READINGS = ("adjusted", "literal")


def p_bounds(n, n1, q):
    """Lower and upper bound of the number of non-empty trees ``p`` (000 §4.1.2, eq. 3).

    Parameters
    ----------
    n : float or array
        Points stored.
    n1 : float or array
        Maximum size of the smallest tree.
    q : float or array
        Size ratio between consecutive trees (> 1).

    Returns
    -------
    lo, hi : float arrays
        ``log_q(n/n1 (q-1) + 1)`` and ``log_q(n/n1) + 1``, broadcast over the inputs.

    Examples
    --------
    >>> lo, hi = p_bounds(50000, 3500, 5.5)
    >>> round(float(lo), 3), round(float(hi), 3)
    (2.451, 2.56)
    """
    n, n1, q = (np.asarray(a, dtype=float) for a in (n, n1, q))
    lo = np.log(n / n1 * (q - 1.0) + 1.0) / np.log(q)
    hi = np.log(n / n1) / np.log(q) + 1.0
    return lo, hi


def _p(n, n1, q, p_rule):
    lo, hi = p_bounds(n, n1, q)
    if p_rule == "upper":
        return hi
    if p_rule == "lower":
        return lo
    # integer: the number of trees actually needed to hold n points
    return np.ceil(lo - 1e-12)


def t_search(n1, q, p):
    """``T_search = p log2 n1 + p(p-1)/2 log2 q``: one query over ``p`` trees (000 §4.1.2).

    Parameters
    ----------
    n1 : float or array
        Maximum size of the smallest tree.
    q : float or array
        Size ratio between consecutive trees.
    p : float or array
        Number of non-empty trees.

    Returns
    -------
    float array
        Search cost in units of one search step.

    Examples
    --------
    >>> float(t_search(1024, 2.0, 1))
    10.0
    """
    n1, q, p = (np.asarray(a, dtype=float) for a in (n1, q, p))
    return p * np.log2(n1) + p * (p - 1.0) / 2.0 * np.log2(q)


def t_modify(n1, q, p, m):
    """``T_modify = m q p log2 n1 + m q p(p-1)/2 log2 q``: mean merge cost per iteration (000 §4.1.2).

    Parameters
    ----------
    n1, q, p : float or array
        Smallest tree size, size ratio, number of non-empty trees.
    m : float
        Points inserted per iteration.

    Returns
    -------
    float array
        Merge cost in units of one build step.

    Examples
    --------
    >>> float(t_modify(1024, 2.0, 1, 10))
    200.0
    """
    n1, q, p = (np.asarray(a, dtype=float) for a in (n1, q, p))
    return m * q * t_search(n1, q, p)


def search_kd(n1, q, p, C):
    """The Appendix's ``searchKd = p log2 n1 + C p(p-1)/2 log2 q``, literally (``C`` inside).

    Parameters
    ----------
    n1, q, p : float or array
        Smallest tree size, size ratio, number of non-empty trees.
    C : float
        Cost of a search step relative to a build step.

    Returns
    -------
    float array

    Examples
    --------
    >>> float(search_kd(1024, 2.0, 2, 9.0))
    29.0
    """
    n1, q, p = (np.asarray(a, dtype=float) for a in (n1, q, p))
    return p * np.log2(n1) + C * p * (p - 1.0) / 2.0 * np.log2(q)


def add_kd(n1, q, p, m):
    """The Appendix's ``addKd = n1 log2 n1 + m q p log2 n1 + m q/2 p(p-1) log2 q`` (build term + ``T_modify``).

    Parameters
    ----------
    n1, q, p : float or array
        Smallest tree size, size ratio, number of non-empty trees.
    m : float
        Points inserted per iteration.

    Returns
    -------
    float array

    Examples
    --------
    >>> float(add_kd(1024, 2.0, 1, 10))
    10440.0
    """
    n1 = np.asarray(n1, dtype=float)
    return n1 * np.log2(n1) + t_modify(n1, q, p, m)


def iter_time(n1, q, *, n: float = 50000, s: float = 500, m: float = 500, C: float = 9.0,
              p_rule: str = "upper", build_term: bool = True, reading: str = "adjusted"):
    """Per-iteration cost of the multi kd-tree (000 Appendix, §4.1.2), element-wise.

    ``reading="literal"``: the Appendix as printed, ``addKd + C searchKd`` (``s`` unused);
    ``"adjusted"`` (default): ``addKd + C s T_search``, the search term of §4.1.2 (the one
    change that lands on 000's optimum). ``p_rule`` picks ``p`` from the bounds (3);
    ``build_term=False`` drops ``n1 log2 n1`` (§4.1.2's ``f = T_modify + C s T_search``).

    Parameters
    ----------
    n1 : float or array
        Maximum size of the smallest tree (> 1).
    q : float or array
        Size ratio between consecutive trees (> 1).
    n : float
        Points stored (000: 50000).
    s : float
        Searches per iteration.
    m : float
        Inserts per iteration.
    C : float
        Cost of a search step relative to a build step (000: 9).
    p_rule : {'upper', 'lower', 'integer'}
        How ``p`` is taken from the bounds.
    build_term : bool
        Include the build term ``n1 log2 n1``.
    reading : {'adjusted', 'literal'}
        Which reading of 000's formula.

    Returns
    -------
    float array
        Cost per iteration in build steps, broadcast over ``n1`` and ``q``.

    Examples
    --------
    >>> round(float(iter_time(3500, 5.5) / iter_time(1200, 2.3)), 3), round(float(
    ...     iter_time(3500, 5.5, reading="literal") / iter_time(1200, 2.3, reading="literal")), 3)
    (0.717, 1.45)
    """
    check_choice(p_rule, "p_rule", P_RULES)
    check_choice(reading, "reading", READINGS)
    n1 = np.asarray(n1, dtype=float)
    q = np.asarray(q, dtype=float)
    if np.any(n1 <= 1) or np.any(q <= 1):
        raise ValueError("`n1` and `q` must be > 1")
    p = _p(n, n1, q, p_rule)
    if reading == "literal":
        out = add_kd(n1, q, p, m) + C * search_kd(n1, q, p, C)
        return out if build_term else out - n1 * np.log2(n1)
    out = t_modify(n1, q, p, m) + C * s * t_search(n1, q, p)
    return out + n1 * np.log2(n1) if build_term else out


def calibrate_C(s: float, t_search_s: float, m: float, t_modify_s: float, n: float) -> float:
    """``C = C1 / C2`` from one tree: ``C1 s log n = t_s``, ``C2 n log n = t_m`` (000 §4.1.2).

    The insert of ``m`` points is modelled as a rebuild of all ``n`` points, so
    ``m`` does not enter.

    Parameters
    ----------
    s : float
        Searches timed.
    t_search_s : float
        Their time in seconds.
    m : float
        Points inserted (checked, unused by the model).
    t_modify_s : float
        Time of the inserts in seconds.
    n : float
        Points in the tree.

    Returns
    -------
    float
        ``C``.

    Examples
    --------
    000's numbers give 8.98:

    >>> round(calibrate_C(526, 0.079, 678, 0.750, 44828), 2)
    8.98
    """
    for val, name in ((s, "s"), (t_search_s, "t_search_s"), (t_modify_s, "t_modify_s"), (n, "n")):
        check_positive(val, name)
    check_positive(m, "m")
    return (t_search_s / s) / (t_modify_s / n)


def minimise_iter_time(*, n: float = 50000, s: float = 500, m: float = 500, C: float = 9.0, p_rule: str = "upper",
                       build_term: bool = True, reading: str = "adjusted", n1_range=(500.0, 20000.0), q_range=(1.5, 10.0),
                       grid: tuple[int, int] = (391, 171)):
    """Grid minimum of :func:`iter_time` over ``n1_range × q_range`` (000's Maple plot ranges).

    Returns ``(n1, q, value, N1, Q, F)`` with the grid for plotting. The grid
    steps are 50 points in ``n1`` and 0.05 in ``q`` by default.

    Parameters
    ----------
    n, s, m, C, p_rule, build_term, reading
        As in :func:`iter_time`.
    n1_range, q_range : (float, float)
        Grid ranges of ``n1`` and ``q``.
    grid : (int, int)
        Grid points along ``n1`` and ``q``.

    Returns
    -------
    n1, q, value : float
        The grid minimum and its cost.
    N1 : (grid[0],) float
    Q : (grid[1],) float
        The grid axes.
    F : (grid[0], grid[1]) float
        The cost surface.
    """
    N1 = np.linspace(*n1_range, grid[0])
    Q = np.linspace(*q_range, grid[1])
    F = iter_time(N1[:, None], Q[None, :], n=n, s=s, m=m, C=C, p_rule=p_rule, build_term=build_term, reading=reading)
    i, j = np.unravel_index(np.argmin(F), F.shape)
    return float(N1[i]), float(Q[j]), float(F[i, j]), N1, Q, F


@dataclass(frozen=True)
class CostModelResult:
    """Optimum of the multi kd-tree cost model under each reading of 000's formulas.

    Attributes
    ----------
    n, s, m, C : float
        The model's inputs (points, searches, inserts per iteration; relative search cost).
    readings : tuple of (str, float, float, float, bool)
        Per reading: name, optimal ``n1``, ``q``, cost and whether the optimum is on the grid's edge.
    flat_n1, flat_q : (float, float)
        Ranges of ``n1`` and ``q`` within 1 % of the adjusted reading's minimum.
    N1, Q : 1-d float
        Grid axes.
    F : (len(N1), len(Q)) float
        The adjusted reading's cost surface.
    """

    n: float
    s: float
    m: float
    C: float
    readings: tuple[tuple[str, float, float, float, bool], ...]  # (name, n1, q, cost, at_edge)
    flat_n1: tuple[float, float]  # n1 range within 1 % of the minimum (the adjusted reading)
    flat_q: tuple[float, float]
    N1: np.ndarray = field(repr=False)
    Q: np.ndarray = field(repr=False)
    F: np.ndarray = field(repr=False)  # the adjusted reading's surface

    @property
    def literal(self):
        """``(name, n1, q, cost, at_edge)`` of the Appendix as printed."""
        return self.readings[0]

    @property
    def optimum(self):
        """``(name, n1, q, cost, at_edge)`` of the adjusted reading (``addKd + C s T_search``)."""
        return self.readings[1]

    def __str__(self) -> str:
        _, n1l, ql, _, _ = self.literal
        _, n1, q, _, _ = self.optimum
        return (f"optimum for n = {self.n:.0f}, s = {self.s:.0f}, m = {self.m:.0f}, C = {self.C:.2f}: "
                f"n1 = {n1:.0f}, q = {q:.2f} (as printed: n1 = {n1l:.0f}, q = {ql:.2f})")

    def table(self) -> str:
        """The optimum ``n1``, ``q`` of each reading beside 000's, and the 1 % region.

        Returns
        -------
        str
            Text table and one line on the region within 1 % of the minimum.
        """
        rows = [[name, f"{n1:.0f}", f"{q:.2f}", "edge of the range" if edge else ""]
                for name, n1, q, _, edge in self.readings]
        rows.append(["000 (read off its Maple plot)", "3500", "5.50", ""])
        t = format_table(["reading of 000's formulas", "n1", "q", "note"], rows)
        return (t + f"\nwithin 1 % of the minimum (adjusted reading): n1 {self.flat_n1[0]:.0f}-{self.flat_n1[1]:.0f},"
                f" q {self.flat_q[0]:.2f}-{self.flat_q[1]:.2f}")


def run_cost_model(*, n: float = 50000, s: float = 500, m: float = 500, C: float = 9.0) -> CostModelResult:
    """Minimise the cost under 000's readings and report each optimum (000 §4.1.2, Appendix).

    Parameters
    ----------
    n : float
        Points stored.
    s : float
        Searches per iteration.
    m : float
        Inserts per iteration.
    C : float
        Cost of a search step relative to a build step.

    Returns
    -------
    CostModelResult
        ``readings`` (the optimum per reading) and the adjusted surface.
    """
    n = check_positive(n, "n")
    s = check_positive(s, "s")
    m = check_positive(m, "m")
    C = check_positive(C, "C")
    specs = [
        ("Appendix as printed: addKd + C searchKd, p upper (real)", "upper", True, "literal"),
        ("changed search term: addKd + C s T_search", "upper", True, "adjusted"),
        ("same, p at the lower bound (real)", "lower", True, "adjusted"),
        ("same, p integer (trees actually needed)", "integer", True, "adjusted"),
        ("§4.1.2 f = T_modify + C s T_search (no build term)", "upper", False, "adjusted"),
    ]
    readings = []
    main = None
    for name, rule, build, reading in specs:
        n1, q, val, N1, Q, F = minimise_iter_time(n=n, s=s, m=m, C=C, p_rule=rule, build_term=build, reading=reading)
        edge = n1 in (N1[0], N1[-1]) or q in (Q[0], Q[-1])
        readings.append((name, n1, q, val, bool(edge)))
        if main is None and reading == "adjusted":
            main = (N1, Q, F)
    N1, Q, F = main
    near = 1.01 * F.min() >= F
    flat_n1 = (float(N1[near.any(axis=1)].min()), float(N1[near.any(axis=1)].max()))
    flat_q = (float(Q[near.any(axis=0)].min()), float(Q[near.any(axis=0)].max()))
    return CostModelResult(n, s, m, C, tuple(readings), flat_n1, flat_q, N1, Q, F)
