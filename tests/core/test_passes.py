"""Validation of pass events and the class defaults."""

from __future__ import annotations

import numpy as np

from rail_monitor.core.node_params import StampParams
from rail_monitor.core.passes import (
    PassTable,
    ahead_of_stream,
    ahead_reason,
    publishable,
    reject_ahead,
    rejection_reasons,
    with_class_defaults,
)

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


def _ahead_one_by_one(stamps, usable, newest, margin):
    """The stamp margin as its definition reads, one pass at a time (the independent method)."""
    out = []
    for t, ok in zip(stamps.tolist(), usable.tolist(), strict=True):
        far = ok and newest > 0 and t - newest > margin
        out.append(far)
        if ok and not far:
            newest = max(newest, t)
    return np.array(out, dtype=bool), newest


def test_ahead_of_stream_equals_the_pass_by_pass_definition():
    # Random streams (unsorted, gaps, unusable passes, with and without a starting reference):
    # the vectorised path and its fallback give exactly the one-by-one result.
    rng = np.random.default_rng(7)
    margin = 100
    for case in range(300):
        n = int(rng.integers(0, 40))
        stamps = 1000 + np.cumsum(rng.choice([1, 5, -20, 150, 5000], size=n, p=[0.5, 0.3, 0.1, 0.07, 0.03]))
        usable = rng.random(n) > 0.15
        newest = int(rng.choice([0, 900, 1500]))
        got, got_newest = ahead_of_stream(stamps, usable, newest, margin)
        want, want_newest = _ahead_one_by_one(stamps, usable, newest, margin)
        assert np.array_equal(got, want) and got_newest == want_newest, case


def test_one_far_future_pass_is_rejected_and_the_stream_goes_on():
    # A pass in 2037 arriving mid-stream: rejected with its reason, and every later real pass taken
    # (the reference stays at the real stream).
    day = 86_400 * 10**9
    stamps = np.array([1_790_000_000 * 10**9 + k * day for k in range(5)])
    stamps = np.insert(stamps, 2, 2_130_000_000 * 10**9)
    reasons = np.full(len(stamps), "", dtype=object)
    margins = StampParams(max_ahead_of_stream_s=366 * 86_400.0, max_ahead_of_clock_s=86_400.0)
    newest = reject_ahead(stamps, reasons, 0, margins)
    assert reasons.tolist() == ["", "", ahead_reason(366 * 86_400.0, "stream"), "", "", ""]
    assert newest == int(stamps[-1])


def test_the_clock_margin_applies_only_with_a_clock():
    now = 1_790_000_000 * 10**9
    stamps = np.array([now - 10**9, now + 2 * 86_400 * 10**9])
    margins = StampParams(max_ahead_of_stream_s=366 * 86_400.0, max_ahead_of_clock_s=86_400.0)
    reasons = np.full(2, "", dtype=object)
    reject_ahead(stamps, reasons, 0, margins, clock_ns=now)
    assert reasons.tolist() == ["", "stamp more than 1 d ahead of the clock (stamps.max_ahead_of_clock_s)"]
    reasons = np.full(2, "", dtype=object)
    reject_ahead(stamps, reasons, 0, margins)           # sim time / batch: the stream only
    assert reasons.tolist() == ["", ""]


def test_a_source_leaves_out_what_it_cannot_or_should_not_send():
    day = 86_400 * 10**9
    base = PassTable.from_rows([dict(GOOD, stamp_ns=GOOD["stamp_ns"] + k * day, train_id=f"T{k}") for k in range(3)])
    odd = PassTable.from_rows([dict(GOOD, stamp_ns=2**31 * 10**9 + 5, train_id="2038"),
                               dict(GOOD, stamp_ns=GOOD["stamp_ns"] + 800 * day, train_id="FAR")])
    margins = StampParams(max_ahead_of_stream_s=366 * 86_400.0, max_ahead_of_clock_s=86_400.0)
    sent, left_out = publishable(PassTable.concat([odd, base]), margins)
    assert sent.train_id.tolist() == ["T0", "T1", "T2"]
    assert left_out == {"stamp not representable (builtin_interfaces/Time seconds are int32)": 1,
                        ahead_reason(366 * 86_400.0, "stream"): 1}


def test_the_control_character_class_is_unicodes_cc_zl_and_zp():
    """The regular expression that rejects a train_id or class equals Unicode's categories Cc, Zl
    and Zp over every code point (it replaced a per-character unicodedata lookup)."""
    import sys
    import unicodedata

    from rail_monitor.core.passes import _has_control

    for cp in range(sys.maxunicode + 1):
        c = chr(cp)
        assert _has_control(c) == (unicodedata.category(c) in ("Cc", "Zl", "Zp")), hex(cp)


def test_class_groups_are_slices_in_class_order_and_masks_otherwise():
    mixed = PassTable.from_rows({**GOOD, "train_id": str(i), "vehicle_class": c}
                                for i, c in enumerate(["emu", "freight", "emu", "dmu", "freight", "emu"]))
    groups = dict(mixed.class_groups)
    assert sorted(groups) == ["dmu", "emu", "freight"]
    assert groups["emu"].tolist() == [True, False, True, False, False, True]
    ordered = mixed.take(mixed.class_order())
    assert ordered.train_id.tolist() == ["0", "2", "5", "1", "4", "3"]          # stable within a class
    assert dict(ordered.class_groups) == {"emu": slice(0, 3), "freight": slice(3, 5), "dmu": slice(5, 6)}
    for name, rows in mixed.class_groups:  # the same passes either way
        assert sorted(mixed.train_id[rows]) == sorted(ordered.train_id[dict(ordered.class_groups)[name]])
    assert PassTable.empty().class_groups == [] and len(PassTable.empty().class_order()) == 0
