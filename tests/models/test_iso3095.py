"""The pass-by processor (rail_monitor.models.iso3095) on signals with known answers."""

from __future__ import annotations

import numpy as np
import pytest
from scipy import integrate, optimize

from rail_monitor.models import iec61260, iso3095
from rail_monitor.models.iec61672 import a_weighting_db

FS = 48_000
P0 = 20e-6


def _tone(level_db: float, f_hz: float, seconds: float, fs: int = FS) -> np.ndarray:
    t = np.arange(round(seconds * fs)) / fs
    return np.sqrt(2) * P0 * 10 ** (level_db / 20) * np.sin(2 * np.pi * f_hz * t)


def test_a_1_khz_tone_at_94_db_reads_94_db_everywhere_it_should():
    """A 94 dB, 1 kHz tone of 10 s (a calibrator): LpAeq 94.00, LpAFmax 94.00, SEL 104.00 (10 s),
    its band 94.00 and the neighbouring bands down by the filter's attenuation at their centres'
    ratio (G^(1/3): 21.3 dB), to 0.01 dB; one tone found, at 1 kHz, at 94.00 dB."""
    r = iso3095.passby_levels(_tone(94.0, 1000.0, 10.0), FS)
    assert (r.lpaeq_tp_db, r.lpafmax_db, r.tel_db, r.sel_db) == pytest.approx((94.0, 94.0, 94.0, 104.0), abs=0.01)
    k = list(r.band_centres_hz).index(1000.0)
    assert r.band_levels_db[k] == pytest.approx(94.0, abs=0.01)
    down = -10 * np.log10(iec61260.band_power_response(1000.0, np.array([-1, 1])).ravel())
    assert r.band_levels_db[[k - 1, k + 1]] == pytest.approx(94.0 - down, abs=0.01)
    assert [round(t.frequency_hz) for t in r.tones] == [1000] and r.tones[0].level_db == pytest.approx(94.0, abs=0.01)


def test_the_calibration_scales_a_recording_to_its_calibrator():
    """A 94 dB calibrator recorded at 0.3 full scale with a DC offset, then a 1 kHz tone at 0.03 of
    full scale: the tone reads 74.00 dB (20 lg(0.03 / 0.3) below 94)."""
    t = np.arange(FS) / FS
    scale = iso3095.sensitivity_pa_per_unit(0.01 + 0.3 * np.sqrt(2) * np.sin(2 * np.pi * 1000 * t), 94.0)
    r = iso3095.passby_levels(scale * 0.03 * np.sqrt(2) * np.sin(2 * np.pi * 1000 * t), FS)
    assert r.lpaeq_tp_db == pytest.approx(74.0, abs=0.01)
    with pytest.raises(ValueError, match="silent"):
        iso3095.sensitivity_pa_per_unit(np.zeros(100))


def test_noise_of_known_band_levels_reads_them_within_the_effective_bandwidth():
    """A random-phase multisine, 40 lines of equal power in each 1/3-octave band 50 Hz - 10 kHz at
    levels falling 1 dB a band from 80 dB: each band reads its level plus the filters' effective
    bandwidth (+0.20 dB, flat spectra; here within 0.4 dB, the neighbours' skirts included), and
    the A-weighted total is the power of each line weighted by A(f) of IEC 61672-1 eq. E.6, to
    0.05 dB."""
    rng = np.random.default_rng(56)
    n = 10 * FS
    x = np.arange(-13, 11)
    want = 80.0 - np.arange(len(x))
    spectrum = np.zeros(n // 2 + 1, complex)
    a_power = 0.0
    for lv, bx in zip(want, x, strict=True):
        f1, f2 = iec61260.band_edges(bx)
        lines = np.round(np.linspace(f1, f2, 42)[1:-1] * 10).astype(int)  # bins of the 0.1 Hz grid of 10 s
        amp = np.sqrt(2 * P0**2 * 10 ** (lv / 10) / len(lines))
        # A sine of amplitude amp on bin k: rfft coefficient amp n / 2 (its phase random).
        spectrum[lines] = amp * n / 2 * np.exp(1j * rng.uniform(0, 2 * np.pi, len(lines)))
        a_power += np.sum(amp**2 / 2 * 10 ** (a_weighting_db(lines / 10.0) / 10))
    p = np.fft.irfft(spectrum, n)
    r = iso3095.passby_levels(p, FS)
    assert np.all(np.abs(r.band_levels_db - want - 0.2) <= 0.4), r.band_levels_db - want
    assert r.lpaeq_tp_db == pytest.approx(10 * np.log10(a_power / P0**2), abs=0.05)


def _line_source(t: np.ndarray, length_m: float, speed_mps: float, distance_m: float, k: float) -> np.ndarray:
    """p^2(t) [Pa^2] of an incoherent line source of uniform strength k [Pa^2 m] per metre, its
    front at the microphone's plane at t = 0: k/d [atan(x_f/d) - atan(x_r/d)]."""
    front = speed_mps * t
    return k / distance_m * (np.arctan(front / distance_m) - np.arctan((front - length_m) / distance_m))


def _exposure(t1: float, t2: float, length_m: float, speed_mps: float, distance_m: float, k: float) -> float:
    """int_{t1}^{t2} p^2 dt [Pa^2 s] in closed form: F(u) = u atan(u) - ln(1 + u^2)/2."""
    def f(u):
        return u * np.arctan(u) - 0.5 * np.log1p(u * u)
    d, v = distance_m, speed_mps
    return k / v * (f(v * t2 / d) - f(v * t1 / d) - f((v * t2 - length_m) / d) + f((v * t1 - length_m) / d))


def test_a_moving_line_source_of_known_strength_gives_its_closed_form_levels():
    """A 60 m train at 80 km/h passing 7.5 m from the microphone, an incoherent line of uniform
    strength carried on a 1 kHz tone (A = 0 dB): LpAeq,Tp, TEL and SEL against the exposure in closed
    form (int atan = u atan u - ln(1 + u^2)/2) over the pass and over the 20 s record, and LpAFmax
    against the exponential average of the envelope maximised numerically (scipy quad and a scalar
    optimiser: a method independent of the processor's recursive filter): to 0.02 dB. Tp = 2.70 s."""
    length, v, d, k = 60.0, 80 / 3.6, 7.5, 0.05
    t = np.arange(-8.0 * FS, 12.0 * FS) / FS
    p = np.sqrt(2 * _line_source(t, length, v, d, k)) * np.sin(2 * np.pi * 1000.0 * t)
    tp = length / v
    r = iso3095.passby_levels(p, FS, start_s=8.0, end_s=8.0 + tp)
    assert r.tp_s == pytest.approx(tp, abs=1 / FS) and round(tp, 2) == 2.70
    whole = _exposure(t[0], t[-1] + 1 / FS, length, v, d, k)
    assert r.lpaeq_tp_db == pytest.approx(10 * np.log10(_exposure(0, tp, length, v, d, k) / tp / P0**2), abs=0.02)
    assert r.tel_db == pytest.approx(10 * np.log10(whole / tp / P0**2), abs=0.02)
    assert r.sel_db == pytest.approx(10 * np.log10(whole / P0**2), abs=0.02)

    def f_level(t_end: float) -> float:
        value, _ = integrate.quad(lambda s: _line_source(np.array(s), length, v, d, k) * np.exp(-(t_end - s) / 0.125)
                                  / 0.125, t_end - 3.0, t_end, limit=200)
        return -value
    best = optimize.minimize_scalar(f_level, bounds=(0.0, tp + 1.0), method="bounded", options={"xatol": 1e-5})
    assert r.lpafmax_db == pytest.approx(10 * np.log10(-best.fun / P0**2), abs=0.02)


def test_a_window_outside_the_record_is_refused():
    with pytest.raises(ValueError, match="not inside the record"):
        iso3095.passby_levels(_tone(80.0, 1000.0, 1.0), FS, start_s=0.5, end_s=2.0)
    with pytest.raises(ValueError, match="finite"):
        iso3095.passby_levels(np.array([0.0, np.nan]), FS)
