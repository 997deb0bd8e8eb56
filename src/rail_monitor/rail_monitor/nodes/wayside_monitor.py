"""wayside_monitor: the whole graph in one process (multi-threaded executor), like a component
container. Hosts the pass source (replayer of ``source``, or the simulator when ``source`` is
empty) and the recorder; the model nodes join as they land. Exits when the history has been
replayed and every recorded topic has drained; prints a summary.
"""

from __future__ import annotations

import sys
import threading
import time
from dataclasses import dataclass

import rclpy
from rclpy.executors import Executor, ExternalShutdownException, MultiThreadedExecutor, SingleThreadedExecutor
from rclpy.node import Node

from rail_monitor.errors import RailMonitorError
from rail_monitor.nodes.base import declare, use_flow_control_profile
from rail_monitor.nodes.mcap_recorder import McapRecorder
from rail_monitor.nodes.pass_replayer import REPLAYER_SPECS, PassReplayer
from rail_monitor.nodes.pass_simulator import PassSimulator
from rail_monitor.params import ParamSpec

MONITOR_SPECS: tuple[ParamSpec, ...] = (
    ParamSpec("record", True, "Host an mcap_recorder for every output topic."),
    ParamSpec("drain_timeout_s", 60.0, "After the replay, wait at most this for the recorder to catch up [s].",
              0.0, 3600.0),
    ParamSpec("executor", "multi_threaded", "Executor hosting the nodes: multi_threaded (like a component "
              "container) or single_threaded (about 8x the pass rate here: rclpy's thread pool costs more than "
              "it gains under the GIL).", choices=("multi_threaded", "single_threaded")),
    ParamSpec("threads", 4, "Threads of the multi_threaded executor [-].", 1, 64),
)


@dataclass
class MonitorResult:
    published: int
    recorded: dict[str, int]
    bag: str | None
    wall_s: float


class _Settings(Node):
    """Holds the process-level parameters (no topics)."""

    def __init__(self) -> None:
        super().__init__("wayside_monitor")
        self.cfg = declare(self, (*MONITOR_SPECS, REPLAYER_SPECS[0]))


def run_graph(args: list[str] | None = None) -> MonitorResult:
    """Build the graph in this process, replay, drain, shut down; return what happened."""
    use_flow_control_profile()  # for subscribers in other processes (in-process ones are paced exactly)
    rclpy.init(args=args)
    nodes: list[Node] = []
    executor = None
    spinner = None
    t0 = time.monotonic()
    try:
        settings = _Settings()
        nodes.append(settings)
        recorder = McapRecorder() if settings.cfg["record"] else None
        if recorder is not None:
            nodes.append(recorder)
        subscribers = len(nodes) - 1  # every hosted node but the settings takes train_pass
        source = PassReplayer() if settings.cfg["source"] else PassSimulator()
        nodes.append(source)
        source.cfg["wait_for_subscribers"] = max(source.cfg["wait_for_subscribers"], subscribers)
        if recorder is not None:
            topic = source.pub.topic_name
            source.consumed = lambda: recorder.counts.get(topic, 0)
        executor = _make_executor(settings.cfg["executor"], settings.cfg["threads"])
        for n in nodes:
            executor.add_node(n)
        spinner = threading.Thread(target=executor.spin, daemon=True)
        spinner.start()
        published = source.run()
        recorded: dict[str, int] = {}
        bag = None
        if recorder is not None:
            _drain(recorder, source.pub.topic_name, published, settings.cfg["drain_timeout_s"])
            bag = str(recorder.close())
            recorded = dict(recorder.counts)
        return MonitorResult(published, recorded, bag, time.monotonic() - t0)
    finally:
        if executor is not None:
            executor.shutdown(timeout_sec=2.0)
            if spinner is not None and spinner.is_alive():
                spinner.join(timeout=5.0)
        for n in reversed(nodes):
            close = getattr(n, "close", None)
            if close is not None:
                close()
            n.destroy_node()
        rclpy.try_shutdown()


def _make_executor(kind: str, threads: int) -> Executor:
    if kind == "single_threaded":
        return SingleThreadedExecutor()
    return MultiThreadedExecutor(num_threads=threads)


def _drain(recorder: McapRecorder, topic: str, expected: int, timeout_s: float) -> None:
    deadline = time.monotonic() + timeout_s
    while recorder.counts.get(topic, 0) < expected:
        if time.monotonic() > deadline:
            raise RailMonitorError(f"recorder got {recorder.counts.get(topic, 0)} of {expected} messages "
                                   f"on {topic} within {timeout_s:g} s")
        time.sleep(0.02)


def main(args: list[str] | None = None) -> int:
    try:
        r = run_graph(args)
    except RailMonitorError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2
    except (KeyboardInterrupt, ExternalShutdownException):
        return 130
    print(f"wayside_monitor: {r.published} passes through the graph in {r.wall_s:.1f} s "
          f"({r.published / max(r.wall_s, 1e-9):.0f} passes/s)")
    if r.bag:
        print(f"recorded {sum(r.recorded.values())} messages to {r.bag}: "
              + ", ".join(f"{t} {n}" for t, n in sorted(r.recorded.items())))
    return 0


if __name__ == "__main__":
    sys.exit(main())
