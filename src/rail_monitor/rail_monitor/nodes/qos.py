"""QoS profiles of the graph's topics, and their rosbag2 metadata form."""

from __future__ import annotations

from typing import Any

from rclpy.qos import DurabilityPolicy, HistoryPolicy, QoSProfile, ReliabilityPolicy

from rail_monitor.bagio.mcap_bag import qos_dict

# Pass events and model outputs: reliable, deep enough that a burst is queued, not dropped;
# publishers also wait for acknowledgement in batches (PassPublisher) for end-to-end flow control.
STREAM_QOS = QoSProfile(depth=1000, history=HistoryPolicy.KEEP_LAST, reliability=ReliabilityPolicy.RELIABLE,
                        durability=DurabilityPolicy.VOLATILE)
# Standing alerts: a late subscriber sees them.
LATCHED_QOS = QoSProfile(depth=100, history=HistoryPolicy.KEEP_LAST, reliability=ReliabilityPolicy.RELIABLE,
                         durability=DurabilityPolicy.TRANSIENT_LOCAL)
DIAGNOSTICS_QOS = QoSProfile(depth=100, reliability=ReliabilityPolicy.RELIABLE)
CLOCK_QOS = QoSProfile(depth=10, reliability=ReliabilityPolicy.RELIABLE)


def qos_to_dict(qos: QoSProfile) -> dict[str, Any]:
    """An rclpy QoS profile in rosbag2's metadata layout."""
    return qos_dict(
        reliable=qos.reliability == ReliabilityPolicy.RELIABLE,
        transient_local=qos.durability == DurabilityPolicy.TRANSIENT_LOCAL,
        depth=qos.depth,
        keep_all=qos.history == HistoryPolicy.KEEP_ALL,
    )


def subscription_qos(offered: list[QoSProfile]) -> QoSProfile:
    """A subscription QoS compatible with every offered profile (as rosbag2 adapts it)."""
    reliable = bool(offered) and all(q.reliability == ReliabilityPolicy.RELIABLE for q in offered)
    latched = bool(offered) and all(q.durability == DurabilityPolicy.TRANSIENT_LOCAL for q in offered)
    return QoSProfile(
        depth=1000, history=HistoryPolicy.KEEP_LAST,
        reliability=ReliabilityPolicy.RELIABLE if reliable else ReliabilityPolicy.BEST_EFFORT,
        durability=DurabilityPolicy.TRANSIENT_LOCAL if latched else DurabilityPolicy.VOLATILE,
    )
