"""The batched likelihood-field gather against a per-particle, per-beam loop of the documented definition.

``LikelihoodFieldModel`` (its class docstring) puts a beam's end point in the cell ``col = floor(x + cos θ·bx −
sin θ·by + 0.5)``, ``row = floor(y + sin θ·bx + cos θ·by + 0.5)``, float64, left to right, ``(bx, by)`` the beam's
``Beams.end_xy``; the cell's value is ``log_table`` on the map and ``log_outside`` off it. The reference below is
that sentence as a plain Python loop (``math.cos``, ``math.floor``), so the batched path must pick the same cell
for every particle and beam: per-beam values are compared exactly. A float32 end point (what the gather did
before) puts about one particle in a thousand of the benchmark's room in another cell; the boundary particles
here, placed within a few ulps of a cell edge and exactly on .5 positions, tell the two apart.
"""

import math

import numpy as np
import pytest

from slamlab import localisation as L
from slamlab import sim as S
from slamlab.scans import FREE, OBSTACLE, Scan


def reference_cells(X, beams: L.Beams, used) -> np.ndarray:
    """``(N, B_used, 2)`` cells (col, row) of the end points, one particle and one beam at a time."""
    out = np.empty((len(X), len(used), 2), dtype=np.int64)
    for i, (x, y, th) in enumerate(np.asarray(X, dtype=float).tolist()):
        c, s = math.cos(th), math.sin(th)
        for j, k in enumerate(used):
            bx, by = float(beams.end_xy[k, 0]), float(beams.end_xy[k, 1])
            out[i, j] = math.floor(x + c * bx - s * by + 0.5), math.floor(y + s * bx + c * by + 0.5)
    return out


def reference_log_q(model: L.LikelihoodFieldModel, X, beams: L.Beams):
    """Per-beam ``log q`` (float32, as the model stores its table) and ``log p(z | x)`` summed in a loop."""
    used = np.flatnonzero(model.used(beams)).tolist()
    cells = reference_cells(X, beams, used)
    H, W = model.shape
    table = model.log_table.reshape(H, W)
    q = np.empty(cells.shape[:2], dtype=np.float32)
    ll = np.empty(len(X))
    for i in range(len(X)):
        acc = 0.0
        for j in range(len(used)):
            col, row = int(cells[i, j, 0]), int(cells[i, j, 1])
            v = table[row, col] if 0 <= row < H and 0 <= col < W else model.log_outside
            q[i, j] = v
            acc += float(q[i, j])
        ll[i] = acc
    return q, ll, cells


def lookup(model: L.LikelihoodFieldModel, cells) -> np.ndarray:
    """``log_table`` at ``(M, 2)`` cells (col, row), ``log_outside`` off the map."""
    H, W = model.shape
    col, row = cells[:, 0], cells[:, 1]
    on = (col >= 0) & (col < W) & (row >= 0) & (row < H)
    out = np.full(len(cells), model.log_outside)
    out[on] = model.log_table[row[on] * W + col[on]]
    return out


def edge_particles(beams: L.Beams, shape, n: int, rng) -> np.ndarray:
    """Particles whose end point of one beam lies within a few ulps of a column edge and of another beam
    within a few ulps of a row edge (evaluated in the definition's order), and some exactly on them."""
    H, W = shape
    th = rng.uniform(-math.pi, math.pi, n)
    k1, k2 = rng.integers(beams.n, size=n), rng.integers(beams.n, size=n)
    c, s = np.cos(th), np.sin(th)
    ex = c * beams.end_xy[k1, 0] - s * beams.end_xy[k1, 1]
    ey = s * beams.end_xy[k2, 0] + c * beams.end_xy[k2, 1]
    x = rng.integers(20, W - 20, n) - 0.5 - ex  # x + ex + 0.5 ≈ an integer: a column edge
    y = rng.integers(20, H - 20, n) - 0.5 - ey
    steps = rng.integers(-3, 4, (n, 2))  # then 0 to 3 ulps either way
    for _ in range(3):
        x = np.where(steps[:, 0] > 0, np.nextafter(x, np.inf), np.where(steps[:, 0] < 0, np.nextafter(x, -np.inf), x))
        y = np.where(steps[:, 1] > 0, np.nextafter(y, np.inf), np.where(steps[:, 1] < 0, np.nextafter(y, -np.inf), y))
        steps -= np.sign(steps)
    return np.column_stack([x, y, th])


def half_lattice(shape, n_side: int) -> np.ndarray:
    """Poses at x, y = m + 0.5 (cell edges) with headings 0, ±π/2, π."""
    H, W = shape
    xs = np.linspace(5, W - 6, n_side).round() + 0.5
    ys = np.linspace(5, H - 6, n_side).round() + 0.5
    gx, gy, gt = np.meshgrid(xs, ys, [0.0, math.pi / 2, math.pi, -math.pi / 2], indexing="ij")
    return np.column_stack([gx.ravel(), gy.ravel(), gt.ravel()])


def float32_cells(X, beams: L.Beams) -> np.ndarray:
    """The cells of the former float32 gather (the end point in float32): a negative control."""
    X32, e32 = np.asarray(X, np.float32), beams.end_xy.astype(np.float32)
    c, s = np.cos(X[:, 2]).astype(np.float32)[:, None], np.sin(X[:, 2]).astype(np.float32)[:, None]
    col = np.floor(X32[:, :1] + np.float32(0.5) + c * e32[:, 0] - s * e32[:, 1])
    row = np.floor(X32[:, 1:2] + np.float32(0.5) + s * e32[:, 0] + c * e32[:, 1])
    return np.stack([col, row], axis=-1).astype(np.int64)


@pytest.fixture(scope="module")
def room():
    """The benchmark's case: the 200×200 test room, 60 beams of the scan at path_004's pose 30, z_max 300."""
    M = S.test_room_200()
    scan = S.Rangefinder(n_beams=60, max_range_cells=300, range_std_cells=0.5).scan(M, S.path_004(121)[30], rng=0)
    model = L.MCLParams(max_beams=60).model(M, 300.0)
    beams = L.scan_beams(scan, 60)
    assert beams.n == 60
    assert model.used(beams).all()
    X = np.vstack([L.uniform_free_particles(M, 10_000, 0), edge_particles(beams, M.shape, 4000, np.random.default_rng(1))])
    return model, beams, X, reference_log_q(model, X, beams)


@pytest.mark.parametrize("no_numba", ["0", "1"])
def test_batched_log_likelihood_is_the_definition_on_the_benchmark_room(room, no_numba, monkeypatch):
    # localisation has no compiled path: SLAMLAB_NO_NUMBA must change nothing (both settings checked)
    monkeypatch.setenv("SLAMLAB_NO_NUMBA", no_numba)
    model, beams, X, (q_ref, ll_ref, _) = room
    assert len(X) >= 10_000
    np.testing.assert_array_equal(model.beam_log_q(X, beams), q_ref)  # the same cell for every particle-beam
    # the float64 sum of the same 60 float32 terms: only the summation order may differ (≤ 60 ulps of the sum)
    np.testing.assert_allclose(model.log_likelihood(X, beams), ll_ref, rtol=1e-13, atol=0)
    np.testing.assert_allclose(model.log_score(X, beams, "likelihood"), ll_ref, rtol=1e-13, atol=0)


def test_the_edge_particles_separate_float32_from_the_definition(room):
    # negative control: without it the equality above could hold because no end point is near an edge
    model, beams, X, (_, _, cells) = room
    edge = slice(10_000, None)
    f32 = float32_cells(X[edge], beams)
    differ = (f32 != cells[edge]).any(axis=-1)
    assert differ.any(axis=1).mean() > 0.05  # float32 puts many of them in another cell…
    # …and at hundreds of them the table's values differ (elsewhere both cells are beyond max_dist or off the
    # map), so a wrong cell would show in the per-beam comparison
    i, j = np.nonzero(differ)
    assert np.count_nonzero(lookup(model, f32[i, j]) != lookup(model, cells[edge][i, j])) > 200


def test_cell_edges_round_half_up_on_a_half_lattice():
    # x, y = m + 0.5, headings of exact quarter turns, integer ranges along the axes: many end points fall on
    # x + 0.5 = an integer exactly; the definition's floor(· + 0.5) puts them in the upper cell
    rng = np.random.default_rng(5)
    M = np.where(rng.random((50, 70)) < 0.06, OBSTACLE, FREE)
    model = L.LikelihoodFieldModel(M, z_max=30.0, max_dist=40.0, sigma_hit=3.0)
    scan = Scan(np.radians([0.0, 90.0, 180.0, 270.0, 45.0]), [3.0, 4.0, 5.0, 2.0, 4.0], np.ones(5, bool), max_range=30)
    beams = L.scan_beams(scan)
    X = half_lattice(M.shape, 12)
    q_ref, ll_ref, cells = reference_log_q(model, X, beams)
    assert cells[X[:, 2] == 0.0, 0, 0].tolist() == (X[X[:, 2] == 0.0, 0] + 3.5).astype(int).tolist()  # upper cell
    np.testing.assert_array_equal(model.beam_log_q(X, beams), q_ref)
    np.testing.assert_allclose(model.log_likelihood(X, beams), ll_ref, rtol=1e-13, atol=0)


def test_distances_and_off_map_poses_follow_the_definition():
    # a random map (distinct distances in most neighbouring cells), poses on, beside and far off the map (the
    # gather's clip path), beams at z_max skipped
    rng = np.random.default_rng(6)
    M = np.where(rng.random((60, 80)) < 0.04, OBSTACLE, FREE)
    model = L.LikelihoodFieldModel(M, z_max=25.0, max_dist=30.0, sigma_hit=2.0)
    b = np.linspace(-math.pi, math.pi, 37)[:-1]
    r = rng.uniform(0.5, 25.0, b.size)
    r[::7] = 25.0  # at z_max: not used
    beams = L.scan_beams(Scan(b, r, np.ones(b.size, bool), max_range=25.0), keep_max=True)
    X = np.vstack([
        np.column_stack([rng.uniform(-3, 83, 3000), rng.uniform(-3, 63, 3000), rng.uniform(-4, 4, 3000)]),
        edge_particles(beams, M.shape, 2000, rng),
        [[-500.0, 30.0, 0.3], [40.0, 1e4, -2.0], [-1.0, -1.0, 1.0], [80.0, 60.0, 2.0]],
    ])
    used = np.flatnonzero(model.used(beams)).tolist()
    assert len(used) < beams.n
    cells = reference_cells(X, beams, used)
    H, W = model.shape
    on = (cells[..., 0] >= 0) & (cells[..., 0] < W) & (cells[..., 1] >= 0) & (cells[..., 1] < H)
    d_ref = np.full(cells.shape[:2], model.max_dist, dtype=np.float32)
    d_ref[on] = model.dist[cells[..., 1][on], cells[..., 0][on]]
    d, keep = model.beam_distances(X, beams)
    assert keep.tolist() == model.used(beams).tolist()
    np.testing.assert_array_equal(d, d_ref)
    q_ref, _, _ = reference_log_q(model, X, beams)
    np.testing.assert_array_equal(model.beam_log_q(X, beams)[:, keep], q_ref)
    assert (~on).sum() > 100  # both sides of the map edge were exercised
    assert on.mean() > 0.5
