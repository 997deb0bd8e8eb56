"""Tonal components and their audibility (rail_monitor.models.tonality, ISO/PAS 20065) on signals
with known answers."""

from __future__ import annotations

import numpy as np
import pytest

from rail_monitor.models import tonality

FS = 48_000
P0 = 20e-6


def test_the_critical_band_and_masking_index_at_their_published_anchor_points():
    """Zwicker's critical bandwidth: about 100 Hz up to 500 Hz, 162 Hz at 1 kHz, 20 % of f above
    (Zwicker & Fastl, 6.2): 102.1 Hz at 100 Hz, 162.2 Hz at 1 kHz; the masking index a_v at 1 kHz:
    -2 - lg(1 + (1000/502)^2.5) = -2.82 dB."""
    assert tonality.critical_bandwidth_hz(100.0) == pytest.approx(100.0, rel=0.03)
    assert tonality.critical_bandwidth_hz(1000.0) == pytest.approx(162.2, abs=0.1)
    assert tonality.critical_bandwidth_hz(5000.0) / 5000.0 == pytest.approx(0.2, rel=0.1)
    assert tonality.masking_index_db(1000.0) == pytest.approx(-2.82, abs=0.01)


@pytest.mark.parametrize(("tone_db", "f_hz"), [(60.0, 1000.0), (68.0, 3150.0), (70.0, 630.0)])
def test_a_tone_in_white_noise_has_its_computed_audibility(tone_db, f_hz):
    """A tone of level L_T in white noise of density N0: L_G = 10 lg(N0 delta_f_c / p0^2) and
    delta_L = L_T - L_G - a_v, computed from the definitions; the method reads the seeded 10 s record
    to 0.5 dB (the estimate's scatter over seeds is about 0.3 dB)."""
    rng = np.random.default_rng(20065)
    n0 = 1e-6  # [Pa^2/Hz]
    t = np.arange(10 * FS) / FS
    tone = np.sqrt(2) * P0 * 10 ** (tone_db / 20) * np.sin(2 * np.pi * f_hz * t)
    p = rng.normal(0, np.sqrt(n0 * FS / 2), len(t)) + tone
    found = tonality.tones(p, FS)
    assert len(found) == 1 and found[0].frequency_hz == pytest.approx(f_hz, abs=1.0)
    level_g = 10 * np.log10(n0 * tonality.critical_bandwidth_hz(f_hz) / P0**2)
    assert found[0].level_db == pytest.approx(tone_db, abs=0.5)
    assert found[0].masking_db == pytest.approx(level_g, abs=0.5)
    assert found[0].audibility_db == pytest.approx(tone_db - level_g - tonality.masking_index_db(f_hz), abs=0.5)


def test_noise_alone_and_an_inaudible_tone_give_no_tone():
    """White noise alone, and with a tone 10 dB under its masking threshold (delta_L = -10 dB):
    no audible tone."""
    rng = np.random.default_rng(7)
    n0 = 1e-6
    t = np.arange(5 * FS) / FS
    noise = rng.normal(0, np.sqrt(n0 * FS / 2), len(t))
    assert tonality.tones(noise, FS) == []
    threshold = 10 * np.log10(n0 * tonality.critical_bandwidth_hz(2000.0) / P0**2) + tonality.masking_index_db(2000.0)
    level_t = threshold - 10
    quiet = np.sqrt(2) * P0 * 10 ** (level_t / 20) * np.sin(2 * np.pi * 2000.0 * t)
    assert tonality.tones(noise + quiet, FS) == []
