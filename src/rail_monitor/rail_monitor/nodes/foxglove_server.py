"""foxglove_server: a live view of the site in Foxglove, over the Foxglove WebSocket protocol.

Serves every rail_msgs topic and /diagnostics as it appears (or the ``topics`` named), each as a
channel with its ``ros2msg`` schema (the installed .msg text with its dependencies, as the
recorder writes it) and the CDR payloads as published: Foxglove decodes them as it decodes a
bag, field comments and units included. A client that subscribes a channel gets its latest
message at once (as a latched ROS subscriber gets the standing alerts). The server is the
Foxglove SDK's (foxglove-sdk); this node only feeds it. Open Foxglove, connect to ``ws://HOST:PORT`` and load
``share/rail_monitor/config/foxglove_layout.json``.
"""

from __future__ import annotations

import queue
import sys
import time
from collections import Counter

import foxglove
from rclpy.qos import QoSProfile

from rail_monitor.codec.typestore import schema_text
from rail_monitor.core.node_params import FOXGLOVE_SPECS, FoxgloveParams
from rail_monitor.messages.topics import DIAGNOSTICS_TOPIC, GRAPH_TOPICS
from rail_monitor.nodes.base import Diagnostics, RateMeter, announce, wall_timer
from rail_monitor.nodes.process import run_node
from rail_monitor.nodes.topic_tap import DIAGNOSTICS_TYPE, TapNode, TopicTap


class FoxgloveServer(TapNode):
    EXECUTABLE = "foxglove_server"
    PARAMETERS = (("", FOXGLOVE_SPECS),)
    CONFIG = FoxgloveParams

    def __init__(self, **kwargs) -> None:
        super().__init__(**kwargs)
        self.fg = foxglove.Context()
        self.channels: dict[str, foxglove.Channel] = {}
        self.latest: dict[str, tuple[bytes, int]] = {}  # per topic: the last message and its log time
        # Topics a client has just subscribed, from the server's thread: their latest message is
        # logged from this node's own callbacks (the SDK is never called back from its own thread).
        self._subscribed: queue.SimpleQueue[str] = queue.SimpleQueue()
        self.server = foxglove.start_server(name=f"rail_monitor {self.get_namespace()}", host=self.cfg.host,
                                            port=self.cfg.port, context=self.fg, supported_encodings=["cdr"],
                                            server_listener=_SendLatest(self))
        self.counts: Counter[str] = Counter()
        self.meter = RateMeter()
        # The graph's own topics get their channels at once, before any client connects: a channel
        # advertised while a client is subscribing can be missed by it (seen with the SDK's server).
        wanted = {self.resolve_topic_name(t) for t in self.cfg.topics if t}
        for name, (typename, _) in (*GRAPH_TOPICS.items(), (DIAGNOSTICS_TOPIC, (DIAGNOSTICS_TYPE, None))):
            topic = self.resolve_topic_name(name)
            if not wanted or topic in wanted:
                self._add_topic(topic, typename, [])
        self.tap = TopicTap(self, self.cfg.topics, self.cfg.discovery_period_s, self._add_topic, self._on_messages)
        wall_timer(self, 0.05, self._send_latest, callback_group=self.tap.group)
        Diagnostics(self, lambda: {"served": self.meter.count, "rate_per_s": f"{self.meter.rate():.1f}",
                                   "channels": len(self.channels), "port": self.server.port})
        self.tap.discover()
        announce(self, url=f"ws://{self.cfg.host}:{self.server.port}")

    def _add_topic(self, topic: str, typename: str, offered: list[QoSProfile]) -> None:
        if topic in self.channels:
            return
        schema = foxglove.Schema(name=typename, encoding="ros2msg", data=schema_text(typename).encode())
        self.channels[topic] = foxglove.Channel(topic, schema=schema, message_encoding="cdr", context=self.fg)

    def _on_messages(self, topic: str, msgs: list[bytes]) -> None:
        channel = self.channels[topic]
        now = self.get_clock().now().nanoseconds or time.time_ns()  # receipt time; pass time on sim time
        for data in msgs:
            channel.log(data, log_time=now)
        self.latest[topic] = (msgs[-1], now)
        self.counts[topic] += len(msgs)
        self.meter.tick(len(msgs))

    def subscribed(self, topic: str) -> None:
        """A client has subscribed a channel (called from the server's thread)."""
        self._subscribed.put(topic)

    def _send_latest(self) -> None:
        """Log again the latest message of each channel a client has just subscribed."""
        while not self._subscribed.empty():
            topic = self._subscribed.get()
            if topic in self.latest:
                data, stamp = self.latest[topic]
                self.channels[topic].log(data, log_time=stamp)

    def close(self) -> None:
        self.server.stop()


class _SendLatest(foxglove.ServerListener):
    """The server's callbacks: on a subscription, the channel's latest message at once."""

    def __init__(self, node: FoxgloveServer) -> None:
        self.node = node

    def on_subscribe(self, client: foxglove.websocket.Client, channel: foxglove.websocket.ChannelView) -> None:
        self.node.subscribed(channel.topic)


def main(args: list[str] | None = None) -> int:
    return run_node(FoxgloveServer, args)


if __name__ == "__main__":
    sys.exit(main())
