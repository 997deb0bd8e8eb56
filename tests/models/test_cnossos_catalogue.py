"""A user's own CNOSSOS-EU tables (models.cnossos_catalogue.with_catalogue): added in the package's format, read
the way the package's tables are, and every fault refused with one line that names it."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from rail_monitor.models import cnossos as cn
from rail_monitor.models import cnossos_catalogue as cc
from rail_monitor.models import cnossos_roughness as crough
from rail_monitor.models import cnossos_tables as ct
from rail_monitor.models import cnossos_transfer as xfer

T = ct.tables()


def frequency_table(columns: dict[str, np.ndarray]) -> str:
    rows = ["# my tables", "frequency_hz," + ",".join(columns)]
    rows += [",".join([f"{f:g}", *(repr(float(v[i])) for v in columns.values())]) for i, f in enumerate(T.band_hz)]
    return "\n".join(rows) + "\n"


def wavelength_table(name: str, values: np.ndarray, grid_mm: np.ndarray) -> str:
    # written from the longest wavelength down, as the package's files are
    return f"wavelength_mm,{name}\n" + "".join(f"{w:g},{float(v)!r}\n" for w, v in zip(grid_mm[::-1], values[::-1],
                                                                              strict=True))


RNG = np.random.default_rng(11)
TRACK = 80.0 + 30.0 * RNG.random(24)
WHEEL = 85.0 + 30.0 * RNG.random(24)
LOCO_A, LOCO_B = 90.0 + 5.0 * RNG.random(24), 92.0 + 5.0 * RNG.random(24)
FILTER = -np.linspace(0.0, 30.0, len(T.wavelength_m))[::-1]


def catalogue() -> str:
    return frequency_table({"track_slab": TRACK, "vehicle_wheel_760mm": WHEEL, "traction_shunter_constant_A": LOCO_A,
                            "traction_shunter_constant_B": LOCO_B}) \
        + wavelength_table("contact_filter_80kN_760mm", FILTER, T.wavelength_m * 1e3)


def test_the_catalogues_tables_are_read_as_the_packages_are():
    t = cc.with_catalogue(T, catalogue())
    name, track = xfer.track_transfer("monoblock", 3.5e8, t)      # the edition's own still there
    np.testing.assert_array_equal(track, T.by_frequency[name])
    np.testing.assert_array_equal(t.by_frequency["track_slab"], TRACK)       # the values exactly as written
    assert xfer.vehicle_transfer(0.77, t) == (0.76, pytest.approx(WHEEL))     # nearest diameter, now 760 mm
    assert xfer.vehicle_transfer(0.92, t)[0] == 0.92
    key, a3 = crough.contact_filter(80e3, 0.76, t)
    assert key == (80e3, 0.76)
    np.testing.assert_array_equal(a3, FILTER)                                # put on the ascending grid
    np.testing.assert_array_equal(cn.traction_sound_power("shunter", "B", "constant", t), LOCO_B)
    np.testing.assert_array_equal(cn.traction_sound_power("shunter", "A", "idling", t), LOCO_A)  # idling: constant
    assert "shunter" in t.traction_types and cc.with_catalogue(T, "  \n") is T
    assert "track_slab" not in T.by_frequency                                # the edition's tables untouched


GRID = ",".join(f"{f:g}" for f in T.band_hz)


@pytest.mark.parametrize(("text", "why"), [
    ("frequency,track_x\n50,1\n", "first column must be one of"),
    ("frequency_hz\n" + "\n".join(f"{f:g}" for f in T.band_hz), "every row needs"),
    ("frequency_hz,track_x\n50,1\n63\n", "every row needs"),
    (frequency_table({"track_x": TRACK})[:-40], "grid's 24 values"),
    (frequency_table({"track_x": TRACK}).replace("\n80,", "\n81,"), "grid's 24 values"),
    (frequency_table({"track_x": TRACK}).replace(repr(float(TRACK[3])), "loud"), "not a number"),
    (frequency_table({"track_x": TRACK}).replace(repr(float(TRACK[3])), "nan"), "finite, within"),
    (frequency_table({"track_x": TRACK}).replace(repr(float(TRACK[3])), "1e300"), "finite, within"),
    (frequency_table({"track x": TRACK}), "is none of"),
    (frequency_table({"rail_roughness_mine": TRACK}), "is none of"),
    (frequency_table({"track_monoblock_soft_pad": TRACK}), "already a table of edition 2021"),
    (frequency_table({"track_x": TRACK, "track_y": TRACK}) + frequency_table({"track_x": TRACK}), "already a table"),
    (frequency_table({"traction_shunter_constant_A": LOCO_A}), "needs its constant-speed spectrum at A and B"),
    (wavelength_table("contact_filter_80kN_760mm", FILTER[1:], T.wavelength_m[1:] * 1e3), "grid's 35 values"),
    (wavelength_table("vehicle_wheel_760mm", FILTER, T.wavelength_m * 1e3), "is none of"),
    ("frequency_hz," + ",".join(f"track_{i}" for i in range(300)) + "\n", "every row needs"),
    ("#" * (cc.CATALOGUE_MAX_CHARS + 1), "more than"),
    ("frequency_hz,track_x\n\r0", "not CSV text"),
    ("frequency_hz,track_x\n50,\x00\n", "not CSV text|every row|not a number"),
])
def test_a_faulty_catalogue_is_refused_with_one_line(text, why):
    with pytest.raises(ValueError, match=why) as err:
        cc.with_catalogue(T, text)
    assert "\n" not in str(err.value)


def test_a_2015_catalogue_is_on_the_2015_grid():
    t15 = ct.tables("2015")
    text = wavelength_table("contact_filter_80kN_760mm", FILTER[3:], t15.wavelength_m * 1e3)
    assert (80e3, 0.76) in cc.with_catalogue(t15, text).contact_filters
    with pytest.raises(ValueError, match="edition 2015 grid's 32 values"):
        cc.with_catalogue(t15, wavelength_table("contact_filter_80kN_760mm", FILTER, T.wavelength_m * 1e3))


@settings(max_examples=300, deadline=None)
@given(st.text(max_size=300), st.sampled_from(["", "frequency_hz,track_x\n", "wavelength_mm,contact_filter_1kN_1mm\n",
                                                "frequency_hz,track_x\n" + "".join(f"{f:g},1\n" for f in T.band_hz)]))
def test_any_text_is_a_catalogue_or_one_line_refusal(text, head):
    # Hostile input: whatever the text, a ValueError of one line or tables; never another exception.
    try:
        cc.with_catalogue(T, head + text)
    except ValueError as exc:
        assert "\n" not in str(exc)
