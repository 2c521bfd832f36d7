"""The monocular loop on rendered arena sequences (003 §5.2: ATE after alignment) and the failure cases."""

from __future__ import annotations

import numpy as np

from slamlab.mono.experiments import run_mono_sequence


def test_strafe_sequence_tracks_with_centimetre_ate():
    r = run_mono_sequence("strafe", n_frames=40, progress=False)
    # 40 frames, 2 cm apart (0.78 m): initialised within 5 frames, then tracked throughout
    assert r.fraction_tracked > 0.85
    assert r.ate_m < 0.02  # metres, after Sim(3) alignment
    assert np.all(np.isfinite(r.estimate))
    assert r.verdict == "ok"
