"""The site (rail_monitor.core.site): the rolling-stock table, strict sections, the contact patch."""

from __future__ import annotations

import pytest

from rail_monitor.core.errors import ConfigError
from rail_monitor.core.site import site_from_values


def test_classes_contact_and_track_from_flat_values(site_values):
    site = site_from_values(site_values)
    assert list(site.vehicles) == ["emu", "dmu", "freight"]
    emu = site.vehicle("emu")
    assert emu.mean_axles_per_train == 4 * (3 + 6) / 2
    assert site.track.pad_stiffness_npm == 3.5e8 and site.contact.rail_head_radius_m == 0.3
    # Hertz patch of the EMU wheel at its nominal load: a few mm, longer along the rail for a conical
    # tread on a 300 mm rail head (Johnson 1985, ch. 4).
    patch = site.contact_patch(emu.wheel_diameter_m / 2, emu.wheel_load_n)
    assert 3e-3 < float(patch.a) < 1e-2 and 3e-3 < float(patch.b) < 1e-2


def test_inconsistent_or_unknown_entries_are_refused(site_values):
    with pytest.raises(ConfigError, match="unknown vehicle class 'tram'"):
        site_from_values(site_values).vehicle("tram")
    with pytest.raises(ConfigError, match="a minimum exceeds its maximum"):
        site_from_values({**site_values, "vehicle.emu.vehicles_min": 9})
    with pytest.raises(ConfigError, match=r"vehicle\.emu\.wheel_diamter_m.*wheel_diameter_m"):
        site_from_values({**site_values, "vehicle.emu.wheel_diamter_m": 0.8})
    with pytest.raises(ConfigError, match="names no vehicle class"):
        site_from_values({**site_values, "vehicle_classes": []})
