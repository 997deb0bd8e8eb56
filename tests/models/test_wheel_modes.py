"""Wheel modes by axisymmetric finite elements (models.wheel_modes) and the modal wheel in the
mechanics rolling-noise model (models.wheel_rail_noise)."""

import numpy as np
import pytest

from rail_monitor.models import track
from rail_monitor.models import wheel_modes as wm
from rail_monitor.models import wheel_rail_noise as wrn
from rail_monitor.models.levels import level, power

STEEL = (2.1e11, 0.3, 7850.0)
BAND = np.arange(-13, 11)   # 50 Hz - 10 kHz


@pytest.mark.parametrize("n", [2, 3, 4])
def test_a_thin_free_ring_has_the_classical_ring_frequencies(n):
    """Independent method: a free circular ring of square section (R = 0.5 m, h = 20 mm, h / R = 0.04).
    In-plane flexure: w^2 = EI n^2 (n^2 - 1)^2 / (rho A R^4 (n^2 + 1)) (Hoppe 1871; Blevins,
    Formulas for Natural Frequency and Mode Shape, 1979, table 9-1); out-of-plane flexure with
    torsion: w^2 = EI n^2 (n^2 - 1)^2 / (rho A R^4 (n^2 + EI / GJ)), J = 0.1406 h^4 (same table).
    Thin-ring theory neglects shear and rotary inertia, of order (h / R)^2: tolerance 1 %."""
    e, nu, rho = STEEL
    r, h = 0.5, 0.02
    got = wm.harmonic_modes(((r - h / 2, r + h / 2, 0.0, h),), STEEL, n, 5000.0, (r + h / 2, h / 2), None, 0.005)
    flexural = np.sort(got.frequency_hz)[:2]          # the two lowest: out-of-plane, then in-plane
    i, a = h**4 / 12, h * h
    base = e * i / (rho * a * r**4) * n**2 * (n**2 - 1) ** 2
    in_plane = np.sqrt(base / (n**2 + 1)) / (2 * np.pi)
    out_of_plane = np.sqrt(base / (n**2 + e * i / (e / (2 * (1 + nu)) * 0.1406 * h**4))) / (2 * np.pi)
    np.testing.assert_allclose(flexural, [out_of_plane, in_plane], rtol=0.01)


def test_unit_generalised_mass_makes_a_rigid_translation_weigh_the_ring():
    """Conservation: a free body's n = 0 rigid axial translation, normalised to unit generalised
    mass, has displacement 1 / sqrt(M) everywhere, M = rho 2 pi R A (exact for the FE mass)."""
    r, h = 0.5, 0.02
    got = wm.harmonic_modes(((r - h / 2, r + h / 2, 0.0, h),), STEEL, 0, 1.0, (r, h / 2), None, 0.005)
    assert got.frequency_hz[0] < 1.0
    mass = STEEL[2] * 2 * np.pi * r * h * h
    # The axial translation moves every face normal to z by 1 / sqrt(M): both faces' integral is 2 A_face / M.
    assert got.axial_surface[0] == pytest.approx(2 * 2 * np.pi * r * h / mass, rel=1e-6)


@pytest.fixture(scope="module")
def wheel920():
    return wm.wheel_modes(wm.WheelSection())


def test_the_920_mm_wheel_has_the_published_axial_mode_ladder(wheel920):
    """Thompson (2009), section 5.2 (and Thompson, J. Sound Vib. 161 (1993) 401-419, for a 920 mm
    freight wheel): the axial modes with no nodal circle climb from about 360 Hz (n = 2) by roughly
    0.8-1 kHz per nodal diameter (about 1.0, 1.8, 2.7 kHz for n = 3, 4, 5). The idealised section
    gives 369, 1009, 1842, 2782 Hz: tolerance 10 %."""
    lowest = [wheel920.frequency_hz[wheel920.nodal_diameters == n].min() for n in (2, 3, 4, 5)]
    np.testing.assert_allclose(lowest, [360.0, 1000.0, 1800.0, 2700.0], rtol=0.10)


def _freight_transfer(modes, damping=1.0e-4):
    return wrn.axle_transfer(BAND, track.Track(), 600.0, 1.2e9, 0.92, points=400, modes=modes,
                             wheel_damping_ratio=damping)


def test_without_modes_the_wheel_is_the_rigid_mass_and_modes_only_add(wheel920):
    rigid = _freight_transfer(None)
    modal = _freight_transfer(wheel920)
    # The rail and sleepers barely change (the wheel's receptance enters the contact force only).
    np.testing.assert_allclose(modal["rail"][BAND >= -2], rigid["rail"][BAND >= -2], atol=3.0)
    assert np.all(modal["wheel"][BAND >= 3] > rigid["wheel"][BAND >= 3] + 20.0)   # 2 kHz up


def test_a_wheel_damper_lowers_the_wheel_above_2_khz(wheel920):
    """Thompson (2009), section 5.7: wheel dampers act on the lightly damped modes that make the
    wheel the main source at high frequency. Raising their damping ratio from 1e-4 to 1e-2 lowers
    the wheel's power above 2 kHz by more than 5 dB and leaves the rail, where it dominates
    (500-1600 Hz), within 1 dB per band."""
    high = BAND >= 3
    plain, damped = _freight_transfer(wheel920), _freight_transfer(wheel920, 1.0e-2)
    drop = level(np.sum(power(plain["wheel"][high]))) - level(np.sum(power(damped["wheel"][high])))
    assert drop > 5.0, drop
    mid = (BAND >= -3) & (BAND <= 2)
    np.testing.assert_allclose(damped["rail"][mid], plain["rail"][mid], atol=1.0)
