"""CNOSSOS-EU railway source model (models.cnossos) against the Directive's tables.

Source: Commission Directive (EU) 2015/996, Annex II 2.3 and Appendix G, as amended by
Commission Delegated Directive (EU) 2021/1226 (tables transcribed into
the package's data files).
"""

import numpy as np
import pytest

from rail_monitor.models import cnossos as cn

T = cn.tables()


def _col(name):
    return T.by_wavelength[name]


def test_tables_have_the_documented_shapes():
    assert len(T.wavelength_m) == 35 and T.wavelength_m[0] == pytest.approx(0.8e-3) and T.wavelength_m[-1] == 2.0
    assert len(T.band_hz) == 24 and T.band_hz[0] == 50 and T.band_hz[-1] == 10000
    assert set(T.contact_filters) == {(50e3, 0.36), (50e3, 0.68), (25e3, 0.92), (50e3, 0.92), (100e3, 0.92)}
    assert set(T.vehicle_transfers) == {0.92, 0.84, 0.68, 1.2}


def test_unrounded_wheel_roughness_rounds_to_printed_table_g1a():
    """The unrounded values behind G-1a agree with the printed table to its rounding (0.05 dB), on the
    printed grid (labels 120, 12, 3.2, 1.2 mm are the 125, 12.5, 3.15, 1.25 mm bands)."""
    labels, printed = cn.printed_wheel_roughness()
    label_to_band = {0.12: 0.125, 0.012: 0.0125, 0.0032: 0.00315, 0.0012: 0.00125}
    wl = np.array([label_to_band.get(round(x, 6), x) for x in labels])
    idx = [int(np.argmin(np.abs(np.log(T.wavelength_m / w)))) for w in wl]
    np.testing.assert_allclose(T.wavelength_m[idx], wl, rtol=1e-9)
    for brake, col in (("cast_iron", "cast_iron_tread_brake"), ("composite", "composite_or_sinter_tread_brake"),
                       ("disc", "non_tread_disc_brake")):
        np.testing.assert_allclose(cn.wheel_roughness(brake)[idx], printed[col], atol=0.051)


def test_hand_computed_band_disc_brake_class_e_monoblock_medium_pad():
    """One documented case by hand: 4-axle disc-braked vehicle, 920 mm wheels at 50 kN, rail class E,
    monoblock sleepers on a medium pad, 20 m/s (72 km/h), the 1 kHz band: lambda = 20 mm.

    Table G-1b (E, 20 mm): -6.2; G-1a (disc, 20 mm): -8.58; G-2 (50 kN / 920 mm, 20 mm): -8.0;
    L_R,TOT = 10 lg(10^-0.62 + 10^-0.858) - 8.0 = -12.219 dB; G-3a (monoblock medium, 1 kHz): 104.4;
    L_W,0,TR = -12.219 + 104.4 + 10 lg 4 = 98.202 dB. G-3b (920 mm, 1 kHz): 94.9 -> L_W,0,VEH = 88.702 dB.
    """
    _, a3 = cn.contact_filter(50e3, 0.92)
    lr = cn.total_roughness(cn.rail_roughness("E"), cn.wheel_roughness("disc"), a3)
    lrf = cn.at_band_frequencies(lr, 20.0)
    _, track = cn.track_transfer("monoblock", 400e6)
    _, veh = cn.vehicle_transfer(0.92)
    power = cn.rolling_sound_power(lrf, 4, track, veh)
    i = list(T.band_hz).index(1000)
    hand_lr = 10 * np.log10(10 ** -0.62 + 10 ** -0.858) - 8.0
    assert lrf[i] == pytest.approx(hand_lr, abs=1e-9)
    assert power.track[i] == pytest.approx(hand_lr + 104.4 + 10 * np.log10(4), abs=1e-9)
    assert power.vehicle[i] == pytest.approx(hand_lr + 94.9 + 10 * np.log10(4), abs=1e-9)
    assert power.superstructure[i] == pytest.approx(hand_lr + 10 * np.log10(4), abs=1e-9)
    assert power.track[i] == pytest.approx(98.202, abs=5e-4)


@pytest.mark.parametrize("rule", cn.INTERPOLATION_RULES)
def test_both_rules_reproduce_table_values_where_bands_fall_on_table_wavelengths(rule):
    """At 20 m/s, v / f_i is a table wavelength for most nominal bands (e.g. 1 kHz -> 20 mm)."""
    level = _col("rail_roughness_M_average_network")
    out = cn.at_band_frequencies(level, 20.0, rule=rule)
    lam = 20.0 / T.band_hz
    on_grid = np.isclose(lam[:, None], T.wavelength_m[None, :], rtol=1e-12).any(axis=1)
    assert on_grid.sum() >= 15
    expected = np.interp(lam[on_grid], T.wavelength_m, level)
    np.testing.assert_allclose(out[on_grid], expected, atol=1e-9)


def test_rules_differ_between_table_wavelengths_and_hold_the_ends():
    level = _col("rail_roughness_M_average_network")
    # 31.5 m/s at 1 kHz: 31.5 mm, a node; 33 m/s: between 31.5 and 40 mm, where the rules part.
    ref = cn.at_band_frequencies(level, 33.0, rule="reference")
    energy = cn.at_band_frequencies(level, 33.0, rule="energy_log_frequency")
    assert np.max(np.abs(ref - energy)) > 0.05
    lo, hi = (0.0315, -0.8), (0.040, -0.3)
    i = list(T.band_hz).index(1000)
    w = (0.033 - lo[0]) / (hi[0] - lo[0])
    assert ref[i] == pytest.approx(lo[1] + w * (hi[1] - lo[1]), abs=1e-9)
    we = np.log(0.033 / lo[0]) / np.log(hi[0] / lo[0])
    assert energy[i] == pytest.approx(10 * np.log10((1 - we) * 10 ** (lo[1] / 10) + we * 10 ** (hi[1] / 10)),
                                      abs=1e-9)
    # Beyond the grid (120 m/s at 50 Hz: 2.4 m) both hold the 2000 mm value.
    for rule in cn.INTERPOLATION_RULES:
        assert cn.at_band_frequencies(level, 120.0, rule=rule)[0] == pytest.approx(level[-1], abs=1e-9)


def test_table_choices_follow_the_directive():
    assert [cn.pad_class(k) for k in (100e6, 200e6, 250e6, 500e6, 800e6, 900e6, 2e9)] == \
        ["soft", "soft", "medium", "medium", "medium", "hard", "hard"]
    assert cn.track_transfer("biblock", 900e6)[0] == "track_biblock_hard_pad"
    assert cn.track_transfer("wooden", 900e6)[0] == "track_wooden_sleepers"
    assert cn.contact_filter(65e3, 0.84)[0] == (50e3, 0.92)
    assert cn.contact_filter(100e3, 0.92)[0] == (100e3, 0.92)
    assert cn.contact_filter(40e3, 0.70)[0] == (50e3, 0.68)
    assert cn.vehicle_transfer(0.86)[0] == 0.84
    assert [cn.curve_squeal_db(r) for r in (250.0, 300.0, 400.0, 500.0, 800.0)] == [8, 8, 5, 5, 0]
    assert cn.bridge_transfer("none") is None
    with pytest.raises(ValueError):
        cn.track_transfer("slab", 1e8)


def test_impact_roughness_scales_with_joint_density():
    one = cn.impact_roughness(0.01)
    np.testing.assert_allclose(one, _col("impact_single_joint_per_100m"))
    np.testing.assert_allclose(cn.impact_roughness(0.1) - one, 10.0)
    # Adding the joints in energy never lowers L_R,TOT, and dominates where they are 10 dB above it.
    base = cn.total_roughness(cn.rail_roughness("E"), cn.wheel_roughness("disc"), 0.0)
    with_joints = cn.total_roughness(cn.rail_roughness("E"), cn.wheel_roughness("disc"), 0.0, one)
    assert np.all(with_joints >= base)


def test_directivity():
    np.testing.assert_allclose(cn.horizontal_directivity_db([np.pi / 2, 0.0]), [0.0, -20.0], atol=1e-12)
    # Vertical (source A): zero at and below the source; its sign changes at cos psi = 3/4.
    assert cn.vertical_directivity_a_db(-0.2, 1000.0) == 0.0
    assert cn.vertical_directivity_a_db(np.arccos(0.75), 1000.0) == pytest.approx(0.0, abs=1e-12)
    assert cn.vertical_directivity_a_db(0.3, 1000.0) > 0 > cn.vertical_directivity_a_db(1.2, 1000.0)
    # At psi = 90 deg: -40/3 lg((f + 600) / 200); 1 kHz: -12.04 dB.
    assert cn.vertical_directivity_a_db(np.pi / 2, 1000.0) == pytest.approx(-40 / 3 * np.log10(8.0), abs=1e-9)


def test_line_sound_power_of_a_flow():
    """eq. 2.3.1: 100 vehicles per hour at 100 km/h are one vehicle per km: -30 dB re one vehicle per metre."""
    assert cn.line_sound_power_db(100.0, 100.0, 100.0) == pytest.approx(70.0)


def test_the_reference_rule_maps_each_table_before_combining():
    # The European reference module maps each wavelength table to the band frequencies on its
    # own (dB linear in wavelength, ends held) and combines per band. Independent method: np.interp
    # of each table at lambda = v / f_i, then eq. 2.3.6 and 2.3.10 per band.
    _, a3 = cn.contact_filter(50e3, 0.92)
    rail, wheel, joints = cn.rail_roughness("E"), cn.wheel_roughness("cast_iron"), cn.impact_roughness(0.01)
    for v in (10.0, 20.0, 33.3):
        lam = v / T.band_hz
        at = [np.interp(lam, T.wavelength_m, table) for table in (rail, wheel, a3, joints)]
        filtered = 10 * np.log10(10 ** (at[0] / 10) + 10 ** (at[1] / 10)) + at[2]
        want = 10 * np.log10(10 ** (filtered / 10) + 10 ** (at[3] / 10))
        got = cn.band_roughness(rail, wheel, a3, v, impact_db=joints)
        np.testing.assert_allclose(got, want, rtol=0, atol=1e-9)
    # Combining on the wavelength grid first is not the same where the tables curve between
    # grid points: a difference of order 0.1 dB in some band.
    first = cn.at_band_frequencies(cn.total_roughness(rail, wheel, a3, joints), 20.0)
    assert 0.01 < np.max(np.abs(first - cn.band_roughness(rail, wheel, a3, 20.0, impact_db=joints))) < 0.5
