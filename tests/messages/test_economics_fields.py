"""Grinding outlooks and programmes as messages (rail_monitor.messages.economics_fields): an outlook
read back from its CDR bytes is the outlook, to the bit, and the bytes decode alike with rosbags'
independent deserialiser; a programme's visits are its sites' months, in month order."""

from __future__ import annotations

import numpy as np
import pytest

from rail_monitor.codec.cdr import message_view, serialize
from rail_monitor.codec.typestore import typestore
from rail_monitor.corrugation.surveys import KIND_GRINDING, MaintenanceEvent
from rail_monitor.economics.outlook import Option, SiteOutlook
from rail_monitor.economics.replan import Replanner
from rail_monitor.messages.economics_fields import grinding_outlook_fields, grinding_programme_fields, outlook_from_msg

OUTLOOK, PROGRAMME = "rail_msgs/msg/GrindingOutlook", "rail_msgs/msg/GrindingProgramme"
DAY = 86_400 * 10**9
T0 = 1_700_000_000 * 10**9


def _outlook(site: str, due: float, options: bool) -> SiteOutlook:
    opts = (Option("grind", np.array([300.0, 700.0, 1900.0])),
            Option("friction_modifier", np.array([500.0, 1300.0, np.inf]), 400.0, "squeal 24.7 -> 23.8 %")) \
        if options else ()
    return SiteOutlook(site, T0 + 3 * DAY, np.array([0.4, 1.0, 2.5]) * due, np.array([300.0, 700.0, 1900.0]),
                       500.0, 1500.0, 500.0, opts)


@pytest.mark.parametrize("options", [False, True])
def test_an_outlook_read_back_from_its_bytes_is_the_outlook(options):
    o = _outlook("curve_250", 200.0, options)
    event = MaintenanceEvent(T0 + 4 * DAY, KIND_GRINDING, np.zeros(0), np.zeros(0))
    data = serialize(OUTLOOK, grinding_outlook_fields(event, o, o.site_id))
    stamp, back = outlook_from_msg(message_view(OUTLOOK, data))
    assert stamp == event.stamp_ns and back.site_id == o.site_id and back.newest_ns == o.newest_ns
    for name in ("due_days", "cycle_days"):
        np.testing.assert_array_equal(getattr(back, name), getattr(o, name))
    assert (back.visit_cost, back.late_visit_cost, back.length_m) == (o.visit_cost, o.late_visit_cost, o.length_m)
    assert [(p.name, p.cost_per_year, p.effects) for p in back.options] == [(p.name, p.cost_per_year, p.effects)
                                                                           for p in o.options]
    for a, b in zip(back.options, o.options, strict=True):
        np.testing.assert_array_equal(a.cycle_days, b.cycle_days)
    # an independent reader (rosbags' deserialiser, from the installed .msg) reads the same fields
    msg = typestore().deserialize_cdr(data, OUTLOOK)
    assert msg.event_kind == KIND_GRINDING and msg.header.frame_id == "curve_250"
    assert msg.due_days_p90 == o.due_days[2] and list(msg.option) == [p.name for p in o.options]


def test_a_programme_message_lists_every_visit_in_month_order():
    planner = Replanner(years=3.0)
    planner.take(T0, _outlook("a", 400.0, False))
    r = planner.take(T0 + DAY, _outlook("b", 90.0, True))
    data = serialize(PROGRAMME, grinding_programme_fields(r))
    msg = typestore().deserialize_cdr(data, PROGRAMME)
    p = r.programme
    assert list(msg.site_id) == ["a", "b"] and msg.header.frame_id == "b" and msg.months == 36
    want = sorted((int(m), s) for s, v in zip(p.sites, p.visits, strict=True) for m in v)
    assert list(zip(msg.visit_month.tolist(), msg.visit_site_id, strict=True)) == want and len(want) >= 2
    assert msg.visits.tolist() == [len(v) for v in p.visits]
    assert msg.first_visit_month.tolist() == [int(v[0]) if len(v) else -1 for v in p.visits]
    assert msg.total_expected_cost == pytest.approx(p.expected_cost.sum(), rel=1e-12)
    starts = [r.rules.month_ns(m) for m, _ in want]
    assert [t.sec * 10**9 + t.nanosec for t in msg.visit_start] == starts
