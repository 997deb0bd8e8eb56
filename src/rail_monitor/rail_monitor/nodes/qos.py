"""QoS profiles of the graph's topics, and their rosbag2 metadata form."""

from __future__ import annotations

from typing import Any

from rclpy.qos import DurabilityPolicy, HistoryPolicy, QoSProfile, ReliabilityPolicy

from rail_monitor.bagio.mcap_bag import qos_dict

# Pass events and model outputs: reliable. Publishers keep 1000; subscribers queue 10000 so a
# burst waits rather than drops. The pass source adds flow control on top (see pass_source):
# KEEP_ALL readers would give DDS-level backpressure, but Fast DDS's stalled at about 5,100
# samples here, so we do not use them.
STREAM_QOS = QoSProfile(depth=1000, history=HistoryPolicy.KEEP_LAST, reliability=ReliabilityPolicy.RELIABLE,
                        durability=DurabilityPolicy.VOLATILE)
STREAM_SUB_QOS = QoSProfile(depth=10000, history=HistoryPolicy.KEEP_LAST, reliability=ReliabilityPolicy.RELIABLE,
                            durability=DurabilityPolicy.VOLATILE)
DIAGNOSTICS_QOS = QoSProfile(depth=100, reliability=ReliabilityPolicy.RELIABLE)
# A state whose latest value is what matters (corrugation state, speed advisory): a late
# subscriber (a dashboard started later) gets the current one at once.
LATEST_QOS = QoSProfile(depth=1, history=HistoryPolicy.KEEP_LAST, reliability=ReliabilityPolicy.RELIABLE,
                        durability=DurabilityPolicy.TRANSIENT_LOCAL)
# The corrugation state: every state matters to the noise predictor, the alert manager and the
# recorder (each takes them all, in order), and the estimator publishes a backlog's states in one
# burst. A reliable KEEP_LAST writer overwrites samples not yet delivered once its history is full,
# so at depth 1 a burst over UDP lost states (5 of 304 at the recorder, one at the noise predictor).
# Latched too: a late subscriber gets the recent states; one with depth 1 keeps the current one.
STATE_QOS = QoSProfile(depth=1000, history=HistoryPolicy.KEEP_LAST, reliability=ReliabilityPolicy.RELIABLE,
                       durability=DurabilityPolicy.TRANSIENT_LOCAL)
# A subscriber that must see every state in order (not just the latest): latched, deep queue.
STATE_SUB_QOS = QoSProfile(depth=10000, history=HistoryPolicy.KEEP_LAST, reliability=ReliabilityPolicy.RELIABLE,
                           durability=DurabilityPolicy.TRANSIENT_LOCAL)
# Rare events that must not be lost (roughness surveys, grinding events).
EVENT_QOS = QoSProfile(depth=100, history=HistoryPolicy.KEEP_LAST, reliability=ReliabilityPolicy.RELIABLE,
                       durability=DurabilityPolicy.VOLATILE)
# Alert raise/clear events: reliable and latched, deep enough that a late subscriber gets the
# recent history; the standing set is on alerts/standing (LATEST_QOS).
ALERT_QOS = QoSProfile(depth=1000, history=HistoryPolicy.KEEP_LAST, reliability=ReliabilityPolicy.RELIABLE,
                       durability=DurabilityPolicy.TRANSIENT_LOCAL)
CLOCK_QOS = QoSProfile(depth=10, reliability=ReliabilityPolicy.RELIABLE)


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
