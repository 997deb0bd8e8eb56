"""mcap_recorder: record the graph's topics into a rosbag2-compatible MCAP bag folder.

Records every topic whose type is in rail_msgs, and /diagnostics, or the topics named in
``topics``. Messages are taken serialised (no decode). Log time is the node clock at receipt, as
rosbag2 records (on sim time: pass time); ``log_time:=header`` uses the header stamp. The bag is
finalised on SIGINT and SIGTERM, after taking what was already delivered (a stop right after a
burst loses nothing); chunks are closed every ``flush_period_s``, so a SIGKILL loses
at most that much. A write error (a full disk) stops the recording: /diagnostics goes to ERROR
with the error and a count of messages not recorded, the file keeps every whole record written
before it (rail-monitor info --salvage reads them), and the node exits 2 at shutdown.
"""

from __future__ import annotations

import sys
import threading
import time
from collections import Counter
from datetime import UTC, datetime
from pathlib import Path

from diagnostic_msgs.msg import DiagnosticStatus
from rclpy.executors import Executor
from rclpy.qos import QoSProfile

from rail_monitor.bagio.mcap_bag import McapBagWriter
from rail_monitor.bagio.site_record import SITE_RECORD, custom_data, describe, site_record
from rail_monitor.codec.typestore import header_stamp_ns, starts_with_header
from rail_monitor.core.errors import RailMonitorError
from rail_monitor.core.node_params import RECORDER_SPECS, RecorderParams
from rail_monitor.core.timeutil import NS_PER_S
from rail_monitor.messages.topics import DIAGNOSTICS_TOPIC
from rail_monitor.nodes.base import Diagnostics, RateMeter, announce, wall_timer
from rail_monitor.nodes.process import SESSION_PARAMS_FILES, run_node, spin_once_guarded
from rail_monitor.nodes.qos import qos_to_dict
from rail_monitor.nodes.topic_tap import TapNode, TopicTap

BEFORE_CLOCK_MAX = 20_000  # messages held for the first /clock; past that, logged as they come


class McapRecorder(TapNode):
    EXECUTABLE = "mcap_recorder"
    PARAMETERS = (("", RECORDER_SPECS),)
    CONFIG = RecorderParams

    def __init__(self, **kwargs) -> None:
        super().__init__(**kwargs)
        out = self.cfg.output or f"rail_monitor_{datetime.now(UTC):%Y_%m_%d-%H_%M_%S}"
        site = self.cfg.site_file or next(iter(SESSION_PARAMS_FILES), "")
        record = site_record(site) if site else None
        self.writer = McapBagWriter(
            Path(out), compression=self.cfg.compression, chunk_size=self.cfg.chunk_size,
            max_file_bytes=self.cfg.max_bag_size,
            max_file_duration_ns=int(self.cfg.max_bag_duration_s * NS_PER_S),
            flush_wall_period_s=self.cfg.flush_period_s, max_total_bytes=self.cfg.max_total_bytes,
            max_age_ns=int(self.cfg.max_age_s * NS_PER_S),
            records={SITE_RECORD: record} if record else None, custom_data=custom_data(record) if record else None)
        self._lock = threading.RLock()  # a write failure publishes diagnostics, which read the writer
        self._has_header: dict[str, bool] = {}
        self._before_clock: list[tuple[str, bytes]] = []  # received on sim time before the first /clock
        self.counts: dict[str, int] = {}
        self.meter = RateMeter()
        self.tap = TopicTap(self, self.cfg.topics, self.cfg.discovery_period_s, self._add_topic, self._on_messages)
        wall_timer(self, max(self.cfg.flush_period_s, 0.05), self._flush, callback_group=self.tap.group)
        self.dropped = 0  # messages not recorded after a write error
        self._failed = False  # a write error was reported
        self.refused: Counter[str] = Counter()  # messages that could not be written, by cause
        self.diagnostics = Diagnostics(
            self, lambda: {"recorded": self.meter.count, "recorded outputs": self.outputs_recorded(),
                           "rate_per_s": f"{self.meter.rate():.1f}",
                           "topics": len(self.tap.subs), "bag": str(self.writer.folder),
                           "not recorded (write failed)": self.dropped, "write error": self.writer.error,
                           **{f"refused: {why}": n for why, n in sorted(self.refused.items())},
                           **{f"recorded {topic}": n for topic, n in sorted(self.counts.items())},
                           **self._health()},
            level=lambda: (DiagnosticStatus.ERROR, self.writer.error) if self.writer.error
            else (DiagnosticStatus.OK, "ok"))
        self.tap.discover()
        announce(self, bag=self.writer.folder, site=describe(record) if record else "none stored",
                 log_time=self.cfg.log_time, compression=self.cfg.compression,
                 max_bag_size=self.cfg.max_bag_size, max_total_bytes=self.cfg.max_total_bytes)

    def outputs_recorded(self) -> int:
        """Messages recorded but /diagnostics (which every node sends each period): a pass source
        waits for this count to stand still before it ends a replay."""
        return self.meter.count - self.counts.get(DIAGNOSTICS_TOPIC, 0)

    def _health(self) -> dict[str, object]:
        with self._lock:
            return self.writer.health()

    def _add_topic(self, topic: str, typename: str, offered: list[QoSProfile]) -> None:
        with self._lock:
            self.writer.add_topic(topic, typename, [qos_to_dict(q) for q in offered])
            self.counts[topic] = 0
            self._has_header[topic] = starts_with_header(typename)
        self.get_logger().info(f"recording {topic} [{typename}]")

    def _on_messages(self, topic: str, msgs: list[bytes]) -> None:
        """The messages of one take, received together: one receipt time."""
        with self._lock:
            if self.writer.closed:
                return
            now = self.get_clock().now().nanoseconds
            if now <= 0 and self.cfg.log_time == "receive":
                for data in msgs:
                    self._before_first_clock(topic, data)
                return
            self._write_before_clock(now)
            self._write(topic, msgs, [self._log_time(topic, data, now) for data in msgs])

    def _before_first_clock(self, topic: str, data: bytes) -> None:
        """Sim time before the first /clock: no receipt time yet. Held, and logged at the clock's
        first time, so the bag's timeline is the pass time's alone (at most BEFORE_CLOCK_MAX held)."""
        if len(self._before_clock) < BEFORE_CLOCK_MAX:
            self._before_clock.append((topic, data))
            return
        self._write_before_clock(0)
        self._write(topic, [data], [self._log_time(topic, data, 0)])

    def _write_before_clock(self, now: int) -> None:
        """Log what arrived before the first /clock at now (the clock's first time), or, when no
        clock ever came (now 0), at its header stamp or the wall clock."""
        held, self._before_clock = self._before_clock, []
        for topic, data in held:
            self._write(topic, [data], [now if now > 0 else self._log_time(topic, data, 0)])

    def _write(self, topic: str, datas: list[bytes], log_times_ns: list[int]) -> None:
        """Write messages of a topic in order; one that cannot be written is counted and skipped."""
        with self._lock:
            before = self.writer.written(topic)
            try:
                self.writer.write_many(topic, datas, log_times_ns)
                done, failed = len(datas), None
            except RailMonitorError as exc:
                done, failed = self.writer.written(topic) - before, None
                self._write_failed(exc, len(datas) - done)
            except Exception as exc:  # one malformed message must not stop the recording
                done, failed = self.writer.written(topic) - before, exc
            self.counts[topic] += done
            self.meter.tick(done)
            if failed is not None:
                self.refused[f"{type(failed).__name__}: {(str(failed).splitlines() or [''])[0]}"] += 1
                self._write(topic, datas[done + 1:], log_times_ns[done + 1:])

    def _log_time(self, topic: str, data: bytes, now: int) -> int:
        """The node clock at receipt, now (as rosbag2; pass time on sim time), or with log_time
        header the header stamp. A time the clock cannot give (0: sim time before the first
        /clock) and a stamp before 1970 cannot be an MCAP log time: the other one, else the wall
        clock, stands in."""
        stamp = header_stamp_ns(data) if self._has_header[topic] else 0
        if self.cfg.log_time == "header" and stamp > 0:
            return stamp
        return now if now > 0 else stamp if stamp > 0 else time.time_ns()

    def _write_failed(self, exc: RailMonitorError, lost: int = 0) -> None:
        """A full disk or a write error: the bag stops; what it holds stays readable (salvage).
        lost: the messages it leaves unrecorded."""
        first = not self._failed
        self._failed = True
        self.dropped += lost
        if first:
            self.get_logger().error(str(exc))
            self.diagnostics.publish()  # at once: an operator must hear of it before the next period

    def _flush(self) -> None:
        with self._lock:
            if not self.writer.closed:
                now = self.get_clock().now().nanoseconds
                if self._before_clock and now > 0:  # the clock started, and nothing came since
                    self._write_before_clock(now)
                try:
                    self.writer.flush()
                except RailMonitorError as exc:
                    self._write_failed(exc)

    def drain(self, executor: Executor, quiet_s: float = 0.3) -> None:
        """After SIGINT or SIGTERM: take what is already queued (a burst just before the signal)
        until nothing arrives for quiet_s [s], at most stop_timeout_s; then the bag is closed."""
        deadline = time.monotonic() + self.cfg.stop_timeout_s
        last, quiet_since = self.meter.count, time.monotonic()
        while time.monotonic() < deadline and spin_once_guarded(executor, 0.05):
            if self.meter.count != last:
                last, quiet_since = self.meter.count, time.monotonic()
            elif time.monotonic() - quiet_since >= quiet_s:
                return

    def close(self) -> Path:
        """Finalise the bag (metadata.yaml, summary); safe to call twice."""
        with self._lock:
            if self.writer.closed:
                return self.writer.folder
            self._write_before_clock(self.get_clock().now().nanoseconds)
            folder = self.writer.close()  # RailMonitorError after a write error: run_node exits 2
        self.get_logger().info(f"bag {folder}: {self.meter.count} messages")
        return folder


def main(args: list[str] | None = None) -> int:
    return run_node(McapRecorder, args)


if __name__ == "__main__":
    sys.exit(main())
