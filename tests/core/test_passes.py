"""Validation of pass events and the class defaults."""

from __future__ import annotations

import numpy as np

from rail_monitor.core.passes import PassTable, rejection_reasons, with_class_defaults

GOOD = dict(stamp_ns=1_790_000_000_000_000_000, train_id="EMU-1", vehicle_class="emu", vehicle_count=3,
            axle_count=0, speed_mps=19.0, angle_of_attack_rad=0.005, wheel_load_n=0.0, friction_state=1,
            train_length_m=0.0)


def cases_index(cases: dict, key: str) -> int:
    """Row of a case in the table (after the good row, in the cases' order)."""
    return 1 + list(cases).index(key)


def test_each_bad_field_has_its_reason(site):
    cases = {
        "speed_mps": (float("nan"), "speed_mps not finite"),
        "angle_of_attack_rad": (0.5, "|angle_of_attack_rad| above"),
        "wheel_load_n": (-1.0, "wheel_load_n negative"),
        "friction_state": (9, "friction_state unknown"),
        "vehicle_class": ("maglev", "vehicle_class unknown"),
        "train_id": ("   ", "empty train_id"),
        "stamp_ns": (0, "stamp not set"),
        "stamp before 1970": (None, "stamp before 1970"),
        "stamp past 2038": (None, "stamp past 2038-01-19"),
        "train_length_m": (float("inf"), "train_length_m not finite"),
        "vehicle_count": (501, "vehicle_count above 500"),
        "axle_count": (65535, "axle_count above 2000"),
    }
    rows = [GOOD] + [{**GOOD, k: v} for k, (v, _) in cases.items() if k in GOOD]
    rows.insert(cases_index(cases, "stamp before 1970"), {**GOOD, "stamp_ns": -5 * 10**9})
    rows.insert(cases_index(cases, "stamp past 2038"), {**GOOD, "stamp_ns": 2**31 * 10**9})
    # 400 vehicles of the class's length and no length given: a train far past 5 km, filled in unchecked before
    rows.append({**GOOD, "vehicle_count": 400, "train_length_m": 0.0})
    cases["implied length"] = (None, "train length from vehicle_count and the class's vehicle length above 5000 m")
    reasons = rejection_reasons(PassTable.from_rows(rows), site)
    assert reasons[0] == ""
    for got, (_, want) in zip(reasons[1:], cases.values(), strict=True):
        assert got.startswith(want), (got, want)


def test_class_defaults_fill_zero_fields(site):
    t = with_class_defaults(PassTable.from_rows([GOOD]), site)
    emu = site.vehicle("emu")
    assert t.axle_count[0] == 3 * emu.axles_per_vehicle
    assert t.wheel_load_n[0] == emu.wheel_load_n
    assert np.isclose(t.train_length_m[0], 3 * emu.vehicle_length_m)
