"""Settings and result of correlation localisation (004 §7): 004's constants, :class:`LocaliseParams`,
:class:`Localisation` (re-exported by :mod:`slamlab.correlation.algorithm`), and the checks of the constants and
of the score normalisation (:func:`check_score_norm`, ours)."""

from __future__ import annotations

import contextlib
from dataclasses import dataclass, field

import numpy as np

from .._params import Params, param
from .._validate import check_choice, check_int, check_positive, check_real

__all__ = ["SCORE_NORMS", "Localisation", "LocaliseParams", "check_constants", "check_score_norm"]


def check_constants(a_c, a_p, a_n) -> tuple[float, float, float]:
    """Validate 004's constants: real numbers with ``a_c ≠ a_p`` (004 §7, conditions (1)-(3)).

    Parameters
    ----------
    a_c : float
        Value of a free (scan-crossed) cell in T_n and of a free map cell.
    a_p : float
        Value of an obstacle (beam end) cell.
    a_n : float
        Value of every other cell (unexplored map cells, unmarked T_n cells).

    Returns
    -------
    tuple of float
        ``(a_c, a_p, a_n)`` as floats.
    """
    a_c, a_p, a_n = check_real(a_c, "a_c"), check_real(a_p, "a_p"), check_real(a_n, "a_n")
    if a_c == a_p:
        raise ValueError(f"`a_c` and `a_p` must differ (free and obstacle must be told apart); got both {a_c}")
    return a_c, a_p, a_n


@dataclass(frozen=True)
class Localisation:
    """Result of :func:`localise`: the pose at the correlation maximum (004 §7).

    Attributes
    ----------
    pose : numpy.ndarray, shape (3,)
        ``(x = col, y = row)`` [cells] and heading [rad], in [0, 2π) for a full search.
    row, col : int
        The peak's map cell.
    heading_index : int
        Index of the peak's heading in ``headings_rad``.
    score : float
        Correlation at the peak.
    headings_rad : numpy.ndarray, shape (n,)
        Candidate headings.
    best_per_heading : numpy.ndarray, shape (n,)
        Maximum of each D_n.
    score_map : numpy.ndarray, shape (H, W)
        D at the best heading.
    rival_score : float
        Best score of a pose more than ``rival_radius_cells`` or ``rival_heading_rad`` away (NaN: not searched,
        -inf: no such pose).
    rival_pose : numpy.ndarray, shape (3,) or None
        That pose (None: not searched).
    n_scans : int
        Scans joined by odometry into the stamp (:func:`localise_joined`).
    """

    pose: np.ndarray  # (3,) x = col, y = row [cells], heading [rad] in [0, 2π) for a full search
    row: int
    col: int
    heading_index: int
    score: float
    headings_rad: np.ndarray = field(repr=False)  # (n,) candidates
    best_per_heading: np.ndarray = field(repr=False)  # (n,) max of each D_n
    score_map: np.ndarray = field(repr=False)  # (H, W) D at the best heading
    rival_score: float = float("nan")  # best score of a pose > rival_radius_cells or > rival_heading_rad away
    rival_pose: np.ndarray | None = field(default=None, repr=False)  # (3,) that pose (None: not searched)
    n_scans: int = 1  # scans joined by odometry into the stamp (localise_joined)

    @property
    def ambiguity(self) -> float:
        """How close the best rival comes to the peak, in [0, 1] (ours): 1 = a tie, 0 = no better than a wrong heading.

        ``(rival − base) / (score − base)`` with ``base`` the median over headings of each heading's best
        score (what a wrong heading typically reaches: with a_c < 0 every pose in open space collects the
        free-cell matches, so the raw ratio rival/score sits near 1 even for a unique pose). NaN when the
        rival was not searched (``ambiguity=False``); 0 when no pose lies outside the window.
        """
        if not np.isfinite(self.rival_score):
            return 0.0 if self.rival_score == -np.inf else float("nan")
        base = float(np.median(self.best_per_heading))
        if self.score - base <= 0:
            return 1.0
        return float(np.clip((self.rival_score - base) / (self.score - base), 0.0, 1.0))

    @property
    def margin(self) -> float:
        """How far the peak stands above its best rival, in units of the peak's own counting noise (ours, issue 25).

        ``(score − rival) / √(score − base)`` with ``rival`` and ``base`` as in :attr:`ambiguity`. The score
        above ``base`` counts the marks of the scan that match the map better than at a wrong heading; if
        matches came at random, two poses' counts would differ by about its square root, so a margin below
        about 1 means the peak could as well be its rival. Small = doubtful (the opposite sense of
        :attr:`ambiguity`); ``docs/benchmarks.md`` (correlation section) gives its threshold as a failure
        flag (1.2) and how well it separates on the five shared CARMEN logs. NaN when the rival was not
        searched; ``inf`` when no pose lies outside the rival window; 0 when the peak is no better than ``base``.
        """
        if np.isnan(self.rival_score):
            return float("nan")
        if self.rival_score == -np.inf:
            return float("inf")
        above = self.score - float(np.median(self.best_per_heading))
        if above <= 0:
            return 0.0
        return float(max(self.score - self.rival_score, 0.0) / np.sqrt(above))

    def __str__(self) -> str:
        amb = f", ambiguity {self.ambiguity:.3f}" if np.isfinite(self.ambiguity) else ""
        return (f"pose x={self.pose[0]:.0f}, y={self.pose[1]:.0f} cells, heading "
                f"{np.degrees(self.pose[2]):.1f} deg (score {self.score:.1f}{amb})")


@dataclass(frozen=True)
class LocaliseParams(Params):
    """Every setting of :func:`localise` and of the ``run_*`` experiments built on it (004 §7).

    ``prior_heading_rad`` / ``window_rad`` (tracking mode) are per call, not settings.

    Attributes
    ----------
    delta_alpha_rad : float
        Heading step Δα [rad] (004: 1°).
    a_c, a_p, a_n : float
        004's values of free, obstacle and other cells (-1, 1, 0).
    delta_l_cells : float
        ±Δl around a beam end marked as obstacle [cells] (0 marks one cell).
    hit_offset_cells : float
        How far beyond the range the obstacle mark sits [cells] (0.5: the range ends on the cell's face).
    step_cells : float
        Sampling step along a beam [cells], at most 1.
    use_misses : bool
        Mark beams without a return as free along their length.
    chunk : int
        Base stamps per batched FFT call.
    dtype : {"float32", "float64"}
        FFT precision.
    workers : int or None
        scipy.fft threads (None: scipy's default).
    ambiguity : bool
        Also search the best rival pose (:attr:`Localisation.ambiguity`).
    rival_radius_cells : float
        A rival lies farther than this from the peak [cells] ...
    rival_heading_rad : float
        ... or its heading differs by more than this [rad], below π.
    wall_balance : bool
        Weigh each obstacle mark of the scan(s) by the rarity of its wall direction (ours, issue 25): returns
        on a corridor's long walls count less, those on door frames and corners more.
    free_mark_weight : float
        The stamp's free marks are ``free_mark_weight·a_c`` (the map keeps ``a_c``; ours, issue 25): below 1
        the agreement of free marks with free map cells, and their conflicts with map obstacles, count less
        than the obstacle marks (1: 004's stamp).
    """

    delta_alpha_rad: float = param(float(np.radians(1.0)), "004 §7: Δα = 1°")
    a_c: float = param(-1.0, "004 §7: sign opposite to a_p (ours: a_c < 0); sharpest at a_p = -a_c")
    a_p: float = param(1.0, "004 §7")
    a_n: float = param(0.0, "004 §7: conditions (1)-(3) give a_n = 0")
    delta_l_cells: float = param(0.0, "004 §7: ±Δl, value not given (0 marks one cell)")
    hit_offset_cells: float = param(0.5, "ours: a range ends on the obstacle cell's face")
    step_cells: float = param(0.5, "ours: sampling step along a beam")
    use_misses: bool = param(False, "ours: 004 is silent on beams without a return")
    chunk: int = param(8, "ours: base stamps per batched FFT call (CPU caches)")
    dtype: str = param("float32", "ours: float32 FFTs find the float64 peak (test) in about half the time")
    workers: int | None = param(None, "ours: scipy.fft threads (None = scipy's default)")
    ambiguity: bool = param(True, "ours: also find the best rival pose (re-scores the headings near the peak)")
    rival_radius_cells: float = param(5.0, "ours: a rival is farther than this from the peak (1 m at 0.2 m)")
    rival_heading_rad: float = param(float(np.radians(30.0)), "ours: ... or its heading is more than 30° off")
    wall_balance: bool = param(False, "ours, an experiment chosen on the real logs: a_p × count(wall bin)^(-1/2)")
    free_mark_weight: float = param(1.0, "ours, an experiment chosen on the real logs: free marks a_c × this (1: 004)")

    def __post_init__(self) -> None:
        with contextlib.suppress(TypeError):  # accept numpy dtypes (np.float32) too; check() names a bad one
            object.__setattr__(self, "dtype", np.dtype(self.dtype).name)
        super().__post_init__()

    def check(self) -> None:
        d = check_positive(self.delta_alpha_rad, "delta_alpha_rad")
        if d > np.pi:
            raise ValueError(f"`delta_alpha_rad` must be <= π; got {d}")
        check_constants(self.a_c, self.a_p, self.a_n)
        check_positive(self.delta_l_cells, "delta_l_cells", allow_zero=True)
        check_positive(self.hit_offset_cells, "hit_offset_cells", allow_zero=True)
        st = check_positive(self.step_cells, "step_cells")
        if st > 1:
            raise ValueError(f"`step_cells` must be <= 1 (a larger step skips cells); got {st}")
        if not isinstance(self.use_misses, (bool, np.bool_)):
            raise TypeError(f"`use_misses` must be a bool; got {type(self.use_misses).__name__}")
        check_int(self.chunk, "chunk", minimum=1)
        check_choice(self.dtype, "dtype", ("float32", "float64"))
        if self.workers is not None:
            check_int(self.workers, "workers", minimum=1)
        if not isinstance(self.ambiguity, (bool, np.bool_)):
            raise TypeError(f"`ambiguity` must be a bool; got {type(self.ambiguity).__name__}")
        check_positive(self.rival_radius_cells, "rival_radius_cells", allow_zero=True)
        if not isinstance(self.wall_balance, (bool, np.bool_)):
            raise TypeError(f"`wall_balance` must be a bool; got {type(self.wall_balance).__name__}")
        check_positive(self.free_mark_weight, "free_mark_weight")
        h = check_positive(self.rival_heading_rad, "rival_heading_rad", allow_zero=True)
        if h >= np.pi:
            raise ValueError(f"`rival_heading_rad` must be < π (else no heading is far enough); got {h}")


#: Choices of ``score_norm`` (:func:`~slamlab.correlation.localise`; ours, issue 25).
SCORE_NORMS = ("none", "explored")


def check_score_norm(score_norm, min_explored_fraction, params: LocaliseParams) -> tuple[str, float]:
    """Validate the score normalisation of :func:`~slamlab.correlation.localise` against its settings (ours, issue 25).

    Parameters
    ----------
    score_norm : {"none", "explored"}
        ``"explored"``: a pose scores its correlation per stamp mark on an explored map cell.
    min_explored_fraction : float
        The fraction of the stamp's marks that must fall on explored cells, in (0, 1].
    params : LocaliseParams
        The settings: ``"explored"`` tells explored cells by their value, so ``a_n`` must differ from ``a_c``
        and ``a_p``.

    Returns
    -------
    tuple
        ``(score_norm, min_explored_fraction)`` checked, as ``(str, float)``.

    Examples
    --------
    >>> check_score_norm("explored", 0.8, LocaliseParams())
    ('explored', 0.8)
    """
    sn = check_choice(score_norm, "score_norm", SCORE_NORMS)
    f = check_positive(min_explored_fraction, "min_explored_fraction")
    if f > 1:
        raise ValueError(f"`min_explored_fraction` must be <= 1; got {f}")
    if not isinstance(params, LocaliseParams):
        raise TypeError(f"`params` must be a LocaliseParams; got {type(params).__name__}")
    if sn == "explored" and params.a_n in (params.a_c, params.a_p):
        raise ValueError(f"`score_norm='explored'` needs `a_n` to differ from `a_c` and `a_p` (it tells explored "
                         f"cells by their value); got a_n = {params.a_n}")
    return sn, f
