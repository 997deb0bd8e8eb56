"""Shared base of the model nodes: take train_pass, validate, count rejections, diagnose.

A malformed pass is rejected with its reason (rail_monitor.passes.rejection_reasons), counted
per reason on /diagnostics, logged (throttled) and never reaches the model, so it leaves any
state untouched. A model raising on an accepted pass is a bug: it is counted and logged, the
node's diagnostics go to ERROR, and the node goes on with the next pass.

A callback takes the passes already queued behind its message too (at most ``max_batch``), and
the model handles each run of accepted passes in one vectorised call: a replay or a catch-up
costs a fraction per pass of what it costs one pass at a time; outputs and their order are the same.
"""

from __future__ import annotations

from collections import Counter
from typing import Any

from diagnostic_msgs.msg import DiagnosticStatus
from rclpy.node import Node

from rail_monitor.nodes.base import Diagnostics, RateMeter, declare, declare_site, subscribe_batched
from rail_monitor.nodes.convert import time_ns, train_pass_row
from rail_monitor.nodes.qos import STREAM_SUB_QOS
from rail_monitor.params import ParamSpec
from rail_monitor.passes import PassTable, rejection_reasons, with_class_defaults
from rail_monitor.timeutil import format_iso_ns
from rail_msgs.msg import TrainPass

BATCH_SPECS: tuple[ParamSpec, ...] = (
    ParamSpec("max_batch", 200, "Most queued train passes a callback takes and handles at once (1: one by one) [-].",
              1, 10_000),
)


class PassModelNode(Node):
    """Subscribes ``train_pass``; subclasses implement :meth:`on_pass` for accepted passes."""

    def __init__(self, name: str, **kwargs: Any) -> None:
        super().__init__(name, **kwargs)
        self.site = declare_site(self)
        self.taken = 0  # train_pass messages handled (the pass source's flow control reads it)
        self.accepted = RateMeter()
        self.rejected: Counter[str] = Counter()
        self.model_errors: Counter[str] = Counter()  # accepted passes a model raised on (a bug: ERROR)
        self.last_pass_ns = 0
        self.max_batch = declare(self, BATCH_SPECS)["max_batch"]
        subscribe_batched(self, TrainPass, "train_pass", self._on_train_passes, STREAM_SUB_QOS, self.max_batch)
        Diagnostics(self, self.diagnostic_values, level=self._level)

    def on_pass(self, table: PassTable, msg: TrainPass) -> None:
        """Handle one accepted pass: a one-row table with class defaults filled, and its message."""
        raise NotImplementedError

    def on_passes(self, table: PassTable, msgs: list[TrainPass]) -> None:
        """Handle consecutive accepted passes, in order (table rows match msgs). Default: on_pass
        one by one; a model overrides it with one vectorised call, computing before it publishes."""
        for i, msg in enumerate(msgs):
            self.on_pass(table.take(slice(i, i + 1)), msg)

    def on_rejected(self, msg: TrainPass, reason: str) -> None:
        """Handle one rejected pass (after it is counted); nothing by default."""

    def _on_train_passes(self, msgs: list[TrainPass]) -> None:
        try:
            self._handle(msgs)
        finally:
            self.taken += len(msgs)  # after handling: a reader of ``taken`` sees the passes' effects

    def _handle(self, msgs: list[TrainPass]) -> None:
        """Rejections and runs of accepted passes, in message order."""
        table = PassTable.from_rows([train_pass_row(m) for m in msgs])
        reasons = rejection_reasons(table, self.site).tolist()
        i = 0
        while i < len(msgs):
            if reasons[i]:
                self.rejected[reasons[i]] += 1
                self.get_logger().warning(f"pass {msgs[i].train_id!r} rejected: {reasons[i]}",
                                          throttle_duration_sec=5.0)
                self.on_rejected(msgs[i], reasons[i])
                i += 1
                continue
            j = i + 1
            while j < len(msgs) and not reasons[j]:
                j += 1
            self._accept(with_class_defaults(table.take(slice(i, j)), self.site), msgs[i:j])
            i = j

    def _accept(self, table: PassTable, msgs: list[TrainPass]) -> None:
        self.accepted.tick(len(msgs))
        self.last_pass_ns = time_ns(msgs[-1].header.stamp)
        self._run(table, msgs)

    def _run(self, table: PassTable, msgs: list[TrainPass]) -> None:
        try:
            self.on_passes(table, msgs)
        except Exception as exc:  # a model failing on one accepted pass must not stop the node
            if len(msgs) > 1:  # find the pass it fails on: the others go through
                for i, msg in enumerate(msgs):
                    self._run(table.take(slice(i, i + 1)), [msg])
                return
            self.model_error(msgs[0], exc)

    def model_error(self, msg: TrainPass, exc: Exception) -> None:
        """Count and log a model raising on an accepted pass (diagnostics go to ERROR)."""
        why = f"{type(exc).__name__}: {(str(exc).splitlines() or [''])[0]}"
        self.model_errors[why] += 1
        self.get_logger().error(f"pass {msg.train_id!r}: model error {why}", throttle_duration_sec=5.0)

    def diagnostic_values(self) -> dict[str, Any]:
        values: dict[str, Any] = {
            "accepted": self.accepted.count,
            "rejected": sum(self.rejected.values()),
            "rate_per_s": f"{self.accepted.rate():.1f}",
            "last_pass": format_iso_ns(self.last_pass_ns) if self.last_pass_ns else "",
        }
        values.update({f"rejected: {reason}": n for reason, n in sorted(self.rejected.items())})
        values["model errors"] = sum(self.model_errors.values())
        values.update({f"model error: {why}": n for why, n in sorted(self.model_errors.items())})
        return values

    def _level(self) -> tuple[int, str]:
        if self.model_errors:
            return DiagnosticStatus.ERROR, f"{sum(self.model_errors.values())} pass(es) failed in a model"
        n = sum(self.rejected.values())
        if n:
            return DiagnosticStatus.WARN, f"{n} pass(es) rejected"
        return DiagnosticStatus.OK, "ok"
