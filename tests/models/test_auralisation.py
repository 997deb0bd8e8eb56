"""A predicted pass made audible (rail_monitor.models.auralisation), read back by the pass-by
processor: the levels it was made of come back."""

from __future__ import annotations

import numpy as np
import pytest

from rail_monitor.models import auralisation as au
from rail_monitor.models import iso3095
from rail_monitor.models.iec61260 import third_octave_bands
from rail_monitor.models.levels import a_weighted_total
from rail_monitor.models.passby_kernel import kernel_total, kernel_window_mean

from conftest import band_noise_tolerance_db, band_readings_db

FS = 48_000
BANDS = third_octave_bands(50, 10_000)


def test_a_synthesised_line_source_gives_back_its_levels():
    """A 100 m train at 20 m/s, 7.5 m away (direct path 7.53 m), a spectrum peaking at 80 dB at 1 kHz:
    LpAeq,Tp equals the A-weighted sum of the bands to 0.1 dB; TEL equals it plus 10 lg(total / mean)
    of the kernel to 0.1 dB (10 s either side); each band, against what the filters pass of the bands'
    noise (conftest.band_readings_db), within conftest.band_noise_tolerance_db."""
    lp = 80.0 - 0.05 * BANDS.astype(float) ** 2
    d, r, length, v = 7.5, float(np.hypot(7.5, 0.7)), 100.0, 20.0
    p = au.passby_pressure(BANDS, lp, d, r, length, v, FS, 10.0, 10.0, seed=56)
    res = iso3095.passby_levels(p, FS, 10.0, 10.0 + length / v)
    la = float(a_weighted_total(lp, BANDS))
    assert res.lpaeq_tp_db == pytest.approx(la, abs=0.1)
    whole = 10 * np.log10(kernel_total(d, r) / kernel_window_mean(length, d, r))
    assert res.tel_db == pytest.approx(la + whole, abs=0.1)
    off = res.band_levels_db - band_readings_db(lp, BANDS)
    assert np.all(np.abs(off) <= band_noise_tolerance_db(BANDS, length / v)), off


def test_the_squeal_tone_is_doppler_shifted_as_it_comes_and_goes():
    """A 1.2 kHz tone on a train at 30 m/s: in the first and the last second of a record 8 s either
    side (where the tone glides slowly), it reads f0 / (1 - v cos(theta) / c), theta the angle at the
    emission time (found here by fixed-point iteration, not the closed form the module solves), to
    0.5 %: +9 % as it comes, -8 % as it goes."""
    d, length, v, f0 = 7.5, 60.0, 30.0, 1200.0
    t = np.arange(-8.0, length / v + 8.0, 1 / FS)
    p = au.moving_tone(f0, 90.0, d, length, v, t)
    for t_mid in (-7.5, length / v + 7.5):
        i = slice(int((t_mid + 8.0 - 0.5) * FS), int((t_mid + 8.0 + 0.5) * FS))
        spectrum = np.abs(np.fft.rfft(p[i] * np.hanning(i.stop - i.start)))
        f = np.fft.rfftfreq(i.stop - i.start, 1 / FS)[np.argmax(spectrum)]
        c, tau = au.SOUND_SPEED_MPS, t_mid
        for _ in range(50):  # the emission time, by fixed point: tau = t - r(tau) / c
            tau = t_mid - np.hypot(d, v * tau - length / 2) / c
        x = v * tau - length / 2
        cos_theta = -x / np.hypot(d, x)  # positive while it comes
        assert f == pytest.approx(f0 / (1 - v * cos_theta / c), rel=0.005), t_mid
