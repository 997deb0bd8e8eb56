"""The mechanics rolling-noise model (models.wheel_rail_noise) and the track decay rate."""

import numpy as np
import pytest

from rail_monitor.models import track
from rail_monitor.models import wheel_rail_noise as wrn
from rail_monitor.models.levels import a_weighted_total, level, power

BAND = np.arange(-13, 11)   # 50 Hz - 10 kHz


def test_decay_rate_matches_the_far_field_of_the_transfer_receptance():
    """Independent method: 20 lg |alpha(10 m) / alpha(20 m)| / 10 m, where the propagating wave alone
    remains, equals 8.686 Im(k) of the slower-decaying pole (0.5 %)."""
    trk = track.Track()
    f = np.array([800.0, 1250.0, 2000.0, 4000.0])
    a10 = track.continuous_receptance(f, trk, distance=10.0)
    a20 = track.continuous_receptance(f, trk, distance=20.0)
    np.testing.assert_allclose(20 * np.log10(np.abs(a10 / a20)) / 10.0, track.decay_rate(f, trk), rtol=5e-3)


def test_rail_follows_the_roughness_when_the_wheel_and_contact_are_stiff():
    """Limit case: alpha_W, alpha_C -> 0 gives |v_R| = w r (the rail takes the whole roughness);
    a rail much stiffer than the wheel gives the wheel the whole roughness."""
    f = np.array([100.0, 1000.0])
    w = 2 * np.pi * f
    vr2, vw2 = wrn.contact_velocity_ratios(f, 1e-9 + 0j, 1e-15 + 0j, 1e15)
    np.testing.assert_allclose(vr2, w**2, rtol=1e-5)
    vr2, vw2 = wrn.contact_velocity_ratios(f, 1e-15 + 0j, 1e-9 + 0j, 1e15)
    np.testing.assert_allclose(vw2, w**2, rtol=1e-5)


def test_contact_filter_band_average_tends_to_one_for_long_wavelengths():
    f2 = wrn.contact_filter_power(np.array([40.0]), BAND, 0.006)
    assert f2[0, 0] == pytest.approx(1.0, abs=1e-3)        # 50 Hz at 40 m/s: 0.8 m >> 6 mm, 1 - (ka)^2/4
    assert np.all(np.diff(f2[0][:15]) < 0)                 # falls with frequency up to the first zero
    assert f2[0, -1] < 1e-2                                # 10 kHz: 4 mm, under the patch


def _rail_dba(trk: track.Track) -> float:
    lh = wrn.axle_transfer(BAND, trk, 600.0, 1.2e9, 0.84)
    return float(a_weighted_total(lh["rail"], BAND))


def test_a_softer_pad_lowers_the_decay_rate_and_raises_rail_noise():
    """Thompson (2009), section 5.6 and 6: soft pads decouple the rail, lowering the decay rate above
    the pad resonance, so the rail radiates over a longer length."""
    stiff, soft = track.Track(pad_stiffness_npm=1.0e9), track.Track(pad_stiffness_npm=120e6)
    f = np.array([630.0, 800.0, 1000.0, 1250.0, 1600.0, 2000.0])
    assert np.all(track.decay_rate(f, soft) < track.decay_rate(f, stiff))
    assert _rail_dba(soft) > _rail_dba(stiff) + 3.0


def test_axle_transfer_components_order_as_in_twins():
    """For a standard ballasted track and a rigid wheel: the sleepers dominate below about 400 Hz and
    the rail from 630 Hz up; the rigid wheel (no modes) stays below the rail in every band above 400 Hz."""
    lh = wrn.axle_transfer(BAND, track.Track(), 600.0, 1.2e9, 0.84)
    low = BAND <= -4          # up to 400 Hz
    high = BAND >= -2         # 630 Hz up
    assert np.all(lh["sleeper"][low & (BAND >= -9)] > lh["rail"][low & (BAND >= -9)])
    assert np.all(lh["rail"][high] > lh["sleeper"][high])
    assert np.all(lh["rail"][BAND >= -4] > lh["wheel"][BAND >= -4])
    # Energy bookkeeping: the total is the energy sum of the components.
    total = level(sum(power(v) for v in lh.values()))
    assert np.all(total >= lh["rail"])
