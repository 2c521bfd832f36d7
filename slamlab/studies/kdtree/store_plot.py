"""Plots of the landmark-store chapter: cost surface and contour, multi kd-tree sizes, crossover (000 §4)."""

from __future__ import annotations

import matplotlib.pyplot as plt
import numpy as np

from ...plotting import new_axes

__all__ = [
    "plot_cost_contour",
    "plot_cost_surface",
    "plot_crossover",
    "plot_iteration_times",
    "plot_multi_tree_sizes",
]

_COLORS = {"rebuild": "tab:blue", "multi": "tab:orange", "flann": "tab:green", "brute": "tab:red"}
_NAMES = {"rebuild": "kd-tree (rebuilt)", "multi": "buffer + multi kd-tree", "flann": "FLANN (rebuilt)",
          "brute": "brute force (BLAS)"}


def plot_cost_surface(result, *, ax=None, cmap: str = "viridis"):
    """000's Maple plot: iterTime over (n1, q) as a 3D surface with the optimum marked (000 Appendix).

    Parameters
    ----------
    result : CostModelResult
        From :func:`slamlab.kdtree.cost_model.run_cost_model`.
    ax : mpl_toolkits.mplot3d.Axes3D, optional
        3-D axes to draw into.
    cmap : str
        Matplotlib colour map of the surface.

    Returns
    -------
    mpl_toolkits.mplot3d.Axes3D
    """
    if ax is None:
        fig = plt.figure(figsize=(7, 5))
        ax = fig.add_subplot(projection="3d")
    N1, Q, F = result.N1, result.Q, result.F
    X, Y = np.meshgrid(N1, Q, indexing="ij")
    s = max(1, N1.size // 60), max(1, Q.size // 60)
    ax.plot_surface(X[::s[0], ::s[1]], Y[::s[0], ::s[1]], F[::s[0], ::s[1]] / 1e6, cmap=cmap, linewidth=0,
                    antialiased=True, alpha=0.9)
    _, n1, q, val, _ = result.optimum
    ax.scatter([n1], [q], [val / 1e6], color="red", s=40, depthshade=False, label=f"optimum n1={n1:.0f}, q={q:.2f}")
    ax.set_xlabel("n1")
    ax.set_ylabel("q")
    ax.set_zlabel("iterTime [10^6 steps]")
    ax.set_title("cost of one iteration (000 Appendix)")
    ax.legend(loc="upper right")
    return ax


def plot_cost_contour(result, *, ax=None, levels: int = 30, mark_000: bool = True):
    """Contour of the cost surface with our optimum, 000's optimum and the 1 % region (000 §4.1.2).

    Parameters
    ----------
    result : CostModelResult
        From :func:`slamlab.kdtree.cost_model.run_cost_model`.
    ax : matplotlib.axes.Axes, optional
        Axes to draw into.
    levels : int
        Number of filled contour levels.
    mark_000 : bool
        Mark 000's optimum (n1 ≈ 3500, q = 5.5).

    Returns
    -------
    matplotlib.axes.Axes
    """
    ax = new_axes(ax, figsize=(7, 5), title="iterTime(n1, q): contour (000 Appendix reading)", xlabel="n1",
                  ylabel="q")
    N1, Q, F = result.N1, result.Q, result.F
    cs = ax.contourf(N1, Q, F.T / 1e6, levels=levels, cmap="viridis")
    ax.figure.colorbar(cs, ax=ax, label="iterTime [10^6 steps]")
    ax.contour(N1, Q, F.T, levels=[1.01 * F.min()], colors="white", linewidths=1.2)
    _, n1, q, _, _ = result.optimum
    ax.plot(n1, q, "o", color="red", markersize=8, label=f"our optimum n1={n1:.0f}, q={q:.2f}")
    if mark_000:
        ax.plot(3500, 5.5, "x", color="white", markersize=10, mew=2, label="000: n1≈3500, q=5.5")
    ax.plot([], [], color="white", label="within 1 % of the minimum")
    ax.legend(loc="upper right", facecolor="0.85")
    return ax


def plot_multi_tree_sizes(history, n1: int, q: float, *, ax=None, n_trees: int | None = None):
    """Sizes of trees 1..p after each add, with the maximum sizes ``n1 q^i`` dashed (000 §4.1 invariant).

    Parameters
    ----------
    history : list of list of int
        Tree sizes after each add (:func:`slamlab.kdtree.multi.multi_tree_sizes`).
    n1 : int
        Maximum size of the first tree.
    q : float
        Size ratio between consecutive trees.
    ax : matplotlib.axes.Axes, optional
        Axes to draw into.
    n_trees : int, optional
        Trees drawn (default: the most the history holds).

    Returns
    -------
    matplotlib.axes.Axes
    """
    ax = new_axes(ax, figsize=(8, 4), title=f"multi kd-tree, n1 = {n1}, q = {q:g}: tree sizes after each add",
                  xlabel="add", ylabel="points in tree")
    p = n_trees or max(len(h) for h in history)
    S = np.zeros((len(history), p))
    for t, h in enumerate(history):
        S[t, :min(len(h), p)] = h[:p]
    x = np.arange(1, len(history) + 1)
    for i in range(p):
        c = plt.cm.tab10(i % 10)
        ax.step(x, S[:, i], where="mid", color=c, label=f"tree {i + 1}")
        ax.axhline(np.floor(n1 * q ** i + 1e-9), color=c, linestyle="--", linewidth=0.8)
    ax.set_yscale("symlog", linthresh=max(1.0, n1 / 2))
    ax.legend(loc="upper left", ncol=min(p, 4))
    return ax


def plot_crossover(result, *, ax=None):
    """Iteration time vs stored points for each store, log-log, with the crossover marked (000 §4.3).

    Parameters
    ----------
    result : CrossoverResult
        From :func:`slamlab.studies.kdtree.crossover.run_crossover`.
    ax : matplotlib.axes.Axes, optional
        Axes to draw into.

    Returns
    -------
    matplotlib.axes.Axes
    """
    ax = new_axes(ax, figsize=(7, 4.5), title="mean iteration time vs stored points", xlabel="stored points",
                  ylabel="iteration time [ms]")
    for s in result.stores:
        ax.plot(result.sizes, 1e3 * result.iteration_s(s), "o-", color=_COLORS[s], label=_NAMES[s])
    if "rebuild" in result.stores and "multi" in result.stores:
        c = result.crossover()
        if np.isfinite(c):
            ax.axvline(c, color="0.4", linestyle=":", label=f"crossover ≈ {c:.0f} points")
    ax.axvline(20000, color="0.7", linestyle="--", linewidth=0.8, label="000: ~20000")
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.legend()
    return ax


def plot_iteration_times(result, *, ax=None):
    """Per-iteration time (search + add) of each store over a Table 1/2 run (000 §4.2).

    Parameters
    ----------
    result : StoreComparisonResult
        From :func:`slamlab.studies.kdtree.experiments.run_store_comparison`.
    ax : matplotlib.axes.Axes, optional
        Axes to draw into.

    Returns
    -------
    matplotlib.axes.Axes
    """
    ax = new_axes(ax, figsize=(8, 4), title=f"000 {result.scenario.replace('table', 'Table ')} workload: time per iteration", xlabel="iteration",
                  ylabel="time [ms]")
    for s in result.stores:
        ax.plot(1e3 * (result.add_s[s] + result.search_s[s]), color=_COLORS[s], linewidth=1, label=_NAMES[s])
    ax.legend()
    return ax
