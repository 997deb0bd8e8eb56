"""Taking the graph's topics serialised, as they appear: what the recorder and the Foxglove server share.

A tap looks for topics every ``period_s`` (every rail_msgs type and /diagnostics, or the topics
named), subscribes each once a publisher shows its QoS (with a profile every publisher accepts,
as rosbag2 adapts it), and hands the serialised messages (CDR bytes, no decode) on in batches.

The looking is done by a thread of its own, outside the executor: rclpy has no graph-change event,
and a timer would wake the executor five times a second to rebuild its wait set (about 1 ms each
in the recorder, a third of the idle graph's CPU), where a graph query costs a few tens of µs. The
thread wakes the executor (a guard condition) only when a wanted topic has a publisher and is not
taken yet; subscribing stays in the executor, serialised with the message callbacks.
"""

from __future__ import annotations

import threading
from collections.abc import Callable
from typing import Any

from rclpy.callback_groups import MutuallyExclusiveCallbackGroup
from rclpy.event_handler import SubscriptionEventCallbacks
from rclpy.node import Node
from rclpy.qos import QoSProfile, qos_policy_name_from_kind

from rail_monitor.core.params import values_of
from rail_monitor.nodes.base import RailNode, declare, subscribe_batched
from rail_monitor.nodes.convert import message_class
from rail_monitor.nodes.qos import subscription_qos

DEFAULT_TYPES_PREFIX = "rail_msgs/"
DIAGNOSTICS_TYPE = "diagnostic_msgs/msg/DiagnosticArray"
TAKE_AT_ONCE = 500  # most queued messages of a topic one callback takes (a burst costs fewer wake-ups)


class TapNode(RailNode):
    """A node that records or serves any graph's topics (mcap_recorder, foxglove_server): it has no
    site of its own, and its parameters are its one PARAMETERS group, read into ``cfg`` (CONFIG)."""

    USES_SITE = False
    CONFIG: type

    def __init__(self, **kwargs) -> None:
        super().__init__(self.EXECUTABLE, **kwargs)
        self.cfg = values_of(self.CONFIG, declare(self, self.PARAMETERS[0][1]))

    def destroy_node(self) -> None:
        tap = getattr(self, "tap", None)
        if tap is not None:
            tap.close()  # its thread queries the graph through this node
        super().destroy_node()


class TopicTap:
    """Subscribe node to every wanted topic as it appears.

    topics: names (absolute or relative to the node's namespace); empty: every rail_msgs topic
    and /diagnostics; types: only topics of these types (empty: any). on_topic(topic, typename,
    offered QoS) runs once per topic before its first message; on_messages(topic, [CDR bytes]) per
    batch taken.
    """

    def __init__(self, node: Node, topics: list[str], period_s: float,
                 on_topic: Callable[[str, str, list[QoSProfile]], None],
                 on_messages: Callable[[str, list[bytes]], None], types: tuple[str, ...] = ()) -> None:
        self.node = node
        self._types = set(types)
        wanted = [t for t in topics if t]
        self._wanted = {node.resolve_topic_name(t) for t in wanted} if wanted else None
        self._on_topic, self._on_messages = on_topic, on_messages
        self.group = MutuallyExclusiveCallbackGroup()
        self.subs: dict[str, object] = {}
        self._wake = node.create_guard_condition(self.discover, callback_group=self.group)
        self._stop = threading.Event()
        self._watcher = threading.Thread(target=self._watch, args=(period_s,), daemon=True,
                                         name=f"{node.get_name()}_topic_watch")
        self._watcher.start()

    def close(self) -> None:
        """Stop looking for topics (before the node is destroyed)."""
        self._stop.set()
        if self._watcher.is_alive() and self._watcher is not threading.current_thread():
            self._watcher.join(timeout=5.0)

    def _watch(self, period_s: float) -> None:
        while not self._stop.wait(period_s):
            try:
                if self._pending():
                    self._wake.trigger()
            except Exception:  # the node or its context is going away: nothing left to look for
                return

    def _pending(self) -> bool:
        """Whether a wanted topic with a publisher is not taken yet (discover() has work)."""
        node = self.node
        return any(topic not in self.subs and self._want(topic, types) and node.count_publishers(topic) > 0
                   for topic, types in node.get_topic_names_and_types())

    def _want(self, topic: str, types: list[str]) -> bool:
        if self._types and not self._types.intersection(types):
            return False
        if self._wanted is not None:
            return topic in self._wanted
        return bool(self._types) or any(t.startswith(DEFAULT_TYPES_PREFIX) or t == DIAGNOSTICS_TYPE for t in types)

    def discover(self) -> None:
        """Subscribe to every wanted topic that has appeared, with a QoS its publishers accept."""
        node = self.node
        for topic, types in node.get_topic_names_and_types():
            if topic in self.subs or not self._want(topic, types):
                continue
            if len(types) != 1:
                node.get_logger().warning(f"{topic} has several types {types}; not taken")
                self.subs[topic] = None
                continue
            offered: list[QoSProfile] = [i.qos_profile for i in node.get_publishers_info_by_topic(topic)]
            if not offered:
                continue  # only subscribers so far: wait for a publisher to learn its QoS
            typename = types[0]
            msg_type = message_class(typename)
            self._on_topic(topic, typename, offered)
            # One QoS event handler, not rclpy's default two: every event handler is walked at each of
            # the executor's wake-ups, and the type cannot clash (a topic of several types is not taken).
            events = SubscriptionEventCallbacks(incompatible_qos=self._incompatible(topic), use_default_callbacks=False)
            self.subs[topic] = subscribe_batched(
                node, msg_type, topic, lambda msgs, t=topic: self._on_messages(t, msgs), subscription_qos(offered),
                TAKE_AT_ONCE, raw=True, callback_group=self.group, event_callbacks=events)

    def _incompatible(self, topic: str) -> Callable[[Any], None]:
        def warn(event: Any) -> None:
            self.node.get_logger().warning(
                f"a publisher of {topic} offers a QoS this subscription cannot match "
                f"({qos_policy_name_from_kind(event.last_policy_kind)}); its messages are not taken")
        return warn
