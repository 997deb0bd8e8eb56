"""CNOSSOS-EU railway source model (models.cnossos) against the Directive's tables.

Source: Commission Directive (EU) 2015/996, Annex II 2.3 and Appendix G, as amended by
Commission Delegated Directive (EU) 2021/1226 (tables transcribed into
the package's data files).
"""

import numpy as np
import pytest

from rail_monitor.models import cnossos as cn
from rail_monitor.models import cnossos_bands as cb
from rail_monitor.models import cnossos_directivity as cdir
from rail_monitor.models import cnossos_roughness as crough
from rail_monitor.models import cnossos_tables as ct
from rail_monitor.models import cnossos_transfer as xfer

T = ct.tables()


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
    labels, printed = ct.printed_wheel_roughness()
    label_to_band = {0.12: 0.125, 0.012: 0.0125, 0.0032: 0.00315, 0.0012: 0.00125}
    wl = np.array([label_to_band.get(round(x, 6), x) for x in labels])
    idx = [int(np.argmin(np.abs(np.log(T.wavelength_m / w)))) for w in wl]
    np.testing.assert_allclose(T.wavelength_m[idx], wl, rtol=1e-9)
    for brake, col in (("cast_iron", "cast_iron_tread_brake"), ("composite", "composite_or_sinter_tread_brake"),
                       ("disc", "non_tread_disc_brake")):
        np.testing.assert_allclose(crough.wheel_roughness(brake)[idx], printed[col], atol=0.051)


def test_hand_computed_band_disc_brake_class_e_monoblock_medium_pad():
    """One documented case by hand: 4-axle disc-braked vehicle, 920 mm wheels at 50 kN, rail class E,
    monoblock sleepers on a medium pad, 20 m/s (72 km/h), the 1 kHz band: lambda = 20 mm.

    Table G-1b (E, 20 mm): -6.2; G-1a (disc, 20 mm): -8.58; G-2 (50 kN / 920 mm, 20 mm): -8.0;
    L_R,TOT = 10 lg(10^-0.62 + 10^-0.858) - 8.0 = -12.219 dB; G-3a (monoblock medium, 1 kHz): 104.4;
    L_W,0,TR = -12.219 + 104.4 + 10 lg 4 = 98.202 dB. G-3b (920 mm, 1 kHz): 94.9 -> L_W,0,VEH = 88.702 dB.
    """
    _, a3 = crough.contact_filter(50e3, 0.92)
    lr = crough.total_roughness(crough.rail_roughness("E"), crough.wheel_roughness("disc"), a3)
    lrf = cb.at_band_frequencies(lr, 20.0)
    _, track = xfer.track_transfer("monoblock", 400e6)
    _, veh = xfer.vehicle_transfer(0.92)
    power = cn.rolling_sound_power(lrf, 4, track, veh)
    i = list(T.band_hz).index(1000)
    hand_lr = 10 * np.log10(10 ** -0.62 + 10 ** -0.858) - 8.0
    assert lrf[i] == pytest.approx(hand_lr, abs=1e-9)
    assert power.track[i] == pytest.approx(hand_lr + 104.4 + 10 * np.log10(4), abs=1e-9)
    assert power.vehicle[i] == pytest.approx(hand_lr + 94.9 + 10 * np.log10(4), abs=1e-9)
    assert power.superstructure[i] == pytest.approx(hand_lr + 10 * np.log10(4), abs=1e-9)
    assert power.track[i] == pytest.approx(98.202, abs=5e-4)


def test_table_choices_follow_the_directive():
    assert [xfer.pad_class(k) for k in (100e6, 200e6, 250e6, 500e6, 800e6, 900e6, 2e9)] == \
        ["soft", "soft", "medium", "medium", "medium", "hard", "hard"]
    assert xfer.track_transfer("biblock", 900e6)[0] == "track_biblock_hard_pad"
    assert xfer.track_transfer("wooden", 900e6)[0] == "track_wooden_sleepers"
    assert crough.contact_filter(65e3, 0.84)[0] == (50e3, 0.92)
    assert crough.contact_filter(100e3, 0.92)[0] == (100e3, 0.92)
    assert crough.contact_filter(40e3, 0.70)[0] == (50e3, 0.68)
    assert xfer.vehicle_transfer(0.86)[0] == 0.84
    assert [cn.curve_squeal_db(r) for r in (250.0, 300.0, 400.0, 500.0, 800.0)] == [8, 8, 5, 5, 0]
    assert xfer.bridge_transfer("none") is None
    with pytest.raises(ValueError):
        xfer.track_transfer("slab", 1e8)


def test_impact_roughness_scales_with_joint_density():
    one = crough.impact_roughness(0.01)
    np.testing.assert_allclose(one, _col("impact_single_joint_per_100m"))
    np.testing.assert_allclose(crough.impact_roughness(0.1) - one, 10.0)
    # Adding the joints in energy never lowers L_R,TOT, and dominates where they are 10 dB above it.
    base = crough.total_roughness(crough.rail_roughness("E"), crough.wheel_roughness("disc"), 0.0)
    with_joints = crough.total_roughness(crough.rail_roughness("E"), crough.wheel_roughness("disc"), 0.0, one)
    assert np.all(with_joints >= base)


def test_directivity():
    np.testing.assert_allclose(cdir.horizontal_directivity_db([np.pi / 2, 0.0]), [0.0, -20.0], atol=1e-12)
    # Vertical (source A): zero at and below the source; its sign changes at cos psi = 3/4.
    assert cdir.vertical_directivity_a_db(-0.2, 1000.0) == 0.0
    assert cdir.vertical_directivity_a_db(np.arccos(0.75), 1000.0) == pytest.approx(0.0, abs=1e-12)
    assert cdir.vertical_directivity_a_db(0.3, 1000.0) > 0 > cdir.vertical_directivity_a_db(1.2, 1000.0)
    # At psi = 90 deg: -40/3 lg((f + 600) / 200); 1 kHz: -12.04 dB.
    assert cdir.vertical_directivity_a_db(np.pi / 2, 1000.0) == pytest.approx(-40 / 3 * np.log10(8.0), abs=1e-9)


def test_line_sound_power_of_a_flow():
    """eq. 2.3.1: 100 vehicles per hour at 100 km/h are one vehicle per km: -30 dB re one vehicle per metre."""
    assert cdir.line_sound_power_db(100.0, 100.0, 100.0) == pytest.approx(70.0)
