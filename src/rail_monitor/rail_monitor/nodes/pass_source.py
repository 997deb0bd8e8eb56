"""Publishing a pass history into the graph: timing, /clock, flow control, progress.

Shared by pass_replayer (history from a file) and pass_simulator (generated traffic).
"""

from __future__ import annotations

import sys
import threading
import time
from collections.abc import Callable

import rclpy
from diagnostic_msgs.msg import DiagnosticArray
from rclpy.duration import Duration
from rosgraph_msgs.msg import Clock
from tqdm import tqdm

from rail_monitor.core.errors import RailMonitorError
from rail_monitor.core.friction import ApplicatorEvent
from rail_monitor.core.node_params import PUBLISH_SPECS, STAMP_SPECS, PublishParams, StampParams
from rail_monitor.core.params import ParamGroups, values_of
from rail_monitor.core.passes import PassTable, publishable
from rail_monitor.core.timeutil import NS_PER_S
from rail_monitor.corrugation.surveys import MaintenanceEvent
from rail_monitor.measured.records import Measurement
from rail_monitor.messages.event_fields import friction_applicator_fields, roughness_survey_fields
from rail_monitor.messages.fields import measured_pass_noise_fields, train_pass_columns
from rail_monitor.messages.topics import DIAGNOSTICS_TOPIC
from rail_monitor.nodes.base import DIAGNOSTICS_PERIOD_S, Diagnostics, RailNode, RateMeter, announce, declare
from rail_monitor.nodes.convert import time_msg, to_cdr, to_cdr_many
from rail_monitor.nodes.qos import CLOCK_QOS, DIAGNOSTICS_QOS, EVENT_QOS, STREAM_QOS
from rail_msgs.msg import FrictionApplicator, MeasuredPassNoise, RoughnessSurvey, TrainPass

GRAPH_SETTLE_S = 1.0  # the graph's endpoints unchanged this long [s]: every node has subscribed
CDR_BLOCK = 4096  # passes whose TrainPass bytes are written together from the table's columns


class PassSourceNode(RailNode):
    """Base of the nodes that publish train passes on ``train_pass`` (relative: site namespace)."""

    PARAMETERS: ParamGroups = (("", PUBLISH_SPECS), ("stamps.", STAMP_SPECS))

    def __init__(self, name: str, **kwargs) -> None:
        super().__init__(name, **kwargs)
        self.cfg = values_of(PublishParams, declare(self, PUBLISH_SPECS))
        self.margins = values_of(StampParams, declare(self, STAMP_SPECS, prefix="stamps."))
        self.pub = self.create_publisher(TrainPass, "train_pass", STREAM_QOS)
        self.clock_pub = self.create_publisher(Clock, "/clock", CLOCK_QOS) if self.cfg.publish_clock else None
        self.meter = RateMeter()
        self.total = 0
        self.last_stamp_ns = 0
        self.done = threading.Event()
        # Passes taken by the slowest subscriber hosted in this process (set by wayside_monitor), and
        # whether subscribers in other processes are expected too (a live view): then the graph settles.
        self.consumed: Callable[[], int] | None = None
        self.foreign_subscribers = False
        self.left_out: dict[str, int] = {}
        self.event_pub = None  # roughness_survey, made when the history has surveys or grinding
        self.events_sent = 0
        self.measured_pub = None  # noise/measured, made when the history has measured pass-bys
        self.measurements_sent = 0
        self.applicator_pub = None  # friction_applicator, made when the history has applicator events
        self.applicator_sent = 0
        self._bounds = (0, 0)  # stamps of the replay window [ns]
        self._status: dict[str, dict[str, str]] = {}  # latest /diagnostics values, by status name
        self.create_subscription(DiagnosticArray, DIAGNOSTICS_TOPIC, self._on_diagnostics, DIAGNOSTICS_QOS)
        Diagnostics(self, lambda: {"published": self.meter.count, "total": self.total,
                                   "left out": sum(self.left_out.values()), "surveys sent": self.events_sent,
                                   "measurements sent": self.measurements_sent,
                                   "applicator events sent": self.applicator_sent,
                                   **{f"left out: {why}": n for why, n in self.left_out.items()},
                                   "rate_per_s": f"{self.meter.rate():.1f}",
                                   "pass_time_ns": self.last_stamp_ns, "done": self.done.is_set()})

    def passes(self) -> PassTable:
        """The passes to publish, in time order (subclasses)."""
        raise NotImplementedError

    def events(self) -> list[MaintenanceEvent]:
        """The surveys and grinding events of the history, in stamp order (none by default)."""
        return []

    def measurements(self) -> list[Measurement]:
        """The measured pass-bys of the history, in stamp order (none by default)."""
        return []

    def applicators(self) -> list[ApplicatorEvent]:
        """The friction-modifier applicator's starts and stops, in stamp order (none by default)."""
        return []

    def _window(self, table: PassTable) -> PassTable:
        """The passes to publish: in time order, inside the offsets, publishable
        (:func:`rail_monitor.core.passes.publishable`: the others are left out and counted)."""
        table, self.left_out = publishable(table, self.margins)
        for why, n in self.left_out.items():
            self.get_logger().warning(f"{n} pass(es) left out: {why}")
        if len(table) == 0:
            return table
        t0 = int(table.stamp_ns[0])
        end = t0 + int(self.cfg.end_offset_s * NS_PER_S) if self.cfg.end_offset_s > 0.0 else 2**63 - 1
        self._bounds = (t0 + int(self.cfg.start_offset_s * NS_PER_S), end)
        keep = (table.stamp_ns >= self._bounds[0]) & (table.stamp_ns <= end)
        return table.take(keep)

    def advertise_events(self) -> None:
        """Create the roughness_survey publisher (before the start-up wait, so that a recorder
        discovers the topic in time; a source whose history has events calls it at construction)."""
        if self.event_pub is None:
            self.event_pub = self.create_publisher(RoughnessSurvey, "roughness_survey", EVENT_QOS)

    def advertise_measurements(self) -> None:
        """Create the noise/measured publisher (as advertise_events)."""
        if self.measured_pub is None:
            self.measured_pub = self.create_publisher(MeasuredPassNoise, "noise/measured", STREAM_QOS)

    def advertise_applicators(self) -> None:
        """Create the friction_applicator publisher (as advertise_events)."""
        if self.applicator_pub is None:
            self.applicator_pub = self.create_publisher(FrictionApplicator, "friction_applicator", STREAM_QOS)

    def _send_event(self, event: MaintenanceEvent, ok: Callable[[], bool]) -> None:
        """Publish a survey or grinding event. In other processes, wait until every subscriber holds
        it before the next pass goes out (the estimator takes queued surveys before passes); in
        this one, DDS has delivered it to the hosted subscribers when publish returns."""
        self._send(self.event_pub, to_cdr(RoughnessSurvey, roughness_survey_fields(event, self.cfg.site_id)), ok)
        self.events_sent += 1

    def _send_measurement(self, m: Measurement, ok: Callable[[], bool]) -> None:
        """Publish a measured pass-by, held by every subscriber before the next pass goes out (the
        alert manager scores measurements in stamp order as long as each comes before any later
        pass's predictions)."""
        self._send(self.measured_pub, to_cdr(MeasuredPassNoise, measured_pass_noise_fields(m, self.cfg.site_id)), ok)
        self.measurements_sent += 1

    def _send_applicator(self, event: ApplicatorEvent, ok: Callable[[], bool]) -> None:
        """Publish an applicator's start or stop (for the recorder: no model takes it; latched, so a
        recorder matching late gets it), held by the subscribers present before the next pass."""
        data = to_cdr(FrictionApplicator, friction_applicator_fields(event, self.cfg.site_id))
        self._send(self.applicator_pub, data, ok)
        self.applicator_sent += 1

    def _send(self, pub, data: bytes, ok: Callable[[], bool]) -> None:
        """Publish one message's CDR bytes and wait for its acknowledgement (_acknowledged)."""
        pub.publish(data)
        self._acknowledged(pub, ok)

    def _acknowledged(self, pub, ok: Callable[[], bool]) -> None:
        """In other processes, wait until every subscriber of pub holds what it sent (at most
        ack_timeout_s); in this one, DDS has delivered it to the hosted subscribers already."""
        deadline = time.monotonic() + self.cfg.ack_timeout_s
        while self.consumed is None and ok() and not pub.wait_for_all_acked(Duration(seconds=0.05)):
            if time.monotonic() > deadline:
                raise RailMonitorError(f"subscribers of {pub.topic_name} did not take its messages within "
                                       f"{self.cfg.ack_timeout_s:g} s")

    def _publish_clock(self, ns: int) -> None:
        if self.clock_pub is not None:  # a ROS clock cannot run before 1970
            self.clock_pub.publish(Clock(clock=time_msg(max(ns, 0))))

    def _wait_for_subscribers(self, ok: Callable[[], bool]) -> None:
        """Start-up handshake: wait for wait_for_subscribers train_pass subscribers, then (in
        other processes) until the graph's endpoints in this namespace have stood still for
        GRAPH_SETTLE_S: every consumer's publishers exist before it subscribes train_pass
        (PassConsumerNode.listen), and a recorder has then subscribed what they publish."""
        want = self.cfg.wait_for_subscribers
        deadline = time.monotonic() + self.cfg.wait_timeout_s
        while self.pub.get_subscription_count() < want and ok():
            if time.monotonic() > deadline:
                raise RailMonitorError(f"only {self.pub.get_subscription_count()} of {want} subscribers "
                                       f"on {self.pub.topic_name} after {self.cfg.wait_timeout_s:g} s")
            time.sleep(0.02)
        if want == 0 or (self.consumed is not None and not self.foreign_subscribers):
            return  # nobody to wait for, or only the consumers hosted here (paced exactly)
        last, since = self._endpoints(), time.monotonic()
        while ok() and time.monotonic() - since < GRAPH_SETTLE_S and time.monotonic() < deadline:
            time.sleep(0.05)
            now = self._endpoints()
            if now != last:
                last, since = now, time.monotonic()

    def _wait_for_event_subscriber(self, ok: Callable[[], bool]) -> None:
        """Wait (at most wait_timeout_s) until roughness_survey has a subscriber: a survey sent to
        nobody is lost (the topic is volatile)."""
        deadline = time.monotonic() + self.cfg.wait_timeout_s
        while ok() and self.event_pub.get_subscription_count() < 1:
            if time.monotonic() > deadline:
                self.get_logger().warning(f"nobody subscribes {self.event_pub.topic_name}: its surveys go unheard")
                return
            time.sleep(0.02)

    def _endpoints(self) -> list[tuple[str, int, int]]:
        """(topic, publishers, subscribers) of every topic under this node's namespace."""
        ns = self.get_namespace().rstrip("/") + "/"
        return sorted((t, self.count_publishers(t), self.count_subscribers(t))
                      for t, _ in self.get_topic_names_and_types() if t.startswith(ns))

    def _wait_for_graph(self, published: int, ok: Callable[[], bool]) -> None:
        """End-of-replay handshake (other processes): wait until every train_pass consumer that
        reports on /diagnostics has taken every pass and has none pending, then until a recorder's
        count of outputs (/diagnostics aside) has stood still for a diagnostics period, at most
        wait_timeout_s. A finite replay that then exits (ros2 launch shuts down on it) leaves
        nothing in flight."""
        deadline = time.monotonic() + self.cfg.wait_timeout_s
        names = {f"{i.node_namespace.rstrip('/')}/{i.node_name}"
                 for i in self.get_subscriptions_info_by_topic(self.pub.topic_name)}

        def consumers_done() -> bool:
            statuses = [self._status.get(n, {}) for n in names]
            return all(int(v.get("taken", published)) >= published and v.get("pending", "0") == "0"
                       for v in statuses)

        while ok() and not consumers_done() and time.monotonic() < deadline:
            time.sleep(0.05)
        recorded = None
        while ok() and time.monotonic() < deadline:
            now = tuple(self._status.get(n, {}).get("recorded outputs") for n in sorted(names))
            if now == recorded:
                return
            recorded = now
            time.sleep(DIAGNOSTICS_PERIOD_S + 0.2)
        if ok():
            self.get_logger().warning(f"the graph did not settle within {self.cfg.wait_timeout_s:g} s of the "
                                      "last pass; outputs may still be in flight")

    def _on_diagnostics(self, msg: DiagnosticArray) -> None:
        for status in msg.status:
            self._status[status.name] = {kv.key: kv.value for kv in status.values}

    def _throttle(self, published: int, ok: Callable[[], bool]) -> None:
        """Flow control: where the consumers share this process, wait until the slowest has taken
        all but max_backlog; otherwise until every subscriber holds what was sent (DDS
        acknowledgement; their queues of 10000 absorb the rest).

        In one process we never call wait_for_all_acked: it holds the GIL while it blocks and would
        starve the hosted subscribers of the callbacks that empty their queues. Across processes
        we use short blocking waits: zero-timeout polls do not prompt Fast DDS's heartbeat, and
        the acknowledgement then takes seconds (measured: about 3.6 s per batch of 100).
        """
        deadline = time.monotonic() + self.cfg.ack_timeout_s
        slice_ = Duration(seconds=0.05)
        backlog = self.cfg.max_backlog

        def behind() -> bool:
            if self.consumed is not None:  # exact, and cheaper than a DDS acknowledgement round
                return published - self.consumed() > backlog
            return not self.pub.wait_for_all_acked(slice_)

        while ok() and behind():
            if time.monotonic() > deadline:
                raise RailMonitorError(f"subscribers of {self.pub.topic_name} did not keep up within "
                                       f"{self.cfg.ack_timeout_s:g} s")
            time.sleep(0.0005)

    def run(self, ok: Callable[[], bool] | None = None) -> int:
        """Publish every pass (blocking); returns how many were published."""
        ok = ok or (lambda: rclpy.ok(context=self.context))
        table = self._window(self.passes())
        self.total = len(table)
        lo, hi = self._bounds
        events = [e for e in self.events() if lo <= e.stamp_ns <= hi] if len(table) else []
        if events:
            self.advertise_events()
        measured = [m for m in self.measurements() if lo <= m.stamp_ns <= hi] if len(table) else []
        if measured:
            self.advertise_measurements()
        applicator = [e for e in self.applicators() if lo <= e.stamp_ns <= hi] if len(table) else []
        if applicator:
            self.advertise_applicators()
        announce(self, site=self.cfg.site_id, passes=len(table), surveys=len(events), measured=len(measured),
                 rate=f"{self.cfg.rate:g}", wait_for_subscribers=self.cfg.wait_for_subscribers)
        self._wait_for_subscribers(ok)
        if events and self.cfg.wait_for_subscribers > 0:
            self._wait_for_event_subscriber(ok)
        outbox = ((events, self._send_event), (applicator, self._send_applicator), (measured, self._send_measurement))
        rate, frame = self.cfg.rate, self.cfg.site_id
        batch, period = self.cfg.ack_batch, self.cfg.clock_period_s
        stamps = table.stamp_ns
        t0 = int(stamps[0]) if len(table) else 0
        wall0 = time.monotonic()
        bar = tqdm(total=len(table), unit="pass", file=sys.stderr, disable=not self.cfg.progress,
                   mininterval=0.5, desc=self.get_name())
        try:
            for i in range(len(table)):
                if not ok():
                    break
                stamp = int(stamps[i])
                if rate > 0.0:  # recorded timing, scaled: tick /clock while waiting
                    due = wall0 + (stamp - t0) / NS_PER_S / rate
                    while ok() and (left := due - time.monotonic()) > 0:
                        time.sleep(min(left, period))
                        # never past the pass itself: /clock must not step backwards
                        self._publish_clock(min(stamp, t0 + int((time.monotonic() - wall0) * rate * NS_PER_S)))
                self._publish_clock(stamp)
                # Events before the first pass later than them; a measurement after its own pass.
                for items, send in outbox:
                    while items and items[0].stamp_ns < stamp:
                        send(items.pop(0), ok)
                if i % CDR_BLOCK == 0:  # the passes' CDR from their columns, a block at a time
                    part = table.take(slice(i, i + CDR_BLOCK))
                    block = to_cdr_many(TrainPass, train_pass_columns(part, frame), len(part))
                self.pub.publish(block[i % CDR_BLOCK])
                self.meter.tick()
                self.last_stamp_ns = stamp
                bar.update()
                if (i + 1) % batch == 0:
                    self._throttle(i + 1, ok)
            for items, send in outbox:
                for item in items if ok() else []:
                    send(item, ok)
            self._throttle(self.meter.count, ok)
            if self.consumed is None and self.cfg.wait_for_subscribers > 0:
                self._wait_for_graph(self.meter.count, ok)
        finally:
            bar.close()
        self.done.set()
        self.get_logger().info(f"published {self.meter.count} of {len(table)} passes")
        return self.meter.count
