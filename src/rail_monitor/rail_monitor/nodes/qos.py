"""rclpy QoS profiles of the graph's topics (from :mod:`rail_monitor.messages.topics`), and the
profile a recorder subscribes with."""

from __future__ import annotations

from typing import Any

from rclpy.qos import DurabilityPolicy, HistoryPolicy, QoSProfile, ReliabilityPolicy

from rail_monitor.messages import topics
from rail_monitor.messages.topics import qos_dict


def profile(q: topics.Qos) -> QoSProfile:
    """The rclpy profile of a topic QoS."""
    return QoSProfile(depth=q.depth, history=HistoryPolicy.KEEP_LAST,
                      reliability=ReliabilityPolicy.RELIABLE if q.reliable else ReliabilityPolicy.BEST_EFFORT,
                      durability=DurabilityPolicy.TRANSIENT_LOCAL if q.transient_local else DurabilityPolicy.VOLATILE)


STREAM_QOS = profile(topics.STREAM)
STREAM_SUB_QOS = profile(topics.STREAM_SUB)
LATEST_QOS = profile(topics.LATEST)
STATE_QOS = profile(topics.STATE)
STATE_SUB_QOS = profile(topics.STATE_SUB)
EVENT_QOS = profile(topics.EVENT)
ALERT_QOS = profile(topics.ALERT)
DIAGNOSTICS_QOS = profile(topics.DIAGNOSTICS)
CLOCK_QOS = profile(topics.CLOCK)


def qos_to_dict(qos: QoSProfile) -> dict[str, Any]:
    """An rclpy QoS profile in rosbag2's metadata layout (discovered profiles have history
    'unknown' and depth 0, recorded as they are, as rosbag2 does)."""
    return qos_dict(
        reliable=qos.reliability == ReliabilityPolicy.RELIABLE,
        transient_local=qos.durability == DurabilityPolicy.TRANSIENT_LOCAL,
        depth=qos.depth,
        history=qos.history.name.lower(),
    )


def subscription_qos(offered: list[QoSProfile]) -> QoSProfile:
    """A subscription QoS compatible with every offered profile (as rosbag2 adapts it)."""
    reliable = bool(offered) and all(q.reliability == ReliabilityPolicy.RELIABLE for q in offered)
    latched = bool(offered) and all(q.durability == DurabilityPolicy.TRANSIENT_LOCAL for q in offered)
    return QoSProfile(
        depth=STREAM_SUB_QOS.depth, history=HistoryPolicy.KEEP_LAST,
        reliability=ReliabilityPolicy.RELIABLE if reliable else ReliabilityPolicy.BEST_EFFORT,
        durability=DurabilityPolicy.TRANSIENT_LOCAL if latched else DurabilityPolicy.VOLATILE,
    )
