"""Exact k nearest neighbours and the k-NN list helpers: written once, used by every matcher and store.

- :func:`exact_knn` — exact k-NN by brute force: Hamming distance for binary ``uint8``
  descriptors (ORB; OpenCV's ``batchDistance``), Euclidean for float ones (BLAS on
  query blocks, the kept distances recomputed directly in float64; the selection from
  each block compiled in ``slamlab.kdtree._brute_kernel`` unless ``SLAMLAB_NO_NUMBA=1``,
  large problems on two workers);
- :func:`pad_knn` — the one "pad to k" rule: fewer than ``k`` candidates give ``inf``
  distances and id ``-1``;
- :func:`merge_knn` — k-NN lists of several trees merged into one (000 §4: a query
  searches every tree);
- :func:`hamming_distances` — pairwise Hamming distances of packed binary descriptors;
- :func:`flann_index` — OpenCV's FLANN randomised kd-trees, built from a seeded RNG.

The features chapter's matching (:func:`slamlab.features.knn2`), the landmark stores
(:mod:`slamlab.kdtree.stores`) and the stereo pipeline all call these.
"""

from __future__ import annotations

import numpy as np

from .._compiled import numba_enabled

__all__ = ["augment_rows", "exact_knn", "flann_index", "hamming_distances", "merge_knn", "pad_knn"]


def flann_index(data, *, trees: int = 1, opencv_seed: int | None = 0):
    """OpenCV's FLANN randomised kd-trees (``cv2.flann_Index``, ``trees`` of them) over ``data (N, D)``.

    FLANN draws its split dimensions from OpenCV's global RNG, so an unseeded build depends on
    whatever drew from that RNG before (in a notebook: any earlier cell). ``opencv_seed`` (not None)
    reseeds it with ``cv2.setRNGSeed`` first, so the same data give the same trees in any kernel
    (a side effect on OpenCV's global RNG).

    Parameters
    ----------
    data : (N, D) array
        Points (converted to contiguous float32).
    trees : int
        Number of randomised kd-trees.
    opencv_seed : int or None
        Seed for ``cv2.setRNGSeed`` before the build; None leaves OpenCV's RNG as it is. This seeds
        OpenCV's global RNG, not a numpy stream, hence not ``rng=``.

    Returns
    -------
    cv2.flann_Index
    """
    import cv2

    if opencv_seed is not None:
        cv2.setRNGSeed(int(opencv_seed))
    return cv2.flann_Index(np.ascontiguousarray(data, dtype=np.float32), {"algorithm": 1, "trees": int(trees)})


def pad_knn(dist, ids, k: int):
    """``(dist (M, k), ids (M, k))`` from lists with ``k_i <= k`` columns: missing neighbours are ``inf`` / ``-1``.

    Parameters
    ----------
    dist : (M, k_i) float
        Distances, ascending per row.
    ids : (M, k_i) int
        Their ids.
    k : int
        Columns wanted (extra columns of the input are cut).

    Returns
    -------
    dist : (M, k) float
    ids : (M, k) int64

    Examples
    --------
    >>> d, i = pad_knn(np.array([[0.5]]), np.array([[4]]), 2)
    >>> d.tolist(), i.tolist()
    ([[0.5, inf]], [[4, -1]])
    """
    dist = np.asarray(dist, dtype=np.float64)
    ids = np.asarray(ids, dtype=np.int64)
    m, kk = dist.shape
    if kk >= k:
        return dist[:, :k], ids[:, :k]
    out_d = np.full((m, k), np.inf)
    out_i = np.full((m, k), -1, dtype=np.int64)
    out_d[:, :kk], out_i[:, :kk] = dist, ids
    return out_d, out_i


def merge_knn(dists, ids, k: int = 2):
    """Merge per-tree k-NN lists into the k nearest overall (000 §4: a query searches every tree).

    Parameters
    ----------
    dists, ids : lists of (M, k_i) arrays
        Distances (``inf`` for missing) and ids (-1 for missing) from each tree.
    k : int
        Neighbours kept per query.

    Returns
    -------
    dist : (M, k) float
        Ascending; ties keep the tree order.
    ids : (M, k) int64

    Examples
    --------
    >>> d, i = merge_knn([np.array([[1.0, 3.0]]), np.array([[2.0, np.inf]])],
    ...                  [np.array([[10, 11]]), np.array([[20, -1]])])
    >>> d.tolist(), i.tolist()
    ([[1.0, 2.0]], [[10, 20]])
    """
    D = np.concatenate(dists, axis=1)
    idx = np.concatenate(ids, axis=1)
    o = np.argsort(D, axis=1, kind="stable")[:, :k]
    return pad_knn(np.take_along_axis(D, o, axis=1), np.take_along_axis(idx, o, axis=1), k)


def hamming_distances(A, B) -> np.ndarray:
    """Pairwise Hamming distances between binary descriptors packed as uint8 bytes.

    Parameters
    ----------
    A : (M, b) uint8
        Binary descriptors, ``b`` bytes each.
    B : (N, b) uint8
        Binary descriptors of the same width.

    Returns
    -------
    (M, N) int64
        Number of differing bits.

    Examples
    --------
    >>> hamming_distances(np.array([[0b1011]], np.uint8), np.array([[0], [255]], np.uint8)).tolist()
    [[3, 5]]
    """
    A, B = np.asarray(A), np.asarray(B)
    if A.dtype != np.uint8 or B.dtype != np.uint8:
        raise TypeError(f"binary descriptors must be uint8 arrays; got {A.dtype} and {B.dtype}")
    if A.ndim != 2 or B.ndim != 2 or A.shape[1] != B.shape[1]:
        raise ValueError(f"descriptors must be (N, bytes) arrays of equal width; got {A.shape} and {B.shape}")
    out = np.empty((A.shape[0], B.shape[0]), dtype=np.int64)
    step = max(1, 4_000_000 // max(1, B.size))
    for a in range(0, A.shape[0], step):
        out[a:a + step] = np.bitwise_count(A[a:a + step, None, :] ^ B[None, :, :]).sum(axis=2, dtype=np.int64)
    return out


def exact_knn(Q, X, k: int = 2, ids=None, *, augmented=None):
    """The ``k`` nearest rows of ``X`` to every row of ``Q``, exactly, by brute force.

    Parameters
    ----------
    Q, X : (M, d), (N, d) arrays of one kind: ``uint8`` (binary, Hamming distance) or float
        (Euclidean distance). The caller checks shapes and kinds (this is the inner loop).
    k : neighbours per query.
    ids : (N,) int, optional
        Ids of the rows of ``X`` (default: the row indices).
    augmented : (N, d + 1) float32, optional
        ``augment_rows(X)`` kept by the caller (a store) between queries; float ``X`` only.

    Returns
    -------
    dist : (M, k) float, ascending; ``inf`` where ``X`` has fewer than ``k`` rows
    ids : (M, k) int; ``-1`` where missing

    Examples
    --------
    >>> X = np.array([[0.0, 0.0], [3.0, 0.0], [1.0, 1.0]])
    >>> d, i = exact_knn(np.array([[1.0, 0.0]]), X, 2, ids=np.array([10, 11, 12]))
    >>> d.tolist(), i.tolist()
    ([[1.0, 1.0]], [[10, 12]])
    """
    M, N = Q.shape[0], X.shape[0]
    kk = min(k, N)
    if M == 0 or kk == 0:
        return pad_knn(np.empty((M, 0)), np.empty((M, 0), dtype=np.int64), k)
    if Q.dtype == np.uint8 and kk == 2 and Q.shape[1] % 8 == 0 and numba_enabled():
        # the same search compiled: each query keeps its two nearest while it walks X in order, ties to the
        # first, as batchDistance (issue 25; no (M, N) distance matrix)
        from ._hamming_kernel import all_hamming_2nn

        r1, d1, d2, r2 = all_hamming_2nn(np.ascontiguousarray(Q).view(np.uint64),
                                         np.ascontiguousarray(np.ascontiguousarray(X).view(np.uint64).T))
        d, idx = np.column_stack([d1, d2]), np.column_stack([r1, r2])
    elif Q.dtype == np.uint8:
        import cv2  # OpenCV's popcount: several times faster than numpy's for Hamming

        d, idx = cv2.batchDistance(np.ascontiguousarray(Q), np.ascontiguousarray(X), cv2.CV_32S,
                                   normType=cv2.NORM_HAMMING, K=kk)
        idx = idx.astype(np.int64)
        d = np.where(idx >= 0, d, np.inf).astype(np.float64)
    elif numba_enabled():  # the same blocks, the selection compiled (issue 25)
        d, idx = _exact_knn_float_compiled(Q, X, kk, Xa=augmented)
    else:
        d, idx = _exact_knn_float(Q, X, kk, Xa=augmented)
    if ids is not None:
        ids = np.asarray(ids, dtype=np.int64)
        idx = np.where(idx >= 0, ids[np.maximum(idx, 0)], -1)
    return pad_knn(d, idx, k)


def augment_rows(X, out=None) -> np.ndarray:
    """float32 rows ``[x, |x|²/2]`` (the database side of the ranking GEMM of :func:`exact_knn`).

    Parameters
    ----------
    X : (N, d) float
        Points.
    out : (N, d + 1) float32, optional
        Array to write into (a new one when None).

    Returns
    -------
    (N, d + 1) float32

    Examples
    --------
    >>> augment_rows(np.array([[3.0, 4.0]])).tolist()
    [[3.0, 4.0, 12.5]]
    """
    Xa = np.empty((X.shape[0], X.shape[1] + 1), dtype=np.float32) if out is None else out
    Xa[:, :-1] = X
    Xa[:, -1] = 0.5 * np.einsum("ij,ij->i", Xa[:, :-1], Xa[:, :-1])
    return Xa


def _block_setup(Q, X, k, margin, block, Xa):
    """What both blocked k-NN paths (numpy and compiled) start from: ``(M, N, c, Xa, block, Qa)``.

    ``c = min(k + margin, N)`` candidates kept per query; the augmented rows ``[x, |x|²/2]`` (``Xa``, made
    here unless the caller keeps them) and query rows ``[-q, 1]`` make one GEMM per block write the ranking
    key ``|x|²/2 - q·x`` directly; ``block`` database rows per GEMM (default ``_block_rows(M)``).

    Parameters
    ----------
    Q : (M, d) float32
        Queries.
    X : (N, d) float32
        Database.
    k : int
        Neighbours per query.
    margin : int
        Candidates kept beyond ``k``.
    block : int or None
        Database rows per block.
    Xa : (N, d + 1) float32 or None
        ``augment_rows(X)``, when the caller keeps it.

    Returns
    -------
    tuple
        ``(M, N, c, Xa, block, Qa)``.
    """
    M, N = Q.shape[0], X.shape[0]
    return M, N, min(k + margin, N), augment_rows(X) if Xa is None else Xa, block or _block_rows(M), _query_rows(Q)


def _exact_knn_float(Q, X, k, block: int | None = None, margin: int = 1, Xa=None):
    """Exact Euclidean k-NN (k <= N): float32 BLAS ranks, float64 decides.

    For database blocks of ``block`` rows one GEMM gives the ranking key ``|x|²/2 - q·x`` of every
    query against the block (the squared distance minus ``|q|²``, halved); a running list keeps the
    best ``k + margin`` candidates per query (after the first block only the queries with a key
    below their current ``k + margin``-th best take part: one ``min`` pass instead of ``k + margin``
    ``argmin`` passes for the rest; issue 17); their distances are then recomputed directly in
    float64 and sorted, so float32 rounding can only matter if it pushed a true neighbour behind
    ``margin`` others. The full distance matrix is never written.
    """
    M, N, c, Xa, block, Qa = _block_setup(Q, X, k, margin, block, Xa)
    buf = np.empty((M, min(block, N)), dtype=np.float32)
    best_key = np.full((M, 0), np.inf, dtype=np.float32)
    best_idx = np.empty((M, 0), dtype=np.int64)
    for s0 in range(0, N, block):
        s1 = min(s0 + block, N)
        G = buf[:, : s1 - s0]
        np.matmul(Qa, Xa[s0:s1].T, out=G)  # (M, b) ranking keys
        if best_key.shape[1] < c:  # the first block(s): every query takes its best c
            rows = slice(None)
        else:  # later blocks: only queries with a key below their current c-th best (one min pass)
            rows = np.flatnonzero(G.min(axis=1) < best_key.max(axis=1))
            if rows.size == 0:
                continue
            G = G[rows]
        part = _smallest(G, min(c, s1 - s0))
        key = np.concatenate([best_key[rows], _keys(Qa[rows], Xa, part + s0)], axis=1)
        idx = np.concatenate([best_idx[rows], part + s0], axis=1)
        if key.shape[1] > c:
            keep = np.argpartition(key, c - 1, axis=1)[:, :c]
            key, idx = np.take_along_axis(key, keep, axis=1), np.take_along_axis(idx, keep, axis=1)
        if isinstance(rows, slice):
            best_key, best_idx = key, idx
        else:
            best_key[rows], best_idx[rows] = key, idx
    return _final_k(Q, X, best_idx, k)


def _block_rows(M):
    """Database rows per block for ``M`` queries."""
    # blocks of ~2^21 keys (8 MB): the GEMM's output and the passes over it stay in L3 with few GEMM calls
    # (8192-row blocks of 500 queries wrote and re-read 16 MB per block three times; issue 17)
    return max(512, min(8192, (1 << 21) // max(M, 1)))


def _query_rows(Q):
    """``[-q, 1]`` float32 rows (the query side of the ranking GEMM)."""
    Qa = np.empty((Q.shape[0], Q.shape[1] + 1), dtype=np.float32)
    Qa[:, :-1] = -Q
    Qa[:, -1] = 1.0
    return Qa


def _in_pool():
    """Whether this thread is one of :mod:`slamlab._threads`' workers (whose tasks must not submit tasks)."""
    import threading

    return threading.current_thread().name.startswith("slamlab-worker")


def _final_k(Q, X, best_idx, k):
    """The candidates' distances recomputed directly in float64, sorted (ties by index), the best ``k`` kept."""
    diff = Q[:, None, :].astype(np.float64) - X[best_idx].astype(np.float64)
    d = np.sqrt(np.einsum("ijk,ijk->ij", diff, diff))
    o = _order(d, best_idx)[:, :k]
    return np.take_along_axis(d, o, axis=1), np.take_along_axis(best_idx, o, axis=1)


def _exact_knn_float_compiled(Q, X, k, block: int | None = None, margin: int = 1, Xa=None, workers: int = 0):
    """:func:`_exact_knn_float` with the selection compiled: the same BLAS blocks, one pass per block.

    After each block's product, ``_brute_kernel.update_top_c`` merges the block's keys
    into the running ``k + margin`` best of every query in one pass over the block (no ``min`` pass, no
    ``argmin`` passes, no gathers; a query that cannot improve costs one compare per key). The kept keys
    are the product's own (the numpy path recomputes them with ``einsum``), so the two candidate lists
    can differ only where float32 rounding reorders near-equal keys; the final ``k`` come from the same
    float64 recomputation and order, hence the same results whenever both lists hold the true ``k``
    nearest (the numpy path's own condition for exactness). Large problems run on two workers, each
    multiplying (BLAS on one thread) and selecting its own blocks (``_brute_kernel.top_c_blocks``).

    Parameters
    ----------
    Q, X : (M, d), (N, d) float
        Queries and database rows.
    k : int
        Neighbours per query (``k <= N``).
    block : int, optional
        Database rows per BLAS product (default: :func:`_block_rows` on one worker, :func:`_split_rows` on two).
    margin : int
        Candidates kept beyond ``k`` for the float64 re-ranking.
    Xa : (N, d + 1) float32, optional
        ``augment_rows(X)``, when the caller keeps it.
    workers : int
        1: products (BLAS threaded as configured) and selection in this thread; 2: this thread and a worker
        of :mod:`slamlab._threads`' pool; 0: 2 where :func:`_use_two_workers` says so, else 1.

    Returns
    -------
    dist : (M, k) float64
        Ascending, ties by index.
    idx : (M, k) int64
        Row indices into ``X``.
    """
    from ._brute_kernel import top_c_blocks

    M, N = Q.shape[0], X.shape[0]
    workers = workers or (2 if _use_two_workers(M, N) else 1)
    _M, _N, c, Xa, block, Qa = _block_setup(Q, X, k, margin, block or (_split_rows(M) if workers > 1 else None), Xa)
    best_idx = top_c_blocks(Qa, Xa, c, block, workers)
    # a key that never beat inf (an overflowing product) leaves a slot empty: rank those queries in numpy
    bad = np.flatnonzero(best_idx[:, -1] < 0)
    if bad.size:
        best_idx[bad] = _exact_knn_float(Q[bad], X, c, block, 0, Xa)[1]
    return _final_k(Q, X, best_idx, k)


# two workers from this many keys (queries x rows) on: below, a product is too short to share (issue 25; at load
# 10, 2^17-2^20 keys took 0.04-0.54x the one-worker time, the one worker's two-thread BLAS waiting for a core)
_TWO_WORKERS_MIN_KEYS = 1 << 18


def _use_two_workers(M, N):
    """Whether the compiled path runs on two workers: a large problem, not from inside the shared pool.

    Parameters
    ----------
    M, N : int
        Queries and database rows.

    Returns
    -------
    bool
        True where the problem has at least ``_TWO_WORKERS_MIN_KEYS`` keys and two blocks, and numpy's BLAS
        can be held to one thread per worker (:func:`slamlab._threads.blas_threads_settable`).
    """
    from .._threads import blas_threads_settable

    return M * N >= _TWO_WORKERS_MIN_KEYS and 2 * _split_rows(M) <= N and not _in_pool() and blas_threads_settable()


def _split_rows(M):
    """Database rows per block on two workers: a block's keys (``M`` x rows, float32) stay in L2.

    Parameters
    ----------
    M : int
        Queries.

    Returns
    -------
    int
    """
    # 2^17 keys = 512 KB of the 1 MiB L2 per core. Scratch sweeps of 500 queries x 65 000 rows at load 5-10 had
    # 256-384 rows at or near the best of 64-4194 in three of four (issue 25); to be re-measured quietly
    return max(128, min(4096, (1 << 17) // max(M, 1)))


def _keys(Qa, Xa, idx):
    """Ranking keys of the selected (query, row) pairs, (M, c)."""
    return np.einsum("ij,ikj->ik", Qa, Xa[idx])


def _smallest(G, c):
    """Column indices of the ``c`` smallest entries of each row (any order); overwrites ``G``'s winners."""
    n = G.shape[1]
    if c >= n:
        return np.broadcast_to(np.arange(n), G.shape)
    if c > 4:
        return np.argpartition(G, c - 1, axis=1)[:, :c]
    rows = np.arange(G.shape[0])
    out = np.empty((G.shape[0], c), dtype=np.int64)
    for j in range(c):  # a few argmin passes are much faster than argpartition
        out[:, j] = np.argmin(G, axis=1)
        if j < c - 1:
            G[rows, out[:, j]] = np.inf
    return out


def _order(d, idx):
    """Row-wise order by distance, ties by index (a deterministic order, whatever the candidates' order)."""
    o = np.argsort(idx, axis=1, kind="stable")
    o2 = np.argsort(np.take_along_axis(d, o, axis=1), axis=1, kind="stable")
    return np.take_along_axis(o, o2, axis=1)
