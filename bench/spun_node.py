"""A node of a benchmark's own process: an rclpy context of its own on the run's DDS domain, spun on a
thread (bench.live's probe, bench.soak's /diagnostics listener)."""

from __future__ import annotations

import os
import threading


class SpunNode:
    """Make the publishers and subscriptions on ``self.node``, then call start()."""

    def __init__(self, name: str) -> None:
        import rclpy
        from rclpy.executors import SingleThreadedExecutor

        self.rclpy = rclpy
        self.ctx = rclpy.Context()
        rclpy.init(context=self.ctx, domain_id=int(os.environ["ROS_DOMAIN_ID"]))
        self.node = rclpy.create_node(name, context=self.ctx)
        self.lock = threading.Lock()
        self.executor = SingleThreadedExecutor(context=self.ctx)
        self.thread = threading.Thread(target=self._spin, daemon=True)

    def start(self) -> None:
        self.executor.add_node(self.node)
        self.thread.start()

    def _spin(self) -> None:
        while self.ctx.ok():
            self.executor.spin_once(timeout_sec=0.05)

    def close(self) -> None:
        self.executor.shutdown(timeout_sec=1.0)
        self.node.destroy_node()
        self.rclpy.shutdown(context=self.ctx)
        self.thread.join(timeout=5)
