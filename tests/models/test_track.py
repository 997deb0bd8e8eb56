"""Track receptance: limits, resonance structure and convergence (docs/models.md).

Reference values: docs/models.md (UIC60 on a typical ballasted track; static stiffness
about 110 MN/m; full-track resonance 50-150 Hz, rail-on-pad 300-1000 Hz, pinned-pinned
900-1100 Hz with a peak at mid-span and a dip above a sleeper); Knothe & Grassie, Vehicle
System Dynamics 22 (1993) for the structure.
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy.signal import find_peaks

from rail_monitor.models import track as tr
from rail_monitor.models import wheel_rail_noise as wrn

UIC60 = tr.Track()
LOSSLESS = UIC60.with_(rail_loss_factor=0.0, pad_loss_factor=0.0, ballast_loss_factor=0.0)
F = np.geomspace(20.0, 3000.0, 500)


def _peaks(receptance, which="peaks"):
    mag = np.abs(receptance)
    idx, _ = find_peaks(mag if which == "peaks" else -mag)
    return F[idx]


def test_static_stiffness_is_about_110_mn_per_m():
    assert tr.static_stiffness(UIC60) == pytest.approx(110e6, rel=0.05)


def test_low_frequency_limit_is_the_static_stiffness():
    # Euler beam on the smeared support at 0.01 Hz, no damping: 1 / alpha = 2 s / beta (Hetenyi).
    k = 1.0 / tr.continuous_receptance(0.01, LOSSLESS, "euler")
    assert k.real == pytest.approx(tr.static_stiffness(LOSSLESS), rel=1e-6)
    # the discrete model averaged over the bay is within 5 % of it
    kd = 1.0 / tr.bay_averaged_receptance(0.01, LOSSLESS, "euler", positions=4)
    assert kd.real == pytest.approx(tr.static_stiffness(LOSSLESS), rel=0.05)


def test_timoshenko_tends_to_euler_without_shear_flexibility():
    # Limit case: infinite shear stiffness; at low frequency rotary inertia is negligible.
    stiff = UIC60.with_(shear_coefficient=1e8)
    # Rotary inertia adds a relative difference growing as f^2 (2.5e-4 at 50 Hz, 1.5e-3 at 200 Hz).
    f = np.geomspace(1.0, 20.0, 30)
    np.testing.assert_allclose(tr.continuous_receptance(f, stiff, "timoshenko"),
                               tr.continuous_receptance(f, stiff, "euler"), rtol=1e-4)


def test_euler_and_timoshenko_agree_at_low_frequency_and_part_above_500_hz():
    # With UIC60's kappa = 0.4 the static shear deflection keeps Timoshenko 4-8 % softer below
    # 200 Hz (the two resonances then shift apart, up to 24 % near the 270 Hz anti-resonance);
    # above 1 kHz shear and rotary inertia take over and the two part steadily.
    ratio = np.abs(tr.continuous_receptance(F, UIC60) / tr.continuous_receptance(F, UIC60, "euler"))
    assert np.all(np.abs(ratio[F < 200] - 1) < 0.1)
    assert np.all(ratio[F > 1800] > 1.2)
    assert np.all(np.diff(ratio[F > 1000]) > 0)


def test_resonance_structure_of_uic60():
    cont = tr.continuous_receptance(F, UIC60)
    peaks = _peaks(cont)
    assert any(50 <= p <= 150 for p in peaks), peaks       # full-track (rail and sleepers on ballast)
    assert any(300 <= p <= 1000 for p in peaks), peaks     # rail on pads
    mid = tr.discrete_receptance(F, UIC60, position=0.5)
    above = tr.discrete_receptance(F, UIC60, position=0.0)
    pp = [p for p in _peaks(mid) if 900 <= p <= 1100]
    assert pp, _peaks(mid)                                # pinned-pinned peak at mid-span
    dips = [d for d in _peaks(above, "dips") if 900 <= d <= 1200]
    assert dips, _peaks(above, "dips")                    # and a dip above the sleeper
    i = np.argmin(np.abs(F - pp[0]))
    assert np.abs(mid[i]) > 3 * np.abs(above[i])


def test_discrete_supports_converge():
    f = np.array([100.0, 500.0, 1000.0, 2000.0])
    r121 = tr.discrete_receptance(f, UIC60, supports=121)
    r241 = tr.discrete_receptance(f, UIC60, supports=241)
    np.testing.assert_allclose(r121, r241, rtol=0.01)
    r21 = tr.discrete_receptance(f, UIC60, supports=21)
    assert np.max(np.abs(r21 / r241 - 1)) > 0.05  # too few supports is visibly wrong at 1 kHz


def test_wheel_receptance_is_a_mass_line():
    f = np.array([10.0, 100.0])
    r = wrn.wheel_receptance(f, 600.0)
    np.testing.assert_allclose(r, -1.0 / (600.0 * (2 * np.pi * f) ** 2))


_RECEPTANCE_BYTES = """
import sys
import numpy as np
from rail_monitor.models import track as tr
f = np.geomspace(20.0, 5000.0, 300)
sys.stdout.write(tr.discrete_receptance(f, tr.Track(), position=[0.0, 0.25, 0.5]).tobytes().hex())
"""


def test_the_discrete_receptance_does_not_depend_on_the_maths_library_threads():
    # The receptance is cached on disk and shared by every process of a site, so it must be the
    # same bits whatever thread count the process that built it allowed OpenBLAS (its threaded
    # LAPACK solve rounds differently: 5e-10 relative, measured on this 2-core machine).
    import os
    import subprocess
    import sys

    out = {}
    for threads in ("1", "2"):
        env = {**os.environ, "OPENBLAS_NUM_THREADS": threads, "OMP_NUM_THREADS": threads}
        done = subprocess.run([sys.executable, "-c", _RECEPTANCE_BYTES], env=env, capture_output=True, text=True,
                              timeout=120, check=True)
        out[threads] = done.stdout
    assert out["1"] and out["1"] == out["2"]
