"""grinding_planner (issue 57): a separate process that finds every site's grinding/outlook topic as
it appears and publishes the network's programme, re-planned on each outlook, over real DDS. Its
programmes are those of economics.replan over the same outlooks (what ``rail-monitor plan --replan``
runs in batch); an outlook older than its site's newest, one with NaN days and bytes that are no
outlook change nothing, are counted on /diagnostics, and leave the node planning."""

from __future__ import annotations

import signal
import subprocess
from dataclasses import replace

import numpy as np
import rclpy
from diagnostic_msgs.msg import DiagnosticArray

from rail_monitor.corrugation.surveys import KIND_SURVEY, MaintenanceEvent
from rail_monitor.economics.outlook import Option, SiteOutlook
from rail_monitor.economics.replan import Replanner
from rail_monitor.messages.economics_fields import grinding_outlook_fields
from rail_monitor.nodes.convert import to_msg
from rail_monitor.nodes.qos import DIAGNOSTICS_QOS, LATEST_QOS, STREAM_QOS
from rail_msgs.msg import GrindingOutlook, GrindingProgramme

from conftest import TOP, executable, spinning, wait_until

DAY = 86_400 * 10**9
T0 = 1_790_000_000 * 10**9


def _outlook(site: str, day: int, due: float) -> tuple[MaintenanceEvent, SiteOutlook]:
    cycle = np.array([250.0, 600.0, 1500.0])
    options = (Option("grind", cycle), Option("friction_modifier", 1.8 * cycle, 300.0, "squeal 20 -> 12 %")) \
        if site == "b" else ()
    return (MaintenanceEvent(T0 + day * DAY, KIND_SURVEY, np.zeros(0), np.zeros(0)),
            SiteOutlook(site, T0 + day * DAY - 3600 * 10**9, cycle / cycle[1] * due, cycle, 400.0, 1200.0, 500.0,
                        options))


def test_the_planner_process_re_plans_on_each_site_s_outlook(ros_context):
    planner = subprocess.Popen([executable("grinding_planner"), "--ros-args", "-p", "years:=3.0", "-p",
                                "capacity:=1", "-p", "discovery_period_s:=0.05"], cwd=TOP, text=True,
                               stdout=subprocess.PIPE, stderr=subprocess.STDOUT)
    node = rclpy.create_node("planner_test", context=ros_context)
    got: list[GrindingProgramme] = []
    diagnostics: list[dict[str, str]] = []
    node.create_subscription(GrindingProgramme, "/grinding/programme", got.append, LATEST_QOS)
    node.create_subscription(DiagnosticArray, "/diagnostics", lambda m: diagnostics.extend(
        {kv.key: kv.value for kv in s.values} for s in m.status if s.name.endswith("grinding_planner")),
        DIAGNOSTICS_QOS)
    pubs = {s: node.create_publisher(GrindingOutlook, f"/{s}/grinding/outlook", STREAM_QOS) for s in "ab"}
    sent = [_outlook("a", 0, 120.0), _outlook("b", 1, 40.0), _outlook("a", 30, 90.0)]
    try:
        with spinning(ros_context, node):
            assert wait_until(lambda: all(p.get_subscription_count() for p in pubs.values()), timeout_s=60)
            for k, (event, o) in enumerate(sent):
                pubs[o.site_id].publish(to_msg(GrindingOutlook, grinding_outlook_fields(event, o, o.site_id)))
                assert wait_until(lambda k=k: len(got) == k + 1, timeout_s=60), planner.stdout
            old_event, old = _outlook("a", 10, 5.0)     # older than a's newest: no re-plan
            pubs["a"].publish(to_msg(GrindingOutlook, grinding_outlook_fields(old_event, old, "a")))
            pubs["b"].publish(b"\x00\x01\x00\x00\x07")  # no outlook at all
            nan_event, nan = _outlook("b", 35, 20.0)     # days no forecast gives
            nan = replace(nan, due_days=np.array([np.nan, 20.0, 40.0]))
            pubs["b"].publish(to_msg(GrindingOutlook, grinding_outlook_fields(nan_event, nan, "b")))
            event, o = _outlook("b", 40, 20.0)
            sent.append((event, o))
            pubs["b"].publish(to_msg(GrindingOutlook, grinding_outlook_fields(event, o, "b")))
            assert wait_until(lambda: len(got) == 4, timeout_s=60)
            assert wait_until(lambda: any(d.get("re-plans") == "4" and d.get("outlook refused: CdrError") == "1"
                                          and d.get("outlook refused: ValueError") == "1"
                                          and d.get("outlooks older than their site's newest") == "1"
                                          for d in diagnostics), timeout_s=10), diagnostics[-1:]
    finally:
        planner.send_signal(signal.SIGINT)
        out, _ = planner.communicate(timeout=30)
        node.destroy_node()
    assert planner.returncode == 0, out
    # the same outlooks through economics.replan: the same programmes, message for message
    batch = Replanner(3.0, capacity=1)
    for msg, (event, o) in zip(got, sent, strict=True):
        r = batch.take(event.stamp_ns, o)
        p = r.programme
        assert (msg.header.stamp.sec * 10**9 + msg.header.stamp.nanosec, msg.header.frame_id) == (event.stamp_ns,
                                                                                                 o.site_id)
        assert list(msg.site_id) == p.sites and list(msg.option) == p.option
        assert msg.visits.tolist() == [len(v) for v in p.visits]
        assert sorted(zip(msg.visit_month.tolist(), msg.visit_site_id, strict=True)) == sorted(
            (int(m), s) for s, v in zip(p.sites, p.visits, strict=True) for m in v)
        np.testing.assert_allclose(msg.expected_cost, p.expected_cost, rtol=1e-12)
        assert np.bincount(msg.visit_month, minlength=1).max() <= 1  # capacity: one visit a month
    assert list(got[-1].site_id) == ["a", "b"] and "planning on /a/grinding/outlook" in out
