"""Publishing a pass history into the graph: timing, /clock, flow control, progress.

Shared by pass_replayer (history from a file) and pass_simulator (generated traffic).
"""

from __future__ import annotations

import sys
import threading
import time
from collections.abc import Callable

import rclpy
from rclpy.duration import Duration
from rclpy.executors import ExternalShutdownException, SingleThreadedExecutor
from rclpy.node import Node
from rosgraph_msgs.msg import Clock
from tqdm import tqdm

from rail_monitor.errors import RailMonitorError
from rail_monitor.nodes.base import Diagnostics, RateMeter, declare, use_flow_control_profile
from rail_monitor.nodes.convert import time_msg, train_pass_msg
from rail_monitor.nodes.qos import CLOCK_QOS, STREAM_QOS
from rail_monitor.params import ParamSpec
from rail_monitor.passes import PassTable
from rail_monitor.site import SITE_SPECS
from rail_monitor.timeutil import NS_PER_S
from rail_msgs.msg import TrainPass

PUBLISH_SPECS: tuple[ParamSpec, ...] = (
    SITE_SPECS[0],  # site_id: header.frame_id of every pass
    ParamSpec("rate", 0.0, "Replay speed: 0 as fast as the graph takes it, 1 recorded timing, "
              "k k-times faster [-].", 0.0, 1.0e9),
    ParamSpec("start_offset_s", 0.0, "Skip passes earlier than the first pass plus this [s].", 0.0, 1.0e10),
    ParamSpec("end_offset_s", 0.0, "Stop after the first pass plus this; 0: to the end [s].", 0.0, 1.0e10),
    ParamSpec("publish_clock", True, "Publish /clock with pass time (nodes use use_sim_time)."),
    ParamSpec("clock_period_s", 0.1, "Wall time between /clock ticks while waiting for the next pass [s].",
              0.001, 60.0),
    ParamSpec("wait_for_subscribers", 0, "Wait for this many train_pass subscribers before starting [-].", 0, 1000),
    ParamSpec("wait_timeout_s", 30.0, "Give up waiting for subscribers after this [s].", 0.0, 3600.0),
    ParamSpec("ack_batch", 100, "Passes published between flow-control checks (below the publisher's "
              "QoS depth of 1000) [-].", 1, 999),
    ParamSpec("ack_timeout_s", 60.0, "Longest wait for subscribers to catch up before the replay fails [s].",
              0.1, 3600.0),
    ParamSpec("max_backlog", 2000, "In one process: most passes published but not yet taken by the slowest "
              "hosted subscriber (below their queue of 10000) [-].", 1, 9000),
    ParamSpec("progress", True, "Show a progress bar on stderr."),
)


class PassSourceNode(Node):
    """Base of the nodes that publish train passes on ``train_pass`` (relative: site namespace)."""

    def __init__(self, name: str, **kwargs) -> None:
        super().__init__(name, **kwargs)
        self.cfg = declare(self, PUBLISH_SPECS)
        self.pub = self.create_publisher(TrainPass, "train_pass", STREAM_QOS)
        self.clock_pub = self.create_publisher(Clock, "/clock", CLOCK_QOS) if self.cfg["publish_clock"] else None
        self.meter = RateMeter()
        self.total = 0
        self.last_stamp_ns = 0
        self.done = threading.Event()
        # Passes taken by the slowest subscriber hosted in this process (set by wayside_monitor).
        self.consumed: Callable[[], int] | None = None
        Diagnostics(self, lambda: {"published": self.meter.count, "total": self.total,
                                   "rate_per_s": f"{self.meter.rate():.1f}",
                                   "pass_time_ns": self.last_stamp_ns, "done": self.done.is_set()})

    def passes(self) -> PassTable:
        """The passes to publish, in time order (subclasses)."""
        raise NotImplementedError

    def _window(self, table: PassTable) -> PassTable:
        table = table.sorted()
        if len(table) == 0:
            return table
        t0 = int(table.stamp_ns[0])
        keep = table.stamp_ns >= t0 + int(self.cfg["start_offset_s"] * NS_PER_S)
        if self.cfg["end_offset_s"] > 0.0:
            keep &= table.stamp_ns <= t0 + int(self.cfg["end_offset_s"] * NS_PER_S)
        return table.take(keep)

    def _publish_clock(self, ns: int) -> None:
        if self.clock_pub is not None:
            self.clock_pub.publish(Clock(clock=time_msg(ns)))

    def _wait_for_subscribers(self) -> None:
        want = self.cfg["wait_for_subscribers"]
        deadline = time.monotonic() + self.cfg["wait_timeout_s"]
        while self.pub.get_subscription_count() < want:
            if time.monotonic() > deadline:
                raise RailMonitorError(f"only {self.pub.get_subscription_count()} of {want} subscribers "
                                       f"on {self.pub.topic_name} after {self.cfg['wait_timeout_s']:g} s")
            time.sleep(0.02)

    def _throttle(self, published: int) -> None:
        """Flow control: where the consumers share this process, wait until the slowest has taken
        all but max_backlog; otherwise until every subscriber holds what was sent (DDS
        acknowledgement; their queues of 10000 absorb the rest).

        In one process we never call wait_for_all_acked: it holds the GIL while it blocks and would
        starve the hosted subscribers of the callbacks that empty their queues. Across processes
        we use short blocking waits: zero-timeout polls do not prompt Fast DDS's heartbeat, and
        the acknowledgement then takes seconds (measured: about 3.6 s per batch of 100).
        """
        deadline = time.monotonic() + self.cfg["ack_timeout_s"]
        slice_ = Duration(seconds=0.05)
        backlog = self.cfg["max_backlog"]

        def behind() -> bool:
            if self.consumed is not None:  # exact, and cheaper than a DDS acknowledgement round
                return published - self.consumed() > backlog
            return not self.pub.wait_for_all_acked(slice_)

        while behind():
            if time.monotonic() > deadline:
                raise RailMonitorError(f"subscribers of {self.pub.topic_name} did not keep up within "
                                       f"{self.cfg['ack_timeout_s']:g} s")
            time.sleep(0.0005)

    def run(self, ok: Callable[[], bool] | None = None) -> int:
        """Publish every pass (blocking); returns how many were published."""
        ok = ok or (lambda: rclpy.ok(context=self.context))
        table = self._window(self.passes())
        self.total = len(table)
        self._wait_for_subscribers()
        rate, frame = self.cfg["rate"], self.cfg["site_id"]
        batch, period = self.cfg["ack_batch"], self.cfg["clock_period_s"]
        stamps = table.stamp_ns
        t0 = int(stamps[0]) if len(table) else 0
        wall0 = time.monotonic()
        bar = tqdm(total=len(table), unit="pass", file=sys.stderr, disable=not self.cfg["progress"],
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
                self.pub.publish(train_pass_msg(table.row(i), frame))
                self.meter.tick()
                self.last_stamp_ns = stamp
                bar.update()
                if (i + 1) % batch == 0:
                    self._throttle(i + 1)
            self._throttle(self.meter.count)
        finally:
            bar.close()
        self.done.set()
        self.get_logger().info(f"published {self.meter.count} of {len(table)} passes")
        return self.meter.count


def run_source(make: Callable[[], PassSourceNode], args: list[str] | None = None) -> int:
    """main() of a pass source: spin in the background, publish in the foreground, exit when done."""
    use_flow_control_profile()
    rclpy.init(args=args)
    node = None
    executor = SingleThreadedExecutor()
    spinner = threading.Thread(target=executor.spin, daemon=True)
    try:
        node = make()
        executor.add_node(node)
        spinner.start()
        node.run()
    except RailMonitorError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2
    except (KeyboardInterrupt, ExternalShutdownException):
        return 130
    finally:
        executor.shutdown(timeout_sec=1.0)
        if spinner.is_alive():  # leave no thread inside rcl when the interpreter exits
            spinner.join(timeout=5.0)
        if node is not None:
            node.destroy_node()
        rclpy.try_shutdown()
    return 0


