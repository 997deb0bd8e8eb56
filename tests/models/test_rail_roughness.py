"""Rail roughness from a trolley trace (rail_monitor.models.rail_roughness) on a synthetic rail of
known sinusoids plus spikes (issue 54)."""

from __future__ import annotations

import numpy as np
import pytest

from rail_monitor.models import rail_roughness as rr

DX = 0.001


def _rail(length_m: float = 20.0) -> tuple[np.ndarray, np.ndarray]:
    """10 um at 50.1 mm and 5 um at 125.9 mm (two band centres 10^(n/10) m)."""
    x = np.arange(0.0, length_m, DX)
    return x, 10e-6 * np.sin(2 * np.pi * x / 10 ** -1.3) + 5e-6 * np.sin(2 * np.pi * x / 10 ** -0.9 + 1.0)


def test_known_sinusoids_read_their_band_levels_through_spikes():
    """Each sinusoid's band reads 20 lg(A / sqrt(2) / 1 um) (16.99 and 10.97 dB) to 0.1 dB, with 40
    spikes of 100-300 um added: all 40 found (each replaced with a neighbour either side), and every
    other band at least 25 dB below the weaker sinusoid's."""
    _, z = _rail()
    rng = np.random.default_rng(15610)
    spiky = z.copy()
    spiky[rng.choice(len(z), 40, replace=False)] += rng.uniform(100e-6, 300e-6, 40)
    s = rr.roughness_spectrum(spiky, DX)
    level = dict(zip(np.round(np.log10(s.wavelength_m) * 10).astype(int), s.level_db, strict=True))
    assert level[-13] == pytest.approx(20 * np.log10(10 / np.sqrt(2)), abs=0.1)
    assert level[-9] == pytest.approx(20 * np.log10(5 / np.sqrt(2)), abs=0.1)
    others = [v for k, v in level.items() if k not in (-13, -9)]
    assert max(others) < level[-9] - 25.0
    assert s.spikes == 120


def test_without_the_spike_removal_the_spikes_would_swamp_the_short_bands():
    """The same spiky trace through the wheel and the spectrum alone: the 10 mm band rises above
    the clean trace's by more than 20 dB (what the removal takes away)."""
    _, z = _rail()
    rng = np.random.default_rng(15610)
    spiky = z.copy()
    spiky[rng.choice(len(z), 40, replace=False)] += rng.uniform(100e-6, 300e-6, 40)
    band = np.array([0.01])
    raw = rr.band_mean_squares(rr.wheel_trace(spiky, DX), DX, band)
    clean = rr.band_mean_squares(rr.wheel_trace(z, DX), DX, band)
    assert 10 * np.log10(raw / clean)[0] > 20.0


def test_the_wheel_bridges_a_narrow_dip_and_follows_a_gentle_rail():
    """A dip 3 mm wide and 50 um deep: the wheel (R = 0.46 m) stays within 3 um of the rail around it
    (its parabola drops (1.5 mm)^2 / 2R = 2.4 um over the half-width). A 10 um sinusoid of 100 mm
    (curvature 0.039 /m, under 1/R): moved by at most R z'^2 / 2 = 0.09 um, the slope's own term."""
    x = np.arange(0.0, 1.0, DX)
    z = np.zeros(len(x))
    z[(x > 0.5) & (x < 0.503)] = -50e-6
    assert rr.wheel_trace(z, DX).min() > -3e-6
    gentle = 10e-6 * np.sin(2 * np.pi * x / 0.1)
    slope = 10e-6 * 2 * np.pi / 0.1
    assert np.max(np.abs(rr.wheel_trace(gentle, DX) - gentle)) <= 0.46 * slope**2 / 2 * 1.05


def test_a_trace_too_short_is_refused():
    with pytest.raises(ValueError, match="at least 16"):
        rr.roughness_spectrum(np.zeros(10), DX)
