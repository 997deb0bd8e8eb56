"""One end of test_processes' state-burst test, run as its own process.

``state_burst.py pub N``: publishes N CorrugationStates on ``state_burst`` with the graph's QoS for
corrugation/state, in bursts of 200 (as the estimator publishes a backlog's states), once a
subscriber is matched; exits when all are acknowledged (code 1 if not within 30 s).
``state_burst.py sub N``: takes them with the noise predictor's and alert manager's subscription
QoS and prints how many arrived (waits at most 30 s for N).
"""

from __future__ import annotations

import sys
import time

import rclpy
from rclpy.duration import Duration
from rclpy.node import Node

from rail_monitor.nodes.convert import TOPICS
from rail_monitor.nodes.qos import STATE_SUB_QOS
from rail_msgs.msg import CorrugationState

BURST = 200  # the model nodes' default max_batch
BANDS = 21


def _spin_until(node: Node, done, timeout_s: float) -> bool:
    end = time.monotonic() + timeout_s
    while not done() and time.monotonic() < end:
        rclpy.spin_once(node, timeout_sec=0.05)
    return done()


def main(role: str, n: int) -> int:
    rclpy.init()
    node = Node(f"state_burst_{role}")
    try:
        if role == "sub":
            got: list[CorrugationState] = []
            node.create_subscription(CorrugationState, "state_burst", got.append, STATE_SUB_QOS)
            _spin_until(node, lambda: len(got) >= n, 30.0)
            print(len(got), len({m.last_train_id for m in got}))
            return 0
        pub = node.create_publisher(CorrugationState, "state_burst", TOPICS["corrugation/state"][1])
        if not _spin_until(node, lambda: pub.get_subscription_count() > 0, 30.0):
            return 1
        time.sleep(0.5)  # the reader's side of the match
        msg = CorrugationState(wavelength_m=[0.1] * BANDS, amplitude_m=[1e-6] * BANDS, threshold_m=[1e-5] * BANDS,
                               post_grinding_m=[1e-7] * BANDS)
        for i in range(n):
            msg.last_train_id = str(i)
            pub.publish(msg)
            if i % BURST == BURST - 1:
                time.sleep(0.005)  # the models' work between two backlogs
        return 0 if pub.wait_for_all_acked(Duration(seconds=30)) else 1
    finally:
        node.destroy_node()
        rclpy.try_shutdown()


if __name__ == "__main__":
    sys.exit(main(sys.argv[1], int(sys.argv[2])))
