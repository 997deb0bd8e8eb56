"""Squeal detected in a synthesised pass-by, and not in a rolling-only or a flanging one
(rail_monitor.models.squeal_detection)."""

from __future__ import annotations

import numpy as np
import pytest
from scipy import fft

from rail_monitor.models import tonality
from rail_monitor.models.squeal_detection import detect_squeal

FS = 48_000
P0 = 20e-6


def _shaped_noise(rng, seconds: float, low_hz: float, high_hz: float, level_db: float) -> np.ndarray:
    """Gaussian noise of flat density between low_hz and high_hz [Hz], of level level_db [dB]."""
    n = round(seconds * FS)
    spectrum = fft.rfft(rng.normal(size=n))
    f = fft.rfftfreq(n, 1 / FS)
    spectrum[(f < low_hz) | (f > high_hz)] = 0.0
    x = fft.irfft(spectrum, n)
    return x * P0 * 10 ** (level_db / 20) / np.sqrt(np.mean(x**2))


def _rolling(rng, seconds: float = 6.0) -> np.ndarray:
    """Rolling noise: 85 dB between 100 Hz and 3 kHz."""
    return _shaped_noise(rng, seconds, 100.0, 3000.0, 85.0)


def test_a_squealing_pass_is_detected_with_its_tone_duration_and_share():
    """An 800 Hz tone (the published tram squeal's 780-800 Hz) 15 dB above its masking threshold
    for 2.0 s of a 6 s pass of rolling noise: squeal, at 800 Hz within the 5 Hz resolution, its
    level within 1 dB, its duration within one hop (0.1 s) and its share 2/6 likewise."""
    rng = np.random.default_rng(54)
    p = _rolling(rng)
    t = np.arange(len(p)) / FS
    density = P0**2 * 10 ** 8.5 / 2900.0  # [Pa^2/Hz]
    level = 10 * np.log10(density * tonality.critical_bandwidth_hz(800.0) / P0**2) + tonality.masking_index_db(800.0)
    tone_db = float(level + 15.0)
    on = (t >= 2.0) & (t < 4.0)
    p = p + np.where(on, np.sqrt(2) * P0 * 10 ** (tone_db / 20) * np.sin(2 * np.pi * 800.0 * t), 0.0)
    d = detect_squeal(p, FS)
    assert d.squeal and not d.flanging
    assert d.frequency_hz == pytest.approx(800.0, abs=5.0)
    assert d.level_db == pytest.approx(tone_db, abs=1.0)
    assert d.duration_s == pytest.approx(2.0, abs=0.1) and d.share == pytest.approx(2.0 / 6.0, abs=0.1 / 6)


def test_rolling_noise_alone_does_not_squeal():
    d = detect_squeal(_rolling(np.random.default_rng(1)), FS)
    assert not d.squeal and not d.flanging and d.duration_s == 0.0 and np.isnan(d.frequency_hz)


def test_flanging_noise_is_flanging_not_squeal():
    """Broadband noise 5-10 kHz at 88 dB for 2 s of the pass (flanging: high-pitched, no one tone)."""
    rng = np.random.default_rng(2)
    p = _rolling(rng)
    burst = _shaped_noise(rng, 2.0, 5000.0, 10_000.0, 88.0)
    p[2 * FS: 4 * FS] += burst
    d = detect_squeal(p, FS)
    assert not d.squeal and d.flanging and d.flanging_s == pytest.approx(2.0, abs=0.3)


def test_a_short_chirp_of_tone_is_not_a_squeal():
    """The same tone for 0.3 s (below the 0.5 s minimum duration): no squeal."""
    rng = np.random.default_rng(3)
    p = _rolling(rng)
    t = np.arange(len(p)) / FS
    p = p + np.where((t >= 2.0) & (t < 2.3), 0.5 * np.sin(2 * np.pi * 1200.0 * t), 0.0)
    assert not detect_squeal(p, FS).squeal
