"""Issue 27's goals as tests, with the bounds of the goals (not of our output).

- Global localisation in the simulated room: success >= 0.95 with <= 5000 particles within <= 30 steps
  (here 5000 particles, 30 steps, on a seeded subset of 20 runs).
- Kidnapped robot: recovery >= 0.9 with the chapter's defaults (20 runs).
- Injection fires with the defaults ((α_slow, α_fast) = (0.001, 0.1)): particles are injected after a kidnap.
"""

import pytest

from slamlab.studies import localisation as LS


@pytest.mark.slow
def test_global_localisation_success_at_least_095():
    g = LS.run_global_localisation((5000,), n_runs=20, n_steps=30, rng=27, progress=False)
    assert g.success(5000, 30) >= 0.95, g.table()


@pytest.mark.slow
def test_kidnap_recovery_at_least_09_with_the_defaults():
    k = LS.run_kidnapped((("defaults", {}),), n_runs=20, n_particles=1000, n_steps=50, kidnap_step=20, rng=27,
                        progress=False)
    assert k.recovered("defaults") >= 0.9, k.table()
    assert k.table_df["injected_after"].mean() > 0
