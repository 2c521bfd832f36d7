"""SURF-like descriptors drawn in blocks of rows (issue 45: a student's kernel in 512 MiB): the same descriptors
as the whole-array expressions they replaced, which are written out here as the reference."""

import numpy as np
import pytest

from slamlab.studies.kdtree import workloads
from slamlab.studies.kdtree.workloads import DIM, surf_like_descriptors


def _whole_array(n, rng, prototypes=None, clustered=True, n_clusters=256, sigma_cluster=0.35):
    """The former one-shot version (four float64 arrays of all ``n`` rows)."""
    rng = np.random.default_rng(rng)

    def normalise(X):
        X /= np.linalg.norm(X, axis=1, keepdims=True) + 1e-12
        return X

    if not clustered:
        return normalise(rng.standard_normal((n, DIM))).astype(np.float32), None
    if prototypes is None:
        g = rng.standard_normal((n_clusters, 16, 2)) * rng.gamma(2.0, 0.5, (n_clusters, 16, 1))
        absg = np.abs(g) + np.abs(rng.standard_normal((n_clusters, 16, 2))) * 0.5
        prototypes = normalise(np.concatenate([g, absg], axis=2).reshape(n_clusters, DIM))
    c = rng.integers(0, prototypes.shape[0], n)
    X = prototypes[c] + sigma_cluster / np.sqrt(DIM) * rng.standard_normal((n, DIM))
    X = X.reshape(n, 16, 4)
    X[:, :, 2:] = np.abs(X[:, :, 2:])
    return normalise(X.reshape(n, DIM)).astype(np.float32), prototypes


@pytest.mark.parametrize("n", [0, 1, 99, 100, 101, 350])
@pytest.mark.parametrize("clustered", [True, False])
def test_blocks_give_the_whole_array_descriptors(monkeypatch, n, clustered):
    monkeypatch.setattr(workloads, "_BLOCK", 100)  # several blocks and a partial last one
    X, P = surf_like_descriptors(n, clustered=clustered, rng=n + 7)
    X0, P0 = _whole_array(n, n + 7, clustered=clustered)
    assert X.dtype == np.float32
    assert np.array_equal(X, X0)
    assert (P is None and P0 is None) or np.array_equal(P, P0)
    if clustered:  # reusing the prototypes, as the clutter queries do
        Xc, _ = surf_like_descriptors(n, rng=1, prototypes=P)
        assert np.array_equal(Xc, _whole_array(n, 1, prototypes=P0)[0])


def test_the_default_block_holds_4_mib_per_float64_temporary():
    assert workloads._BLOCK * DIM * 8 == 4 << 20
