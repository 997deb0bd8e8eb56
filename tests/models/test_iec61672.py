"""Frequency weighting A (rail_monitor.models.iec61672) against the table of IEC 61672-1:2013."""

from __future__ import annotations

import numpy as np
import pytest

from rail_monitor.models import iec61672


def test_a_weighting_matches_iec_61672_table():
    # IEC 61672-1:2013 Table 3 (0.1 dB resolution), which is evaluated at the exact base-ten
    # frequencies 1 kHz x 10^(n/10), n = -15, -10, 0, 6, 10 (nominal 31.5, 100, 1k, 4k, 10k Hz).
    f = 1000.0 * 10.0 ** (np.array([-15, -10, 0, 6, 10]) / 10)
    np.testing.assert_allclose(iec61672.a_weighting_db(f), [-39.4, -19.1, 0.0, 1.0, -2.5], atol=0.051)


@pytest.mark.parametrize("burst_s", [1.0, 0.5, 0.2, 0.1, 0.05, 0.02, 0.01, 0.005, 0.002, 0.001, 0.0005, 0.00025])
def test_f_time_weighting_gives_the_reference_tone_burst_responses(burst_s):
    """IEC 61672-1:2013, the reference 4 kHz tone-burst responses (Table 4): a burst of duration T_b,
    time weighting F, reads 10 lg(1 - exp(-T_b / 0.125 s)) below the steady tone's level (0.0 dB
    at 1 s ... -27.0 dB at 0.25 ms). The A-weighted burst through the processor's time weighting,
    at 48 kHz: within 0.1 dB (0.2 dB for 0.25 ms, one cycle of 4 kHz: 12 samples)."""
    from rail_monitor.models.iec61672 import a_weighted_pressure, time_weighted_square

    fs = 48_000
    tone = np.sin(2 * np.pi * 4000.0 * np.arange(3 * fs) / fs)
    steady = np.mean(a_weighted_pressure(tone, fs)[fs:2 * fs] ** 2)
    burst = np.zeros(2 * fs)
    n = round(burst_s * fs)
    burst[fs // 2: fs // 2 + n] = tone[:n]
    peak = np.max(time_weighted_square(a_weighted_pressure(burst, fs) ** 2, fs))
    assert 10 * np.log10(peak / steady) == pytest.approx(10 * np.log10(1 - np.exp(-burst_s / 0.125)),
                                                         abs=0.2 if burst_s < 0.0005 else 0.1)


def test_the_a_weighted_pressure_weights_each_tone_by_the_formula():
    """Three tones through a_weighted_pressure: each one's power changes by A(f) of eq. E.6
    (read by the record's own spectrum at each tone's line), to 0.01 dB."""
    from rail_monitor.models.iec61672 import a_weighted_pressure, a_weighting_db

    fs, n = 48_000, 48_000
    t = np.arange(n) / fs
    for f in (63.0, 1000.0, 8000.0):
        out = a_weighted_pressure(np.sin(2 * np.pi * f * t), fs)
        gain = 10 * np.log10(np.mean(out[n // 4: 3 * n // 4] ** 2) / 0.5)
        assert gain == pytest.approx(float(a_weighting_db(f)), abs=0.01), f
