"""The topic tap of the recorder and the Foxglove server (rail_monitor.nodes.topic_tap): a topic that
appears later is taken, and an idle graph never wakes the executor to look for topics (issue 22:
idle <= 2 % of a core; a discovery timer's wake-ups were 40 % of the idle graph's CPU)."""

from __future__ import annotations

import rclpy

from rail_monitor.nodes.qos import EVENT_QOS
from rail_monitor.nodes.topic_tap import TopicTap
from rail_msgs.msg import RoughnessSurvey

from conftest import spinning, wait_until


def test_a_late_topic_is_taken_and_an_idle_graph_never_wakes_discovery(ros_context, monkeypatch):
    runs: list[int] = []
    original = TopicTap.discover

    def counted(self) -> None:
        runs.append(1)
        original(self)

    monkeypatch.setattr(TopicTap, "discover", counted)
    node = rclpy.create_node("tap_test", context=ros_context)
    other = rclpy.create_node("tap_test_publisher", context=ros_context)
    taken: list[tuple[str, str]] = []
    got: list[bytes] = []
    tap = TopicTap(node, [], 0.02, lambda topic, typename, _qos: taken.append((topic, typename)),
                   lambda _topic, msgs: got.extend(msgs))
    try:
        with spinning(ros_context, node, other):
            wait_until(lambda: False, timeout_s=0.6)  # 30 periods with nothing to take
            idle_runs = len(runs)
            pub = other.create_publisher(RoughnessSurvey, "late_survey", EVENT_QOS)
            assert wait_until(lambda: ("/late_survey", "rail_msgs/msg/RoughnessSurvey") in taken, timeout_s=10.0)
            pub.publish(RoughnessSurvey())
            assert wait_until(lambda: len(got) == 1, timeout_s=10.0)
            settled = len(runs)
            wait_until(lambda: False, timeout_s=0.6)
            assert idle_runs == 0 and settled <= 3 and len(runs) == settled  # a timer would have run 60 times
    finally:
        tap.close()
        assert not tap._watcher.is_alive()
        other.destroy_node()
        node.destroy_node()


def test_a_publisher_the_subscription_cannot_match_is_reported_by_the_one_event_handler(ros_context, monkeypatch):
    from rclpy.qos import QoSProfile, ReliabilityPolicy

    seen: list[object] = []
    monkeypatch.setattr(TopicTap, "_incompatible", lambda self, topic: seen.append)
    node = rclpy.create_node("tap_qos_test", context=ros_context)
    other = rclpy.create_node("tap_qos_publisher", context=ros_context)
    other.create_publisher(RoughnessSurvey, "qos_survey", EVENT_QOS)  # reliable: the tap subscribes reliable
    tap = TopicTap(node, [], 0.02, lambda *_: None, lambda *_: None)
    try:
        with spinning(ros_context, node, other):
            assert wait_until(lambda: tap.subs.get("/qos_survey") is not None, timeout_s=10.0)
            handlers = tap.subs["/qos_survey"].event_handlers
            assert len(handlers) == 1  # rclpy's defaults would add an incompatible-type handler too
            best_effort = QoSProfile(depth=10, reliability=ReliabilityPolicy.BEST_EFFORT)
            other.create_publisher(RoughnessSurvey, "qos_survey", best_effort)
            assert wait_until(lambda: len(seen) > 0, timeout_s=10.0)
    finally:
        tap.close()
        other.destroy_node()
        node.destroy_node()
