"""The growth tables per contact regime (rail_monitor.corrugation.growth) and a pass in each regime
through the estimator."""

from __future__ import annotations

import numpy as np
import pytest

from corrugation.conftest import _estimator, _passes
from rail_monitor.core.contact import REGIME_FULL_SLIDING, REGIME_PARTIAL_SLIP, contact_state
from rail_monitor.corrugation.config import corrugation_config
from rail_monitor.models import corrugation as cg
from rail_monitor.models import corrugation_bands
from rail_monitor.models import track as tr
from rail_monitor.models import wheel_rail_noise as wrn
from rail_monitor.models.contact_filter import hertzian_line_filter


def test_full_sliding_reverses_k_b_and_moves_the_growing_wavelength(site_, tables):
    # Wear proportional to frictional power: K_b = -beta k_c w / N with beta = -1 in partial slip
    # and +2/3 in full sliding (docs/models.md, Sliding), so K_b(sliding) = -2/3 K_b(partial slip)
    # at equal mean wear. A harmonic that grows in partial slip (Re F^2 H > 0) then decays.
    assert cg.sliding_wear_sensitivity(1e-5) == pytest.approx(-2e-5 / 3)
    assert cg.sliding_wear_sensitivity(1e-5, 3.0) == pytest.approx(-2e-5)
    tables.set_k_b(corrugation_config({}).k_b)
    j = round(14.0 / 0.1) - 1                                  # an EMU at 14 m/s on dry rail
    assert tables.speeds[j] == pytest.approx(14.0)
    sub = corrugation_bands.band_sub_wavelengths(tables.bands, 5)
    slip, slide = tables.table[0, 0, REGIME_PARTIAL_SLIP, :, j, :], tables.table[0, 0, REGIME_FULL_SLIDING, :, j, :]
    peak_slip, peak_slide = np.unravel_index(slip.argmax(), slip.shape), np.unravel_index(slide.argmax(), slide.shape)
    assert slide[peak_slip] < 0 < slip[peak_slip]
    # Independent method: the table is ln|1 + K_b F^2 H| of the stored kernel with the sliding K_b,
    # averaged over the bay positions.
    k_b = cg.sliding_wear_sensitivity(tables.k_b[0])
    direct = np.log(np.abs(1.0 + k_b * tables.filtered_kernel[:, 0, :, j, :])).mean(axis=0)
    assert slide == pytest.approx(direct, rel=1e-12)
    assert sub[peak_slide] > 1.3 * sub[peak_slip]                   # 76 mm against 52 mm
    assert slide.max() > 0


def test_a_pass_grows_the_state_by_the_table_of_its_regime(site_, tables):
    # Two EMU passes at a grid speed, one at 0 mrad (partial slip), one at 20 mrad (beyond the
    # dry saturation creepage, about 8 mrad): each adds its regime's growth times its axles.
    j = round(14.0 / 0.1) - 1
    for aoa, regime in ((0.0, REGIME_PARTIAL_SLIP), (0.020, REGIME_FULL_SLIDING)):
        est = _estimator(site_, tables)
        passes = _passes(site_, [14.0])
        passes.angle_of_attack_rad = np.array([aoa])
        assert contact_state(site_, passes).regime[0] == regime
        before = est.log_components.copy()
        est.advance(passes)
        assert est.kept.regime[0] == regime
        np.testing.assert_allclose(est.log_components - before,
                                   passes.axle_count[0] * tables.table[0, 0, regime, :, j, :], rtol=0, atol=1e-14)


def test_the_growth_is_averaged_over_the_bay_positions_not_the_receptance(site_, tables):
    # Independent method: for an EMU at 22 m/s on dry rail in partial slip, ln|1 + K_b F^2 H(x)|
    # from the discrete-support receptance at eight positions over the whole bay (not the four of
    # the table, which rely on its symmetry), averaged over them. The table matches within 1 % of the
    # peak (its receptance is interpolated on a log-frequency grid).
    tables.set_k_b(corrugation_config({}).k_b)
    v, speed = site_.vehicle("emu"), 22.0
    j = round(speed / 0.1) - 1
    patch = site_.contact_patch(v.wheel_diameter_m / 2.0, v.wheel_load_n)
    sub = corrugation_bands.band_sub_wavelengths(tables.bands, 5)
    f = speed / sub.ravel()
    r = tr.discrete_receptance(f, site_.track, position=(np.arange(8) + 0.5) / 8)
    h = cg.growth_kernel(float(patch.stiffness), r + wrn.wheel_receptance(f, v.unsprung_mass_kg)[:, None])
    filt = hertzian_line_filter(sub.ravel(), float(patch.a))[:, None]
    direct = np.log(np.abs(1.0 + tables.k_b[0] * filt**2 * h)).mean(axis=1).reshape(sub.shape)
    table = tables.table[0, 0, REGIME_PARTIAL_SLIP, :, j, :]
    assert np.max(np.abs(table - direct)) <= 0.01 * direct.max()
    # Averaging the receptance first (its phase varies along the bay around the pinned-pinned
    # resonance) gives a 20 mm band growing about half as fast again: the order matters there.
    averaged = cg.growth_kernel(float(patch.stiffness), r.mean(axis=1) + wrn.wheel_receptance(f, v.unsprung_mass_kg))
    first = np.log(np.abs(1.0 + tables.k_b[0] * filt[:, 0] ** 2 * averaged)).reshape(sub.shape)
    band = int(np.argmin(np.abs(tables.bands - 0.02)))
    assert first[band].max() > 1.3 * direct[band].max()
    np.testing.assert_allclose(first[-8:], direct[-8:], rtol=1e-2)  # long waves: one phase over the bay
