"""Shared node glue: parameters from specs, the site from parameters, subscriptions that take a
backlog at once, timers, diagnostics (a process's session and main() are in nodes.process)."""

from __future__ import annotations

import sys
import time
from collections import Counter
from collections.abc import Callable, Iterator, Mapping, Sequence
from typing import Any

from diagnostic_msgs.msg import DiagnosticArray, DiagnosticStatus, KeyValue
from rcl_interfaces.msg import FloatingPointRange, IntegerRange, ParameterDescriptor
from rclpy.clock import Clock, ClockType
from rclpy.exceptions import ParameterException
from rclpy.node import Node

from rail_monitor.core.errors import ConfigError
from rail_monitor.core.params import ParamGroups, ParamSpec
from rail_monitor.core.site import CONTACT_SPECS, SITE_SPECS, TRACK_SPECS, VEHICLE_SPECS, Site, site_from_values
from rail_monitor.messages.topics import DIAGNOSTICS_TOPIC
from rail_monitor.nodes.convert import to_cdr
from rail_monitor.nodes.process import CALLBACK_ERRORS, SESSION_DEFAULT_SITE
from rail_monitor.nodes.qos import DIAGNOSTICS_QOS

# The site's parameters, which every model node declares (the vehicle sections per class in
# vehicle_classes).
SITE_PARAMETERS: ParamGroups = (("", SITE_SPECS), ("contact.", CONTACT_SPECS), ("track.", TRACK_SPECS),
                                ("vehicle.<class>.", VEHICLE_SPECS))


def _descriptor(spec: ParamSpec, prefix: str) -> ParameterDescriptor:
    d = ParameterDescriptor(name=prefix + spec.name, description=spec.description, read_only=not spec.tunable)
    if spec.choices:
        d.additional_constraints = spec.range_text()
    if spec.kind is float and (spec.low is not None or spec.high is not None):
        d.floating_point_range = [FloatingPointRange(
            from_value=-sys.float_info.max if spec.low is None else float(spec.low),
            to_value=sys.float_info.max if spec.high is None else float(spec.high), step=0.0)]
    elif spec.kind is int and (spec.low is not None or spec.high is not None):
        d.integer_range = [IntegerRange(from_value=int(spec.low if spec.low is not None else -(2**63)),
                                        to_value=int(spec.high if spec.high is not None else 2**63 - 1), step=0)]
    return d


def declare(node: Node, specs: Sequence[ParamSpec], prefix: str = "") -> dict[str, Any]:
    """Declare each spec (with its descriptor) and return the checked values by spec name.

    A wrongly typed or out-of-range value raises ConfigError naming the parameter and its range.
    """
    values: dict[str, Any] = {}
    for spec in specs:
        name = prefix + spec.name
        if node.has_parameter(name):  # shared specs (e.g. site_id) are declared once
            values[spec.name] = node.get_parameter(name).value
            continue
        try:
            p = node.declare_parameter(name, spec.default, _descriptor(spec, prefix))
        except (ParameterException, TypeError, ValueError) as exc:
            raise ConfigError(f"parameter '{name}': {str(exc).splitlines()[0]} (allowed: {spec.range_text()}, "
                              f"type {spec.kind.__name__})") from None
        value = p.value
        if isinstance(spec.default, list):
            value = list(value)
        values[spec.name] = spec.check(value, prefix)
    return values


def announce(node: Node, **key_parameters: Any) -> None:
    """The node's one start-up line: what it subscribes and publishes, and its key parameters."""
    def topics(endpoints: Any) -> str:
        names = sorted({e.topic_name for e in endpoints} - {"/rosout", "/parameter_events"})
        return ", ".join(names) or "nothing"

    if SESSION_DEFAULT_SITE and getattr(node, "USES_SITE", False):
        key_parameters["site_file"] = f"{SESSION_DEFAULT_SITE[0]} (shipped; no --params-file given)"
    settings = ", ".join(f"{k}={v}" for k, v in key_parameters.items())
    node.get_logger().info(f"started: subscribes {topics(node.subscriptions)}; publishes {topics(node.publishers)}"
                           + (f"; {settings}" if settings else ""))


def refuse_unknown_parameters(node: Node) -> None:
    """ConfigError naming a parameter given to the node (a params file, -p) that no section of a
    site file knows, with the nearest known name: the site file's one strict check
    (:func:`rail_monitor.site_file.check_names`), applied to what rclpy was given."""
    from rail_monitor.site_file import check_names

    check_names({name: p.value for name, p in node._parameter_overrides.items()}, f"node {node.get_name()}: ")


class RailNode(Node):
    """The base of every rail_monitor node: the logger-level services on (as an operator expects
    of a ROS 2 node), and a parameter given that no section knows refused at once.

    USES_SITE: the node reads the site's parameters, so its executable started without any
    --params-file reads the shipped site file (as the command line does)."""

    USES_SITE = True

    def __init__(self, name: str, **kwargs: Any) -> None:
        kwargs.setdefault("enable_logger_service", True)
        super().__init__(name, **kwargs)
        refuse_unknown_parameters(self)


def declare_site(node: Node) -> Site:
    """Declare the site parameters, the contact geometry, the track and the rolling-stock table, and build the Site."""
    return site_from_values(declare_site_values(node))


def declare_site_values(node: Node) -> dict[str, Any]:
    """The site's parameters, the contact geometry, the track and the rolling-stock table declared:
    their values by dotted name, as a site file gives them."""
    flat = declare(node, SITE_SPECS)
    for prefix, specs in (("contact.", CONTACT_SPECS), ("track.", TRACK_SPECS)):
        flat.update({prefix + k: v for k, v in declare(node, specs, prefix=prefix).items()})
    for name in flat["vehicle_classes"]:
        for key, value in declare(node, VEHICLE_SPECS, prefix=f"vehicle.{name}.").items():
            flat[f"vehicle.{name}.{key}"] = value
    return flat


def take_queued(sub: Any, limit: int) -> list[Any]:
    """Up to ``limit`` messages already delivered to a subscription, taken at once without waiting.

    rclpy's executors take one message per subscription per wait-set wake-up; a callback that
    takes the rest of its queue too handles a backlog (a replay, a catch-up after a restart) in
    one vectorised step. With no backlog it takes nothing: a live pass is handled alone, at once.
    """
    out: list[Any] = []
    while len(out) < limit:
        with sub.handle:
            taken = sub.handle.take_message(sub.msg_type, sub.raw)
        if taken is None:
            break
        out.append(taken[0])
    return out


def subscribe_batched(node: Node, msg_type: Any, topic: str, handle: Callable[[list[Any]], None], qos: Any,
                      limit: int, **kwargs: Any) -> Any:
    """A subscription whose callback hands ``handle`` its message and the ones queued behind it
    (at most ``limit`` in all, in arrival order; see take_queued)."""
    subs: list[Any] = []

    def callback(msg: Any) -> None:
        handle([msg, *take_queued(subs[0], limit - 1)])

    subs.append(node.create_subscription(msg_type, topic, callback, qos, **kwargs))
    return subs[0]


def runs(items: Sequence[Any], same: Callable[[Any, Any], bool]) -> Iterator[slice]:
    """The slices of consecutive items that are ``same`` as the first of their run, in order."""
    i = 0
    while i < len(items):
        j = i + 1
        while j < len(items) and same(items[i], items[j]):
            j += 1
        yield slice(i, j)
        i = j


def isolate_failures(n: int, call: Callable[[slice], None], failed: Callable[[int, Exception], None]) -> None:
    """call(slice(0, n)); if it raises, call each item alone, and failed(i, exc) for those that raise."""
    try:
        call(slice(0, n))
        return
    except Exception as exc:  # a bug in a model: find the items it fails on, the others go through
        if n == 1:
            failed(0, exc)
            return
    for i in range(n):
        try:
            call(slice(i, i + 1))
        except Exception as exc:
            failed(i, exc)


def wall_timer(node: Node, period_s: float, callback: Callable[[], None], **kwargs: Any):
    """A timer on the steady clock: housekeeping must run whether or not /clock (sim time) ticks."""
    return node.create_timer(period_s, callback, clock=Clock(clock_type=ClockType.STEADY_TIME), **kwargs)


DIAGNOSTICS_PERIOD_S = 1.0
BEAT_TOLERANCE_S = 0.01  # a diagnostics beat this near a whole multiple of its period is on it


class Diagnostics:
    """Publishes one DiagnosticStatus for a node on /diagnostics every period [s] (none while
    the node's clock reads 0: on sim time before the first /clock)."""

    def __init__(self, node: Node, values: Callable[[], dict[str, Any]], period_s: float = DIAGNOSTICS_PERIOD_S,
                 level: Callable[[], tuple[int, str]] | None = None) -> None:
        self._node = node
        self._values = values
        self._level = level or (lambda: (DiagnosticStatus.OK, "ok"))
        self._pub = node.create_publisher(DiagnosticArray, DIAGNOSTICS_TOPIC, DIAGNOSTICS_QOS)
        # Due at whole multiples of the period on the steady clock (CLOCK_MONOTONIC, which every
        # process shares), so that the nodes of a process, and the recorder taking the statuses of
        # every process, wake once a period instead of once per node: idle, wake-ups are the CPU.
        self._period_s = period_s
        self._timer = wall_timer(node, self._to_next_beat(), self._beat)

    def _to_next_beat(self) -> float:
        return self._period_s - time.monotonic() % self._period_s

    def _beat(self) -> None:
        # A beat off the phase (the first, or one delayed by a busy executor) sets the next on it.
        to_next = self._to_next_beat()
        period = to_next if BEAT_TOLERANCE_S < to_next < self._period_s - BEAT_TOLERANCE_S else self._period_s
        if self._timer.timer_period_ns != round(period * 1e9):
            self._timer.timer_period_ns = round(period * 1e9)
            self._timer.reset()
        self.publish()

    def publish(self) -> None:
        now = self._node.get_clock().now()
        if now.nanoseconds == 0:  # a status stamped 1970 would stretch a bag's timeline over decades
            return
        level, message = self._level()
        values = self._values()
        if CALLBACK_ERRORS:
            values["callbacks failed"] = sum(CALLBACK_ERRORS.values())
            values.update({f"callback failed: {why}": n for why, n in sorted(CALLBACK_ERRORS.items())})
            if level < DiagnosticStatus.WARN:
                level, message = DiagnosticStatus.WARN, f"{sum(CALLBACK_ERRORS.values())} callback(s) failed"
        status = DiagnosticStatus(level=level, name=f"{self._node.get_namespace().rstrip('/')}/{self._node.get_name()}",
                                  message=message, hardware_id=self._node.get_name())
        status.values = [KeyValue(key=k, value=str(v)) for k, v in values.items()]
        msg = DiagnosticArray(status=[status])
        msg.header.stamp = now.to_msg()
        self._pub.publish(msg)


class Sent(Counter):
    """Messages published per topic (resolved name): wayside_monitor drains the recorder against it."""

    def publish(self, pub: Any, fields: Mapping[str, Any]) -> None:
        """Publish the message of these plain fields (messages.fields) as its CDR bytes."""
        self.send(pub, to_cdr(pub.msg_type, fields))

    def send(self, pub: Any, data: bytes) -> None:
        """Publish a message's CDR bytes as they are."""
        pub.publish(data)
        self[pub.topic_name] += 1


class RateMeter:
    """Counts events and reports their rate over the last report interval [1/s]."""

    def __init__(self) -> None:
        self.count = 0
        self._last_count = 0
        self._last_t = time.monotonic()

    def tick(self, n: int = 1) -> None:
        self.count += n

    def rate(self) -> float:
        now = time.monotonic()
        dt = max(now - self._last_t, 1e-9)
        r = (self.count - self._last_count) / dt
        self._last_count, self._last_t = self.count, now
        return r
